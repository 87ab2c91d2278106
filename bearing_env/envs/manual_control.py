"""Manual control of a BearingSLAM env in a pygame window (``bearing-env play``).

The window shows the env's own ``rgb_array`` frame (the regions, estimates, cones and the
robot, drawn by :mod:`bearing_env.rendering`), the pending move as a dashed line from the
robot, and a panel below: the episode, the moves left, the last reward and the episode's
return, the area of each landmark's region and the key help.

The pending move is a turn (relative to the heading, as the env's actions are) and a
length:

* left / right: the next turn counter-clockwise / clockwise. The continuous env steps by
  :data:`TURN_STEP_DEG` degrees; the discrete env steps through its own turn table.
* up / down: the next longer / shorter length, within the env's ``move_length`` range.
  The continuous env steps by a :data:`LENGTH_STEPS`-th of the range; the discrete env
  steps through its length table.
* space or enter: make the move (then the turn returns to straight ahead; the length
  stays).
* left mouse click on the field: move toward the clicked point at once (turn from the
  click, length its distance clipped to the ``move_length`` range; the discrete env takes
  the nearest move of its grid).
* ``r``: the next episode (seed + 1); escape or closing the window: quit.

The preview always shows the move the env will receive: the aim is the decoded action
(:mod:`bearing_env.envs.actions`), so on the discrete env it is a move of the grid.

Events become commands by a pure function, :func:`command_for`; :meth:`ManualControl.apply`
carries a command out and :meth:`ManualControl.run` is the loop (which redraws only after
a change, and waits for events otherwise). Only ``pygame.display`` and ``pygame.font``
are initialised, as the renderer does. pygame (the ``render`` extra) is imported when a
:class:`ManualControl` is made, so this module imports without it.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from bearing_env.envs.actions import DiscreteActions
from bearing_env.envs.bearing_slam import BearingSLAMEnv
from bearing_env.extras import require
from bearing_env.numerics import TWO_PI, wrap, wrap_angle
from bearing_env.rendering import (
    BACKGROUND,
    MUTED,
    PADDING,
    TEXT,
    FieldLayout,
    landmark_colour,
)

FloatArray = NDArray[np.float64]

#: The continuous env's turn step of left / right, degrees (a turn table of 24 turns).
TURN_STEP_DEG = 15.0
#: The continuous env's up / down change the length by this fraction of the range.
LENGTH_STEPS = 10
#: Holding a key repeats it after this delay, at this interval (milliseconds).
KEY_REPEAT_DELAY_MS = 350
KEY_REPEAT_INTERVAL_MS = 70
#: The loop's longest wait for an event, milliseconds (it draws nothing while idle).
IDLE_WAIT_MS = 250
#: The panel under the env's frame: its rows (episode, next move and what the last move
#: did, region areas, keys) may take this many lines each, of this height in pixels.
PANEL_ROW_LINES = (1, 2, 2, 2)
PANEL_LINE = 19
PANEL_ROW_GAP = 4
PANEL_HEIGHT = 8 + sum(PANEL_ROW_LINES) * PANEL_LINE + len(PANEL_ROW_LINES) * PANEL_ROW_GAP
#: The pending move's colour: apart from the landmarks' palette.
AIM = (20, 20, 20)
#: Two values closer than this (radians, metres) are the same table entry.
_SAME = 1e-6


# ----------------------------------------------------------------------------------------
# Commands: what an event asks for
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Turn:
    """Aim at the next turn: ``direction`` +1 counter-clockwise (left), -1 clockwise."""

    direction: int


@dataclass(frozen=True)
class ChangeLength:
    """Aim at the next length: ``direction`` +1 longer, -1 shorter."""

    direction: int


@dataclass(frozen=True)
class Move:
    """Make the pending move."""


@dataclass(frozen=True)
class MoveToward:
    """Move toward the point under the window pixel ``pixel`` (x, y)."""

    pixel: tuple[int, int]


@dataclass(frozen=True)
class Reset:
    """Start the next episode."""


@dataclass(frozen=True)
class Quit:
    """End the loop."""


Command = Turn | ChangeLength | Move | MoveToward | Reset | Quit

#: Keys (pygame key constant names) and their commands.
KEY_COMMANDS: tuple[tuple[tuple[str, ...], Command], ...] = (
    (("K_LEFT",), Turn(+1)),
    (("K_RIGHT",), Turn(-1)),
    (("K_UP",), ChangeLength(+1)),
    (("K_DOWN",), ChangeLength(-1)),
    (("K_SPACE", "K_RETURN", "K_KP_ENTER"), Move()),
    (("K_r",), Reset()),
    (("K_ESCAPE",), Quit()),
)
#: The key help drawn in the window (docs/play.md has the same table).
KEY_HELP: tuple[tuple[str, str], ...] = (
    ("left / right", "turn"),
    ("up / down", "length"),
    ("space / enter", "move"),
    ("click", "move toward the point"),
    ("r", "next episode"),
    ("escape", "quit"),
)


def _pygame() -> Any:
    # Keeps pygame's banner out of the terminal, as the renderer does.
    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    return require("pygame", "manual control (bearing-env play)", extra="render")


def command_for(event: Any) -> Command | None:
    """The command a pygame event asks for; None for any other event.

    Pure: it reads the event's ``type``, ``key``, ``button`` and ``pos`` only. The left
    mouse button (1) moves toward the click; closing the window quits.
    """
    pygame = _pygame()
    if event.type == pygame.QUIT:
        return Quit()
    if event.type == pygame.KEYDOWN:
        for names, command in KEY_COMMANDS:
            if any(event.key == getattr(pygame, name) for name in names):
                return command
        return None
    if event.type == pygame.MOUSEBUTTONDOWN and event.button == 1:
        x, y = event.pos
        return MoveToward((int(x), int(y)))
    return None


# ----------------------------------------------------------------------------------------
# The pending move
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Aim:
    """The pending move: a turn relative to the heading (radians, counter-clockwise) and
    a length (metres)."""

    turn: float
    length: float


def next_turn(turns: FloatArray, current: float, direction: int) -> float:
    """The entry of the circular table ``turns`` nearest to ``current`` strictly in
    ``direction`` (+1 counter-clockwise); ``current`` if the table has no other turn."""
    ahead = np.mod(direction * (turns - current), TWO_PI)
    ahead[(ahead < _SAME) | (ahead > TWO_PI - _SAME)] = np.inf
    if not np.isfinite(ahead.min()):
        return current
    return float(turns[int(np.argmin(ahead))])


def next_length(lengths: FloatArray, current: float, direction: int) -> float:
    """The entry of ``lengths`` nearest to ``current`` strictly in ``direction`` (+1
    longer); ``current`` at the end of the table."""
    ahead = direction * (lengths - current)
    ahead[ahead < _SAME] = np.inf
    if not np.isfinite(ahead.min()):
        return current
    return float(lengths[int(np.argmin(ahead))])


# ----------------------------------------------------------------------------------------
# The window
# ----------------------------------------------------------------------------------------


class ManualControl:
    """Play a BearingSLAM env by hand in a pygame window (see the module doc).

    Args:
        env: a ``BearingSLAM-v1`` or ``BearingSLAMDiscrete-v1`` env (wrapped or not) made
            with ``render_mode="rgb_array"``; the window shows its frames.
        seed: the first episode's seed; episode ``k`` uses ``seed + k``. None: unseeded.

    Attributes:
        aim: the pending move (always one the env's actions can express).
        episode: episodes started before the current one.
        moves, last_reward, episode_return, done: the current episode's so far.
        running: False once a quit command arrived.
    """

    def __init__(self, env: gym.Env[Any, Any], seed: int | None = 0) -> None:
        pygame = _pygame()
        base = env.unwrapped
        if not isinstance(base, BearingSLAMEnv):
            raise TypeError(
                f"manual control needs a BearingSLAM env (BearingSLAM-v1 or "
                f"BearingSLAMDiscrete-v1), got {type(base).__name__}"
            )
        if env.render_mode != "rgb_array":
            raise ValueError(
                "manual control draws the env's frames in its own window: make the env with "
                f"render_mode='rgb_array', got render_mode={env.render_mode!r}"
            )
        self._pygame = pygame
        self.env = env
        self._base = base
        self.layout = FieldLayout.for_arena(base.config.layout.arena)
        self.turns, self.lengths = self._tables()
        self.seed = seed
        self.episode = 0
        self.running = True

        width, height = self.layout.size
        pygame.display.init()
        pygame.font.init()
        title = env.spec.id if env.spec is not None else type(base).__name__
        pygame.display.set_caption(f"bearing-env play: {title}")
        self.window = pygame.display.set_mode((width, height + PANEL_HEIGHT))
        pygame.key.set_repeat(KEY_REPEAT_DELAY_MS, KEY_REPEAT_INTERVAL_MS)
        self._font = pygame.font.Font(None, 21)
        self._redraw = True
        lo, hi = base.config.actions.move_length
        self.aim = self._expressible(0.0, 0.5 * (lo + hi))
        self._start_episode()

    # -- tables and actions ---------------------------------------------------------------

    def _tables(self) -> tuple[FloatArray, FloatArray]:
        """The turns and lengths that left/right and up/down step through."""
        spec, config = self._base.action_spec, self._base.config
        if isinstance(spec, DiscreteActions):
            return spec.tables(config)
        lo, hi = config.actions.move_length
        n_turns = round(360.0 / TURN_STEP_DEG)
        turns = wrap_angle(TWO_PI * np.arange(n_turns) / n_turns)
        return turns, np.unique(np.linspace(lo, hi, LENGTH_STEPS + 1))

    def action(self) -> Any:
        """The env action of the pending move."""
        spec, config = self._base.action_spec, self._base.config
        return spec.encode(config, self.aim.turn, self.aim.length)

    def _expressible(self, turn: float, length: float) -> Aim:
        """The move the env carries out for the action nearest (turn, length)."""
        spec, config = self._base.action_spec, self._base.config
        action = spec.encode(config, turn, length)
        turns, lengths = spec.decode(config, np.array([action]))
        return Aim(float(turns[0]), float(lengths[0]))

    # -- commands -------------------------------------------------------------------------

    def handle(self, events: Iterable[Any]) -> None:
        """Carry out the commands of ``events``, in order; redraw after an exposure."""
        exposed = {self._pygame.VIDEOEXPOSE, self._pygame.WINDOWEXPOSED}
        for event in events:
            command = command_for(event)
            if command is not None:
                self.apply(command)
            elif event.type in exposed:
                self._redraw = True

    def apply(self, command: Command) -> None:
        """Carry out one command."""
        if isinstance(command, Turn):
            turn = next_turn(self.turns, self.aim.turn, command.direction)
            self.aim = self._expressible(turn, self.aim.length)
        elif isinstance(command, ChangeLength):
            length = next_length(self.lengths, self.aim.length, command.direction)
            self.aim = self._expressible(self.aim.turn, length)
        elif isinstance(command, Move):
            self._move()
        elif isinstance(command, MoveToward):
            self._move_toward(command.pixel)
        elif isinstance(command, Reset):
            self.episode += 1
            self._start_episode()
        else:
            self.running = False
        self._redraw = True

    def _start_episode(self) -> None:
        seed = None if self.seed is None else self.seed + self.episode
        _, self.info = self.env.reset(seed=seed)
        self.moves = 0
        self.last_reward = math.nan
        self.episode_return = 0.0
        self.done = False
        self.status = "start"
        self.aim = self._expressible(0.0, self.aim.length)

    def _move(self) -> None:
        if self.done:
            self.status = "the episode has ended: press r for the next one"
            return
        requested = self.aim.length
        _, reward, terminated, truncated, self.info = self.env.step(self.action())
        self.moves += 1
        self.last_reward = float(reward)
        self.episode_return += self.last_reward
        self.done = bool(terminated or truncated)
        travelled = float(self.info["path_length"])
        if terminated:
            self.status = "success: every region is below the target area"
        elif truncated:
            self.status = "out of moves"
        elif travelled < requested - _SAME:
            self.status = f"stopped by the wall after {travelled:.3f} m"
        else:
            self.status = "map updated" if self.info["frame_changed"] else "no map update"
        # Turns are relative: after a move, straight ahead is the natural next aim.
        self.aim = self._expressible(0.0, self.aim.length)

    def _move_toward(self, pixel: tuple[int, int]) -> None:
        if not self.layout.in_field(pixel):
            self.status = "click on the field to move there"
            return
        world = self._base.world
        assert world is not None  # an episode has started
        offset = self.layout.to_world(pixel) - world.position
        distance = math.hypot(float(offset[0]), float(offset[1]))
        if distance < _SAME:
            return
        lo, hi = self._base.config.actions.move_length
        turn = wrap(math.atan2(float(offset[1]), float(offset[0])) - world.heading)
        self.aim = self._expressible(turn, min(max(distance, lo), hi))
        self._move()

    # -- drawing --------------------------------------------------------------------------

    def panel_rows(self) -> list[list[tuple[str, tuple[int, int, int]]]]:
        """The panel's text: rows of (text, colour) items."""
        max_moves = self._base.config.task.max_moves
        reward = "-" if math.isnan(self.last_reward) else f"{self.last_reward:+.3f}"
        seed = "unseeded" if self.seed is None else f"seed {self.seed + self.episode}"
        status = [
            (f"episode {self.episode} ({seed})", TEXT),
            (f"moves left {max_moves - self.moves}/{max_moves}", TEXT),
            (f"last reward {reward}", TEXT),
            (f"return {self.episode_return:+.3f}", TEXT),
        ]
        lo, hi = self._base.config.actions.move_length
        aim = [
            (
                f"next move: turn {math.degrees(self.aim.turn):+.1f} deg, "
                f"length {self.aim.length:.3f} m (range {lo:.3f} to {hi:.3f} m)",
                TEXT,
            ),
            (self.status, MUTED),
        ]
        areas: list[tuple[str, tuple[int, int, int]]] = [("region areas (FL units²):", TEXT)]
        for offset, area in enumerate(np.asarray(self.info["landmark_area"], dtype=float)):
            shown = f"{area:.4f}" if math.isfinite(area) else "not initialised"
            areas.append((f"L{offset + 3} {shown}", landmark_colour(offset + 2)))
        keys = [(f"{keys}: {what}", MUTED) for keys, what in KEY_HELP]
        return [status, aim, areas, keys]

    def draw(self) -> None:
        """Draw the env's frame, the pending move and the panel into the window."""
        pygame = self._pygame
        frame = self.env.render()
        width, height = self.layout.size
        if not isinstance(frame, np.ndarray) or frame.shape != (height, width, 3):
            raise RuntimeError(
                f"expected an rgb_array frame of shape {(height, width, 3)}, got "
                f"{getattr(frame, 'shape', type(frame).__name__)}"
            )
        self.window.fill(BACKGROUND)
        self.window.blit(pygame.image.frombuffer(frame.tobytes(), (width, height), "RGB"), (0, 0))
        self._draw_aim()
        y = height + 6
        for row, lines in zip(self.panel_rows(), PANEL_ROW_LINES, strict=True):
            y = self._flow(row, y, lines)

    def _draw_aim(self) -> None:
        """The pending move as a dashed line from the robot, with a ring at its end."""
        pygame = self._pygame
        world = self._base.world
        assert world is not None
        heading = world.heading + self.aim.turn
        end = world.position + self.aim.length * np.array([math.cos(heading), math.sin(heading)])
        start_px, end_px = self.layout.to_pixels(np.stack([world.position, end]))
        self.window.set_clip(pygame.Rect(*self.layout.field_box))
        span = float(np.hypot(*(end_px - start_px)))
        n_dashes = max(1, int(span // 12))
        for k in range(n_dashes):
            a = start_px + (end_px - start_px) * (k / n_dashes)
            b = start_px + (end_px - start_px) * ((k + 0.6) / n_dashes)
            pygame.draw.line(self.window, AIM, tuple(a), tuple(b), 2)
        pygame.draw.circle(self.window, AIM, tuple(end_px), 6, width=2)
        self.window.set_clip(None)

    def _flow(self, items: list[tuple[str, tuple[int, int, int]]], y: int, lines: int) -> int:
        """Write ``items`` from the left at ``y``, on at most ``lines`` lines; the items
        that do not fit are counted as "+k more". Returns the ``y`` of the next row."""
        font, gap = self._font, 16
        right = self.window.get_width() - PADDING
        # The last line keeps room for the "+k more" note.
        note_width = font.size("+9999 more")[0] + gap
        x, line = PADDING, 1
        for index, (text, colour) in enumerate(items):
            width = font.size(text)[0]
            is_last = index == len(items) - 1
            limit = right if line < lines or is_last else right - note_width
            if x > PADDING and x + width > limit:
                if line == lines:
                    note = font.render(f"+{len(items) - index} more", True, MUTED)
                    self.window.blit(note, (x, y))
                    break
                x, y, line = PADDING, y + PANEL_LINE, line + 1
            self.window.blit(font.render(text, True, colour), (x, y))
            x += width + gap
        return y + PANEL_LINE + PANEL_ROW_GAP

    def screenshot(self, path: str) -> None:
        """Save the window as an image (PNG by the file name)."""
        self._pygame.image.save(self.window, path)

    # -- the loop -------------------------------------------------------------------------

    def run(self) -> None:
        """Handle events until a quit command: redraw after a change, wait otherwise."""
        pygame = self._pygame
        while self.running:
            if self._redraw:
                self.draw()
                pygame.display.flip()
                self._redraw = False
            self.handle([pygame.event.wait(IDLE_WAIT_MS), *pygame.event.get()])

    def close(self) -> None:
        """Close the window and the env."""
        self._pygame.display.quit()
        self.env.close()

    def __enter__(self) -> ManualControl:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
