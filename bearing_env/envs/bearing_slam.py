"""``BearingSLAM-v0``: active exploration for the paper's bearing-only polygon SLAM."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, SupportsFloat

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import ArrayLike, NDArray

from bearing_env.slam import TRANSFERS, PolygonSLAM, fl_to_world
from bearing_env.slam.batch import BatchedPolygonSLAM
from bearing_env.world import (
    SCENARIOS,
    Arena,
    MoveResult,
    NoiseModel,
    World,
    random_layout,
    random_start,
    step_worlds,
)

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Default episode length in moves; also the registered ``max_episode_steps``.
DEFAULT_MAX_MOVES = 20
#: Default number of landmark slots in the observation (more if ``n_landmarks`` is larger).
DEFAULT_MAX_LANDMARKS = 8
#: Default area (FL units squared) at which an uninitialised landmark counts in the reward,
#: and above which areas are capped. |L1 - L2| = 1, so 10 is a region a few times the
#: size of the L1-L2 baseline squared: larger than any useful estimate.
DEFAULT_AREA_CAP = 10.0
#: Default success threshold: every landmark region below this area (FL units squared).
DEFAULT_TARGET_AREA = 0.05
#: Areas are floored here before taking logs, so log-areas stay finite.
AREA_FLOOR = 1e-10
#: FL coordinates in the observation are clipped to +-this (the frame is |L1 - L2| = 1, so
#: this is 50 baselines away: far beyond any landmark of a sensible layout).
FL_COORD_LIMIT = 50.0
#: Bearing error bounds accepted for epsilon (degrees, exclusive).
EPSILON_DEG_RANGE = (0.0, 45.0)

REWARDS: tuple[str, ...] = ("log_area", "area")

#: Observation layout: the robot block first, then one block per mapped landmark slot
#: (landmarks L3, L4, ...), then one block per bearing slot (L1, L2, L3, ...).
ROBOT_FEATURES: tuple[str, ...] = (
    "robot_x",
    "robot_y",
    "robot_log_area",
    "robot_unknown",
    "heading_cos",
    "heading_sin",
    "progress",
    "last_frame_changed",
    "last_move_blocked",
)
LANDMARK_FEATURES: tuple[str, ...] = ("present", "uninitialised", "x", "y", "log_area")
BEARING_FEATURES: tuple[str, ...] = ("present", "cos", "sin")


@dataclass(frozen=True)
class Movement:
    """One step's motion and readings, before the SLAM update."""

    move: MoveResult
    start_position: FloatArray
    start_bearings: FloatArray
    end_bearings: FloatArray
    #: False when the robot could not move: both readings come from the same place.
    changes_map: bool


def observation_size(max_landmarks: int) -> int:
    """Length of the observation vector for ``max_landmarks`` landmark slots."""
    return (
        len(ROBOT_FEATURES)
        + len(LANDMARK_FEATURES) * (max_landmarks - 2)
        + len(BEARING_FEATURES) * max_landmarks
    )


def observation_slices(max_landmarks: int) -> dict[str, slice]:
    """Where each block lives in the observation vector.

    ``"robot"`` is the robot block; ``"landmarks"`` reshapes to ``(max_landmarks - 2,
    len(LANDMARK_FEATURES))``; ``"bearings"`` to ``(max_landmarks, len(BEARING_FEATURES))``.
    """
    robot_end = len(ROBOT_FEATURES)
    landmarks_end = robot_end + len(LANDMARK_FEATURES) * (max_landmarks - 2)
    return {
        "robot": slice(0, robot_end),
        "landmarks": slice(robot_end, landmarks_end),
        "bearings": slice(landmarks_end, observation_size(max_landmarks)),
    }


def _is_number(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(
        value, (int, float, np.integer, np.floating)
    )


def _positive_float(value: Any, name: str) -> float:
    if not _is_number(value):
        raise TypeError(f"{name} must be a number, got {value!r}")
    out = float(value)
    if not math.isfinite(out) or out <= 0.0:
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return out


def _non_negative_float(value: Any, name: str) -> float:
    if not _is_number(value):
        raise TypeError(f"{name} must be a number, got {value!r}")
    out = float(value)
    if not math.isfinite(out) or out < 0.0:
        raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
    return out


def _int_at_least(value: Any, minimum: int, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an int, got {value!r}")
    if value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value!r}")
    return int(value)


def _choice(value: Any, choices: Sequence[str], name: str) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a str, one of {tuple(choices)}, got {value!r}")
    if value not in choices:
        raise ValueError(f"unknown {name} {value!r}; expected one of {tuple(choices)}")
    return value


class BearingSLAMEnv(gym.Env[NDArray[np.float32], NDArray[np.float32]]):
    """
    ## Description

    Active exploration for the bearing-only polygon SLAM of Huang, Maire & Keeratipranon,
    "Uncertainty analysis of a landmark initialization method for SLAM" (ACRA 2005).

    A robot in a rectangular arena sees every landmark and measures only its *bearing*
    (the angle from the robot's direction of motion), to within +-epsilon. It has no
    odometry. Each movement is a straight line between two panoramic readings; the SLAM
    intersects the bearing cones of the two readings and transfers the resulting regions
    into the landmark frame FL, where L1 = (0, 0) and L2 = (1, 0). A landmark's region
    in FL is the intersection of its regions over all movements so far; its area is the
    landmark's uncertainty. The agent chooses the movements and is rewarded for shrinking
    the uncertainty regions of landmarks L3, L4, ... (L1 and L2 define the frame).

    One step is one movement:

    1. turn on the spot by the chosen angle;
    2. panoramic reading (bearings relative to the new heading);
    3. straight move of the chosen length, stopped at the arena wall (robot radius
       margin); a move that cannot start (facing the wall) leaves the map unchanged;
    4. panoramic reading, and the SLAM update.

    Lengths are in metres; the Khepera scenario's field is 1.05 x 0.68 m.

    ## Action Space

    `Box(-1.0, 1.0, (2,), float32)`:

    | Num | Action      | Mapped to                                             |
    |-----|-------------|-------------------------------------------------------|
    | 0   | turn        | turn angle `pi * a[0]` radians, counter-clockwise     |
    | 1   | move length | `lo + (a[1] + 1) / 2 * (hi - lo)` metres, `(lo, hi) = move_length` |

    Non-finite actions, or actions outside `[-1, 1]^2`, raise `ValueError`.
    `BearingSLAMDiscrete-v0` has a `Discrete` action space instead (see
    `BearingSLAMDiscreteEnv`).

    ## Observation Space

    A `Box` of float32 of length `9 + 5 * (M - 2) + 3 * M`, where `M = max_landmarks`
    (default `max(8, n_landmarks)`, so 63 elements). It holds only what the robot can
    know, never ground truth. FL coordinates are in units of |L1 - L2| and clipped to
    +-50; log-areas are natural logs of FL areas clipped to
    `[log(1e-10), log(area_cap)]`. Slots beyond the number of landmarks are all zeros.

    | Num | Observation | Min | Max |
    |-----|-------------|-----|-----|
    | 0 | robot position estimate x in FL (centroid of its region; 0 if unknown) | -50 | 50 |
    | 1 | robot position estimate y in FL | -50 | 50 |
    | 2 | log-area of the robot's region (`log(area_cap)` if unknown) | log(1e-10) | log(area_cap) |
    | 3 | 1 if the robot has no region yet (no movement has changed frames) | 0 | 1 |
    | 4 | cos of the robot heading in FL (0 if unknown) | -1 | 1 |
    | 5 | sin of the robot heading in FL (0 if unknown) | -1 | 1 |
    | 6 | progress: moves made / `max_moves` | 0 | 1 |
    | 7 | 1 if the last movement could change frames and update the map | 0 | 1 |
    | 8 | 1 if the last movement was stopped by the wall | 0 | 1 |
    | 9 + 5j | slot j (landmark L(j+3)): 1 if the landmark exists | 0 | 1 |
    | 10 + 5j | 1 if L(j+3) is not initialised yet | 0 | 1 |
    | 11 + 5j | L(j+3) estimate x in FL (centroid; 0 if not initialised) | -50 | 50 |
    | 12 + 5j | L(j+3) estimate y in FL | -50 | 50 |
    | 13 + 5j | log-area of L(j+3)'s region (`log(area_cap)` if not initialised) | log(1e-10) | * |
    | B + 3k | bearing slot k (landmark L(k+1)): 1 if the landmark exists | 0 | 1 |
    | B + 3k + 1 | cos of the latest bearing of L(k+1) | -1 | 1 |
    | B + 3k + 2 | sin of the latest bearing of L(k+1) | -1 | 1 |

    with `j = 0 .. M-3`, `k = 0 .. M-1`, `B = 9 + 5 * (M - 2)` and `*` = `max(log(area_cap),
    0)` (0 keeps the all-zero padding inside the space when `area_cap < 1`). The latest bearings
    are the reading at the current position (at reset: the initial reading), relative to
    the current heading. `observation_slices(M)` gives the three blocks as slices.

    ## Rewards

    With `reward="log_area"` (default), the reward is the decrease of the potential

        Phi = sum over landmarks i >= 3 of log(min(area_i, area_cap))

    where a landmark that is not initialised counts at `area_cap` (default 10 FL units
    squared). The return therefore telescopes: the sum of the rewards of an episode is
    `Phi(start) - Phi(end) = (n - 2) * log(area_cap) - Phi(end)`.
    With `reward="area"`, the potential is `sum min(area_i, area_cap)` instead.
    Optional costs: `path_cost` per metre travelled and `move_cost` per move are
    subtracted. `info["rewards"]` holds the named parts: `"uncertainty"`, `"path_cost"`
    and `"move_cost"` (both <= 0); the reward is their sum.

    ## Starting State

    The landmark layout is the scenario's (`"random"`: a new layout every episode). The
    robot starts at a uniformly random position inside the wall margin, away from the
    landmarks, with a uniformly random heading, takes one reading, and has an empty map.

    ## Episode End

    - Termination (success): every landmark L3, L4, ... is initialised and its region's
      area is at most `target_area`.
    - Truncation: after `max_moves` moves. The registered ids also carry
      `max_episode_steps = 20` (the default `max_moves`) on their spec; when passing a
      larger `max_moves` to `gym.make`, pass the same `max_episode_steps`.

    ## Info

    Ground truth, for evaluation only (arrays are over landmarks i >= 3):
    `landmark_area` (inf if not initialised), `landmark_error` (centroid to true FL
    position; inf if not initialised), `landmark_contains_truth` (bool), `total_area`
    (sum of `landmark_area`), `robot_error` (robot region centroid to the robot's true FL
    position; inf before the first frame change), `frame_changed` (bool), `inconsistent`
    (empty intersections this step), `path_length` (metres moved this step), and
    `rewards` (the named reward parts).

    ## Arguments

    ```python
    import gymnasium as gym
    env = gym.make("bearing_env:BearingSLAM-v0", scenario="khepera", render_mode="rgb_array")
    ```

    - `scenario`: `"random"` (default unless `landmarks` is given; a new layout of
      `n_landmarks` every episode), `"khepera"` (the paper's real arena, 4 landmarks),
      `"paper_sim"` (the paper's simulation: 4 landmarks around the centre of a 2 x 2 m
      square) or `"custom"` (default when `landmarks` is given).
    - `n_landmarks`: number of landmarks (>= 3) for `"random"`; default 4. A range
      `(lo, hi)` draws the count anew every episode (for policies that must generalise
      across landmark counts); `max_landmarks` then defaults to `max(8, hi)`.
    - `landmarks`: explicit landmark positions `(n, 2)` in metres (L1 first, then L2).
    - `arena`: `(width, height)` in metres; default the scenario's (Khepera 1.05 x 0.68).
    - `epsilon_deg`: the SLAM's bearing error bound in degrees, in (0, 45); default 2.
    - `noise`: the true sensor noise: a `NoiseModel`, a mapping of its fields
      (`kind` = `"uniform"` | `"gaussian"` | `"none"`, `bound_deg`, `sigma_deg`,
      `outlier_rate`) or a kind name; default uniform within +-epsilon.
    - `transfer`: `"conservative"` (default; regions contain the truth whenever the noise
      is within +-epsilon) or `"paper"` (the paper's vertex hull).
    - `reward`: `"log_area"` (default) or `"area"`.
    - `target_area`: success threshold per landmark, FL units squared; default 0.05.
    - `max_moves`: moves per episode; default 20.
    - `move_length`: a fixed length or a `(lo, hi)` range in metres; default
      `(0.05, 0.30)` scaled with the arena's longer side relative to 1.05 m.
    - `path_cost`, `move_cost`: reward costs per metre and per move; default 0.
    - `area_cap`: the area counted for an uninitialised landmark; default 10.
    - `max_landmarks`: observation slots; default `max(8, n_landmarks)`.
    - `render_mode`: `None`, `"human"` or `"rgb_array"`.

    ## Version History

    * v0: Initial version.
    """

    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 4}  # noqa: RUF012

    def __init__(
        self,
        scenario: str | None = None,
        n_landmarks: int | tuple[int, int] | None = None,
        landmarks: ArrayLike | None = None,
        arena: tuple[float, float] | Arena | None = None,
        epsilon_deg: float = 2.0,
        noise: NoiseModel | Mapping[str, Any] | str | None = None,
        transfer: str = "conservative",
        reward: str = "log_area",
        target_area: float = DEFAULT_TARGET_AREA,
        max_moves: int = DEFAULT_MAX_MOVES,
        move_length: float | tuple[float, float] | None = None,
        path_cost: float = 0.0,
        move_cost: float = 0.0,
        area_cap: float = DEFAULT_AREA_CAP,
        max_landmarks: int | None = None,
        render_mode: str | None = None,
    ) -> None:
        super().__init__()
        self.scenario = self._resolve_scenario(scenario, landmarks)
        scenario_spec = SCENARIOS[self.scenario]
        self.arena = self._resolve_arena(arena, scenario_spec.arena_size)
        self.fixed_landmarks = self._resolve_landmarks(landmarks, scenario_spec.landmarks)
        self.landmark_counts = self._resolve_landmark_counts(n_landmarks, self.fixed_landmarks)
        #: Landmarks in the current episode (drawn from ``landmark_counts`` at each reset).
        self.n_landmarks = self.landmark_counts[1]

        if not _is_number(epsilon_deg):
            raise TypeError(f"epsilon_deg must be a number, got {epsilon_deg!r}")
        lo_eps, hi_eps = EPSILON_DEG_RANGE
        if not lo_eps < float(epsilon_deg) < hi_eps:
            raise ValueError(
                f"epsilon_deg must be in ({lo_eps:g}, {hi_eps:g}) degrees, got {epsilon_deg!r}"
            )
        self.epsilon_deg = float(epsilon_deg)
        self.epsilon = math.radians(self.epsilon_deg)
        self.noise = NoiseModel.parse(noise)
        self.transfer = _choice(transfer, TRANSFERS, "transfer")
        self.reward_kind = _choice(reward, REWARDS, "reward")
        self.target_area = _positive_float(target_area, "target_area")
        self.max_moves = _int_at_least(max_moves, 1, "max_moves")
        self.move_length = self._resolve_move_length(move_length)
        self.path_cost = _non_negative_float(path_cost, "path_cost")
        self.move_cost = _non_negative_float(move_cost, "move_cost")
        self.area_cap = _positive_float(area_cap, "area_cap")
        if self.area_cap <= AREA_FLOOR:
            raise ValueError(f"area_cap must be > {AREA_FLOOR:g}, got {area_cap!r}")
        if max_landmarks is None:
            self.max_landmarks = max(DEFAULT_MAX_LANDMARKS, self.n_landmarks)
        else:
            self.max_landmarks = _int_at_least(max_landmarks, self.n_landmarks, "max_landmarks")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"unknown render_mode {render_mode!r}; expected None or one of "
                f"{tuple(self.metadata['render_modes'])}"
            )
        self.render_mode = render_mode

        self.action_space = self._make_action_space()
        self.observation_space = self._make_observation_space()

        self._slam = self._make_slam(self.n_landmarks)
        self._world: World | None = None
        #: True FL positions of landmarks 3.. (complex), fixed per episode, for info.
        self._landmarks_fl = np.zeros(0, dtype=complex)
        self._frame_origin, self._frame_unit = 0j, 1 + 0j
        self._moves = 0
        self._potential = 0.0
        self._latest_bearings = np.zeros(self.n_landmarks)
        self._last_frame_changed = False
        self._last_move: MoveResult | None = None
        self._trajectory: list[FloatArray] = []
        self._last_start_bearings: FloatArray | None = None
        self._last_start_position: FloatArray | None = None
        self._renderer: Any = None

    # ------------------------------------------------------------------------------------
    # Construction helpers
    # ------------------------------------------------------------------------------------

    @staticmethod
    def _resolve_scenario(scenario: str | None, landmarks: ArrayLike | None) -> str:
        if scenario is None:
            return "random" if landmarks is None else "custom"
        name = _choice(scenario, tuple(SCENARIOS), "scenario")
        if name == "custom" and landmarks is None:
            raise ValueError("scenario 'custom' needs explicit `landmarks` positions")
        if name != "custom" and landmarks is not None:
            raise ValueError(
                f"`landmarks` were given with scenario {name!r}; explicit positions use "
                "scenario 'custom' (or leave scenario unset)"
            )
        return name

    @staticmethod
    def _resolve_arena(
        arena: tuple[float, float] | Arena | None, default: tuple[float, float]
    ) -> Arena:
        if arena is None:
            return Arena(*default)
        if isinstance(arena, Arena):
            return arena
        if isinstance(arena, (str, bytes)) or not isinstance(arena, (Sequence, np.ndarray)):
            raise TypeError(f"arena must be (width, height) in metres, got {arena!r}")
        if len(arena) != 2:
            raise ValueError(f"arena must be (width, height) in metres, got {arena!r}")
        return Arena(arena[0], arena[1])

    def _resolve_landmarks(
        self,
        landmarks: ArrayLike | None,
        scenario_landmarks: tuple[tuple[float, float], ...] | None,
    ) -> FloatArray | None:
        if landmarks is None:
            if scenario_landmarks is None:
                return None
            points = np.array(scenario_landmarks, dtype=np.float64)
        else:
            try:
                points = np.array(landmarks, dtype=np.float64)
            except (TypeError, ValueError) as error:
                raise TypeError(
                    f"landmarks must be an (n, 2) array of positions, got {landmarks!r}"
                ) from error
            if points.ndim != 2 or points.shape[1] != 2:
                raise ValueError(
                    f"landmarks must have shape (n, 2), got shape {points.shape}: {landmarks!r}"
                )
            if points.shape[0] < 3:
                raise ValueError(
                    f"landmarks must hold >= 3 positions (L1, L2 and one to map), "
                    f"got {points.shape[0]}"
                )
            if not np.all(np.isfinite(points)):
                raise ValueError(f"landmarks must be finite, got {points.tolist()}")
        inside = self.arena.contains(points)
        if not np.all(inside):
            raise ValueError(
                f"landmarks {points[~inside].tolist()} lie outside the arena "
                f"{self.arena.width:g} x {self.arena.height:g} m"
            )
        separation = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
        np.fill_diagonal(separation, np.inf)
        if separation.min() < 1e-6 * self.arena.scale:
            raise ValueError(f"landmarks must be distinct points, got {points.tolist()}")
        return points

    def _resolve_landmark_counts(
        self, n_landmarks: int | tuple[int, int] | None, fixed: FloatArray | None
    ) -> tuple[int, int]:
        """``(lo, hi)``: each episode has between lo and hi landmarks (both included)."""
        if isinstance(n_landmarks, (tuple, list)):
            if fixed is not None:
                raise ValueError(
                    f"n_landmarks={n_landmarks!r}: a range needs random layouts, but scenario "
                    f"{self.scenario!r} has fixed landmark positions"
                )
            if len(n_landmarks) != 2:
                raise ValueError(f"n_landmarks range must be (lo, hi), got {n_landmarks!r}")
            lo = _int_at_least(n_landmarks[0], 3, "n_landmarks")
            hi = _int_at_least(n_landmarks[1], lo, "n_landmarks")
            return lo, hi
        n = self._resolve_n_landmarks(n_landmarks, fixed)
        return n, n

    def _resolve_n_landmarks(self, n_landmarks: int | None, fixed: FloatArray | None) -> int:
        if fixed is not None:
            n_fixed = int(fixed.shape[0])
            if n_landmarks is not None:
                n = _int_at_least(n_landmarks, 3, "n_landmarks")
                if n != n_fixed:
                    raise ValueError(
                        f"n_landmarks={n_landmarks!r} contradicts the {n_fixed} landmark "
                        f"positions of scenario {self.scenario!r}"
                    )
            return n_fixed
        if n_landmarks is None:
            return 4
        return _int_at_least(n_landmarks, 3, "n_landmarks")

    def _resolve_move_length(
        self, move_length: float | tuple[float, float] | None
    ) -> tuple[float, float]:
        if move_length is None:
            return self.arena.default_move_length
        if _is_number(move_length):
            length = _positive_float(move_length, "move_length")
            return (length, length)
        if isinstance(move_length, (str, bytes)) or not isinstance(
            move_length, (Sequence, np.ndarray)
        ):
            raise TypeError(
                f"move_length must be a number or a (lo, hi) pair of metres, got {move_length!r}"
            )
        if len(move_length) != 2:
            raise ValueError(f"move_length must be a (lo, hi) pair, got {move_length!r}")
        lo = _positive_float(move_length[0], "move_length lo")
        hi = _positive_float(move_length[1], "move_length hi")
        if lo > hi:
            raise ValueError(f"move_length must have lo <= hi, got {move_length!r}")
        return (lo, hi)

    def _make_action_space(self) -> spaces.Space[Any]:
        return spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)

    def _make_observation_space(self) -> spaces.Box:
        low, high = self._observation_bounds()
        return spaces.Box(low, high, dtype=np.float32)

    def _observation_bounds(self) -> tuple[NDArray[np.float32], NDArray[np.float32]]:
        log_min, log_max = math.log(AREA_FLOOR), math.log(self.area_cap)
        robot_low = [-FL_COORD_LIMIT, -FL_COORD_LIMIT, log_min, 0, -1, -1, 0, 0, 0]
        robot_high = [FL_COORD_LIMIT, FL_COORD_LIMIT, log_max, 1, 1, 1, 1, 1, 1]
        landmark_low = [0, 0, -FL_COORD_LIMIT, -FL_COORD_LIMIT, min(log_min, 0.0)]
        landmark_high = [1, 1, FL_COORD_LIMIT, FL_COORD_LIMIT, max(log_max, 0.0)]
        bearing_low, bearing_high = [0, -1, -1], [1, 1, 1]
        n_slots = self.max_landmarks
        low = np.concatenate(
            [robot_low, np.tile(landmark_low, n_slots - 2), np.tile(bearing_low, n_slots)]
        )
        high = np.concatenate(
            [robot_high, np.tile(landmark_high, n_slots - 2), np.tile(bearing_high, n_slots)]
        )
        # Rounding to float32 must not leave a computed value outside its own bound.
        return (
            np.nextafter(low.astype(np.float32), np.float32(-np.inf)),
            np.nextafter(high.astype(np.float32), np.float32(np.inf)),
        )

    # ------------------------------------------------------------------------------------
    # Gymnasium API
    # ------------------------------------------------------------------------------------

    @property
    def slam(self) -> PolygonSLAM:
        """The robot's map: everything the robot knows (regions, estimates, its pose)."""
        return self._slam

    @property
    def world(self) -> World | None:
        """Ground truth (true landmarks, the robot's true pose); None before the first reset.

        For evaluation and privileged policies only: a policy that reads it cheats.
        """
        return self._world

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        super().reset(seed=seed)
        rng = self.np_random
        lo, hi = self.landmark_counts
        if hi > lo:
            count = int(rng.integers(lo, hi + 1))
            if count != self.n_landmarks:
                self.n_landmarks = count
                self._slam = self._make_slam(count)
        if self.fixed_landmarks is not None:
            landmarks = self.fixed_landmarks.copy()
        else:
            landmarks = random_layout(rng, self.arena, self.n_landmarks)
        position, heading = random_start(rng, self.arena, landmarks)
        self._world = World(self.arena, landmarks, position, heading, self.noise, self.epsilon)
        # Landmarks do not move: their true FL positions (for info) are fixed per episode.
        self._frame_origin = complex(*landmarks[0])
        self._frame_unit = complex(*landmarks[1]) - self._frame_origin
        points = landmarks[2:, 0] + 1j * landmarks[2:, 1]
        self._landmarks_fl = (points - self._frame_origin) / self._frame_unit
        self._slam.reset()
        self._moves = 0
        self._latest_bearings = self._world.read_bearings(rng)
        self._last_frame_changed = False
        self._last_move = None
        self._trajectory = [self._world.position.copy()]
        self._last_start_bearings = None
        self._last_start_position = None
        batch, rows = self._slam.batch, self._slam_rows()
        self._potential = float(_potentials([self], batch, rows)[0])
        observation = _observations([self], batch, rows)[0]
        zeros = np.zeros(1)
        no_change = np.zeros(1, dtype=bool)
        infos = _batched_infos(
            [self], batch, rows, no_change, np.zeros(1, np.int64), zeros, zeros, zeros
        )
        info = _row_info(infos, 0)
        if self.render_mode == "human":
            self.render()
        return observation, info

    def step(
        self, action: NDArray[np.float32] | ArrayLike
    ) -> tuple[NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        if self._world is None:
            raise RuntimeError("call reset() before step()")
        movement = self._move(*self._decode_action(action))
        frame_changed, inconsistent = False, 0
        if movement.changes_map:
            result = self._slam.update(movement.start_bearings, movement.end_bearings)
            frame_changed, inconsistent = result.frame_changed, result.n_inconsistent
        return self._finish_step(movement, frame_changed, inconsistent)

    def _move(self, turn: float, length: float) -> Movement:
        """The world half of a step: turn, read, move, read (the SLAM update comes next)."""
        return self._move_batch([self], np.array([turn]), np.array([length]))[0]

    @staticmethod
    def _move_batch(
        envs: Sequence[BearingSLAMEnv], turns: FloatArray, lengths: FloatArray
    ) -> list[Movement]:
        """:meth:`_move` for envs with equal settings and landmark counts, at once."""
        worlds = [env._world for env in envs]
        assert all(world is not None for world in worlds)
        rngs = [env.np_random for env in envs]
        moves = step_worlds(worlds, turns, lengths, rngs)  # type: ignore[arg-type]
        # A move that could not start took both readings from the same place: there is no
        # robot frame (R1 = R2), so the SLAM must not see it. The robot knows it did not
        # move (it is stuck against the wall).
        changes_map = moves.travelled >= worlds[0].min_baseline  # type: ignore[union-attr]
        results = zip(
            moves.requested.tolist(), moves.travelled.tolist(), moves.blocked.tolist(), strict=True
        )
        return [
            Movement(
                MoveResult(*result),
                moves.start_positions[i],
                moves.start_bearings[i],
                moves.end_bearings[i],
                bool(changes_map[i]),
            )
            for i, result in enumerate(results)
        ]

    def _finish_step(
        self, movement: Movement, frame_changed: bool, inconsistent: int
    ) -> tuple[NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        """The bookkeeping half of a step, after the SLAM update of ``movement``."""
        observations, rewards, terminated, truncated, infos = self._finish_steps(
            [self], [movement], np.array([frame_changed]), np.array([inconsistent])
        )
        if self.render_mode == "human":
            self.render()
        return (
            observations[0],
            float(rewards[0]),
            bool(terminated[0]),
            bool(truncated[0]),
            _row_info(infos, 0),
        )

    @staticmethod
    def _finish_steps(
        envs: Sequence[BearingSLAMEnv],
        movements: Sequence[Movement],
        frame_changed: NDArray[np.bool_],
        inconsistent: NDArray[np.int64],
    ) -> tuple[
        NDArray[np.float32], FloatArray, NDArray[np.bool_], NDArray[np.bool_], dict[str, Any]
    ]:
        """:meth:`_finish_step` for several envs whose maps share one batch, at once.

        Returns batched observations, rewards, terminations, truncations and infos (as a
        Gymnasium vector env batches them, without the masks). The single env calls it
        with a batch of one, so both compute with the same code and agree bit for bit.
        """
        for env, movement, changed in zip(envs, movements, frame_changed, strict=True):
            assert env._world is not None
            env._moves += 1
            env._latest_bearings = movement.end_bearings
            env._last_frame_changed = bool(changed)
            env._last_move = movement.move
            env._last_start_bearings = movement.start_bearings
            env._last_start_position = movement.start_position
            env._trajectory.append(env._world.position.copy())

        first = envs[0]
        batch, rows = _batch_rows(envs)
        travelled = np.array([movement.move.travelled for movement in movements])
        potential = _potentials(envs, batch, rows)
        previous = np.array([env._potential for env in envs])
        uncertainty = previous - potential
        path_cost = -first.path_cost * travelled
        move_cost = np.full(len(envs), -first.move_cost)
        rewards = ((0.0 + uncertainty) + path_cost) + move_cost
        for env, value in zip(envs, potential, strict=True):
            env._potential = float(value)

        areas = batch.areas[rows]
        terminated = np.all(batch.initialised[rows], axis=-1) & np.all(
            areas <= first.target_area, axis=-1
        )
        moves = np.array([env._moves for env in envs])
        truncated = ~terminated & (moves >= first.max_moves)
        observations = _observations(envs, batch, rows)
        infos = _batched_infos(
            envs,
            batch,
            rows,
            frame_changed,
            inconsistent,
            travelled,
            uncertainty,
            path_cost,
            move_cost,
        )
        return observations, rewards, terminated, truncated, infos

    def render(self) -> NDArray[np.uint8] | None:
        if self.render_mode is None:
            gym.logger.warn(
                "render() called without a render_mode; pass render_mode='rgb_array' or "
                "'human' to the constructor (gym.make(..., render_mode=...))."
            )
            return None
        if self._world is None:
            raise RuntimeError("call reset() before render()")
        if self._renderer is None:
            from bearing_env.rendering import Renderer

            self._renderer = Renderer(
                self.render_mode, self.arena, fps=self.metadata["render_fps"]
            )
        return self._renderer.render(self._scene())

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __getstate__(self) -> dict[str, Any]:
        # A pygame window or surface cannot be pickled; a fresh one is made on demand.
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state

    # ------------------------------------------------------------------------------------
    # Internals
    # ------------------------------------------------------------------------------------

    def _batch_settings(self) -> tuple[Any, ...]:
        """Every setting the batched step functions read from the first env of a batch:
        envs stepped together must agree on all of them."""
        return (
            self.move_length,
            self.path_cost,
            self.move_cost,
            self.target_area,
            self.max_moves,
            self.area_cap,
            self.reward_kind,
            self.max_landmarks,
            self.arena,
            self.noise,
            self.epsilon,
        )

    def _slam_rows(self) -> IntArray:
        """This env's row of its map batch, as an index array."""
        return self._slam.rows

    def _robot_fl(self) -> complex:
        """The robot's true position in FL, as a complex number."""
        assert self._world is not None
        x, y = self._world.position
        return (complex(x, y) - self._frame_origin) / self._frame_unit

    def _make_slam(self, n_landmarks: int) -> PolygonSLAM:
        """The map for an episode with ``n_landmarks`` (the batched vector env overrides
        this per sub-env, to hand out rows of its shared batch)."""
        return PolygonSLAM(n_landmarks, self.epsilon, transfer=self.transfer)

    def _decode_actions(self, actions: NDArray[Any]) -> tuple[FloatArray, FloatArray]:
        """(turn angles, move lengths) from a batch of actions (N, 2), as
        :meth:`_decode_action` computes them one at a time."""
        values = np.asarray(actions, dtype=np.float64)
        if not np.all(np.isfinite(values)):
            raise ValueError(f"actions must be finite, got {actions!r}")
        if np.any(np.abs(values) > 1.0 + 1e-6):
            raise ValueError(f"actions {actions!r} are outside the action space [-1, 1]^2")
        values = np.minimum(np.maximum(values, -1.0), 1.0)
        lo, hi = self.move_length
        return math.pi * values[:, 0], lo + 0.5 * (values[:, 1] + 1.0) * (hi - lo)

    def _decode_action(self, action: Any) -> tuple[float, float]:
        """(turn angle in radians, requested move length in metres) from an action."""
        try:
            values = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError) as error:
            raise ValueError(f"action must be 2 numbers in [-1, 1], got {action!r}") from error
        if values.shape != (2,):
            raise ValueError(f"action must have shape (2,), got shape {values.shape}: {action!r}")
        if not np.all(np.isfinite(values)):
            raise ValueError(f"action must be finite, got {action!r}")
        # float32 rounding of +-1 must not be rejected; anything else outside is a bug.
        if np.any(np.abs(values) > 1.0 + 1e-6):
            raise ValueError(f"action {action!r} is outside the action space [-1, 1]^2")
        values = np.clip(values, -1.0, 1.0)
        lo, hi = self.move_length
        return math.pi * float(values[0]), lo + 0.5 * (float(values[1]) + 1.0) * (hi - lo)

    def _scene(self) -> Any:
        from bearing_env.rendering import Scene

        world, slam = self._world, self._slam
        assert world is not None
        l1, l2 = world.landmarks[0], world.landmarks[1]

        def to_world(points: FloatArray | None) -> FloatArray | None:
            return None if points is None else fl_to_world(points, l1, l2)

        areas = slam.areas
        return Scene(
            arena=self.arena,
            landmarks=world.landmarks.copy(),
            estimates=fl_to_world(slam.estimates, l1, l2),
            regions=[to_world(polygon) for polygon in slam.polygons],
            robot_region=to_world(slam.robot_polygon),
            robot_position=world.position.copy(),
            robot_heading=world.heading,
            trajectory=np.array(self._trajectory),
            start_position=None
            if self._last_start_position is None
            else self._last_start_position.copy(),
            start_bearings=None
            if self._last_start_bearings is None
            else self._last_start_bearings.copy(),
            end_bearings=self._latest_bearings.copy(),
            epsilon=self.epsilon,
            moves=self._moves,
            max_moves=self.max_moves,
            total_area=float(np.sum(areas)),
            n_initialised=int(np.sum(slam.initialised)),
            frame_changed=self._last_frame_changed,
            robot_radius=self.arena.wall_margin,
        )



# ----------------------------------------------------------------------------------------
# Batched bookkeeping: observations, potentials and infos of envs sharing one map batch
# ----------------------------------------------------------------------------------------


def _batch_rows(envs: Sequence[BearingSLAMEnv]) -> tuple[BatchedPolygonSLAM, IntArray]:
    """The map batch the envs share and their rows in it."""
    batch = envs[0].slam.batch
    if len(envs) == 1:
        return batch, envs[0]._slam_rows()
    if any(env.slam.batch is not batch for env in envs):
        raise ValueError("the envs' maps must live in one batch")
    return batch, np.array([env.slam.index for env in envs])


def _log_capped(areas: FloatArray, area_cap: float) -> FloatArray:
    # Uninitialised landmarks have area inf, so the cap also stands in for them.
    return np.log(_clipped(areas, AREA_FLOOR, area_cap))


def _clipped(values: FloatArray, low: float, high: float) -> FloatArray:
    # np.clip's Python wrapper costs more than the arithmetic on these small arrays.
    return np.minimum(np.maximum(values, low), high)


def _xy(points: NDArray[np.complex128]) -> FloatArray:
    """Complex points as (..., 2) coordinates, without copying."""
    points = np.ascontiguousarray(points)
    return points.view(np.float64).reshape(*points.shape, 2)


def _potentials(
    envs: Sequence[BearingSLAMEnv], batch: BatchedPolygonSLAM, rows: IntArray
) -> FloatArray:
    """The uncertainty potential Phi of each env (see the env's Rewards section)."""
    first = envs[0]
    areas = batch.areas[rows]
    if first.reward_kind == "log_area":
        return _log_capped(areas, first.area_cap).sum(axis=-1)
    return _clipped(areas, AREA_FLOOR, first.area_cap).sum(axis=-1)


def _observations(
    envs: Sequence[BearingSLAMEnv], batch: BatchedPolygonSLAM, rows: IntArray
) -> NDArray[np.float32]:
    """Observations (len(envs), observation_size) of envs with equal settings."""
    first = envs[0]
    n_envs, n_slots, n_landmarks = len(envs), first.max_landmarks, first.n_landmarks
    observation = np.zeros((n_envs, observation_size(n_slots)))
    blocks = observation_slices(n_slots)
    robot = observation[:, blocks["robot"]]
    mapped = observation[:, blocks["landmarks"]].reshape(n_envs, n_slots - 2, -1)
    bearing = observation[:, blocks["bearings"]].reshape(n_envs, n_slots, -1)

    centroid = batch.robot_centroid[rows]
    known = batch.has_robot[rows] & np.isfinite(centroid)
    robot[:, 0:2] = _clipped(
        _xy(np.where(known, centroid, 0.0)), -FL_COORD_LIMIT, FL_COORD_LIMIT
    )
    robot[:, 2] = np.where(
        known, _log_capped(batch.robot_area[rows], first.area_cap), math.log(first.area_cap)
    )
    robot[:, 3] = ~known
    heading = batch.robot_heading[rows]
    has_heading = np.isfinite(heading)
    safe_heading = np.where(has_heading, heading, 0.0)
    robot[:, 4] = np.where(has_heading, np.cos(safe_heading), 0.0)
    robot[:, 5] = np.where(has_heading, np.sin(safe_heading), 0.0)
    for row, env in enumerate(envs):
        robot[row, 6] = min(env._moves / env.max_moves, 1.0)
        robot[row, 7] = env._last_frame_changed
        robot[row, 8] = env._last_move is not None and env._last_move.blocked

    n_mapped = n_landmarks - 2
    initialised = batch.initialised[rows]
    mapped[:, :n_mapped, 0] = 1.0
    mapped[:, :n_mapped, 1] = ~initialised
    mapped[:, :n_mapped, 2:4] = _clipped(
        _xy(np.where(initialised, batch.centroids[rows], 0.0)), -FL_COORD_LIMIT, FL_COORD_LIMIT
    )
    mapped[:, :n_mapped, 4] = _log_capped(batch.areas[rows], first.area_cap)

    latest = np.stack([env._latest_bearings for env in envs])
    bearing[:, :n_landmarks, 0] = 1.0
    bearing[:, :n_landmarks, 1] = np.cos(latest)
    bearing[:, :n_landmarks, 2] = np.sin(latest)
    return observation.astype(np.float32)


def _batched_infos(
    envs: Sequence[BearingSLAMEnv],
    batch: BatchedPolygonSLAM,
    rows: IntArray,
    frame_changed: NDArray[np.bool_],
    inconsistent: NDArray[np.int64],
    path_length: FloatArray,
    uncertainty: FloatArray,
    path_cost: FloatArray,
    move_cost: FloatArray | None = None,
) -> dict[str, Any]:
    """The envs' infos, batched along a first axis (see the env's Info section)."""
    initialised = batch.initialised[rows]
    areas = batch.areas[rows]
    truth = np.stack([env._landmarks_fl for env in envs])
    errors = np.where(
        initialised, np.abs(np.where(initialised, batch.centroids[rows] - truth, 0.0)), np.inf
    )
    contains = batch.contains(truth, rows)
    robot_truth = np.array([env._robot_fl() for env in envs])
    robot_centroid = batch.robot_centroid[rows]
    robot_known = np.isfinite(robot_centroid)
    robot_error = np.where(
        robot_known, np.abs(np.where(robot_known, robot_centroid - robot_truth, 0.0)), np.inf
    )
    if move_cost is None:
        move_cost = np.zeros(len(envs))
    return {
        "landmark_area": areas,
        "landmark_error": errors,
        "landmark_contains_truth": contains,
        "total_area": areas.sum(axis=-1),
        "robot_error": robot_error,
        "frame_changed": np.asarray(frame_changed, dtype=bool),
        "inconsistent": np.asarray(inconsistent, dtype=np.int64),
        "path_length": np.asarray(path_length, dtype=np.float64),
        "rewards": {
            "uncertainty": np.asarray(uncertainty, dtype=np.float64),
            "path_cost": np.asarray(path_cost, dtype=np.float64),
            "move_cost": np.asarray(move_cost, dtype=np.float64),
        },
    }


def _row_info(infos: dict[str, Any], row: int) -> dict[str, Any]:
    """One env's info dict (Python scalars, per-landmark arrays) from batched infos."""
    info: dict[str, Any] = {}
    for key, value in infos.items():
        if isinstance(value, dict):
            info[key] = _row_info(value, row)
        elif value.ndim > 1:
            info[key] = value[row].copy()
        else:
            info[key] = value[row].item()
    return info
