"""Every construction setting of the BearingSLAM envs, in one frozen, validated object.

:class:`EnvConfig` is shared by the continuous env, the discrete env and the batched
vector env. It is frozen, hashable and comparable, so the vector env can group its
sub-envs by config and step each group as one batch.

Two ways to build one:

- :meth:`EnvConfig.create` takes the envs' keyword arguments (``scenario="khepera"``,
  ``n_landmarks=(4, 8)``, ``noise={"kind": "gaussian"}``, ...), fills in the scenario's
  defaults and validates everything;
- ``EnvConfig(...)`` / :meth:`EnvConfig.replace` take the resolved fields; they are
  validated too (``__post_init__``), so no config object holds an invalid setting.

Invalid values raise ``TypeError`` (wrong type) or ``ValueError`` (wrong value), naming
the value.
"""

from __future__ import annotations

import dataclasses
import inspect
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env.slam import FUSIONS, INCONSISTENCY_POLICIES, TRANSFERS
from bearing_env.slam.batch import DEFAULT_MAX_OUTLIERS, DEFAULT_WINDOW
from bearing_env.validation import (
    EPSILON_RANGE,
    choice,
    int_at_least,
    int_at_most,
    is_real,
    non_negative_float,
    positive_float,
)
from bearing_env.world import SCENARIOS, Arena, NoiseModel

#: Default episode length in moves (``max_moves``, the one episode cap).
DEFAULT_MAX_MOVES = 20
#: Default number of landmark slots in the observation (more if ``n_landmarks`` is larger).
DEFAULT_MAX_LANDMARKS = 8
#: Default number of landmarks of the ``"random"`` scenario.
DEFAULT_N_LANDMARKS = 4
#: Most landmarks (and observation slots) an env accepts: beyond this the map update and
#: the observation grow past anything a policy can use, and memory use gets silly.
MAX_N_LANDMARKS = 1024
#: Default area (FL units squared) at which an uninitialised landmark counts in the reward,
#: and above which areas are capped. |L1 - L2| = 1, so 10 is a region a few times the
#: size of the L1-L2 baseline squared: larger than any useful estimate.
DEFAULT_AREA_CAP = 10.0
#: Largest accepted ``area_cap``: ``reward="area"`` sums capped areas over up to
#: ``MAX_N_LANDMARKS`` landmarks, and the reward must stay a finite, well-scaled number.
MAX_AREA_CAP = 1e6
#: Default success threshold: every landmark region below this area (FL units squared).
DEFAULT_TARGET_AREA = 0.05
#: Areas are floored here before taking logs, so log-areas stay finite.
AREA_FLOOR = 1e-10
#: Bearing error bounds accepted for epsilon (degrees, exclusive): the world model's own
#: (``bearing_env.validation.EPSILON_RANGE``), in degrees.
EPSILON_DEG_RANGE = (math.degrees(EPSILON_RANGE[0]), math.degrees(EPSILON_RANGE[1]))
#: Default number of relative headings of the discrete env: every 45 degrees.
DEFAULT_N_TURNS = 8
#: Default number of move lengths of the discrete env when ``move_length`` is a range.
DEFAULT_N_MOVE_LENGTHS = 3
#: Most entries of each discrete action table (``n_turns``, ``n_move_lengths``). The
#: tables are rebuilt at every step, so their size is per-step cost (10**8 turns take
#: seconds a step, 10**9 exhaust memory); 4096 turns are 0.088 degrees apart, far finer
#: than the bearing error bound (epsilon_deg > 0, 2 by default) lets a map tell apart.
MAX_ACTION_TABLE = 4096

REWARDS: tuple[str, ...] = ("log_area", "area")
#: Observation kinds: the flat Box (default) or a Dict of a robot block and a landmark
#: table (``bearing_env.envs.observations.EntityObservation``).
OBSERVATIONS: tuple[str, ...] = ("flat", "entities")


#: The settings of the discrete action grid, which only the discrete env takes.
GRID_SETTINGS: tuple[str, ...] = ("n_turns", "n_move_lengths")


def settings_signature(
    *, grid: bool, leading: Sequence[inspect.Parameter] = ()
) -> inspect.Signature:
    """The keyword signature of an env constructor, generated from
    :meth:`EnvConfig.create`'s, the one home of the settings, their types and defaults
    (less :data:`GRID_SETTINGS` unless ``grid``), after the ``leading`` parameters.

    The envs take ``**settings`` and set this as their ``__init__.__signature__``, so
    ``help()``, ``inspect.signature`` and IDEs that run the code show every setting.
    """
    settings = [
        parameter.replace(kind=inspect.Parameter.KEYWORD_ONLY)
        for name, parameter in inspect.signature(EnvConfig.create).parameters.items()
        if grid or name not in GRID_SETTINGS
    ]
    return inspect.Signature([*leading, *settings])


#: ``EnvConfig.map_settings``: the world model's keyword settings as a hashable tuple.
MapSettings = tuple[tuple[str, Any], ...]


def _is_pair_like(value: Any) -> bool:
    return not isinstance(value, (str, bytes)) and isinstance(value, (Sequence, np.ndarray))


@dataclass(frozen=True)
class EnvConfig:
    """The settings of one BearingSLAM env (see ``BearingSLAMEnv``'s Arguments section).

    Fields hold resolved values: ``landmark_counts`` is ``(lo, hi)`` (equal for a fixed
    count), ``landmarks`` the fixed positions as a tuple of ``(x, y)`` (None for random
    layouts), ``move_length`` a ``(lo, hi)`` pair. ``n_turns`` and ``n_move_lengths``
    are the discrete env's action grid; the continuous env ignores them.
    """

    scenario: str
    landmark_counts: tuple[int, int]
    landmarks: tuple[tuple[float, float], ...] | None
    arena: Arena
    epsilon_deg: float
    noise: NoiseModel
    transfer: str
    reward: str
    target_area: float
    max_moves: int
    move_length: tuple[float, float]
    path_cost: float
    move_cost: float
    area_cap: float
    max_landmarks: int
    n_turns: int = DEFAULT_N_TURNS
    n_move_lengths: int = DEFAULT_N_MOVE_LENGTHS
    fusion: str = "intersect"
    max_outliers: int = DEFAULT_MAX_OUTLIERS
    on_inconsistency: str = "restart"
    observation: str = "flat"

    # ------------------------------------------------------------------------------------
    # Construction
    # ------------------------------------------------------------------------------------

    @classmethod
    def create(
        cls,
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
        n_turns: int = DEFAULT_N_TURNS,
        n_move_lengths: int | None = None,
        fusion: str = "intersect",
        max_outliers: int = DEFAULT_MAX_OUTLIERS,
        on_inconsistency: str = "restart",
        observation: str = "flat",
    ) -> EnvConfig:
        """A validated config from the envs' keyword arguments, with the scenario's
        defaults for what is left out."""
        name = _resolve_scenario(scenario, landmarks)
        spec = SCENARIOS[name]
        resolved_arena = _resolve_arena(arena, spec.arena_size)
        fixed = _resolve_landmarks(landmarks, spec.landmarks)
        counts = _resolve_landmark_counts(n_landmarks, fixed, name)
        lengths = (
            resolved_arena.default_move_length
            if move_length is None
            else _resolve_move_length(move_length)
        )
        if max_landmarks is None:
            max_landmarks = max(DEFAULT_MAX_LANDMARKS, counts[1])
        n_turns = int_at_most(int_at_least(n_turns, 1, "n_turns"), MAX_ACTION_TABLE, "n_turns")
        if n_move_lengths is None:
            n_move_lengths = 1 if lengths[0] == lengths[1] else DEFAULT_N_MOVE_LENGTHS
        return cls(
            scenario=name,
            landmark_counts=counts,
            landmarks=fixed,
            arena=resolved_arena,
            epsilon_deg=epsilon_deg,
            noise=NoiseModel.parse(noise),
            transfer=transfer,
            reward=reward,
            target_area=target_area,
            max_moves=max_moves,
            move_length=lengths,
            path_cost=path_cost,
            move_cost=move_cost,
            area_cap=area_cap,
            max_landmarks=max_landmarks,
            n_turns=n_turns,
            n_move_lengths=n_move_lengths,
            fusion=fusion,
            max_outliers=max_outliers,
            on_inconsistency=on_inconsistency,
            observation=observation,
        )

    def __post_init__(self) -> None:
        # Every check of a resolved field lives here, so direct construction and
        # replace() are validated as create() is. Values are normalised to plain Python
        # types so that equal settings give equal (and equally hashed) configs.
        def normalise(name: str, value: Any) -> None:
            object.__setattr__(self, name, value)

        choice(self.scenario, tuple(SCENARIOS), "scenario")
        # Direct construction and replace() may still hold a raw (width, height) here.
        arena = cast("tuple[float, float] | Arena", self.arena)
        if not isinstance(arena, Arena):
            normalise("arena", _resolve_arena(arena, SCENARIOS[self.scenario].arena_size))
        lo, hi = _resolve_count_pair(self.landmark_counts)
        normalise("landmark_counts", (lo, hi))
        if self.landmarks is not None:
            points = _landmark_points(self.landmarks)
            if points.shape[0] != lo or lo != hi:
                raise ValueError(
                    f"n_landmarks={self.landmark_counts!r} contradicts the "
                    f"{points.shape[0]} fixed landmark positions"
                )
            _check_layout(points, self.arena)
            normalise("landmarks", tuple((float(x), float(y)) for x, y in points))

        if not is_real(self.epsilon_deg):
            raise TypeError(f"epsilon_deg must be a number, got {self.epsilon_deg!r}")
        lo_eps, hi_eps = EPSILON_DEG_RANGE
        if not lo_eps < float(self.epsilon_deg) < hi_eps:
            raise ValueError(
                f"epsilon_deg must be in ({lo_eps:g}, {hi_eps:g}) degrees, got {self.epsilon_deg!r}"
            )
        normalise("epsilon_deg", float(self.epsilon_deg))
        normalise("noise", NoiseModel.parse(self.noise))
        choice(self.transfer, TRANSFERS, "transfer")
        choice(self.reward, REWARDS, "reward")
        normalise("target_area", positive_float(self.target_area, "target_area"))
        normalise("max_moves", int_at_least(self.max_moves, 1, "max_moves"))
        normalise("move_length", _resolve_move_length(self.move_length))
        normalise("path_cost", non_negative_float(self.path_cost, "path_cost"))
        normalise("move_cost", non_negative_float(self.move_cost, "move_cost"))
        area_cap = positive_float(self.area_cap, "area_cap")
        if not AREA_FLOOR < area_cap <= MAX_AREA_CAP:
            raise ValueError(
                f"area_cap must be in ({AREA_FLOOR:g}, {MAX_AREA_CAP:g}], got {self.area_cap!r}"
            )
        normalise("area_cap", area_cap)
        max_landmarks = int_at_least(self.max_landmarks, hi, "max_landmarks")
        normalise("max_landmarks", int_at_most(max_landmarks, MAX_N_LANDMARKS, "max_landmarks"))
        for table in ("n_turns", "n_move_lengths"):
            size = int_at_least(getattr(self, table), 1, table)
            normalise(table, int_at_most(size, MAX_ACTION_TABLE, table))
        choice(self.fusion, FUSIONS, "fusion")
        max_outliers = int_at_least(self.max_outliers, 0, "max_outliers")
        normalise("max_outliers", int_at_most(max_outliers, DEFAULT_WINDOW - 1, "max_outliers"))
        choice(self.on_inconsistency, INCONSISTENCY_POLICIES, "on_inconsistency")
        choice(self.observation, OBSERVATIONS, "observation")

    def replace(self, **changes: Any) -> EnvConfig:
        """A copy with some fields changed (validated)."""
        unknown = set(changes) - {f.name for f in dataclasses.fields(self)}
        if unknown:
            raise TypeError(f"unknown EnvConfig fields {sorted(unknown)!r}")
        return dataclasses.replace(self, **changes)

    # ------------------------------------------------------------------------------------
    # Derived settings
    # ------------------------------------------------------------------------------------

    @property
    def epsilon(self) -> float:
        """The SLAM's bearing error bound, radians."""
        return math.radians(self.epsilon_deg)

    @property
    def map_settings(self) -> MapSettings:
        """The world model's settings (``BatchedPolygonSLAM`` keywords), as a hashable
        key: envs whose maps share them can share a batch."""
        return (
            ("epsilon", self.epsilon),
            ("transfer", self.transfer),
            ("fusion", self.fusion),
            ("max_outliers", self.max_outliers),
            ("on_inconsistency", self.on_inconsistency),
        )

    @property
    def fixed_landmarks(self) -> NDArray[np.float64] | None:
        """The fixed landmark positions (n, 2) in metres (a new array), or None."""
        return None if self.landmarks is None else np.array(self.landmarks, dtype=np.float64)

    @property
    def has_count_range(self) -> bool:
        """Whether the landmark count is drawn anew every episode."""
        return self.landmark_counts[0] < self.landmark_counts[1]


# ----------------------------------------------------------------------------------------
# Resolution of the user-facing forms
# ----------------------------------------------------------------------------------------


def _resolve_scenario(scenario: str | None, landmarks: ArrayLike | None) -> str:
    if scenario is None:
        return "random" if landmarks is None else "custom"
    name = choice(scenario, tuple(SCENARIOS), "scenario")
    if name == "custom" and landmarks is None:
        raise ValueError("scenario 'custom' needs explicit `landmarks` positions")
    if name != "custom" and landmarks is not None:
        raise ValueError(
            f"`landmarks` were given with scenario {name!r}; explicit positions use "
            "scenario 'custom' (or leave scenario unset)"
        )
    return name


def _resolve_arena(
    arena: tuple[float, float] | Arena | None, default: tuple[float, float]
) -> Arena:
    if arena is None:
        return Arena(*default)
    if isinstance(arena, Arena):
        return arena
    if not _is_pair_like(arena):
        raise TypeError(f"arena must be (width, height) in metres, got {arena!r}")
    if len(arena) != 2:
        raise ValueError(f"arena must be (width, height) in metres, got {arena!r}")
    return Arena(arena[0], arena[1])


def _landmark_points(landmarks: ArrayLike) -> NDArray[np.float64]:
    """Landmark positions as an (n, 2) float array, shape and count checked."""
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
            f"landmarks must hold >= 3 positions (L1, L2 and one to map), got {points.shape[0]}"
        )
    if points.shape[0] > MAX_N_LANDMARKS:
        raise ValueError(
            f"landmarks must hold <= {MAX_N_LANDMARKS} positions, got {points.shape[0]}"
        )
    if not np.all(np.isfinite(points)):
        raise ValueError(f"landmarks must be finite, got {points.tolist()}")
    return points


def _check_layout(points: NDArray[np.float64], arena: Arena) -> None:
    inside = arena.contains(points)
    if not np.all(inside):
        raise ValueError(
            f"landmarks {points[~inside].tolist()} lie outside the arena "
            f"{arena.width:g} x {arena.height:g} m"
        )
    separation = np.hypot(*(points[:, None, :] - points[None, :, :]).transpose(2, 0, 1))
    np.fill_diagonal(separation, np.inf)
    if separation.min() < 1e-6 * arena.scale:
        raise ValueError(f"landmarks must be distinct points, got {points.tolist()}")


def _resolve_landmarks(
    landmarks: ArrayLike | None, scenario_landmarks: tuple[tuple[float, float], ...] | None
) -> tuple[tuple[float, float], ...] | None:
    if landmarks is None:
        return scenario_landmarks
    points = _landmark_points(landmarks)
    return tuple((float(x), float(y)) for x, y in points)


def _resolve_count_pair(counts: Any) -> tuple[int, int]:
    if not isinstance(counts, (tuple, list)) or len(counts) != 2:
        raise ValueError(f"n_landmarks range must be (lo, hi), got {counts!r}")
    lo = int_at_least(counts[0], 3, "n_landmarks")
    hi = int_at_least(counts[1], lo, "n_landmarks")
    return lo, int_at_most(hi, MAX_N_LANDMARKS, "n_landmarks")


def _resolve_landmark_counts(
    n_landmarks: int | tuple[int, int] | None,
    fixed: tuple[tuple[float, float], ...] | None,
    scenario: str,
) -> tuple[int, int]:
    """``(lo, hi)``: each episode has between lo and hi landmarks (both included)."""
    if isinstance(n_landmarks, (tuple, list)):
        if fixed is not None:
            raise ValueError(
                f"n_landmarks={n_landmarks!r}: a range needs random layouts, but scenario "
                f"{scenario!r} has fixed landmark positions"
            )
        return _resolve_count_pair(n_landmarks)
    if fixed is not None:
        if n_landmarks is not None:
            n = int_at_least(n_landmarks, 3, "n_landmarks")
            if n != len(fixed):
                raise ValueError(
                    f"n_landmarks={n_landmarks!r} contradicts the {len(fixed)} landmark "
                    f"positions of scenario {scenario!r}"
                )
        return len(fixed), len(fixed)
    if n_landmarks is None:
        return DEFAULT_N_LANDMARKS, DEFAULT_N_LANDMARKS
    n = int_at_least(n_landmarks, 3, "n_landmarks")
    int_at_most(n, MAX_N_LANDMARKS, "n_landmarks")
    return n, n


def _resolve_move_length(move_length: Any) -> tuple[float, float]:
    if is_real(move_length):
        length = positive_float(move_length, "move_length")
        return (length, length)
    if not _is_pair_like(move_length):
        raise TypeError(
            f"move_length must be a number or a (lo, hi) pair of metres, got {move_length!r}"
        )
    if len(move_length) != 2:
        raise ValueError(f"move_length must be a (lo, hi) pair, got {move_length!r}")
    lo = positive_float(move_length[0], "move_length lo")
    hi = positive_float(move_length[1], "move_length hi")
    if lo > hi:
        raise ValueError(f"move_length must have lo <= hi, got {tuple(move_length)!r}")
    return (lo, hi)
