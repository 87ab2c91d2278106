"""The simulated world: arena, true landmarks, robot pose, motion and the bearing sensor.

numpy, with the motion and the noise-free bearings in the native core (no gymnasium, no
pygame), so it can be reused by planners and benchmarks.

Units: lengths are in **metres**, angles in **radians** (the public constructor arguments
that are in degrees say so in their names, e.g. ``bound_deg``). The paper's Khepera field
is 1.05 m x 0.68 m. World coordinates have their origin at the lower-left corner of the
arena, x to the right, y up; headings are counter-clockwise from +x.

All randomness goes through a :class:`numpy.random.Generator` passed in by the caller, so
the same generator state gives the same world, bit for bit.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env._core import _add_wrapped as _add_wrapped
from bearing_env._core import _add_wrapped_with_outliers as _add_wrapped_with_outliers
from bearing_env._core import _true_bearings_into as _true_bearings_into
from bearing_env._core import bearing as bearing
from bearing_env._core import obstructed_move as obstructed_move
from bearing_env._core import straight_move as straight_move
from bearing_env.numerics import wrap_angle
from bearing_env.obstacles import Obstacle, box
from bearing_env.sensing import Packed, clearance, landmarks_seen, pack_polygons
from bearing_env.validation import float_in, non_negative_float, positive_float

FloatArray = NDArray[np.float64]

#: The Khepera robot-soccer field of the paper's real-robot experiment (metres).
KHEPERA_ARENA_SIZE: tuple[float, float] = (1.05, 0.68)

#: Lengths that are not given explicitly (move length, wall margin, landmark spacing)
#: are scaled with the arena's longer side relative to the Khepera field, so that a
#: scenario behaves the same at any scale.
REFERENCE_ARENA_SIDE: float = KHEPERA_ARENA_SIZE[0]

#: Default move length range on the Khepera field (metres): from a nudge to ~30% of
#: the field's length. The reference runs of docs/design.md use 0.25 m.
REFERENCE_MOVE_LENGTH: tuple[float, float] = (0.05, 0.30)

#: The Khepera robot's radius: the robot centre stops this far from a wall.
REFERENCE_WALL_MARGIN: float = 0.025

#: A move shorter than this (metres, times the arena scale) is "no move": the two readings
#: are taken from the same place, the robot frame FR (R1 = 0, R2 = 1) does not exist and
#: the SLAM update is skipped.
REFERENCE_MIN_BASELINE: float = 1e-4

NOISE_KINDS: tuple[str, ...] = ("uniform", "gaussian", "none")


# --------------------------------------------------------------------------------------
# Arena
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Arena:
    """A rectangular arena ``[0, width] x [0, height]`` in metres."""

    width: float
    height: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "width", positive_float(self.width, "arena width"))
        object.__setattr__(self, "height", positive_float(self.height, "arena height"))

    @property
    def scale(self) -> float:
        """The arena's longer side relative to the Khepera field (1.0 for Khepera)."""
        return max(self.width, self.height) / REFERENCE_ARENA_SIDE

    @property
    def wall_margin(self) -> float:
        """How close (metres) the robot centre may come to a wall."""
        return min(REFERENCE_WALL_MARGIN * self.scale, 0.25 * min(self.width, self.height))

    @property
    def min_baseline(self) -> float:
        """The shortest move (metres) that counts as a move: a robot that cannot travel at
        least this far (facing the wall, up to rounding) stays where it is."""
        return REFERENCE_MIN_BASELINE * self.scale

    @property
    def default_move_length(self) -> tuple[float, float]:
        """Default move length range (metres) at this arena's scale."""
        lo, hi = REFERENCE_MOVE_LENGTH
        return (lo * self.scale, hi * self.scale)

    def contains(self, points: ArrayLike, margin: float = 0.0) -> NDArray[np.bool_]:
        """Whether points (..., 2) lie inside the arena shrunk by ``margin``."""
        p = np.asarray(points, dtype=np.float64)
        x, y = p[..., 0], p[..., 1]
        return (
            (x >= margin) & (x <= self.width - margin) & (y >= margin) & (y <= self.height - margin)
        )

    def free_distance(self, position: ArrayLike, heading: float, margin: float) -> float:
        """Distance the robot can travel from ``position`` along ``heading`` before it
        comes within ``margin`` of a wall (0 if it already is, facing the wall)."""
        x, y = (float(v) for v in np.asarray(position, dtype=np.float64))
        dx, dy = math.cos(heading), math.sin(heading)
        limits = []
        # Per axis: the wall the heading points at is the only one that can stop it.
        if dx > 0.0:
            limits.append((self.width - margin - x) / dx)
        elif dx < 0.0:
            limits.append((margin - x) / dx)
        if dy > 0.0:
            limits.append((self.height - margin - y) / dy)
        elif dy < 0.0:
            limits.append((margin - y) / dy)
        return max(0.0, min(limits)) if limits else math.inf


# --------------------------------------------------------------------------------------
# Bearing sensor noise
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class NoiseModel:
    """The *true* bearing noise of the simulated sensor (the SLAM only knows epsilon).

    Attributes:
        kind: ``"uniform"`` (error uniform in ``[-bound, +bound]``), ``"gaussian"``
            (error normal with standard deviation ``sigma``) or ``"none"``.
        bound_deg: half-width of the uniform error in degrees; ``None`` means "equal to
            the SLAM's epsilon", the paper's assumption. It may exceed epsilon to model a
            sensor that is worse than the SLAM believes.
        sigma_deg: standard deviation of the Gaussian error in degrees; ``None`` means
            epsilon / 2 (so ~95% of readings fall within +-epsilon).
        outlier_rate: probability, per landmark per reading, that the bearing is replaced
            by a uniformly random angle (a mis-identified blob in the panoramic image).
        detection_rate: probability, per landmark per reading, that the landmark is seen
            at all; a missed landmark's bearing is NaN (occlusion, a missed detection),
            which the SLAM skips for that movement.
    """

    kind: str = "uniform"
    bound_deg: float | None = None
    sigma_deg: float | None = None
    outlier_rate: float = 0.0
    detection_rate: float = 1.0

    def __post_init__(self) -> None:
        if self.kind not in NOISE_KINDS:
            raise ValueError(f"noise kind must be one of {NOISE_KINDS}, got {self.kind!r}")
        for name in ("bound_deg", "sigma_deg"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, non_negative_float(value, f"noise {name}"))
        rate = float_in(self.outlier_rate, "noise outlier_rate", 0.0, 1.0)
        object.__setattr__(self, "outlier_rate", rate)
        rate = float_in(self.detection_rate, "noise detection_rate", 0.0, 1.0, closed_low=False)
        object.__setattr__(self, "detection_rate", rate)

    @classmethod
    def parse(cls, spec: NoiseModel | Mapping[str, Any] | str | None) -> NoiseModel:
        """Build a noise model from a :class:`NoiseModel`, a mapping of its fields (e.g.
        ``{"kind": "gaussian", "sigma_deg": 1.0}``, handy in YAML configs), a kind name,
        or ``None`` (the default: uniform within +-epsilon)."""
        if spec is None:
            return cls()
        if isinstance(spec, NoiseModel):
            return spec
        if isinstance(spec, str):
            return cls(kind=spec)
        if isinstance(spec, Mapping):
            unknown = set(spec) - {
                "kind",
                "bound_deg",
                "sigma_deg",
                "outlier_rate",
                "detection_rate",
            }
            if unknown:
                raise TypeError(f"unknown noise fields {sorted(unknown)!r} in {dict(spec)!r}")
            return cls(**spec)
        raise TypeError(f"noise must be a NoiseModel, a mapping, a str or None, got {spec!r}")

    def corrupt(
        self, rng: np.random.Generator, true_bearings: FloatArray, epsilon: float
    ) -> FloatArray:
        """Noisy bearings (radians, wrapped to [-pi, pi)) from true ones.

        Args:
            rng: the generator all draws come from.
            true_bearings: noise-free bearings (n,), radians.
            epsilon: the SLAM's error bound (radians), the default scale of the noise.
        """
        return self.corrupt_rows([rng], true_bearings[None], epsilon)[0]

    def corrupt_rows(
        self, rngs: Sequence[np.random.Generator], true_bearings: FloatArray, epsilon: float
    ) -> FloatArray:
        """:meth:`corrupt` for many robots at once: row ``i`` of ``true_bearings`` (N, n)
        draws from ``rngs[i]`` (one generator per row), in the order :meth:`corrupt` would."""
        draws = self.draw_rows(rngs, true_bearings.shape[1], epsilon)
        out = np.empty(true_bearings.shape)
        apply_noise(np.ascontiguousarray(true_bearings, dtype=np.float64), draws, out)
        return out

    def draw_rows(
        self, rngs: Sequence[np.random.Generator], size: int, epsilon: float
    ) -> NoiseDraws:
        """The random draws of one reading of ``size`` bearings per robot (row ``i`` from
        ``rngs[i]``); :func:`apply_noise` turns true bearings into the reading.

        Each robot draws its noise, then (with outliers) both outlier arrays in full, then
        (with missed detections) which landmarks it misses, so the stream of draws does
        not depend on which landmarks turn out to be outliers or missed. A missed bearing
        is an outlier whose replacement is NaN.
        """
        rows = len(rngs)
        extras = self.outlier_rate > 0.0 or self.detection_rate < 1.0
        offsets = np.zeros((rows, size))
        is_outlier = np.zeros((rows, size), dtype=bool) if extras else None
        replacement = np.zeros((rows, size)) if extras else None
        for row, rng in enumerate(rngs):
            self._draw_reading(
                rng,
                epsilon,
                offsets[row],
                None if is_outlier is None else is_outlier[row],
                None if replacement is None else replacement[row],
            )
        return NoiseDraws(offsets, is_outlier, replacement)

    @property
    def draws_in_bulk(self) -> bool:
        """Whether a reading draws its offsets alone (no outliers, no missed detections),
        so that ``k`` readings of ``n`` bearings are one draw of ``k * n`` offsets: the
        stream of draws is the same (both distributions draw element by element)."""
        return self.outlier_rate == 0.0 and self.detection_rate == 1.0

    def draw_readings(
        self,
        rng: np.random.Generator,
        epsilon: float,
        offsets: FloatArray,
        is_outlier: NDArray[np.bool_],
        replacement: FloatArray,
    ) -> None:
        """The draws of ``len(offsets)`` successive readings of one robot, into the
        arrays (readings, n) given, in the order :meth:`draw_rows` makes them one reading
        at a time: the envs draw a block of an episode's readings at once. Without
        outliers ``is_outlier`` is all False and ``replacement`` is left as it is."""
        if self.draws_in_bulk:
            is_outlier[:] = False
            self._draw_reading(rng, epsilon, offsets.reshape(-1), None, None)
            return
        for k in range(offsets.shape[0]):
            self._draw_reading(rng, epsilon, offsets[k], is_outlier[k], replacement[k])

    def _draw_reading(
        self,
        rng: np.random.Generator,
        epsilon: float,
        offsets: FloatArray,
        is_outlier: NDArray[np.bool_] | None,
        replacement: FloatArray | None,
    ) -> None:
        """One robot's draws into its arrays: the offsets, then (with outliers) both
        outlier arrays in full, then (with missed detections) which landmarks it misses."""
        size = offsets.shape[0]
        if self.kind == "uniform":
            bound = epsilon if self.bound_deg is None else math.radians(self.bound_deg)
            offsets[:] = rng.uniform(-bound, bound, size)
        elif self.kind == "gaussian":
            sigma = 0.5 * epsilon if self.sigma_deg is None else math.radians(self.sigma_deg)
            offsets[:] = rng.normal(0.0, sigma, size)
        else:
            offsets[:] = 0.0
        if is_outlier is None or replacement is None:
            return
        is_outlier[:] = False
        if self.outlier_rate > 0.0:
            is_outlier[:] = rng.random(size) < self.outlier_rate
            replacement[:] = rng.uniform(-np.pi, np.pi, size)
        if self.detection_rate < 1.0:
            missed = rng.random(size) >= self.detection_rate
            is_outlier |= missed
            replacement[missed] = np.nan


@dataclass(frozen=True)
class NoiseDraws:
    """One reading's random draws per robot (rows): an offset per bearing and, with
    outliers, which bearings are outliers and the random bearings that replace them."""

    offsets: FloatArray
    is_outlier: NDArray[np.bool_] | None
    replacement: FloatArray | None


def apply_noise(true_bearings: FloatArray, draws: NoiseDraws, out: FloatArray) -> None:
    """The noisy reading (wrapped to [-pi, pi)) of true bearings (N, n), into ``out``."""
    if draws.is_outlier is None or draws.replacement is None:
        _add_wrapped(true_bearings, draws.offsets, out)
    else:
        _add_wrapped_with_outliers(
            true_bearings, draws.offsets, draws.is_outlier, draws.replacement, out
        )


# --------------------------------------------------------------------------------------
# Scenarios and layouts
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Scenario:
    """A named world: arena size, unless random fixed landmark positions, and its
    obstacles (polygons, see :mod:`bearing_env.obstacles`)."""

    name: str
    arena_size: tuple[float, float]
    landmarks: tuple[tuple[float, float], ...] | None
    description: str = field(default="", compare=False)
    obstacles: tuple[Obstacle, ...] = ()

    @property
    def n_landmarks(self) -> int | None:
        return None if self.landmarks is None else len(self.landmarks)


SCENARIOS: dict[str, Scenario] = {
    # The paper's Fig 8/9: L1 and L2, 20 cm apart, side by side on the near half of the
    # field; L3 (right) and L4 (left) further up the field. The paper gives no
    # coordinates beyond L1-L2 = 20 cm; these reproduce the figure's arrangement.
    "khepera": Scenario(
        name="khepera",
        arena_size=KHEPERA_ARENA_SIZE,
        landmarks=((0.425, 0.16), (0.625, 0.16), (0.78, 0.50), (0.30, 0.52)),
        description="the paper's real arena: Khepera field 1.05 x 0.68 m, 4 landmarks, "
        "L1-L2 = 0.20 m",
    ),
    # The paper's simulation (Sec 3.2, Fig 7): four landmarks around the centre of a
    # square world, the robot wandering around the centre. L1-L2 = 0.5 m = 1 FL unit.
    "paper_sim": Scenario(
        name="paper_sim",
        arena_size=(2.0, 2.0),
        landmarks=((0.75, 0.60), (1.25, 0.60), (1.35, 1.30), (0.65, 1.40)),
        description="the paper's simulation: 4 landmarks around the centre of a 2 x 2 m square",
    ),
    # A living room of 2 x 1.5 m with a table in the middle, a sofa along the top wall,
    # a shelf against the right wall and an armchair: each hides some landmarks from
    # some places, and the robot must go round them.
    "furnished_room": Scenario(
        name="furnished_room",
        arena_size=(2.0, 1.5),
        landmarks=((0.45, 0.25), (1.05, 0.25), (1.85, 0.85), (1.2, 1.35), (0.12, 0.7)),
        description="a furnished room: 2 x 1.5 m, 5 landmarks, a table, a sofa, a shelf "
        "and an armchair that block motion and sight",
        obstacles=(
            box(0.8, 0.55, 1.2, 0.85),
            box(0.2, 1.15, 0.9, 1.35),
            box(1.6, 0.1, 1.85, 0.6),
            box(1.45, 1.0, 1.7, 1.25),
        ),
    ),
    # A corridor 0.7 m wide that turns a corner: the block fills the rest of a 2 x 2 m
    # square, so no place sees both ends.
    "l_corridor": Scenario(
        name="l_corridor",
        arena_size=(2.0, 2.0),
        landmarks=((0.35, 0.15), (0.95, 0.15), (1.8, 0.5), (0.15, 1.2), (0.55, 1.85)),
        description="a corridor with an L-turn: 0.7 m wide along two walls of a 2 x 2 m "
        "square, 5 landmarks",
        obstacles=(box(0.7, 0.7, 2.0, 2.0),),
    ),
    "random": Scenario(
        name="random",
        arena_size=KHEPERA_ARENA_SIZE,
        landmarks=None,
        description="a new random layout of n_landmarks every episode",
    ),
    "custom": Scenario(
        name="custom",
        arena_size=KHEPERA_ARENA_SIZE,
        landmarks=None,
        description="the explicit landmark positions passed as `landmarks`",
    ),
}


def random_layout(
    rng: np.random.Generator,
    arena: Arena,
    n_landmarks: int,
    max_attempts: int = 200,
    obstacles: Packed | None = None,
) -> FloatArray:
    """Draw ``n_landmarks`` landmark positions (n, 2) uniformly in the arena.

    Landmarks keep away from the walls (the robot must be able to get round them) and
    from each other (two landmarks on top of each other are one landmark). L1 and L2 are
    at least a quarter of the arena's shorter side apart, so the landmark frame FL is well
    conditioned: the FL unit |L1 - L2| is then never tiny compared with the arena.
    Among ``obstacles`` (packed, see :mod:`bearing_env.sensing`) they also keep as far
    from them as from the walls.
    """
    if n_landmarks < 2:
        raise ValueError(f"n_landmarks must be >= 2, got {n_landmarks}")
    inset = min(0.05 * arena.scale, 0.2 * min(arena.width, arena.height))
    low = np.array([inset, inset])
    high = np.array([arena.width - inset, arena.height - inset])
    free_area = float(np.prod(high - low))
    # Spacing: ~a Khepera diameter at Khepera scale, less when many landmarks must fit.
    spacing = min(0.08 * arena.scale, 0.5 * math.sqrt(free_area / n_landmarks))
    frame_spacing = max(spacing, 0.25 * min(arena.width, arena.height))
    while True:
        points = np.empty((n_landmarks, 2))
        count = 0
        attempts = 0
        while count < n_landmarks and attempts < max_attempts * n_landmarks:
            attempts += 1
            candidate = rng.uniform(low, high)
            if obstacles is not None and _clearance(candidate, obstacles) < inset:
                continue
            if count > 0:
                distances = np.hypot(*(points[:count] - candidate).T)
                if distances.min() < spacing or (count == 1 and distances[0] < frame_spacing):
                    continue
            points[count] = candidate
            count += 1
        if count == n_landmarks:
            return points
        # Too crowded for this spacing (deterministic given rng): relax and redraw.
        spacing *= 0.8
        frame_spacing = max(spacing, 0.8 * frame_spacing)


def random_start(
    rng: np.random.Generator,
    arena: Arena,
    landmarks: FloatArray,
    max_attempts: int = 1000,
    obstacles: Packed | None = None,
) -> tuple[FloatArray, float]:
    """A random start pose: position inside the wall margin, not on top of a landmark,
    twice the wall margin from ``obstacles`` (packed, see :mod:`bearing_env.sensing`),
    and a uniform heading."""
    margin = arena.wall_margin
    low = np.array([margin, margin])
    high = np.array([arena.width - margin, arena.height - margin])
    landmark_clearance = 0.04 * arena.scale
    position = rng.uniform(low, high)
    for _ in range(max_attempts):
        if np.min(np.hypot(*(landmarks - position).T)) >= landmark_clearance and (
            obstacles is None or _clearance(position, obstacles) >= 2.0 * margin
        ):
            break
        position = rng.uniform(low, high)
    else:
        if obstacles is not None and _clearance(position, obstacles) < margin:
            raise ValueError(f"found no free start position among the obstacles in {arena}")
    heading = float(rng.uniform(-np.pi, np.pi))
    return position, heading


def _clearance(point: FloatArray, obstacles: Packed) -> float:
    return float(clearance(float(point[0]), float(point[1]), *obstacles))


# --------------------------------------------------------------------------------------
# The world
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class MoveResult:
    """What one straight move did."""

    requested: float
    travelled: float
    blocked: bool


class World:
    """Ground truth: the arena, the landmarks, the robot pose; motion and sensing.

    Args:
        arena: the arena.
        landmarks: true landmark positions (n, 2), metres; index 0 is L1, 1 is L2.
        position: robot start position (2,).
        heading: robot start heading, radians CCW from +x.
        noise: the true bearing noise model.
        epsilon: the SLAM's bearing error bound in radians (the default noise bounds are
            expressed relative to it).
        half_fov: half the camera's field of view, radians (pi, the default: the paper's
            panoramic camera).
        max_range: the camera's range, metres (default: no limit).
        obstacles: polygons that stop moves and hide landmarks (default: none).
    """

    def __init__(
        self,
        arena: Arena,
        landmarks: ArrayLike,
        position: ArrayLike,
        heading: float,
        noise: NoiseModel,
        epsilon: float,
        half_fov: float = math.pi,
        max_range: float = math.inf,
        obstacles: tuple[Obstacle, ...] = (),
    ) -> None:
        self.arena = arena
        self.landmarks = np.array(landmarks, dtype=np.float64)
        if self.landmarks.ndim != 2 or self.landmarks.shape[1] != 2:
            raise ValueError(f"landmarks must have shape (n, 2), got {self.landmarks.shape}")
        self.position = np.array(position, dtype=np.float64)
        self.heading = float(wrap_angle(heading))
        self.noise = noise
        self.epsilon = float(epsilon)
        self.half_fov = float(half_fov)
        self.max_range = float(max_range)
        self.obstacles = tuple(obstacles)
        self._packed = pack_polygons(self.obstacles)

    @property
    def n_landmarks(self) -> int:
        return int(self.landmarks.shape[0])

    @property
    def min_baseline(self) -> float:
        return self.arena.min_baseline

    def turn(self, angle: float) -> None:
        """Turn on the spot by ``angle`` radians (CCW positive)."""
        self.heading = float(wrap_angle(self.heading + angle))

    def move(self, length: float) -> MoveResult:
        """Move straight ahead by ``length`` metres, stopping at the wall margin or an
        obstacle's."""
        travelled, blocked, position = obstructed_moves(
            self.arena,
            self.position[None],
            np.array([self.heading]),
            np.array([float(length)]),
            self._packed,
        )
        self.position = position[0]
        return MoveResult(float(length), float(travelled[0]), bool(blocked[0]))

    def true_bearings(self) -> FloatArray:
        """Noise-free bearings (n,) of all landmarks, relative to the heading, [-pi, pi)."""
        return true_bearings(self.landmarks[None], self.position[None], np.array([self.heading]))[0]

    def seen(self) -> NDArray[np.bool_]:
        """Which landmarks (n,) the camera sees from the pose: within the field of view
        and the range, in line of sight."""
        return landmarks_seen(
            self.landmarks, self.position[None], np.array([self.heading]), self.half_fov,
            self.max_range, self._packed,
        )[0]  # fmt: skip

    def read_bearings(self, rng: np.random.Generator) -> FloatArray:
        """A reading: noisy bearings (n,) relative to the heading, [-pi, pi); NaN for a
        landmark the camera does not see (:meth:`seen`) or the noise model misses."""
        bearings = self.noise.corrupt(rng, self.true_bearings(), self.epsilon)
        return np.where(self.seen(), bearings, np.nan)


# --------------------------------------------------------------------------------------
# Many worlds at once (the envs' core, bearing_env.envs.core; a World is a batch of one)
# --------------------------------------------------------------------------------------


def true_bearings(landmarks: FloatArray, positions: FloatArray, headings: FloatArray) -> FloatArray:
    """Noise-free bearings (N, n) of landmarks (N, n, 2) from poses (N, 2), (N,)."""
    out = np.empty(landmarks.shape[:2])
    _true_bearings_into(
        np.ascontiguousarray(landmarks, dtype=np.float64),
        np.ascontiguousarray(positions, dtype=np.float64),
        np.ascontiguousarray(headings, dtype=np.float64),
        out,
    )
    return out


def straight_moves(
    arena: Arena,
    positions: FloatArray,
    headings: FloatArray,
    lengths: FloatArray,
    min_baseline: float,
) -> tuple[FloatArray, NDArray[np.bool_], FloatArray]:
    """:func:`straight_move` for many robots: ``(travelled, blocked, new positions)``."""
    travelled = np.empty(len(positions))
    blocked = np.empty(len(positions), dtype=bool)
    moved = np.empty((len(positions), 2))
    for i, ((x, y), heading, length) in enumerate(zip(positions, headings, lengths, strict=True)):
        moved[i, 0], moved[i, 1], travelled[i], blocked[i] = straight_move(
            float(x),
            float(y),
            float(heading),
            float(length),
            arena.width,
            arena.height,
            arena.wall_margin,
            min_baseline,
        )
    return travelled, blocked, moved


def obstructed_moves(
    arena: Arena,
    positions: FloatArray,
    headings: FloatArray,
    lengths: FloatArray,
    obstacles: Packed,
) -> tuple[FloatArray, NDArray[np.bool_], FloatArray]:
    """:func:`obstructed_move` for many robots, stopped by the walls and ``obstacles``
    (packed): ``(travelled, blocked, new positions)``; without obstacles it is
    :func:`straight_moves`, bit for bit."""
    settings = (arena.width, arena.height, arena.wall_margin, arena.min_baseline)
    travelled = np.empty(len(positions))
    blocked = np.empty(len(positions), dtype=bool)
    moved = np.empty((len(positions), 2))
    for i, ((x, y), heading, length) in enumerate(zip(positions, headings, lengths, strict=True)):
        moved[i, 0], moved[i, 1], travelled[i], blocked[i] = obstructed_move(
            float(x), float(y), float(heading), float(length), settings, *obstacles
        )
    return travelled, blocked, moved
