"""Pygame rendering of the bearing-only SLAM environment, in the style of the paper's
figures: true landmarks as stars, estimates as circles, uncertainty polygons, the robot,
its trajectory, and the bearing cones of the last movement.

pygame is imported lazily, inside the renderer, so the environment runs without it
unless something is rendered. Only ``pygame.display`` (for the "human" window) and
``pygame.font`` (for text) are initialised, never the whole of pygame: audio and
joystick subsystems fail or hang on headless machines.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from bearing_env.extras import require
from bearing_env.slam import fl_to_world
from bearing_env.world import Arena

if TYPE_CHECKING:
    from bearing_env.envs.config import EnvConfig
    from bearing_env.envs.state import BatchState
    from bearing_env.slam import PolygonSLAM

FloatArray = NDArray[np.float64]

#: Width of the frame in pixels; the height follows the arena's aspect ratio.
FRAME_WIDTH = 800
HEADER_HEIGHT = 34
FOOTER_HEIGHT = 30
PADDING = 16

BACKGROUND = (250, 250, 247)
FIELD = (236, 242, 232)
FIELD_EDGE = (90, 100, 90)
TEXT = (30, 30, 35)
MUTED = (110, 110, 118)
ROBOT = (40, 40, 48)
TRAJECTORY = (120, 120, 130)
FRAME_LANDMARK = (55, 55, 62)
OBSTACLE = (120, 104, 88)
OBSTACLE_EDGE = (70, 60, 50)
#: The camera's field of view (a translucent wedge) and a landmark the last reading missed.
FIELD_OF_VIEW = (230, 190, 60)
MISSED = (175, 175, 180)
# Tableau-like palette for landmarks L3, L4, ...: distinct and readable on light green.
PALETTE = (
    (214, 39, 40),
    (31, 119, 180),
    (44, 160, 44),
    (148, 103, 189),
    (255, 127, 14),
    (140, 86, 75),
    (227, 119, 194),
    (23, 190, 207),
    (188, 189, 34),
)


def landmark_colour(index: int) -> tuple[int, int, int]:
    """Display colour of landmark ``index`` (0 = L1, 1 = L2, then the palette)."""
    if index < 2:
        return FRAME_LANDMARK
    return PALETTE[(index - 2) % len(PALETTE)]


@dataclass(frozen=True)
class FieldLayout:
    """Where the arena lies in a frame: the frame size and the world <-> pixel mapping.

    Pure arithmetic (no pygame), so a window that shows the env's frames (``bearing-env
    play``) maps mouse clicks to the world and draws over the field exactly as the
    renderer does.
    """

    #: Frame (width, height) in pixels.
    size: tuple[int, int]
    #: The field's (left, top, width, height) in pixels.
    field_box: tuple[int, int, int, int]
    pixels_per_metre: float

    @classmethod
    def for_arena(cls, arena: Arena) -> FieldLayout:
        usable = FRAME_WIDTH - 2 * PADDING
        pixels_per_metre = usable / arena.width
        field_height = round(arena.height * pixels_per_metre)
        return cls(
            size=(FRAME_WIDTH, HEADER_HEIGHT + field_height + FOOTER_HEIGHT),
            field_box=(PADDING, HEADER_HEIGHT, usable, field_height),
            pixels_per_metre=pixels_per_metre,
        )

    def to_pixels(self, points: ArrayLike) -> FloatArray:
        """World (..., 2) metres -> pixel (..., 2) (y down)."""
        p = np.asarray(points, dtype=np.float64)
        left, top, _, height = self.field_box
        x = left + p[..., 0] * self.pixels_per_metre
        y = top + height - p[..., 1] * self.pixels_per_metre
        return np.stack([x, y], axis=-1)

    def to_world(self, pixels: ArrayLike) -> FloatArray:
        """Pixel (..., 2) -> world (..., 2) metres: the inverse of :meth:`to_pixels`."""
        p = np.asarray(pixels, dtype=np.float64)
        left, top, _, height = self.field_box
        x = (p[..., 0] - left) / self.pixels_per_metre
        y = (top + height - p[..., 1]) / self.pixels_per_metre
        return np.stack([x, y], axis=-1)

    def in_field(self, pixel: tuple[float, float]) -> bool:
        """Whether a pixel lies on the field (edges included)."""
        left, top, width, height = self.field_box
        return left <= pixel[0] <= left + width and top <= pixel[1] <= top + height


@dataclass(frozen=True)
class Scene:
    """Everything drawn in one frame, in world coordinates (metres).

    The FL regions are mapped to the world with the *true* L1 and L2
    (``z_world = L1 + z_fl * (L2 - L1)``): what the map would mean if the frame were
    anchored at the real landmarks. A region containing the truth in FL contains the true
    landmark on screen.
    """

    arena: Arena
    landmarks: FloatArray
    estimates: FloatArray
    regions: list[FloatArray | None]
    robot_region: FloatArray | None
    robot_position: FloatArray
    robot_heading: float
    trajectory: FloatArray
    start_position: FloatArray | None
    start_bearings: FloatArray | None
    end_bearings: FloatArray
    epsilon: float
    moves: int
    max_moves: int
    total_area: float
    n_initialised: int
    frame_changed: bool
    robot_radius: float
    #: The arena's obstacles (polygons of (x, y) vertices, metres).
    obstacles: tuple[tuple[tuple[float, float], ...], ...] = ()
    #: The camera's half field of view (radians; pi: panoramic) and range (metres).
    half_fov: float = math.pi
    max_range: float = math.inf


def scene(state: BatchState, row: int, config: EnvConfig, slam: PolygonSLAM) -> Scene:
    """What the renderer draws for row ``row`` of an env batch's state: the truth from
    ``state``, the robot's map ``slam``, the settings from ``config``. Rendering reads
    the envs' functional core; the core never imports rendering."""
    n = int(state.n_landmarks[row])
    landmarks = state.landmarks[row, :n].copy()
    l1, l2 = landmarks[0], landmarks[1]

    def to_world(points: FloatArray | None) -> FloatArray | None:
        return None if points is None else fl_to_world(points, l1, l2)

    has_moved = bool(np.all(np.isfinite(state.start_positions[row])))
    areas = slam.areas
    return Scene(
        arena=config.layout.arena,
        landmarks=landmarks,
        estimates=fl_to_world(slam.estimates, l1, l2),
        regions=[to_world(polygon) for polygon in slam.polygons],
        robot_region=to_world(slam.robot_polygon),
        robot_position=state.positions[row].copy(),
        robot_heading=float(state.headings[row]),
        trajectory=state.trajectory[row, : state.trajectory_length[row]].copy(),
        start_position=state.start_positions[row].copy() if has_moved else None,
        start_bearings=state.start_bearings[row, :n].copy() if has_moved else None,
        end_bearings=state.latest_bearings[row, :n].copy(),
        epsilon=config.epsilon,
        moves=int(state.moves[row]),
        max_moves=config.task.max_moves,
        total_area=float(np.sum(areas)),
        n_initialised=int(np.sum(slam.initialised)),
        frame_changed=bool(state.frame_changed[row]),
        robot_radius=config.layout.arena.wall_margin,
        obstacles=config.layout.obstacles,
        half_fov=config.sensor.half_fov,
        max_range=config.sensor.max_range,
    )


class Renderer:
    """Draws :class:`Scene` s with pygame.

    Args:
        render_mode: ``"rgb_array"`` (off-screen surface, returns frames) or ``"human"``
            (a window, paced at ``fps``).
        arena: fixes the frame size and the world-to-pixel mapping.
        fps: frames per second of the "human" window.
    """

    def __init__(self, render_mode: str, arena: Arena, fps: int) -> None:
        if render_mode not in ("human", "rgb_array"):
            raise ValueError(f"unknown render_mode {render_mode!r}")
        # Keeps pygame's banner out of every test and training log.
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        pygame = require("pygame", f"rendering (render_mode={render_mode!r})", extra="render")

        self._pygame = pygame
        self.render_mode = render_mode
        self.arena = arena
        self.fps = fps
        self.layout = FieldLayout.for_arena(arena)
        self.pixels_per_metre = self.layout.pixels_per_metre
        self.field_rect = pygame.Rect(*self.layout.field_box)
        self.size = self.layout.size
        pygame.font.init()
        self._font = pygame.font.Font(None, 22)
        self._small_font = pygame.font.Font(None, 18)
        self._window: Any = None
        self._clock: Any = None
        if render_mode == "human":
            pygame.display.init()
            pygame.display.set_caption("BearingSLAM")
            self._window = pygame.display.set_mode(self.size)
            self._clock = pygame.time.Clock()
        self._canvas = pygame.Surface(self.size)
        # Translucent shapes are drawn on this layer and blended in one blit.
        self._overlay = pygame.Surface(self.size, pygame.SRCALPHA)

    # -- coordinates --------------------------------------------------------------------

    def to_pixels(self, points: FloatArray) -> FloatArray:
        """World (..., 2) metres -> pixel (..., 2) (y down)."""
        return self.layout.to_pixels(points)

    def _clipped_outline(self, polygon: FloatArray) -> list[tuple[float, float]] | None:
        """The polygon clipped to a margin around the field, in pixels.

        Regions of far landmarks can be huge; clipping in world coordinates keeps the
        shape exact on screen and the pixel values small for pygame.
        """
        if polygon is None or len(polygon) < 3 or not np.all(np.isfinite(polygon)):
            return None
        reach = 0.5 * max(self.arena.width, self.arena.height)
        clipped = shapely.clip_by_rect(
            shapely.Polygon(polygon),
            -reach,
            -reach,
            self.arena.width + reach,
            self.arena.height + reach,
        )
        if clipped.is_empty or not isinstance(clipped, shapely.Polygon):
            return None
        xy = np.asarray(clipped.exterior.coords)[:-1]
        if len(xy) < 3:
            return None
        return [tuple(p) for p in self.to_pixels(xy)]

    # -- drawing ------------------------------------------------------------------------

    def render(self, scene: Scene) -> NDArray[np.uint8] | None:
        pygame = self._pygame
        canvas, overlay = self._canvas, self._overlay
        canvas.fill(BACKGROUND)
        overlay.fill((0, 0, 0, 0))
        pygame.draw.rect(canvas, FIELD, self.field_rect)

        self._draw_fields_of_view(scene)
        self._draw_cones(scene)
        self._draw_regions(scene)
        # Everything translucent stays inside the field.
        canvas.set_clip(self.field_rect)
        canvas.blit(overlay, (0, 0))
        self._draw_obstacles(scene)
        self._draw_region_outlines(scene)
        self._draw_trajectory(scene)
        canvas.set_clip(None)
        pygame.draw.rect(canvas, FIELD_EDGE, self.field_rect, width=2)
        self._draw_landmarks(scene)
        self._draw_robot(scene)
        self._draw_header(scene)
        self._draw_footer()

        if self.render_mode == "human":
            assert self._window is not None and self._clock is not None
            self._window.blit(canvas, (0, 0))
            pygame.event.pump()
            pygame.display.flip()
            self._clock.tick(self.fps)
            return None
        # surfarray is (width, height, 3); frames are (height, width, 3).
        return np.transpose(pygame.surfarray.array3d(canvas), (1, 0, 2)).astype(np.uint8)

    def _draw_cones(self, scene: Scene) -> None:
        """The +-epsilon bearing cones of the last movement: light at R1, stronger at R2."""
        pygame = self._pygame
        reach = math.hypot(self.arena.width, self.arena.height)
        # The robot's heading during the last move is its current heading (it turns
        # before moving), so both readings are relative to it.
        readings = [(scene.robot_position, scene.end_bearings, 45)]
        if scene.start_position is not None and scene.start_bearings is not None:
            readings.insert(0, (scene.start_position, scene.start_bearings, 22))
        for origin, bearings, alpha in readings:
            for index, bearing in enumerate(bearings):
                angles = scene.robot_heading + bearing + np.linspace(-1, 1, 7) * scene.epsilon
                tips = origin + reach * np.stack([np.cos(angles), np.sin(angles)], axis=-1)
                outline = self._clipped_outline(np.vstack([origin, tips]))
                if outline is not None:
                    pygame.draw.polygon(self._overlay, (*landmark_colour(index), alpha), outline)

    def _draw_fields_of_view(self, scene: Scene) -> None:
        """The camera's field of view (cut at its range) at both readings of the last
        move, light at R1 and stronger at R2; nothing for the panoramic camera."""
        if scene.half_fov >= math.pi and math.isinf(scene.max_range):
            return
        reach = min(scene.max_range, math.hypot(self.arena.width, self.arena.height))
        readings = [(scene.robot_position, 60)]
        if scene.start_position is not None:
            readings.insert(0, (scene.start_position, 30))
        for origin, alpha in readings:
            angles = scene.robot_heading + np.linspace(-1, 1, 33) * min(scene.half_fov, math.pi)
            rim = origin + reach * np.stack([np.cos(angles), np.sin(angles)], axis=-1)
            wedge = rim if scene.half_fov >= math.pi else np.vstack([origin, rim])
            outline = self._clipped_outline(wedge)
            if outline is not None:
                self._pygame.draw.polygon(self._overlay, (*FIELD_OF_VIEW, alpha), outline)

    def _draw_obstacles(self, scene: Scene) -> None:
        for polygon in scene.obstacles:
            outline = [tuple(p) for p in self.to_pixels(np.asarray(polygon))]
            self._pygame.draw.polygon(self._canvas, OBSTACLE, outline)
            self._pygame.draw.polygon(self._canvas, OBSTACLE_EDGE, outline, width=2)

    def _draw_regions(self, scene: Scene) -> None:
        pygame = self._pygame
        # The robot's region can dwarf the arena after a poorly conditioned frame change;
        # shading it would then grey out the whole field, so only its outline is drawn.
        if scene.robot_region is not None and _shoelace_area(scene.robot_region) < (
            0.5 * self.arena.width * self.arena.height
        ):
            outline = self._clipped_outline(scene.robot_region)
            if outline is not None:
                pygame.draw.polygon(self._overlay, (*ROBOT, 40), outline)
        for offset, region in enumerate(scene.regions):
            outline = self._clipped_outline(region) if region is not None else None
            if outline is not None:
                pygame.draw.polygon(self._overlay, (*landmark_colour(offset + 2), 70), outline)

    def _draw_region_outlines(self, scene: Scene) -> None:
        pygame = self._pygame
        if scene.robot_region is not None:
            outline = self._clipped_outline(scene.robot_region)
            if outline is not None:
                pygame.draw.polygon(self._canvas, ROBOT, outline, width=1)
        for offset, region in enumerate(scene.regions):
            outline = self._clipped_outline(region) if region is not None else None
            if outline is not None:
                pygame.draw.polygon(self._canvas, landmark_colour(offset + 2), outline, width=2)

    def _draw_trajectory(self, scene: Scene) -> None:
        pygame = self._pygame
        points = self.to_pixels(scene.trajectory)
        if len(points) >= 2:
            pygame.draw.lines(self._canvas, TRAJECTORY, False, [tuple(p) for p in points], 2)
        for point in points:
            pygame.draw.circle(self._canvas, TRAJECTORY, tuple(point), 3)

    def _draw_landmarks(self, scene: Scene) -> None:
        pygame = self._pygame
        radius = 11
        for index, landmark in enumerate(scene.landmarks):
            # A landmark the last reading missed is drawn grey: the sensor did not see it.
            colour = landmark_colour(index)
            centre = self.to_pixels(landmark)
            if index >= 2:
                estimate = scene.estimates[index - 2]
                if np.all(np.isfinite(estimate)):
                    at = self.to_pixels(estimate)
                    # The error, as in the paper's Fig 10: estimate to truth.
                    pygame.draw.line(self._canvas, colour, tuple(centre), tuple(at), 1)
                    pygame.draw.circle(self._canvas, (255, 255, 255), tuple(at), 7)
                    pygame.draw.circle(self._canvas, colour, tuple(at), 7, width=3)
            star = _star(centre, radius, 0.45 * radius)
            # A landmark the last reading missed is drawn grey: the sensor did not see it.
            seen = not math.isnan(scene.end_bearings[index])
            pygame.draw.polygon(self._canvas, colour if seen else MISSED, star)
            pygame.draw.polygon(self._canvas, (255, 255, 255), star, width=1)
            label = self._small_font.render(f"L{index + 1}", True, colour)
            self._canvas.blit(label, (centre[0] + radius - 1, centre[1] - radius - 4))

    def _draw_robot(self, scene: Scene) -> None:
        pygame = self._pygame
        centre = self.to_pixels(scene.robot_position)
        radius = max(6.0, scene.robot_radius * self.pixels_per_metre)
        pygame.draw.circle(self._canvas, (255, 255, 255), tuple(centre), radius)
        pygame.draw.circle(self._canvas, ROBOT, tuple(centre), radius, width=3)
        # Screen y points down, so the heading's sine flips sign.
        tip = centre + 1.6 * radius * np.array(
            [math.cos(scene.robot_heading), -math.sin(scene.robot_heading)]
        )
        pygame.draw.line(self._canvas, ROBOT, tuple(centre), tuple(tip), 3)

    def _draw_header(self, scene: Scene) -> None:
        n_mapped = len(scene.regions)
        total = f"{scene.total_area:.4f} FL units²" if math.isfinite(scene.total_area) else "n/a"
        status = "map updated" if scene.frame_changed else "no update"
        if scene.moves == 0:
            status = "start"
        text = (
            f"move {scene.moves}/{scene.max_moves}    total area {total}    "
            f"mapped {scene.n_initialised}/{n_mapped}    {status}"
        )
        self._canvas.blit(self._font.render(text, True, TEXT), (PADDING, 9))

    def _draw_footer(self) -> None:
        pygame = self._pygame
        y = self.size[1] - FOOTER_HEIGHT // 2
        x: float = PADDING
        pygame.draw.polygon(self._canvas, FRAME_LANDMARK, _star(np.array([x + 6, y]), 7, 3))
        x = self._footer_text("true landmark", x + 16, y)
        pygame.draw.circle(self._canvas, PALETTE[0], (x + 6, y), 5, width=2)
        x = self._footer_text("estimate (centroid)", x + 16, y)
        pygame.draw.rect(self._canvas, PALETTE[0], pygame.Rect(x, y - 5, 12, 10), width=2)
        x = self._footer_text("uncertainty region", x + 16, y)
        pygame.draw.circle(self._canvas, ROBOT, (x + 6, y), 5, width=2)
        x = self._footer_text("robot", x + 16, y)
        pygame.draw.polygon(
            self._canvas, (200, 200, 205), [(x, y), (x + 16, y - 6), (x + 16, y + 6)]
        )
        x = self._footer_text("bearing cones ±ε", x + 20, y)
        # A scale bar keeps metric distances readable whatever the arena size.
        bar_metres = _nice_length(0.12 * self.arena.width)
        bar_pixels = bar_metres * self.pixels_per_metre
        right = self.size[0] - PADDING
        pygame.draw.line(self._canvas, MUTED, (right - bar_pixels, y), (right, y), 2)
        for end in (right - bar_pixels, right):
            pygame.draw.line(self._canvas, MUTED, (end, y - 4), (end, y + 4), 2)
        label = self._small_font.render(_format_length(bar_metres), True, MUTED)
        self._canvas.blit(label, (right - bar_pixels - label.get_width() - 6, y - 6))

    def _footer_text(self, text: str, x: float, y: float) -> float:
        surface = self._small_font.render(text, True, MUTED)
        self._canvas.blit(surface, (x, y - surface.get_height() // 2))
        return x + surface.get_width() + 14

    def close(self) -> None:
        if self._window is not None:
            self._pygame.display.quit()
            self._window = None


def _shoelace_area(vertices: FloatArray) -> float:
    x, y = vertices[:, 0], vertices[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def _star(centre: FloatArray, outer: float, inner: float) -> list[tuple[float, float]]:
    """A five-pointed star, point up, in pixel coordinates."""
    angles = -math.pi / 2 + np.arange(10) * math.pi / 5
    radii = np.where(np.arange(10) % 2 == 0, outer, inner)
    xs = centre[0] + radii * np.cos(angles)
    ys = centre[1] + radii * np.sin(angles)
    return list(zip(xs.tolist(), ys.tolist(), strict=True))


def _nice_length(length: float) -> float:
    """The largest 1, 2 or 5 x 10^k not above ``length``."""
    exponent = math.floor(math.log10(length))
    for mantissa in (5.0, 2.0, 1.0):
        candidate = mantissa * 10.0**exponent
        if candidate <= length:
            return candidate
    return 10.0**exponent


def _format_length(metres: float) -> str:
    return f"{metres * 100:g} cm" if metres < 1.0 else f"{metres:g} m"
