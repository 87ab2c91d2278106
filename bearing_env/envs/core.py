"""The envs' pure functional core: world state and bookkeeping of a batch, as arrays.

In the spirit of Gymnasium's ``phys2d/cartpole.py``: one
:class:`~bearing_env.envs.state.BatchState` holds the
state of ``N`` envs as a structure of arrays (one row per env), and plain functions
compute on a group of rows at once:

- :func:`reset_rows` starts new episodes (in Python: a layout's rejection sampling
  draws from the row's generator), and draws each row's first block of movement noise
  ahead (:func:`fill_noise`);
- :func:`step` moves the robots, reads the sensors, updates the maps and computes the
  rewards, terminations, truncations, observations and infos, in one native call
  (``_core.step_rows``); :func:`report` gives the observations and infos alone;
- :func:`infos` and :func:`single_info` make the info dicts of the step's arrays.

``BearingSLAMEnv`` is a batch of one; ``BearingSLAMVectorEnv`` steps the whole batch.
Both call exactly these functions, so they agree bit for bit: every computation is
row-wise (a row's result does not depend on the other rows of its batch), and every
random draw comes from the row's own generator, in the same order as in a batch of one
(and as drawing move by move: the noise drawn ahead that an episode does not spend is
handed back, :func:`release_noise`).

A *group* is a set of rows that share one :class:`~bearing_env.envs.config.EnvConfig`
and one landmark count ``n`` (so one map batch, and arrays ``[:, :n]`` without padding).
The functions below take a :class:`Group` (its rows, config, landmark count, map batch
and kernel inputs), which :meth:`MapBank.group` builds once per step; rows outside it are
untouched.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env.envs import candidates, kernels, robot_map
from bearing_env.envs.config import AREA_FLOOR, EnvConfig
from bearing_env.envs.kernels import Settings
from bearing_env.envs.observations import FL_COORD_LIMIT
from bearing_env.envs.state import BatchState
from bearing_env.numerics import wrap_angle
from bearing_env.obstacles import Obstacle
from bearing_env.sensing import visible_rows
from bearing_env.slam import MapSettings, PolygonSLAM
from bearing_env.slam import kernels as slam_kernels
from bearing_env.slam.batch import (
    CONTAINMENT_TOLERANCE,
    PARALLEL_MIN_MAPS,
    STATE_ARRAYS,
    BatchedPolygonSLAM,
)
from bearing_env.world import (
    Arena,
    NoiseModel,
    World,
    random_layout,
    random_start,
    true_bearings,
)

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
ComplexArray = NDArray[np.complex128]


# ----------------------------------------------------------------------------------------
# State
# ----------------------------------------------------------------------------------------


class MapBank:
    """The robots' maps: one :class:`BatchedPolygonSLAM` per (landmark count,
    :class:`~bearing_env.slam.MapSettings`), each with a row per env (row ``i`` of every
    batch belongs to env ``i``).

    Envs whose landmark count varies switch batches at reset; their rows in the other
    batches are simply left idle. The bank also keeps each (config, landmark count)'s
    kernel inputs (:meth:`group`).
    """

    def __init__(self, num_rows: int) -> None:
        self.num_rows = num_rows
        self.batches: dict[tuple[int, MapSettings], BatchedPolygonSLAM] = {}
        self._views: dict[tuple[int, MapSettings, int], PolygonSLAM] = {}
        #: Each (landmark count, config)'s native kernel inputs (``_core.EnvInputs``),
        #: with the state and map batch they were made of, and what its steps reuse (the
        #: step's output arrays: see :func:`step`).
        self._inputs: dict[tuple[int, EnvConfig], tuple[Any, Any, Any, dict[Any, Any]]] = {}

    def group(self, state: BatchState, rows: IntArray, config: EnvConfig) -> Group:
        """The group of ``rows`` (all with ``config`` and one landmark count), with its
        kernel inputs: made once per (config, count) and state, then reused."""
        n = int(state.n_landmarks[rows[0]])
        last = self.__dict__.get("_last")
        if last is None or last[0] is not config or last[1] != n or last[2] is not state:
            last = self._last = (config, n, state, *self._inputs_for(n, config, state))
        return Group(rows, config, n, last[3], last[4], last[5])

    def batch(self, n_landmarks: int, config: EnvConfig) -> BatchedPolygonSLAM:
        return self._batch_for(int(n_landmarks), config.map_settings)

    def _inputs_for(
        self, n: int, config: EnvConfig, state: BatchState
    ) -> tuple[BatchedPolygonSLAM, Any, dict[Any, Any]]:
        batch = self._batch_for(n, config.map_settings)
        kept = self._inputs.get((n, config))
        if kept is None or kept[0] is not state or kept[1] is not batch:
            # The batch's arrays are only ever written in place (a new batch, after a
            # pickle, has new ones): the inputs hold views of them and of the state's.
            maps = _core.MapState(slam_kernels.State(*(batch.__dict__[k] for k in STATE_ARRAYS)))
            params = batch._kernel_params(True)
            inputs = _core.EnvInputs(kernel_settings(n, config), params, maps, state)
            kept = self._inputs[n, config] = (state, batch, inputs, {})
        return batch, kept[2], kept[3]

    def _batch_for(self, n_landmarks: int, settings: MapSettings) -> BatchedPolygonSLAM:
        key = (n_landmarks, settings)
        if key not in self.batches:
            self.batches[key] = BatchedPolygonSLAM.from_settings(
                self.num_rows, n_landmarks, settings
            )
        return self.batches[key]

    def view(self, n_landmarks: int, config: EnvConfig, row: int) -> PolygonSLAM:
        """Row ``row``'s map as a :class:`PolygonSLAM` (the same object every time)."""
        key = (int(n_landmarks), config.map_settings, int(row))
        if key not in self._views:
            self._views[key] = PolygonSLAM.view(self.batch(n_landmarks, config), row)
        return self._views[key]

    def __getstate__(self) -> dict[str, Any]:
        # The native kernel inputs hold views, not arrays: they are made again.
        state = {key: value for key, value in self.__dict__.items() if key != "_last"}
        state["_inputs"] = {}
        return state


class Group(NamedTuple):
    """A group's rows and everything its kernels take, found once per step
    (:meth:`MapBank.group`)."""

    rows: IntArray
    config: EnvConfig
    n: int  #: the rows' landmark count
    batch: BatchedPolygonSLAM  #: their maps
    inputs: Any  #: what the kernels take (a ``_core.EnvInputs``)
    #: What the group's steps reuse: their output arrays (:func:`_outputs`).
    reused: dict[Any, Any]


def kernel_settings(n_landmarks: int, config: EnvConfig) -> Settings:
    """The kernels' settings of a group of ``config`` with ``n_landmarks`` landmarks."""
    arena, task, sensor = config.layout.arena, config.task, config.sensor
    vertices, starts = config.layout.packed_obstacles
    return Settings(
        n=int(n_landmarks),
        n_slots=int(config.observations.max_landmarks),
        shape_features=config.observations.observation == "shapes",
        appended=candidates.features_size(config),
        width=float(arena.width),
        height=float(arena.height),
        margin=float(arena.wall_margin),
        min_baseline=float(arena.min_baseline),
        log_area=task.reward == "log_area",
        floor=AREA_FLOOR,
        cap=float(task.area_cap),
        target_area=float(task.target_area),
        max_moves=int(task.max_moves),
        path_cost=float(task.path_cost),
        move_cost=float(task.move_cost),
        coordinate_limit=FL_COORD_LIMIT,
        tolerance=CONTAINMENT_TOLERANCE,
        half_fov=sensor.half_fov,
        max_range=sensor.max_range,
        obstacle_vertices=vertices,
        obstacle_starts=starts,
    )


def check_config_switch(old: EnvConfig, new: EnvConfig, action_grid_fixed: bool) -> None:
    """Raise unless a live env may change its config from ``old`` to ``new``: the
    observation space (``max_landmarks``) and, for discrete envs (``action_grid_fixed``),
    the action grid cannot change."""
    if not isinstance(new, EnvConfig):
        raise TypeError(f"config must be an EnvConfig, got {new!r}")
    was, now = old.observations, new.observations
    if now.max_landmarks != was.max_landmarks:
        raise ValueError(
            f"max_landmarks cannot change ({was.max_landmarks} -> {now.max_landmarks}): "
            "it fixes the observation space; make a new env"
        )
    if now.observation != was.observation:
        raise ValueError(
            f"observation cannot change ({was.observation!r} -> {now.observation!r}): "
            "it fixes the observation space; make a new env"
        )
    grid_was = (old.actions.n_turns, old.actions.n_move_lengths)
    grid_now = (new.actions.n_turns, new.actions.n_move_lengths)
    if action_grid_fixed and grid_now != grid_was:
        raise ValueError(
            f"n_turns and n_move_lengths cannot change ({grid_was[0]}, {grid_was[1]} "
            f"-> {grid_now[0]}, {grid_now[1]}): they fix the action space"
        )


def switch_maps(state: BatchState, maps: MapBank, row: int, old: EnvConfig, new: EnvConfig) -> None:
    """After a config change of row ``row``: an empty map if the map's settings (epsilon,
    transfer, fusion, ...) changed, since the row may have stale state in that other map
    batch; the noise drawn ahead is handed back (the next move draws with the new
    settings)."""
    if new.map_settings != old.map_settings:
        maps.batch(int(state.n_landmarks[row]), new).reset([row])
    # The noise drawn ahead was drawn with the old settings (noise model, max_moves).
    release_noise(state, row)


# ----------------------------------------------------------------------------------------
# Ground truth, read-only
# ----------------------------------------------------------------------------------------


class WorldView:
    """One row's ground truth (true landmarks, the robot's true pose), read-only and live.

    It is given what it reads: the batch ``state`` (the very object the env steps, so
    the view follows the episode), its ``row``, and the row's ``config``, which the
    owning env sets again whenever the row's config changes. It offers what
    :class:`~bearing_env.world.World` offers for reading. :meth:`copy` (and
    ``copy.deepcopy``) give an independent, mutable :class:`World`.
    """

    def __init__(self, state: BatchState, row: int, config: EnvConfig) -> None:
        self._state = state
        self._row = int(row)
        #: The row's settings (arena, noise, epsilon); its env keeps it current.
        self.config = config

    @property
    def arena(self) -> Arena:
        return self.config.layout.arena

    @property
    def noise(self) -> NoiseModel:
        return self.config.sensor.noise

    @property
    def epsilon(self) -> float:
        return self.config.epsilon

    @property
    def n_landmarks(self) -> int:
        return int(self._state.n_landmarks[self._row])

    @property
    def landmarks(self) -> FloatArray:
        """True landmark positions (n, 2), metres (a read-only view)."""
        return _read_only(self._state.landmarks[self._row, : self.n_landmarks])

    @property
    def position(self) -> FloatArray:
        """The robot's true position (2,), metres (a read-only view)."""
        return _read_only(self._state.positions[self._row])

    @property
    def heading(self) -> float:
        return float(self._state.headings[self._row])

    @property
    def min_baseline(self) -> float:
        return self.arena.min_baseline

    def true_bearings(self) -> FloatArray:
        """Noise-free bearings (n,) of all landmarks, relative to the heading, [-pi, pi)."""
        return true_bearings(self.landmarks[None], self.position[None], np.array([self.heading]))[0]

    @property
    def half_fov(self) -> float:
        """Half the camera's field of view, radians (pi: panoramic)."""
        return self.config.sensor.half_fov

    @property
    def max_range(self) -> float:
        """The camera's range, metres."""
        return self.config.sensor.max_range

    @property
    def obstacles(self) -> tuple[Obstacle, ...]:
        """The arena's obstacles (polygons of (x, y) metres)."""
        return self.config.layout.obstacles

    def copy(self) -> World:
        """An independent, mutable snapshot of this ground truth (the camera and the
        obstacles included)."""
        return World(
            self.arena, self.landmarks, self.position, self.heading, self.noise, self.epsilon,
            self.half_fov, self.max_range, self.obstacles,
        )  # fmt: skip

    def __deepcopy__(self, memo: dict[int, Any]) -> World:
        return self.copy()


def _read_only(array: FloatArray) -> FloatArray:
    view = array.view()
    view.flags.writeable = False
    return view


# ----------------------------------------------------------------------------------------
# Reset
# ----------------------------------------------------------------------------------------


def reset_rows(
    state: BatchState,
    rows: IntArray,
    config: EnvConfig,
    rngs: Sequence[np.random.Generator],
    maps: MapBank,
) -> None:
    """Start new episodes in ``rows`` (all with ``config``); ``rngs[j]`` is row
    ``rows[j]``'s generator.

    Each row draws, from its own generator and in this order: its landmark count (for a
    count range), its layout (``"random"``), its start pose, its first reading, then its
    first block of movement noise (:func:`fill_noise`); the generator becomes the row's
    noise generator.
    Afterwards the rows may have different landmark counts (see :func:`group_rows`).
    """
    layout, noise = config.layout, config.sensor.noise
    lo, hi = layout.landmark_counts
    fixed = layout.fixed_landmarks
    obstacles = layout.packed_obstacles if layout.obstacles else None
    state.landmarks[rows] = 0.0
    state.landmarks_fl[rows] = 0.0
    for row, rng in zip(rows.tolist(), rngs, strict=True):
        # The last episode's unspent noise goes back to its generator first.
        bind_noise(state, row, rng)
        release_noise(state, row)
        # Rejection sampling makes the draws per row: a layout's draw count varies.
        count = int(rng.integers(lo, hi + 1)) if hi > lo else hi
        if fixed is not None:
            landmarks = fixed
        else:
            landmarks = random_layout(rng, layout.arena, count, obstacles=obstacles)
        position, heading = random_start(rng, layout.arena, landmarks, obstacles=obstacles)
        state.n_landmarks[row] = count
        state.landmarks[row, :count] = landmarks
        state.positions[row] = position
        state.headings[row] = float(wrap_angle(heading))
        # Landmarks do not move: their true FL positions (for info) are fixed per episode.
        origin = complex(*landmarks[0])
        unit = complex(*landmarks[1]) - origin
        points = landmarks[2:, 0] + 1j * landmarks[2:, 1]
        state.frame_origin[row] = origin
        state.frame_unit[row] = unit
        state.landmarks_fl[row, : count - 2] = (points - origin) / unit
    state.moves[rows] = 0
    state.frame_changed[rows] = False
    state.blocked[rows] = False
    state.done[rows] = False
    state.start_bearings[rows] = np.nan
    state.start_positions[rows] = np.nan
    state.beliefs.reset(rows)
    state.trajectory_length[rows] = 0
    state.append_positions(rows)
    rng_of = dict(zip(rows.tolist(), rngs, strict=True))
    for n, group in group_rows(state, rows):
        truth = true_bearings(
            state.landmarks[group, :n], state.positions[group], state.headings[group]
        )
        group_rngs = [rng_of[i] for i in group.tolist()]
        readings = noise.corrupt_rows(group_rngs, truth, config.epsilon)
        readings[~sees(state, group, n, config)] = np.nan
        state.latest_bearings[group] = 0.0
        state.latest_bearings[group, :n] = readings
        rows_group = maps.group(state, group, config)
        rows_group.batch.reset(group)
        state.potentials[group] = potentials(state, rows_group)
    fill_noise(state, rows, config)


def sees(state: BatchState, rows: IntArray, n: int, config: EnvConfig) -> BoolArray:
    """Which of their ``n`` landmarks the rows' sensors see from their poses (len(rows), n)."""
    out = np.empty((rows.size, n), dtype=bool)
    vertices, starts = config.layout.packed_obstacles
    sensor = config.sensor
    visible_rows(
        state.landmarks[rows, :n],
        state.positions[rows],
        state.headings[rows],
        sensor.half_fov,
        sensor.max_range,
        vertices,
        starts,
        out,
    )
    return out


def group_rows(state: BatchState, rows: IntArray) -> list[tuple[int, IntArray]]:
    """``rows`` split by landmark count: ``[(n, rows with n landmarks), ...]``."""
    counts = state.n_landmarks[rows]
    first = int(counts[0])
    if np.all(counts == first):  # the common case: one count
        return [(first, rows)]
    return [(int(n), rows[counts == n]) for n in np.unique(counts)]


# ----------------------------------------------------------------------------------------
# Step
# ----------------------------------------------------------------------------------------


def step(
    state: BatchState, group: Group, turns: FloatArray, lengths: FloatArray
) -> tuple[kernels.Report, dict[str, Any] | None]:
    """One movement of every row of a group (same config, same landmark count ``n``):
    turn, read, move straight (stopped at the wall), read, update the map; the rewards,
    episode ends, observations and infos of :func:`report`, in one compiled call.

    ``turns`` and ``lengths`` are decoded actions (radians, metres). The readings' noise
    comes from the rows' noise buffers, which the rows' generators fill ahead
    (:func:`fill_noise`, called at reset and whenever a block is spent).
    """
    config, inputs = group.config, group.inputs
    rows, turns, lengths = _owned(group.rows, np.int64), _owned(turns), _owned(lengths)
    # Small batches stay on one thread (see PARALLEL_MIN_MAPS).
    threads = slam_kernels.threads() if rows.size >= PARALLEL_MIN_MAPS else 1
    report, encoded, outputs = _outputs(group, rows.size)
    with_map = encoded is not None
    while True:
        # The trajectory array is replaced when it grows: read it on every try.
        status = _core.step_rows(
            rows, turns, lengths, inputs, state.trajectory, threads, outputs, with_map
        )
        if status == kernels.STEP_DONE:
            if config.observations.planner_features:
                state.beliefs.moved(
                    rows, turns, lengths, state.frame_changed[rows], state.blocked[rows],
                    (state.start_bearings[rows, :2], state.latest_bearings[rows, :2]),
                    config.epsilon,
                )  # fmt: skip
                _write_candidates(state, group, report)
            return report, _robot_map_of(group, encoded)
        if status == kernels.STEP_NEEDS_NOISE:
            spent = state.noise_used[rows] + 2 * group.n > state.noise_filled[rows]
            fill_noise(state, rows[spent], config)
        else:
            state.grow_trajectory()


def _outputs(group: Group, size: int) -> tuple[kernels.Report, robot_map.Buffers | None, Any]:
    """The step kernels' output arrays for ``size`` of the group's rows: made once per
    group (for every row of the bank), then reused, so that a step hands nothing new out
    of its compiled call (see :mod:`bearing_env.envs.kernels`); the robot map's encoded
    arrays are None with ``robot_map_info`` off. Whoever keeps what a step wrote copies
    it (:func:`infos`, :func:`single_info`). The third is the native ``StepOutputs``
    over the arrays of every row (with the step's buffers): a step of ``size`` rows
    writes their first ``size`` rows."""
    outputs = group.reused.get(_OUTPUTS)
    if outputs is None:
        every_row = np.arange(group.batch.num_maps)
        encoded = None
        if group.config.observations.robot_map_info:
            slots = max(group.config.observations.max_landmarks - 2, group.n - 2)
            encoded = robot_map.buffers(_core.encode_map(group.inputs, every_row, slots))
        report = kernels.Report._make(_core.new_report(every_row.size, group.inputs))
        native = _core.StepOutputs(
            group.inputs, report, None if encoded is None else encoded.kernel
        )
        outputs = group.reused[_OUTPUTS] = (report, encoded, native)
    report, encoded, native = outputs
    if size == report.rewards.size:
        return report, encoded, native
    return (
        kernels.Report._make(values[:size] for values in report),
        None if encoded is None else encoded.rows(size),
        native,
    )


#: The key of the step kernels' output arrays in :attr:`Group.reused`.
_OUTPUTS = "outputs"


def _owned(values: NDArray[Any], dtype: type = np.float64) -> NDArray[Any]:
    """``values`` as a C-contiguous, writeable array of ``dtype`` (itself if it is one):
    the one array type the native step takes."""
    flags = values.flags
    if values.dtype == dtype and values.ndim == 1 and flags.c_contiguous and flags.writeable:
        return values
    return np.require(np.array(values, dtype=dtype, ndmin=1), requirements=["C", "W"])


def report(state: BatchState, group: Group) -> tuple[kernels.Report, dict[str, Any] | None]:
    """The group's observations and infos as they stand (after a reset: nothing moved,
    nothing earned), with the ``robot_map`` info (None with ``robot_map_info`` off), in
    the arrays a step reuses (:func:`_outputs`): whoever keeps them copies them."""
    rows = _owned(group.rows, np.int64)
    report, encoded, outputs = _outputs(group, rows.size)
    _core.report_rows_into(rows, group.inputs, outputs, encoded is not None)
    _write_candidates(state, group, report)
    return report, _robot_map_of(group, encoded)


def _write_candidates(state: BatchState, group: Group, report: kernels.Report) -> None:
    """The planner features at the end of the report's observations (``planner_features``;
    the native step leaves their columns 0): one batched scoring of the group's maps."""
    size = candidates.features_size(group.config)
    if size:
        candidates.write_features(
            state, group.rows, group.batch, group.config, state.potentials[group.rows],
            report.observations[:, -size:], group.reused,
        )  # fmt: skip


def _robot_map_of(group: Group, encoded: robot_map.Buffers | None) -> dict[str, Any] | None:
    """The ``robot_map`` info from the step's reused arrays (views of them); None when the
    setting is off."""
    return None if encoded is None else _with_fusion_arrays(group, dict(encoded.info))


def _with_fusion_arrays(group: Group, info: dict[str, Any]) -> dict[str, Any]:
    """``info`` (every fusion's arrays) with the relaxed fusion's window and bases or the
    robust fusion's levels (one more compiled call)."""
    batch = group.batch
    if batch.fusion == "intersect":
        return info
    slots = max(group.config.observations.max_landmarks - 2, group.n - 2)
    rows = _owned(group.rows, np.int64)
    if batch.fusion == "relaxed":
        more = _core.encode_window(group.inputs, rows, slots)
    else:
        more = _core.encode_levels(group.inputs, rows, slots)
    names = batch.state_names[len(robot_map.MAP_ARRAYS) :]
    return {**info, **robot_map.as_info(names, more)}


# ----------------------------------------------------------------------------------------
# Movement noise, drawn ahead
# ----------------------------------------------------------------------------------------


def fill_noise(state: BatchState, rows: IntArray, config: EnvConfig) -> None:
    """Draw the next block of each row's movement noise into its noise buffer, from its
    generator (the one its last :func:`bind_noise` gave), as many whole moves as fit, up to
    ``max_moves``: the very draws, in the same order, that the moves would make one at a
    time, so the readings do not depend on how the draws are blocked.

    The generator's state before the block is kept, so that :func:`release_noise` can
    hand back the draws the episode did not spend (it ends early, the generator is read,
    the settings change): then the generator is exactly where drawing move by move
    would have left it.
    """
    noise, epsilon = config.sensor.noise, config.epsilon
    capacity = state.noise_offsets.shape[1]
    for row in rows.tolist():
        release_noise(state, row)
        rng = state.noise_generators[row]
        n = int(state.n_landmarks[row])
        moves = max(1, min(config.task.max_moves, capacity // (2 * n)))
        values = 2 * n * moves
        state.noise_marks[row] = (rng.bit_generator.state, noise, epsilon, n)
        noise.draw_readings(
            rng,
            epsilon,
            state.noise_offsets[row, :values].reshape(2 * moves, n),
            state.noise_is_outlier[row, :values].reshape(2 * moves, n),
            state.noise_replacement[row, :values].reshape(2 * moves, n),
        )
        state.noise_used[row], state.noise_filled[row] = 0, values


def bind_noise(state: BatchState, row: int, rng: np.random.Generator | None) -> None:
    """Make ``rng`` row ``row``'s noise generator; the draws its old one made ahead and
    did not spend are handed back to it first (:func:`release_noise`)."""
    if state.noise_generators[row] is not rng:
        release_noise(state, row)
        state.noise_generators[row] = rng


def release_noise(state: BatchState, row: int) -> None:
    """Empty row ``row``'s noise buffer, handing the unspent draws back to its generator:
    it is rewound to the block's start and the spent draws are made again (once per early
    episode end: cheap), so it ends where drawing move by move would have left it."""
    mark = state.noise_marks[row]
    if mark is None:
        return
    state.noise_marks[row] = None
    used, filled = int(state.noise_used[row]), int(state.noise_filled[row])
    state.noise_used[row] = state.noise_filled[row] = 0
    if used == filled:  # every draw was spent: the generator is where it should be
        return
    saved, noise, epsilon, n = mark
    rng = state.noise_generators[row]
    rng.bit_generator.state = saved
    readings = used // n
    offsets = np.empty((readings, n))
    noise.draw_readings(
        rng, epsilon, offsets, np.empty(offsets.shape, bool), np.empty(offsets.shape)
    )


# ----------------------------------------------------------------------------------------
# Potential, observation, info
# ----------------------------------------------------------------------------------------


def potentials(state: BatchState, group: Group) -> FloatArray:
    """The uncertainty potential Phi of the group's maps (see the env's Rewards section)."""
    out = np.empty(group.rows.size)
    _core.potentials(_owned(group.rows, np.int64), group.inputs, out)
    return out


#: The info's entries from a step's report, in order: the name, and whether it is an
#: array per row (per landmark) rather than one value per row. The reward's parts follow,
#: under ``"rewards"`` (see the env's Info section).
INFO_FIELDS: tuple[tuple[str, bool], ...] = (
    ("landmark_area", True),
    ("landmark_error", True),
    ("landmark_contains_truth", True),
    ("total_area", False),
    ("robot_error", False),
    ("frame_changed", False),
    ("inconsistent", False),
    ("outliers", True),
    ("path_length", False),
)
REWARD_PARTS: tuple[str, ...] = ("uncertainty", "path_cost", "move_cost")


def infos(
    report: kernels.Report,
    robot_map_info: dict[str, Any] | None,
    sensor: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """The group's infos, batched along a first axis (see the env's Info section): copies
    of the report's arrays (the step reuses them), ``robot_map`` unless it is None (the
    setting off), and the :func:`sensor_info` entries unless they are None."""
    infos: dict[str, Any] = {name: getattr(report, name).copy() for name, _ in INFO_FIELDS}
    infos["rewards"] = {name: getattr(report, name).copy() for name in REWARD_PARTS}
    if robot_map_info is not None:
        infos[robot_map.KEY] = {key: value.copy() for key, value in robot_map_info.items()}
    if sensor is not None:
        infos.update(sensor)
    return infos


def sensor_info(state: BatchState, group: Group) -> dict[str, Any] | None:
    """The ``sensor_info`` setting's entries, batched: ``seen`` (len(rows), n), which
    landmarks the last reading saw, and ``blocked``, whether a wall or an obstacle
    stopped the last move; None with the setting off."""
    if not group.config.observations.sensor_info:
        return None
    rows = group.rows
    return {
        "seen": ~np.isnan(state.latest_bearings[rows, : group.n]),
        "blocked": state.blocked[rows].copy(),
    }


class _FirstRow(NamedTuple):
    """A group of one row's reused arrays (its report, and its robot map's encoded arrays
    unless None) as views of their first row, made once: a step's info then copies each
    per-landmark view once and reads each value once (:func:`single_info`)."""

    report: kernels.Report  #: the report these are views of
    info: tuple[tuple[str, NDArray[Any], bool], ...]  #: (name, view, copied) per INFO_FIELDS
    rewards: tuple[tuple[str, NDArray[Any]], ...]
    encoded: tuple[tuple[str, NDArray[Any], bool], ...]  #: the robot map's, as its info

    @classmethod
    def of(cls, report: kernels.Report, encoded: robot_map.Buffers | None) -> _FirstRow:
        def first_row(values: NDArray[Any]) -> tuple[NDArray[Any], bool]:
            return (values[0], True) if values.ndim > 1 else (values, False)

        info = tuple((name, *first_row(getattr(report, name))) for name, _ in INFO_FIELDS)
        rewards = tuple((name, getattr(report, name)) for name in REWARD_PARTS)
        arrays = {} if encoded is None else encoded.info
        return cls(report, info, rewards, tuple((k, *first_row(v)) for k, v in arrays.items()))


def single_info(
    group: Group,
    report: kernels.Report,
    robot_map_info: dict[str, Any] | None,
    sensor: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """The info of a group of one row (the single env): Python scalars and copies of the
    per-landmark arrays (the step reuses its report and encoded arrays), through views of
    their first row made once per group (:class:`_FirstRow`)."""
    first = group.reused.get(_FIRST_ROW)
    if first is None or first.report is not report:
        _, encoded, _ = group.reused[_OUTPUTS]
        first = group.reused[_FIRST_ROW] = _FirstRow.of(report, encoded)
    info: dict[str, Any] = {
        name: view.copy() if copied else view.item() for name, view, copied in first.info
    }
    info["rewards"] = {name: view.item() for name, view in first.rewards}
    if robot_map_info is not None:
        info[robot_map.KEY] = entries = {
            key: view.copy() if copied else view.item() for key, view, copied in first.encoded
        }
        if len(robot_map_info) > len(entries):  # the relaxed or robust fusion's own arrays,
            for key, value in robot_map_info.items():  # new every step: no copy needed
                if key not in entries:
                    entries[key] = value[0] if value.ndim > 1 else value.item()
    if sensor is not None:
        info["seen"], info["blocked"] = sensor["seen"][0], bool(sensor["blocked"][0])
    return info


#: The key of a group of one row's :class:`_FirstRow` in :attr:`Group.reused`.
_FIRST_ROW = "first row"
