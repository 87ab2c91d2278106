"""What the robot expects its sensor to see: the planners' visibility prediction.

A planner that scores a move by simulating the readings it would take must also know
which landmarks those readings would miss: with a forward camera (``field_of_view_deg``
below 360) the heading after the turn decides what is in view, and with obstacles a
landmark can hide behind one. :class:`VisibilityPredictor` predicts it from what the
robot knows, never from ground truth:

- its own camera: the field of view and the range (the env's sensor settings, which
  describe the robot's hardware, not the world);
- its own map: the landmark estimates in FL, its believed pose and the FL scale
  (metres per FL unit, from :class:`~bearing_env.agents.belief.RobotBelief`);
- the obstacles only where it bumped into them: after a blocked move it records a disc
  (:data:`BUMP_RADIUS` metres) just ahead of its believed position, and a predicted line
  of sight through a recorded disc is blocked. It has no floor plan.

Everything is in FL (L1 = 0, L2 = 1); bearings are the same there as in the world.
"""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from bearing_env.envs.core import WorldView
from bearing_env.numerics import wrap_angle
from bearing_env.sensing import landmarks_seen, pack_polygons
from bearing_env.world import World, obstructed_moves

from .env_access import bearing_env_of

#: The radius (metres) of the obstacle a bump reveals: the robot knows only that
#: something stopped it about a robot's radius ahead, so it assumes a robot-sized thing.
BUMP_RADIUS = 0.05
#: The radius (metres) of the obstacle a bump is taken for when planning moves: a wall
#: or a piece of furniture is wider than the robot, so paths near a bump are cut too.
OBSTACLE_RADIUS = 0.1
#: The part of the half field of view that counts as well inside it for
#: :func:`keep_in_view`: a landmark's bearing grows over the move.
IN_VIEW = 0.7
#: L1 and L2 further apart than this part of the half field of view: too close to both
#: to keep them in view over a move (the bootstrap backs off).
TOO_CLOSE = 0.4


class VisibilityPredictor:
    """Predicted visibility of landmarks from candidate poses (see the module doc).

    Built from the env only to read the robot's camera (``field_of_view_deg``,
    ``max_range``); :meth:`bumped` and :meth:`reset` keep the obstacles it learnt.
    """

    def __init__(self, env: gym.Env) -> None:
        sensor = bearing_env_of(env).config.sensor
        #: Half the field of view, radians (pi: panoramic), and the range, metres.
        self.half_fov = sensor.half_fov
        self.max_range = sensor.max_range
        #: Centres (FL) of the discs where the robot bumped into something this episode.
        self.bumps: list[complex] = []

    @property
    def limited(self) -> bool:
        """True when the camera itself misses landmarks (a forward field of view or a
        range), whatever the obstacles."""
        return self.half_fov < math.pi or not math.isinf(self.max_range)

    @property
    def trivial(self) -> bool:
        """True when every landmark is predicted visible from everywhere (the paper's
        panoramic camera, no range limit, no bump yet): planners may skip the prediction."""
        return self.half_fov >= math.pi and math.isinf(self.max_range) and not self.bumps

    def reset(self) -> None:
        """Forget the obstacles (a new episode may be a new arena)."""
        self.bumps.clear()

    def bumped(self, position: complex, heading: float, metres_per_unit: float) -> None:
        """Record that a move heading along ``heading`` (FL) was stopped with the robot
        believed at ``position`` (FL): something stands just ahead."""
        ahead = BUMP_RADIUS / metres_per_unit
        self.bumps.append(position + ahead * complex(math.cos(heading), math.sin(heading)))

    def seen(
        self,
        positions: NDArray[np.complex128],
        headings: NDArray[np.float64],
        landmarks: NDArray[np.complex128],
        metres_per_unit: float,
        with_bumps: bool = True,
    ) -> NDArray[np.bool_]:
        """Which landmarks the sensor would see from poses: positions and headings (FL)
        of one shape S, landmarks (..., n) that broadcast against S + (n,) (NaN where
        unknown: predicted seen); out (S + (n,)). ``with_bumps=False``: the camera alone
        (field of view and range), for poses in another frame than the bumps' FL."""
        positions = np.asarray(positions, dtype=np.complex128)[..., None]
        headings = np.asarray(headings, dtype=np.float64)[..., None]
        known = np.isfinite(landmarks)
        offsets = np.where(known, landmarks, 0.0) - positions
        seen = np.ones(offsets.shape, dtype=bool)
        if self.half_fov < math.pi:
            angles = wrap_angle(np.angle(offsets) - headings)
            seen &= np.abs(angles) <= self.half_fov
        if not math.isinf(self.max_range):
            seen &= np.abs(offsets) * metres_per_unit <= self.max_range
        if with_bumps and self.bumps:
            # Every bump at once, on a leading axis.
            bumps = np.array(self.bumps, dtype=np.complex128).reshape(-1, *[1] * offsets.ndim)
            clear = _distance_to_segments(bumps, positions, offsets) > BUMP_RADIUS / metres_per_unit
            seen &= np.all(clear, axis=0)
        return np.asarray(seen | ~np.broadcast_to(known, seen.shape))

    def missed(
        self,
        bearings: NDArray[np.float64],
        positions: NDArray[np.complex128],
        headings: NDArray[np.float64],
        landmarks: NDArray[np.complex128],
        metres_per_unit: float,
        with_bumps: bool = True,
    ) -> NDArray[np.float64]:
        """Simulated ``bearings`` (S + (n,)) with NaN (a missed reading) where
        :meth:`seen` predicts the landmark out of sight; unchanged when :attr:`trivial`."""
        if self.trivial:
            return bearings
        seen = self.seen(positions, headings, landmarks, metres_per_unit, with_bumps)
        return np.where(seen, bearings, np.nan)


def _distance_to_segments(
    point: complex | NDArray[np.complex128],
    starts: NDArray[np.complex128],
    offsets: NDArray[np.complex128],
) -> NDArray[np.float64]:
    """Distances from ``point`` (or points, broadcast) to the segments ``starts`` ->
    ``starts + offsets``."""
    squared = np.abs(offsets) ** 2
    relative = point - starts
    along = np.where(
        squared > 0.0, (relative * np.conj(offsets)).real / np.where(squared > 0, squared, 1), 0.0
    )
    along = np.clip(along, 0.0, 1.0)
    return np.asarray(np.abs(relative - along * offsets))


def travel_until(
    starts: NDArray[np.complex128],
    headings: NDArray[np.float64],
    lengths: NDArray[np.float64],
    obstacles: NDArray[np.complex128],
    radius: float,
) -> NDArray[np.float64]:
    """How far moves (``starts``, ``headings``, ``lengths`` broadcast together) get before
    they touch a disc of ``radius`` around one of the ``obstacles`` (the same frame and
    units); a move from inside a disc and toward its centre gets 0."""
    travelled = np.broadcast_to(np.asarray(lengths, dtype=np.float64), np.broadcast(
        starts, headings, lengths).shape).copy()  # fmt: skip
    turn_back = np.exp(-1j * np.asarray(headings))
    for obstacle in obstacles:
        relative = (obstacle - starts) * turn_back
        along, across = relative.real, relative.imag
        hit = (along > 0.0) & (np.abs(across) < radius)
        contact = np.maximum(along - np.sqrt(np.maximum(radius**2 - across**2, 0.0)), 0.0)
        travelled = np.where(hit, np.minimum(travelled, contact), travelled)
    return travelled


class BearingMemory:
    """The last bearing the robot read of each landmark, carried through its commanded
    turns (relative to the current heading; NaN for a landmark never seen this episode).

    With a forward camera most readings miss most landmarks; the memory tells where to
    turn to bring them back into view. The robot's translation since a reading is
    ignored: a remembered bearing is a hint, fresh readings overwrite it.
    """

    def __init__(self) -> None:
        self.bearings: NDArray[np.float64] = np.empty(0)
        self._turn: float | None = None

    def reset(self) -> None:
        self.bearings = np.empty(0)
        self._turn = None

    def observe(self, bearings: NDArray[np.float64], seen: NDArray[np.bool_], fresh: bool) -> None:
        """Take in a reading (``bearings`` where ``seen``); ``fresh``: a new episode."""
        if fresh or self._turn is None or self.bearings.size != bearings.size:
            self.bearings = np.full(bearings.size, np.nan)
        else:
            self.bearings = wrap_angle(self.bearings - self._turn)
        self.bearings[seen] = bearings[seen]
        self._turn = None

    def commanded(self, turn: float) -> None:
        """Remember the turn about to be made."""
        self._turn = float(turn)


def keep_in_view(
    memory: NDArray[np.float64], turns: NDArray[np.float64], half_fov: float
) -> NDArray[np.float64]:
    """A score per turn for a robot with a forward camera: how many remembered landmarks
    stay well inside the field of view (:data:`IN_VIEW` of its half-width) after the turn, plus 2 if
    L1 and L2 both do (without them the world model learns nothing), plus, below 1, how
    far the nearest of them is from the line of motion (|sin|, as ``spread_turn``)."""
    known = np.isfinite(memory)
    after = wrap_angle(memory[None, :] - turns[:, None])
    inside = known[None, :] & (np.abs(np.where(known[None, :], after, 0.0)) <= IN_VIEW * half_fov)
    frame = inside[:, 0] & inside[:, 1] if memory.size >= 2 else np.zeros(turns.size, bool)
    spread = np.min(np.where(inside, np.abs(np.sin(after)), 1.0), axis=1)
    spread = np.where(inside.any(axis=1), spread, 0.0)
    return np.asarray(inside.sum(axis=1) + 2.0 * frame + 0.99 * spread, dtype=np.float64)


class TrueSensor:
    """PRIVILEGED: what the env's sensor really sees, and how far a move really goes,
    for the oracles (:class:`~bearing_env.agents.heuristics.GreedyOracle`,
    :class:`~bearing_env.agents.lookahead.LookaheadOracle`), never for robot policies.

    Built from the ground truth of a row (its world view, or a :class:`World` copy):
    the true landmarks, the camera's field of view and range, and every obstacle. As a
    planner's ``sensor`` it takes simulated bearings (S + (n,)) from poses given in FL
    (positions and headings of shape S) and puts NaN where the real sensor would miss a
    landmark.
    """

    def __init__(self, world: World | WorldView) -> None:
        self.half_fov = world.half_fov
        self.max_range = world.max_range
        self.arena = world.arena
        self.obstacles = bool(world.obstacles)
        #: The obstacles, packed (see :mod:`bearing_env.sensing`).
        self.obstacle_polygons = pack_polygons(world.obstacles)
        self.landmarks = np.array(world.landmarks, dtype=np.float64)
        l1, l2 = complex(*self.landmarks[0]), complex(*self.landmarks[1])
        #: FL -> world: z_world = origin + unit * z_fl.
        self.origin, self.unit = l1, l2 - l1

    @property
    def trivial(self) -> bool:
        """True for the paper's sensor in an empty arena: every landmark always seen."""
        return self.half_fov >= math.pi and math.isinf(self.max_range) and not self.obstacles

    def __call__(
        self,
        bearings: NDArray[np.float64],
        positions: NDArray[np.complex128],
        headings: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        if self.trivial:
            return bearings
        flat = bearings.reshape(-1, bearings.shape[-1])
        at = self.origin + self.unit * np.broadcast_to(positions, bearings.shape[:-1]).ravel()
        world_headings = np.broadcast_to(headings, bearings.shape[:-1]).ravel() + np.angle(
            self.unit
        )
        seen = landmarks_seen(
            self.landmarks[: flat.shape[1]], np.column_stack([at.real, at.imag]),
            world_headings, self.half_fov, self.max_range, self.obstacle_polygons,
        )  # fmt: skip
        return np.where(seen, flat, np.nan).reshape(bearings.shape)

    def travel(self, position: NDArray[np.float64], heading: float, length: float) -> float:
        """How far (metres) a move from ``position`` (world, metres) along ``heading``
        (world) really goes: stopped by the walls and the obstacles, 0 when it could not
        go the shortest move that changes frames."""
        travelled, _, _ = obstructed_moves(
            self.arena, np.asarray(position)[None], np.array([heading]), np.array([length]),
            self.obstacle_polygons,
        )  # fmt: skip
        return float(travelled[0])
