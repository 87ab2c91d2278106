"""What the robot knows about its own pose, beyond the map: tracked from its commands.

The map (``PolygonSLAM``) gives, after every movement that could change frames, the
robot's region at the end of that movement (its centroid is the position estimate) and
the movement's direction in FL (``robot_heading``). Between such movements the robot
still knows what it *commanded*: the turns (exact: it turns on the spot) and the lengths
(in metres, exact unless a wall stopped it, which it senses). :class:`RobotBelief` adds
those commands to the map's last fix:

- heading in FL = ``slam.robot_heading`` + the turns commanded since the last movement
  that changed frames;
- position in FL = ``slam.robot_estimate`` + the legs driven since then, each converted
  to FL units with the scale below. A leg stopped by the wall counts as 0: the robot
  does not know how far it got.

**The FL scale** (metres per FL unit, i.e. the unknown |L1 - L2| in metres) is needed to
turn a commanded length into FL units. It is estimated from the robot's own bearings:
for every movement that changed frames, L1 and L2 are triangulated in the robot frame FR
(R1 = 0, R2 = 1) from the bearings before and after the move; |L1 - L2| in FR units
times the commanded length is one sample, and the scale is the median of the samples.
The reading before the move is the previous observation's bearings rotated by the
commanded turn (the env takes a fresh reading after the turn that the policy does not
see; both are within +-epsilon of the truth). Samples from bearing pairs with too little
parallax (< 4 epsilon) are dropped: their range error is large. A move stopped by the
wall travelled less than commanded, so its sample overestimates the scale; such samples
are only used while there is no other. Nothing here reads ground truth.

Why not the distance between successive robot estimates? Both are centroids of large
regions (the robot's region is as uncertain as a landmark's), and two successive
movements that both change frames are needed; the triangulation needs one movement and
has a relative error of about epsilon / parallax.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from numpy.typing import NDArray

from bearing_env.belief import median
from bearing_env.belief import scale_sample as scale_sample
from bearing_env.belief import triangulate_fr as triangulate_fr
from bearing_env.envs.observations import (
    BEARING_FEATURES,
    ENTITY_FEATURES,
    ROBOT_FEATURES,
    SPECS,
    EntityObservation,
    observation_slices,
)
from bearing_env.numerics import wrap
from bearing_env.slam import PolygonSLAM

from .base import Movement
from .env_access import bearing_env_of

_PROGRESS = ROBOT_FEATURES.index("progress")
_FRAME_CHANGED = ROBOT_FEATURES.index("last_frame_changed")
_BLOCKED = ROBOT_FEATURES.index("last_move_blocked")
_BEARING_PRESENT = BEARING_FEATURES.index("present")
_BEARING_COS = BEARING_FEATURES.index("cos")
_BEARING_SIN = BEARING_FEATURES.index("sin")


@dataclass(frozen=True)
class ObservationView:
    """The parts of an observation that the heuristics use (all robot-knowable)."""

    progress: float
    frame_changed: bool
    blocked: bool
    #: Latest bearings (n_landmarks,), radians, relative to the current heading; 0 for
    #: a landmark the reading missed (see :attr:`seen`).
    bearings: NDArray[np.float64]
    #: Which landmarks the latest reading saw (n_landmarks,): a missed one reads
    #: (cos, sin) = (0, 0) in the observation.
    seen: NDArray[np.bool_]

    @property
    def n_landmarks(self) -> int:
        """Landmarks in this episode (the bearing slots flagged present)."""
        return int(self.bearings.size)

    @property
    def readings(self) -> NDArray[np.float64]:
        """The bearings with NaN where the reading missed the landmark."""
        return np.where(self.seen, self.bearings, np.nan)

    @property
    def seen_bearings(self) -> NDArray[np.float64]:
        """The bearings of the landmarks the latest reading saw."""
        return self.bearings[self.seen]


class ObservationReader:
    """Parses the env's observation vector (layout: ``BearingSLAMEnv`` docstring).

    The landmark count is read from every observation (its bearing slots' ``present``
    flags), not fixed when the reader is built: with ``n_landmarks=(lo, hi)`` it changes
    from episode to episode, and the empty slots beyond it are not landmarks at bearing 0.
    """

    def __init__(self, env: gym.Env) -> None:
        base = bearing_env_of(env)
        self.bearing_block = observation_slices(int(base.config.observations.max_landmarks))[
            "bearings"
        ]
        #: The landmark table's columns, for the kinds with a table (every kind's table
        #: starts with ENTITY_FEATURES).
        spec = SPECS[base.config.observations.observation]  # the kind's, features or not
        self.table_width = len(spec.features) if isinstance(spec, EntityObservation) else 0

    def read(self, observation: NDArray[np.float32] | Mapping[str, Any]) -> ObservationView:
        """The view of a flat observation, or of one with a landmark table
        (``observation="entities"`` or ``"shapes"``)."""
        if isinstance(observation, Mapping):
            robot = np.asarray(observation["robot"], dtype=np.float64)
            table = np.asarray(observation["landmarks"], dtype=np.float64)
            table = table.reshape(-1, self.table_width)
            present, cos, sin = (
                ENTITY_FEATURES.index(name) for name in ("present", "bearing_cos", "bearing_sin")
            )
        else:
            obs = np.asarray(observation, dtype=np.float64)
            robot = obs
            table = obs[self.bearing_block].reshape(-1, len(BEARING_FEATURES))
            present, cos, sin = _BEARING_PRESENT, _BEARING_COS, _BEARING_SIN
        # The env fills slots L1, L2, ... in order, so the present ones come first.
        bearings = table[: int(np.count_nonzero(table[:, present] > 0.5))]
        return ObservationView(
            progress=float(robot[_PROGRESS]),
            frame_changed=bool(robot[_FRAME_CHANGED] > 0.5),
            blocked=bool(robot[_BLOCKED] > 0.5),
            bearings=np.arctan2(bearings[:, sin], bearings[:, cos]),
            seen=np.hypot(bearings[:, sin], bearings[:, cos]) > 0.5,
        )


@dataclass(frozen=True)
class PoseBelief:
    """The robot's believed pose in FL (before its next turn)."""

    position: complex
    heading: float
    #: Metres per FL unit; None until a movement gave a usable triangulation.
    metres_per_unit: float | None


class RobotBelief:
    """Tracks the robot's FL pose and the FL scale between map fixes (see module doc)."""

    def __init__(self, epsilon: float) -> None:
        self.epsilon = float(epsilon)
        self.reset()

    def reset(self) -> None:
        self._pending: tuple[Movement, NDArray[np.float64]] | None = None
        # Turns commanded since the last movement that changed frames (radians).
        self._turn_since_fix = 0.0
        # Legs driven since that movement: (heading offset from the fix, metres).
        self._legs: list[tuple[float, float]] = []
        self._scale_samples: list[float] = []
        self._blocked_samples: list[float] = []

    def observe(self, view: ObservationView) -> None:
        """Account for the outcome of the last commanded movement."""
        if view.progress == 0.0:
            # A fresh episode (even if the caller forgot reset()): nothing carries over.
            self.reset()
            return
        if self._pending is None:
            return
        movement, bearings_before = self._pending
        self._pending = None
        if view.frame_changed:
            # The map now holds this movement's end point and direction.
            self._turn_since_fix = 0.0
            self._legs = []
            start = np.array([wrap(float(b) - movement.turn) for b in bearings_before])
            sample = scale_sample(start, view.readings, movement.length, self.epsilon)
            if sample is not None:
                # A move stopped by the wall travelled less than commanded, so its sample
                # overestimates the scale: kept apart, used only while there is no other.
                (self._blocked_samples if view.blocked else self._scale_samples).append(sample)
        else:
            self._turn_since_fix = wrap(self._turn_since_fix + movement.turn)
            if not view.blocked:
                self._legs.append((self._turn_since_fix, movement.length))

    def commanded(
        self,
        movement: Movement,
        view: ObservationView,
        remembered: NDArray[np.float64] | None = None,
    ) -> None:
        """Remember the movement about to be sent, with the reading it started from; a
        landmark that reading missed takes its ``remembered`` bearing when given (a
        forward camera's :class:`~bearing_env.agents.visibility.BearingMemory`: stale by
        the moves since it was seen, so a rougher scale sample than none)."""
        readings = view.readings
        if remembered is not None and remembered.size == readings.size:
            readings = np.where(view.seen, readings, remembered)
        self._pending = (movement, readings)

    def metres_per_unit(self) -> float | None:
        samples = self._scale_samples or self._blocked_samples
        if not samples:
            return None
        return median(samples)

    def pose(self, slam: PolygonSLAM) -> PoseBelief | None:
        """The believed pose, or None before the first movement that changed frames."""
        fix_heading = slam.robot_heading
        fix = slam.robot_estimate
        if not (math.isfinite(fix_heading) and np.all(np.isfinite(fix))):
            return None
        scale = self.metres_per_unit()
        position = complex(fix[0], fix[1])
        if self._legs and scale is not None:
            for offset, length in self._legs:
                position += (length / scale) * complex(
                    math.cos(fix_heading + offset), math.sin(fix_heading + offset)
                )
        heading = wrap(fix_heading + self._turn_since_fix)
        return PoseBelief(position=position, heading=heading, metres_per_unit=scale)


def resect_position(
    heading: float, bearings: NDArray[np.float64], landmarks: NDArray[np.complex128]
) -> complex | None:
    """The robot's FL position from its heading in FL and the bearings it reads (NaN:
    missed) of landmarks at known FL positions (NaN: unknown): the point nearest (least
    squares) to the lines of sight back from the landmarks. None without two usable
    lines that cross at 1 degree or more, or if it lies behind one."""
    usable = np.isfinite(bearings) & np.isfinite(landmarks)
    if np.count_nonzero(usable) < 2:
        return None
    directions = np.exp(1j * (heading + bearings[usable]))
    points = landmarks[usable]
    spread = np.abs((directions[:, None].conjugate() * directions[None, :]).imag).max()
    if spread < math.sin(math.radians(1.0)):
        return None
    normal_sum = np.zeros((2, 2))
    target = np.zeros(2)
    for point, direction in zip(points, directions, strict=True):
        unit = np.array([direction.real, direction.imag])
        projector = np.eye(2) - np.outer(unit, unit)
        normal_sum += projector
        target += projector @ np.array([point.real, point.imag])
    solution = np.linalg.solve(normal_sum, target)
    position = complex(solution[0], solution[1])
    if np.any(((points - position) * directions.conjugate()).real <= 0.0):
        return None
    return position


def spread_turn(bearings: NDArray[np.float64], turns: NDArray[np.float64]) -> int:
    """Index of the turn after which every landmark is farthest from the line of motion.

    A landmark near the line of motion (bearing near 0 or pi) gets near-parallel cones
    and no bounded region; the first movement, made before there is any map, maximises
    the smallest ``|sin(bearing - turn)|`` over all landmarks instead.
    """
    clearance = np.min(np.abs(np.sin(bearings[None, :] - turns[:, None])), axis=1)
    return int(np.argmax(clearance))
