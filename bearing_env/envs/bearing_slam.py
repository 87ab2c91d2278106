"""``BearingSLAM-v1``: active exploration for the paper's bearing-only polygon SLAM.

The env is a batch of one of the functional core in :mod:`bearing_env.envs.core`; its
settings are one :class:`~bearing_env.envs.config.EnvConfig`.
"""

from __future__ import annotations

import dataclasses
import inspect
from collections.abc import Collection, Mapping
from typing import Any, ClassVar, SupportsFloat, cast

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from gymnasium.envs.registration import EnvSpec
from numpy.typing import ArrayLike, NDArray

from bearing_env.envs import core
from bearing_env.envs.actions import CONTINUOUS, ActionSpec
from bearing_env.envs.config import (
    AREA_FLOOR,
    DEFAULT_AREA_CAP,
    DEFAULT_MAX_LANDMARKS,
    DEFAULT_MAX_MOVES,
    DEFAULT_TARGET_AREA,
    EPSILON_DEG_RANGE,
    GRID_SETTINGS,
    MAX_AREA_CAP,
    MAX_N_LANDMARKS,
    REWARDS,
    SETTINGS,
    EnvConfig,
    SettingSpec,
    settings_signature,
)
from bearing_env.envs.core import MapBank, WorldView
from bearing_env.envs.observations import (
    BEARING_FEATURES,
    FL_COORD_LIMIT,
    LANDMARK_FEATURES,
    ROBOT_FEATURES,
    ObservationSpec,
    observation_size,
    observation_slices,
    spec_for,
)
from bearing_env.envs.state import BatchState
from bearing_env.slam import PolygonSLAM

__all__ = [
    "AREA_FLOOR",
    "BEARING_FEATURES",
    "DEFAULT_AREA_CAP",
    "DEFAULT_MAX_LANDMARKS",
    "DEFAULT_MAX_MOVES",
    "DEFAULT_TARGET_AREA",
    "EPSILON_DEG_RANGE",
    "FL_COORD_LIMIT",
    "LANDMARK_FEATURES",
    "MAX_AREA_CAP",
    "MAX_N_LANDMARKS",
    "REWARDS",
    "ROBOT_FEATURES",
    "BearingSLAMEnv",
    "EnvConfig",
    "observation_size",
    "observation_slices",
]

FloatArray = NDArray[np.float64]


class Setting:
    """An env attribute backed by a field of the env's config (one per
    :data:`~bearing_env.envs.config.SETTINGS` entry, installed by
    ``BearingSLAMEnv.__init_subclass__``): reading gives the field; assigning replaces
    ``env.config`` by a validated copy with the field changed."""

    def __init__(self, spec: SettingSpec) -> None:
        self.spec = spec
        #: The config field (``config.replace`` takes it).
        self.field = spec.field
        #: Why the attribute cannot be assigned (None: it can).
        self.read_only = spec.read_only
        self.__doc__ = f"The ``{spec.keyword}`` setting (``config.{spec.group}.{spec.field}``)."

    def __get__(self, env: Any, owner: type | None = None) -> Any:
        if env is None:
            return self  # read on the class, a descriptor gives itself (as property does)
        return getattr(getattr(env.config, self.spec.group), self.field)

    def __set__(self, env: Any, value: Any) -> None:
        if self.read_only is not None:
            raise AttributeError(f"{self.spec.attribute} is read-only: {self.read_only}")
        env.config = env.config.replace(**{self.field: value})


def settings_from(config: EnvConfig | None, settings: Mapping[str, Any], grid: bool) -> EnvConfig:
    """The env's config: ``config`` itself, or one built from the keyword settings by
    :meth:`EnvConfig.create` (which names an unknown one).

    Giving both is ambiguous (which wins?), so it is refused, and so are the discrete
    grid's settings on an env without a grid (``grid`` False).
    """
    if not grid and (given := sorted(set(settings) & set(GRID_SETTINGS))):
        raise TypeError(
            f"unexpected keyword argument(s) {given}: they set the discrete action grid of "
            "BearingSLAMDiscrete-v1"
        )
    if config is None:
        return EnvConfig.create(**settings)
    if not isinstance(config, EnvConfig):
        raise TypeError(f"config must be an EnvConfig or None, got {config!r}")
    if settings:
        raise TypeError(
            f"pass the settings either as config or as keywords, not both: {sorted(settings)}"
        )
    return config


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

    Non-finite actions, actions outside `[-1, 1]^2`, and actions that are not real numbers
    (strings, bools, complex numbers) raise `ValueError`. Real actions of any dtype are
    accepted (float16, longdouble and integers are cast to float64 first).
    `BearingSLAMDiscrete-v1` has a `Discrete` action space instead (see
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
    | B + 3k + 1 | cos of the latest bearing of L(k+1) (0 if that reading missed it) | -1 | 1 |
    | B + 3k + 2 | sin of the latest bearing of L(k+1) (0 if that reading missed it) | -1 | 1 |

    with `j = 0 .. M-3`, `k = 0 .. M-1`, `B = 9 + 5 * (M - 2)` and `*` = `max(log(area_cap),
    0)` (0 keeps the all-zero padding inside the space when `area_cap < 1`). The latest bearings
    are the reading at the current position (at reset: the initial reading), relative to
    the current heading. `observation_slices(M)` gives the three blocks as slices.

    With `observation="entities"` the observation is a `Dict` of the same numbers:
    `"robot"` (the 9 elements above) and `"landmarks"`, a table of one row per landmark
    slot L1 .. LM, flattened row by row (a Box of `M * 8`; reshape to `(M, 8)`), with the
    columns `observations.ENTITY_FEATURES`: present, is-frame (L1 and L2, at (0, 0) and (1, 0)),
    not initialised, estimate x, y, log-area (`log(1e-10)` for the exact L1 and L2) and
    the latest bearing's cos and sin. Absent rows are zeros.

    With `observation="shapes"` the table has three more columns per row,
    `observations.SHAPE_FEATURES` (a Box of `M * 11`; reshape to `(M, 11)`): the shape of
    the landmark's region from the second moments of its area, its elongation (half the
    log of the ratio of the principal moments: 0 when round, at most 10) and its long axis
    theta in FL as (cos 2 theta, sin 2 theta) ((0, 0) when round). They are zeros for L1,
    L2, absent rows and landmarks without a region yet.

    With `planner_features=True` the observation ends with what a one-step planner
    predicts of each of the K moves of the discrete action grid (`n_turns` x
    `n_move_lengths`; candidate k is `BearingSLAMDiscrete`'s action k), K rows of
    `candidates.CANDIDATE_FEATURES`: `predicted` (1 once the robot has a map fix and an
    FL scale to predict from, else this row is 0 but for `blocked`), `gain` (the
    predicted decrease of the potential Phi below, the move simulated on a copy of the
    robot's map from its believed pose), `sees_l1`, `sees_l2` (L1, L2 predicted in view
    at both readings) and `blocked` (the last move was stopped and this one turns less
    than 60 degrees). The flat Box gets `5 K` more elements; a Dict kind gets them as
    `"candidates"`. They come from the robot's own map, readings and commands, never
    ground truth (see `bearing_env.envs.candidates`).

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
    `reset(options=...)` takes no options: `None` or `{}`; any key raises `TypeError`
    naming it.

    ## Episode End

    - Termination (success): every landmark L3, L4, ... is initialised and its region's
      area is at most `target_area`.
    - Truncation: after `max_moves` moves, the one episode cap:
      `gym.make(id, max_moves=40)` runs 40 moves. The ids register no `TimeLimit`, and
      `env.spec.max_episode_steps` reads `max_moves`. Stepping an episode that has ended,
      without `reset()`, raises `RuntimeError`.

    ## Info

    `robot_map` (unless `robot_map_info=False`) is the robot's own map, as data (no
    ground truth; what policies may read: see `bearing_env.agents.env_access.MapReader`):
    a dict of the state arrays its fusion
    uses (`BatchedPolygonSLAM.state_names`: `vertices` (M - 2, CAPACITY, 2), the FL
    region vertices as (x, y), of which the first `counts` are used, `areas`,
    `centroids` (M - 2, 2), the robot's
    `robot_vertices`, `robot_counts`, `robot_area`, `robot_centroid`, `robot_heading`, and
    the counters `n_updates`, `n_frame_changes`, `n_inconsistent`; with
    `fusion="relaxed"` also its window and bases, `window_vertices` to `outliers`). The
    per-landmark
    arrays have `M - 2` slots whatever the episode's landmark count (empty slots: count
    0), so infos batch on the vector env; the count is the observation's present slots.
    Unused vertex slots are 0 and unknown values (a centroid without a region, the
    robot's centroid or heading before it has one) are inf, so equal maps give equal
    infos.

    The rest is ground truth, for evaluation only (arrays are over landmarks i >= 3):
    `landmark_area` (inf if not initialised), `landmark_error` (centroid to true FL
    position; inf if not initialised), `landmark_contains_truth` (bool), `total_area`
    (sum of `landmark_area`), `robot_error` (robot region centroid to the robot's true FL
    position; inf before the first frame change), `frame_changed` (bool), `inconsistent`
    (empty intersections this step; with `fusion="relaxed"`, this movement's regions
    that were left out), `outliers` (per landmark, the regions its region leaves out so
    far; always 0 with `"intersect"`), `path_length` (metres moved this step), and
    `rewards` (the named reward parts).

    ## Arguments

    ```python
    import gymnasium as gym
    env = gym.make("bearing_env:BearingSLAM-v1", scenario="khepera", render_mode="rgb_array")
    ```

    - `scenario`: `"random"` (default unless `landmarks` is given; a new layout of
      `n_landmarks` every episode), `"khepera"` (the paper's real arena, 4 landmarks),
      `"paper_sim"` (the paper's simulation: 4 landmarks around the centre of a 2 x 2 m
      square), `"furnished_room"` (2 x 1.5 m, 5 landmarks, four pieces of furniture),
      `"l_corridor"` (a corridor with an L-turn, 5 landmarks) or `"custom"` (default when
      `landmarks` is given).
    - `n_landmarks`: number of landmarks (3 to 1024) for `"random"`; default 4. A range
      `(lo, hi)` draws the count anew every episode (for policies that must generalise
      across landmark counts); `max_landmarks` then defaults to `max(8, hi)`.
    - `landmarks`: explicit landmark positions `(n, 2)` in metres (L1 first, then L2).
    - `arena`: `(width, height)` in metres; default the scenario's (Khepera 1.05 x 0.68).
    - `obstacles`: polygons that block moves (a move stops at the wall margin from them,
      and the observation's `last_move_blocked` says so) and sight: a list of polygons
      of `(x, y)` vertices in metres, the path of a JSON or YAML file, or
      `{"random": count, "seed": seed}` (see `bearing_env.obstacles`); default the
      scenario's (none but for `"furnished_room"` and `"l_corridor"`).
    - `epsilon_deg`: the SLAM's bearing error bound in degrees, in (0, 90) (the world
      model's own bound); default 2.
    - `noise`: the true sensor noise: a `NoiseModel`, a mapping of its fields
      (`kind` = `"uniform"` | `"gaussian"` | `"none"`, `bound_deg`, `sigma_deg`,
      `outlier_rate`, `detection_rate`: a missed landmark's bearing is NaN, and the map
      skips it for that movement) or a kind name; default uniform within +-epsilon.
    - `field_of_view_deg`: the camera's field of view in (0, 360] degrees about the
      heading (the move's direction); default 360, the paper's panoramic camera.
    - `max_range`: the camera's range in metres; default inf. A landmark outside the
      field of view, beyond the range or behind an obstacle is a missed reading: its
      bearing is NaN for the map, and reads (cos, sin) = (0, 0) in the observation.
    - `transfer`: `"conservative"` (default; regions contain the truth whenever the noise
      is within +-epsilon) or `"paper"` (the paper's vertex hull).
    - `reward`: `"log_area"` (default) or `"area"`.
    - `target_area`: success threshold per landmark, FL units squared; default 0.05.
    - `max_moves`: moves per episode; default 20.
    - `move_length`: a fixed length or a `(lo, hi)` range in metres; default
      `(0.05, 0.30)` scaled with the arena's longer side relative to 1.05 m.
    - `path_cost`, `move_cost`: reward costs per metre and per move; default 0.
    - `area_cap`: the area counted for an uninitialised landmark, in `(1e-10, 1e6]`;
      default 10.
    - `max_landmarks`: observation slots (at most 1024); default `max(8, n_landmarks)`.
    - `fusion`: how a landmark's regions are combined over movements: `"intersect"`
      (default; the paper's intersection) or `"relaxed"` (the q-relaxed intersection
      over a window of the last 8 movements: it leaves out up to `max_outliers` regions
      per landmark, and whole movements that are outliers for most landmarks, as a
      misread L1 or L2 makes them; see `bearing_env.slam.PolygonSLAM`), or `"robust"`
      (the relaxed intersection of all of a landmark's regions, leaving out as many as
      the contamination rate estimated from the contradictions seen asks for `risk`;
      on clean data it is almost always the intersection exactly; see
      docs/world_model.md).
    - `risk`: with `"robust"`, the target chance that more of a landmark's regions are
      contaminated than its reported set leaves out, in (0, 0.5]; default 0.05.
    - `robust_set`: with `"robust"`, the set the map reports, and so the observation
      and the reward use: `"guaranteed"` (default; leaves out enough regions for
      `risk`) or `"likely"` (leaves out only the regions that contradict the others:
      smaller, and more often wrong).
    - `noise_bound`: with `"robust"`, the bound the map reads bearings with:
      `"estimate"` (default; `epsilon_deg`, grown when a probe map fused at 0.8 of the
      bound contradicts what the map fused consistently, the regions then rebuilt from
      the last 16 movements) or `"nominal"` (`epsilon_deg` throughout).
    - `max_outliers`: with `"relaxed"`, the most regions per landmark left out, 0..7;
      default 2.
    - `on_inconsistency`: `"restart"` (default: a landmark whose regions contradict
      each other restarts from the newest one) or `"keep"` (it keeps its old region).
      With `"relaxed"`, this applies beyond `max_outliers`.
    - `observation`: `"flat"` (default, the Box above), `"entities"` or `"shapes"` (the
      Dicts above).
    - `robot_map_info`: True (default) or False: whether infos carry `robot_map` (see
      Info). The map-based planners (`Parallax`, `GreedyOneStep`, `Lookahead` and their
      oracles) need it and refuse an env without it; training runs that never read it
      can turn it off to save its cost (observations and rewards are the same either way).
    - `sensor_info`: False (default) or True: whether infos carry `seen` (which
      landmarks the last reading saw) and `blocked` (a wall or an obstacle stopped the
      move).
    - `planner_features`: False (default) or True: whether the observation ends with the
      planner features of the action grid's moves (see Observation Space); the
      `-Planner` task ids set it with `n_turns=8, n_move_lengths=2`.
    - `render_mode`: `None`, `"human"` or `"rgb_array"`.
    - `config`: an `EnvConfig` (`bearing_env.envs.config`) holding all the settings
      above but `render_mode`, instead of the keywords (`EnvConfig.create(...)` takes
      the same keywords; giving both is refused). Invalid settings raise `TypeError` or
      `ValueError` naming the value.

    The settings are written once, as the fields of `EnvConfig`'s groups (`layout`,
    `sensor`, `mapping`, `task`, `actions`, `observations`; see
    `bearing_env.envs.config`): the constructor takes `**settings`, `EnvConfig.create`
    routes each to its group, and the constructor's signature
    (`inspect.signature(BearingSLAMEnv)`, `help()`) is generated from the groups.

    Every setting but `landmarks` is also an attribute (`env.area_cap`, `env.path_cost`,
    ...; `reward` is `env.reward_kind`, `n_landmarks` is `env.landmark_counts`), generated
    from the same groups; assigning one replaces `env.config` with a validated copy.
    `max_landmarks` and `observation_kind` (the `observation` setting) are read-only
    (they fix the observation space). A change of `epsilon_deg`, `transfer`, `fusion`,
    `max_outliers` or `on_inconsistency` gives the env a new, empty map.

    ## Version History

    * v0: Initial version.
    * v1: the conservative transfer grows regions by a local bound instead of one
      global radius per movement (bearing_env 0.2.0); `-v0` keeps the old bound
      (`transfer="conservative_global"`), see `bearing_env.tasks.VERSIONS`.
    """

    #: The action kind: its space, decoding and encoding (:mod:`bearing_env.envs.actions`).
    action_spec: ClassVar[ActionSpec] = CONTINUOUS
    #: The constructor's keywords, generated from the config's groups (:func:`install_settings`).
    __signature__: ClassVar[inspect.Signature]
    metadata: dict[str, Any] = {"render_modes": ["human", "rgb_array"], "render_fps": 4}  # noqa: RUF012

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        install_settings(cls)

    def __init__(
        self, *, render_mode: str | None = None, config: EnvConfig | None = None, **settings: Any
    ) -> None:
        # The settings' one signature is EnvConfig.create's: the keywords go there
        # (``__init__.__signature__``, set below the class, shows them all).
        super().__init__()
        grid = self.action_spec.grid_fixed
        self._setup(settings_from(config, settings, grid), render_mode)

    def _setup(self, config: EnvConfig, render_mode: str | None) -> None:
        """Everything but the config's construction: spaces, state, maps."""
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"unknown render_mode {render_mode!r}; expected None or one of "
                f"{tuple(self.metadata['render_modes'])}"
            )
        self._config = config
        self.render_mode = render_mode
        self.action_space = self._make_action_space()
        #: The observation kind's spec (the kind cannot change on a live env).
        self.observation_spec: ObservationSpec = spec_for(config)
        # Any: the entity kind's Dict space is not the Box the class's type parameter names.
        self.observation_space = cast(Any, self.observation_spec.space(config))
        #: The batch of one this env is; its row index array, for the core's functions.
        self._rows = np.array([0])
        self._state = BatchState.empty(1, config.observations.max_landmarks)
        self._state.n_landmarks[:] = config.layout.landmark_counts[1]
        self._maps = MapBank(1)
        self._world: WorldView | None = None
        self._renderer: Any = None

    def _make_action_space(self) -> spaces.Space[Any]:
        return self.action_spec.space(self.config)

    # ------------------------------------------------------------------------------------
    # Settings and read-only views
    # ------------------------------------------------------------------------------------

    @property
    def config(self) -> EnvConfig:
        """All the settings; assigning a setting attribute replaces it (validated)."""
        return self._config

    @config.setter
    def config(self, config: EnvConfig) -> None:
        grid_fixed = self.action_spec.grid_fixed
        core.check_config_switch(self._config, config, action_grid_fixed=grid_fixed)
        core.switch_maps(self._state, self._maps, 0, self._config, config)
        self._config = config
        if self._world is not None:
            self._world.config = config

    @property
    def epsilon(self) -> float:
        """The SLAM's bearing error bound, radians."""
        return self.config.epsilon

    @property
    def fixed_landmarks(self) -> FloatArray | None:
        """The scenario's fixed landmark positions (n, 2), metres; None if random."""
        return self.config.layout.fixed_landmarks

    @property
    def n_landmarks(self) -> int:
        """Landmarks in the current episode (drawn from ``landmark_counts`` at each reset)."""
        return int(self._state.n_landmarks[0])

    @property
    def slam(self) -> PolygonSLAM:
        """The robot's map: everything the robot knows (regions, estimates, its pose)."""
        return self._maps.view(self.n_landmarks, self.config, 0)

    @property
    def world(self) -> WorldView | None:
        """Ground truth (true landmarks, the robot's true pose), a read-only live view;
        None before the first reset.

        For evaluation and privileged policies only: a policy that reads it cheats.
        """
        return self._world

    @property
    def np_random(self) -> np.random.Generator:
        """The env's generator (as ``gym.Env``'s). The env draws its movement noise ahead
        in blocks; reading the generator first hands the unspent draws back to it, so it
        is where drawing move by move would have left it (the next move draws again)."""
        core.release_noise(self._state, 0)
        return super().np_random

    @np_random.setter
    def np_random(self, value: np.random.Generator) -> None:
        # why: mypy does not follow a property's setter through super()
        gym.Env.np_random.fset(self, value)  # type: ignore[attr-defined]
        core.bind_noise(self._state, 0, value)

    # ------------------------------------------------------------------------------------
    # Gymnasium API
    # ------------------------------------------------------------------------------------

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[NDArray[np.float32], dict[str, Any]]:
        check_reset_options(options)
        super().reset(seed=seed)
        rows, config = self._rows, self.config
        core.reset_rows(self._state, rows, config, [self.np_random], self._maps)
        if self._world is None:
            self._world = WorldView(self._state, 0, config)
        group = self._maps.group(self._state, rows, config)
        report, robot_map_info = core.report(self._state, group)
        if self.render_mode == "human":
            self.render()
        info = core.single_info(
            group, report, robot_map_info, core.sensor_info(self._state, group)
        )
        return self._observation(report.observations[0].copy()), info  # a step reuses it

    def step(
        self, action: NDArray[np.float32] | ArrayLike
    ) -> tuple[NDArray[np.float32], SupportsFloat, bool, bool, dict[str, Any]]:
        if self._world is None:
            raise RuntimeError("call reset() before step()")
        if self._state.done[0]:
            raise RuntimeError(
                "the episode has ended (terminated or truncated): call reset() before step() again"
            )
        turns, lengths = self._decode_batch(self._checked_action(action)[None])
        group = self._maps.group(self._state, self._rows, self._config)
        report, robot_map_info = core.step(self._state, group, turns, lengths)
        if self.render_mode == "human":
            self.render()
        return (
            self._observation(report.observations[0].copy()),  # the step reuses its report
            report.rewards.item(),
            report.terminated.item(),
            report.truncated.item(),
            core.single_info(group, report, robot_map_info, core.sensor_info(self._state, group)),
        )

    def _observation(self, flat: NDArray[np.float32]) -> Any:
        """The observation of the env's kind from the flat vector."""
        return self.observation_spec.convert(flat, self.config.observations.max_landmarks)

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

            arena = self.config.layout.arena
            self._renderer = Renderer(self.render_mode, arena, fps=self.metadata["render_fps"])
        from bearing_env.rendering import scene

        return self._renderer.render(scene(self._state, 0, self.config, self.slam))

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    # ``gym.make`` assigns the spec after construction; the ids register no
    # ``max_episode_steps``, so the spec reads the env's own cap instead.
    _spec: EnvSpec | None = None

    @property
    def spec(self) -> EnvSpec | None:
        """The spec ``gym.make`` gave, whose ``max_episode_steps`` (unless the caller set
        one, which adds a ``TimeLimit``) is this env's ``max_moves``."""
        spec = self._spec
        if spec is None or spec.max_episode_steps is not None:
            return spec
        return dataclasses.replace(spec, max_episode_steps=self.config.task.max_moves)

    @spec.setter
    def spec(self, spec: EnvSpec | None) -> None:
        self._spec = spec

    def __getstate__(self) -> dict[str, Any]:
        # A pygame window or surface cannot be pickled; a fresh one is made on demand.
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        # Ray's object store hands arrays back read-only. The row indices are made
        # writable again, so the step kernels get the one type they are compiled and
        # cached for: read-only ones made each Ray worker compile a second step kernel.
        # (That kernel once segfaulted from the cache: see bearing_env.slam.kernels.common.)
        state["_rows"] = np.require(state["_rows"], requirements=["W"])
        self.__dict__.update(state)

    # ------------------------------------------------------------------------------------
    # Actions
    # ------------------------------------------------------------------------------------

    def _checked_action(self, action: Any) -> NDArray[Any]:
        """One action, checked by the env's action spec (ValueError otherwise)."""
        return self.action_spec.check_one(self.config, action)

    def _decode_batch(self, actions: NDArray[Any]) -> tuple[FloatArray, FloatArray]:
        """(turn angles, move lengths) of a batch of checked actions."""
        return self.action_spec.decode(self.config, actions)

    def _decode_action(self, action: Any) -> tuple[float, float]:
        """(turn angle in radians, requested move length in metres) from an action."""
        turns, lengths = self._decode_batch(self._checked_action(action)[None])
        return float(turns[0]), float(lengths[0])


def check_reset_options(options: object, known: Collection[str] = ()) -> Mapping[str, Any]:
    """``reset``'s ``options`` as a mapping (empty for None), whose keys must be among
    ``known`` (the single env takes none): TypeError naming the value or the keys."""
    if options is None:
        return {}
    if not isinstance(options, Mapping):
        raise TypeError(f"reset options must be a dict or None, got {options!r}")
    unknown = [key for key in options if key not in known]
    if unknown:
        expected = f"expected keys among {sorted(known)!r}" if known else "it takes none"
        raise TypeError(f"unknown reset options {unknown!r}; {expected}")
    return options


def constructor_signature(env_class: type[BearingSLAMEnv]) -> inspect.Signature:
    """The signature ``inspect.signature(env_class)`` and ``help()`` show: ``render_mode``
    and ``config``, then every setting the class takes (generated from the config's
    groups, so the settings are written once)."""
    keyword = inspect.Parameter.KEYWORD_ONLY
    leading = [
        inspect.Parameter("render_mode", keyword, default=None, annotation="str | None"),
        inspect.Parameter("config", keyword, default=None, annotation="EnvConfig | None"),
    ]
    return settings_signature(grid=env_class.action_spec.grid_fixed, leading=leading)


def install_settings(env_class: type[BearingSLAMEnv]) -> None:
    """Give an env class its setting attributes (a :class:`Setting` per
    :data:`~bearing_env.envs.config.SETTINGS` entry that has an attribute; the grid's
    only if the class has a grid) and its constructor signature. Every subclass gets
    them (``__init_subclass__``), after its class body has set its ``action_spec``."""
    grid = env_class.action_spec.grid_fixed
    for spec in SETTINGS:
        if spec.attribute is not None and (grid or not spec.grid):
            setattr(env_class, spec.attribute, Setting(spec))
    env_class.__signature__ = constructor_signature(env_class)


install_settings(BearingSLAMEnv)
