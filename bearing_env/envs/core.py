"""The envs' pure functional core: world state and bookkeeping of a batch, as arrays.

In the spirit of Gymnasium's ``phys2d/cartpole.py``: one
:class:`~bearing_env.envs.state.BatchState` holds the
state of ``N`` envs as a structure of arrays (one row per env), and plain functions
compute on a group of rows at once:

- :func:`reset_rows` starts new episodes;
- :func:`step` moves the robots, reads the sensors, updates the maps and computes the
  rewards (:func:`rewards`), terminations and truncations;
- :func:`observations` and :func:`infos` build the observations and infos.

``BearingSLAMEnv`` is a batch of one; ``BearingSLAMVectorEnv`` steps the whole batch.
Both call exactly these functions, so they agree bit for bit: every computation is
row-wise (a row's result does not depend on the other rows of its batch), and every
random draw comes from the row's own generator, in the same order as in a batch of one.

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

from bearing_env.envs import kernels, robot_map
from bearing_env.envs.config import AREA_FLOOR, EnvConfig
from bearing_env.envs.kernels import Settings
from bearing_env.envs.observations import FL_COORD_LIMIT, observation_size
from bearing_env.envs.state import BatchState
from bearing_env.numerics import wrap_angle
from bearing_env.obstacles import Obstacle
from bearing_env.sensing import visible_rows
from bearing_env.slam import MapSettings, PolygonSLAM
from bearing_env.slam.batch import (
    CONTAINMENT_TOLERANCE,
    BatchedPolygonSLAM,
)
from bearing_env.world import (
    Arena,
    NoiseDraws,
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
        #: Each (landmark count, config)'s kernel inputs (an ``InputsRef``), with the
        #: state and map references they were made of.
        self._inputs: dict[tuple[int, EnvConfig], tuple[Any, Any, kernels.Inputs]] = {}

    def group(self, state: BatchState, rows: IntArray, config: EnvConfig) -> Group:
        """The group of ``rows`` (all with ``config`` and one landmark count), with its
        kernel inputs: made once per (config, count) and state, then reused."""
        n = int(state.n_landmarks[rows[0]])
        state_ref = state.kernel_ref()
        last = self.__dict__.get("_last")
        if last is None or last[0] is not config or last[1] != n or last[2] is not state_ref:
            last = self._last = (config, n, state_ref, *self._inputs_for(n, config, state_ref))
        return Group(rows, config, n, last[3], last[4])

    def batch(self, n_landmarks: int, config: EnvConfig) -> BatchedPolygonSLAM:
        return self._batch_for(int(n_landmarks), config.map_settings)

    def _inputs_for(
        self, n: int, config: EnvConfig, state_ref: BatchState
    ) -> tuple[BatchedPolygonSLAM, kernels.Inputs]:
        batch = self._batch_for(n, config.map_settings)
        maps_ref = batch._kernel_state()
        kept = self._inputs.get((n, config))
        if kept is None or kept[0] is not state_ref or kept[1] is not maps_ref:
            settings = kernel_settings(n, config)
            inputs = kernels.inputs_ref(kernels.Inputs(settings, maps_ref, state_ref))
            kept = self._inputs[n, config] = (state_ref, maps_ref, inputs)
        return batch, kept[2]

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
        # The kernel inputs (structrefs) cannot be pickled; they are made again.
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
    inputs: kernels.Inputs  #: what the kernels take (an ``InputsRef``)


def kernel_settings(n_landmarks: int, config: EnvConfig) -> Settings:
    """The kernels' settings of a group of ``config`` with ``n_landmarks`` landmarks."""
    arena, task, sensor = config.layout.arena, config.task, config.sensor
    vertices, starts = config.layout.packed_obstacles
    return Settings(
        n=int(n_landmarks),
        n_slots=int(config.observations.max_landmarks),
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
    batch."""
    if new.map_settings != old.map_settings:
        maps.batch(int(state.n_landmarks[row]), new).reset([row])


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
    count range), its layout (``"random"``), its start pose, then its first reading.
    Afterwards the rows may have different landmark counts (see :func:`group_rows`).
    """
    layout, noise = config.layout, config.sensor.noise
    lo, hi = layout.landmark_counts
    fixed = layout.fixed_landmarks
    obstacles = layout.packed_obstacles if layout.obstacles else None
    state.landmarks[rows] = 0.0
    state.landmarks_fl[rows] = 0.0
    for row, rng in zip(rows.tolist(), rngs, strict=True):
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


def sees(state: BatchState, rows: IntArray, n: int, config: EnvConfig) -> BoolArray:
    """Which of their ``n`` landmarks the rows' sensors see from their poses (len(rows), n)."""
    out = np.empty((rows.size, n), dtype=bool)
    vertices, starts = config.layout.packed_obstacles
    sensor = config.sensor
    visible_rows(
        state.landmarks[rows, :n], state.positions[rows], state.headings[rows],
        sensor.half_fov, sensor.max_range, vertices, starts, out,
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


class StepOutcome(NamedTuple):
    """What one step of a group did, per row (arrays of the group's length)."""

    rewards: FloatArray
    terminated: BoolArray
    truncated: BoolArray
    frame_changed: BoolArray
    inconsistent: IntArray
    travelled: FloatArray
    #: The named reward parts; the reward is their sum.
    uncertainty: FloatArray
    path_cost: FloatArray
    move_cost: FloatArray


def step(
    state: BatchState,
    group: Group,
    turns: FloatArray,
    lengths: FloatArray,
    rngs: Sequence[np.random.Generator],
) -> StepOutcome:
    """One movement of every row of a group (same config, same landmark count ``n``):
    turn, read, move straight (stopped at the wall), read, update the map.

    ``turns`` and ``lengths`` are decoded actions (radians, metres); ``rngs[j]`` is row
    ``rows[j]``'s generator.
    """
    rows, config, n = group.rows, group.config, group.n
    size = rows.size
    # Each row draws its first reading's noise, then its second's, from its generator.
    first, second = config.sensor.noise.draw_movement_rows(rngs, n, config.epsilon)
    travelled, start, end = np.empty(size), np.empty((size, n)), np.empty((size, n))
    kernels.move_and_read(
        rows,
        np.ascontiguousarray(turns, dtype=np.float64),
        np.ascontiguousarray(lengths, dtype=np.float64),
        group.inputs,
        _draws_for_kernel(first),
        _draws_for_kernel(second),
        travelled,
        start,
        end,
    )
    state.append_positions(rows)

    # A move that could not start took both readings from the same place: there is no
    # robot frame (R1 = R2), so the SLAM must not see it. The robot knows it did not move
    # (it is stuck against the wall).
    changes_map = travelled >= config.layout.arena.min_baseline
    frame_changed = np.zeros(size, dtype=bool)
    inconsistent = np.zeros(size, dtype=np.int64)
    batch = group.batch
    # The readings are the kernel's own float arrays and the rows distinct: the map's
    # unchecked update is enough.
    if changes_map.all():
        result = batch._update_checked(start, end, rows)
        frame_changed, inconsistent = result.frame_changed, result.n_inconsistent
    elif changes_map.any():
        moving = np.flatnonzero(changes_map)
        result = batch._update_checked(start[moving], end[moving], rows[moving])
        frame_changed[moving] = result.frame_changed
        inconsistent[moving] = result.n_inconsistent
    state.frame_changed[rows] = frame_changed

    outcome = StepOutcome(
        rewards=np.empty(size),
        terminated=np.empty(size, dtype=bool),
        truncated=np.empty(size, dtype=bool),
        frame_changed=frame_changed,
        inconsistent=inconsistent,
        travelled=travelled,
        uncertainty=np.empty(size),
        path_cost=np.empty(size),
        move_cost=np.empty(size),
    )
    kernels.finish_steps(
        rows,
        group.inputs,
        travelled,
        outcome.rewards,
        outcome.uncertainty,
        outcome.path_cost,
        outcome.move_cost,
        outcome.terminated,
        outcome.truncated,
    )
    return outcome


def _draws_for_kernel(draws: NoiseDraws) -> kernels.Draws:
    """The draws as the kernel takes them; no outliers: an all-False mask."""
    if draws.is_outlier is None or draws.replacement is None:
        return draws.offsets, np.zeros(draws.offsets.shape, dtype=bool), draws.offsets
    return draws.offsets, draws.is_outlier, draws.replacement


def reset_outcome(size: int) -> StepOutcome:
    """The outcome fields a reset reports in its info: nothing moved, nothing earned."""
    zeros = np.zeros(size)
    no = np.zeros(size, dtype=bool)
    return StepOutcome(zeros, no, no, no, np.zeros(size, np.int64), zeros, zeros, zeros, zeros)


# ----------------------------------------------------------------------------------------
# Potential, observation, info
# ----------------------------------------------------------------------------------------


def potentials(state: BatchState, group: Group) -> FloatArray:
    """The uncertainty potential Phi of the group's maps (see the env's Rewards section)."""
    out = np.empty(group.rows.size)
    kernels.potentials(group.rows, group.inputs, out)
    return out


def observations(state: BatchState, group: Group) -> NDArray[np.float32]:
    """Observations (len(rows), observation_size) of a group (see the env's Observation
    Space section)."""
    size = observation_size(group.config.observations.max_landmarks)
    out = np.zeros((group.rows.size, size), dtype=np.float32)
    kernels.write_observations(group.rows, group.inputs, out)
    return out


def infos(state: BatchState, group: Group, outcome: StepOutcome) -> dict[str, Any]:
    """The group's infos, batched along a first axis (see the env's Info section);
    ``robot_map`` only with the ``robot_map_info`` setting on."""
    rows, batch = group.rows, group.batch
    size, n_mapped = rows.size, group.n - 2
    areas = np.empty((size, n_mapped))
    errors = np.empty((size, n_mapped))
    contains = np.empty((size, n_mapped), dtype=bool)
    total_area = np.empty(size)
    robot_error = np.empty(size)
    kernels.write_infos(rows, group.inputs, areas, errors, contains, total_area, robot_error)
    infos: dict[str, Any] = {
        "landmark_area": areas,
        "landmark_error": errors,
        "landmark_contains_truth": contains,
        "total_area": total_area,
        "robot_error": robot_error,
        "frame_changed": outcome.frame_changed,
        "inconsistent": outcome.inconsistent,
        "outliers": batch.outliers[rows],
        "path_length": outcome.travelled,
        "rewards": {
            "uncertainty": outcome.uncertainty,
            "path_cost": outcome.path_cost,
            "move_cost": outcome.move_cost,
        },
    }
    observations = group.config.observations
    if observations.robot_map_info:
        infos[robot_map.KEY] = robot_map.encode(batch, rows, observations.max_landmarks - 2)
    if observations.sensor_info:
        infos["seen"] = ~np.isnan(state.latest_bearings[rows, : group.n])
        infos["blocked"] = state.blocked[rows].copy()
    return infos


def row_info(batched: dict[str, Any], row: int) -> dict[str, Any]:
    """One env's info dict (Python scalars, per-landmark arrays) from batched infos.
    The arrays are views of the batched ones: :func:`infos` makes them anew at every
    call and keeps none, so a view is as private as a copy, and cheaper."""
    info: dict[str, Any] = {}
    for key, value in batched.items():
        if type(value) is dict:
            info[key] = row_info(value, row)
        elif value.ndim > 1:
            info[key] = value[row]
        else:
            info[key] = value[row].item()
    return info
