"""The envs' pure functional core: world state and bookkeeping of a batch, as arrays.

In the spirit of Gymnasium's ``phys2d/cartpole.py``: one :class:`BatchState` holds the
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
The functions below take a group's row indices; rows with other settings are untouched.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env.envs import kernels, robot_map
from bearing_env.envs.config import AREA_FLOOR, EnvConfig, MapSettings
from bearing_env.envs.observations import FL_COORD_LIMIT, observation_size
from bearing_env.numerics import wrap_angle
from bearing_env.slam import PolygonSLAM
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

#: Trajectory slots allocated per row at first; the array doubles when a row fills it.
INITIAL_TRAJECTORY_SLOTS = 32


# ----------------------------------------------------------------------------------------
# State
# ----------------------------------------------------------------------------------------


@dataclass
class BatchState:
    """World state and env bookkeeping of ``num_rows`` envs, one row each.

    Per-landmark arrays have ``slots`` columns (the largest landmark count a row can
    have); row ``i`` uses the first ``n_landmarks[i]`` (the rest are zeros).
    """

    #: Landmarks in each row's current episode.
    n_landmarks: IntArray
    #: True landmark positions (N, slots, 2), metres; L1 first.
    landmarks: FloatArray
    #: True robot positions (N, 2), metres, and headings (N,), radians CCW from +x.
    positions: FloatArray
    headings: FloatArray
    #: FL frame per row: FL = (world - origin) / unit, as complex numbers (fixed per episode).
    frame_origin: ComplexArray
    frame_unit: ComplexArray
    #: True FL positions (N, slots - 2) of landmarks L3.., for the info.
    landmarks_fl: ComplexArray
    #: Moves made this episode, and the potential Phi after the latest one.
    moves: IntArray
    potentials: FloatArray
    #: The latest reading (N, slots), relative to the current heading.
    latest_bearings: FloatArray
    #: The last movement's first reading and start position (NaN before the first move).
    start_bearings: FloatArray
    start_positions: FloatArray
    #: Flags of the last movement: it changed frames (updated the map); the wall stopped it.
    frame_changed: BoolArray
    blocked: BoolArray
    #: Whether the episode has ended (terminated or truncated) and needs a reset.
    done: BoolArray
    #: Robot positions since the reset (N, capacity, 2), for rendering; the first
    #: ``trajectory_length[i]`` entries of row ``i`` are used.
    trajectory: FloatArray
    trajectory_length: IntArray

    @classmethod
    def empty(cls, num_rows: int, slots: int) -> BatchState:
        """A batch of rows that have not been reset yet."""
        n = num_rows
        return cls(
            n_landmarks=np.zeros(n, dtype=np.int64),
            landmarks=np.zeros((n, slots, 2)),
            positions=np.zeros((n, 2)),
            headings=np.zeros(n),
            frame_origin=np.zeros(n, dtype=complex),
            frame_unit=np.ones(n, dtype=complex),
            landmarks_fl=np.zeros((n, slots - 2), dtype=complex),
            moves=np.zeros(n, dtype=np.int64),
            potentials=np.zeros(n),
            latest_bearings=np.zeros((n, slots)),
            start_bearings=np.full((n, slots), np.nan),
            start_positions=np.full((n, 2), np.nan),
            frame_changed=np.zeros(n, dtype=bool),
            blocked=np.zeros(n, dtype=bool),
            done=np.zeros(n, dtype=bool),
            trajectory=np.zeros((n, INITIAL_TRAJECTORY_SLOTS, 2)),
            trajectory_length=np.zeros(n, dtype=np.int64),
        )

    @property
    def num_rows(self) -> int:
        return int(self.n_landmarks.shape[0])

    def writable(self) -> BatchState:
        """This state with every array writable: read-only arrays (e.g. from an
        out-of-band pickle with read-only buffers) are copied, the others kept."""
        arrays = {
            f.name: np.require(getattr(self, f.name), requirements=["W"]) for f in fields(self)
        }
        return BatchState(**arrays)

    def append_positions(self, rows: IntArray) -> None:
        """Record the rows' current positions in their trajectories."""
        if not kernels.append_positions(
            rows, self.positions, self.trajectory, self.trajectory_length
        ):
            # Some row is full: double the capacity (for every row) and record again.
            capacity = self.trajectory.shape[1]
            grown = np.zeros((self.num_rows, 2 * capacity, 2))
            grown[:, :capacity] = self.trajectory
            self.trajectory = grown
            kernels.append_positions(rows, self.positions, self.trajectory, self.trajectory_length)


class MapBank:
    """The robots' maps: one :class:`BatchedPolygonSLAM` per (landmark count, epsilon,
    transfer), each with a row per env (row ``i`` of every batch belongs to env ``i``).

    Envs whose landmark count varies switch batches at reset; their rows in the other
    batches are simply left idle.
    """

    def __init__(self, num_rows: int) -> None:
        self.num_rows = num_rows
        self.batches: dict[tuple[int, MapSettings], BatchedPolygonSLAM] = {}
        self._views: dict[tuple[int, MapSettings, int], PolygonSLAM] = {}

    def batch(self, n_landmarks: int, config: EnvConfig) -> BatchedPolygonSLAM:
        last = self.__dict__.get("_last")
        if last is not None and last[0] is config and last[1] == n_landmarks:
            return last[2]  # the common case: asked again for the same group's batch
        key = (int(n_landmarks), config.map_settings)
        self._last = (config, n_landmarks, self._batch_for(key))
        return self._last[2]

    def _batch_for(self, key: tuple[int, MapSettings]) -> BatchedPolygonSLAM:
        if key not in self.batches:
            n_landmarks, settings = key
            self.batches[key] = BatchedPolygonSLAM(self.num_rows, n_landmarks, **dict(settings))
        return self.batches[key]

    def view(self, n_landmarks: int, config: EnvConfig, row: int) -> PolygonSLAM:
        """Row ``row``'s map as a :class:`PolygonSLAM` (the same object every time)."""
        key = (int(n_landmarks), config.map_settings, int(row))
        if key not in self._views:
            self._views[key] = PolygonSLAM.view(self.batch(n_landmarks, config), row)
        return self._views[key]


def check_config_switch(old: EnvConfig, new: EnvConfig, action_grid_fixed: bool) -> None:
    """Raise unless a live env may change its config from ``old`` to ``new``: the
    observation space (``max_landmarks``) and, for discrete envs (``action_grid_fixed``),
    the action grid cannot change."""
    if not isinstance(new, EnvConfig):
        raise TypeError(f"config must be an EnvConfig, got {new!r}")
    if new.max_landmarks != old.max_landmarks:
        raise ValueError(
            f"max_landmarks cannot change ({old.max_landmarks} -> {new.max_landmarks}): "
            "it fixes the observation space; make a new env"
        )
    if new.observation != old.observation:
        raise ValueError(
            f"observation cannot change ({old.observation!r} -> {new.observation!r}): "
            "it fixes the observation space; make a new env"
        )
    if action_grid_fixed and (new.n_turns, new.n_move_lengths) != (
        old.n_turns,
        old.n_move_lengths,
    ):
        raise ValueError(
            f"n_turns and n_move_lengths cannot change ({old.n_turns}, {old.n_move_lengths} "
            f"-> {new.n_turns}, {new.n_move_lengths}): they fix the action space"
        )


def switch_maps(
    state: BatchState, maps: MapBank, row: int, old: EnvConfig, new: EnvConfig
) -> None:
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

    It reads the batch's arrays, so it follows the episode; it offers what
    :class:`~bearing_env.world.World` offers for reading. :meth:`copy` (and
    ``copy.deepcopy``) give an independent, mutable :class:`World`.
    """

    def __init__(self, state_owner: Any, row: int) -> None:
        # The owner (an env) is held rather than its state: the state object is
        # replaced when the env is unpickled or its trajectory grows.
        self._owner = state_owner
        self._row = row

    @property
    def _state(self) -> BatchState:
        return self._owner._state

    @property
    def _config(self) -> EnvConfig:
        return self._owner._row_config(self._row)

    @property
    def arena(self) -> Arena:
        return self._config.arena

    @property
    def noise(self) -> NoiseModel:
        return self._config.noise

    @property
    def epsilon(self) -> float:
        return self._config.epsilon

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
        return true_bearings(
            self.landmarks[None], self.position[None], np.array([self.heading])
        )[0]

    def copy(self) -> World:
        """An independent, mutable snapshot of this ground truth."""
        return World(
            self.arena, self.landmarks, self.position, self.heading, self.noise, self.epsilon
        )

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
    lo, hi = config.landmark_counts
    fixed = config.fixed_landmarks
    state.landmarks[rows] = 0.0
    state.landmarks_fl[rows] = 0.0
    for row, rng in zip(rows.tolist(), rngs, strict=True):
        # Rejection sampling makes the draws per row: a layout's draw count varies.
        count = int(rng.integers(lo, hi + 1)) if hi > lo else hi
        landmarks = fixed if fixed is not None else random_layout(rng, config.arena, count)
        position, heading = random_start(rng, config.arena, landmarks)
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
        readings = config.noise.corrupt_rows(group_rngs, truth, config.epsilon)
        state.latest_bearings[group] = 0.0
        state.latest_bearings[group, :n] = readings
        batch = maps.batch(n, config)
        batch.reset(group)
        state.potentials[group] = potentials(group, batch, config)


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


@dataclass(frozen=True)
class StepOutcome:
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
    rows: IntArray,
    config: EnvConfig,
    turns: FloatArray,
    lengths: FloatArray,
    rngs: Sequence[np.random.Generator],
    maps: MapBank,
) -> StepOutcome:
    """One movement of every row of a group (same config, same landmark count ``n``):
    turn, read, move straight (stopped at the wall), read, update the map.

    ``turns`` and ``lengths`` are decoded actions (radians, metres); ``rngs[j]`` is row
    ``rows[j]``'s generator.
    """
    n = int(state.n_landmarks[rows[0]])
    arena, noise, epsilon = config.arena, config.noise, config.epsilon
    min_baseline = arena.min_baseline
    size = rows.size
    # Each row draws its first reading's noise, then its second's, from its generator.
    first_draws, second_draws = noise.draw_movement_rows(rngs, n, epsilon)
    first, second = _draws_as_arrays(first_draws), _draws_as_arrays(second_draws)
    travelled = np.empty(size)
    start_bearings = np.empty((size, n))
    end_bearings = np.empty((size, n))
    kernels.move_and_read(
        rows,
        np.ascontiguousarray(turns, dtype=np.float64),
        np.ascontiguousarray(lengths, dtype=np.float64),
        n,
        arena.width,
        arena.height,
        arena.wall_margin,
        min_baseline,
        *first,
        *second,
        state.positions,
        state.headings,
        state.landmarks,
        state.start_positions,
        state.start_bearings,
        state.latest_bearings,
        state.moves,
        state.blocked,
        travelled,
        start_bearings,
        end_bearings,
    )
    state.append_positions(rows)

    # A move that could not start took both readings from the same place: there is no
    # robot frame (R1 = R2), so the SLAM must not see it. The robot knows it did not move
    # (it is stuck against the wall).
    changes_map = travelled >= min_baseline
    frame_changed = np.zeros(size, dtype=bool)
    inconsistent = np.zeros(size, dtype=np.int64)
    batch = maps.batch(n, config)
    if changes_map.all():
        result = batch.update(start_bearings, end_bearings, maps=rows)
        frame_changed, inconsistent = result.frame_changed, result.n_inconsistent
    elif changes_map.any():
        moving = np.flatnonzero(changes_map)
        result = batch.update(start_bearings[moving], end_bearings[moving], maps=rows[moving])
        frame_changed[moving] = result.frame_changed
        inconsistent[moving] = result.n_inconsistent
    state.frame_changed[rows] = frame_changed

    reward, uncertainty, path_cost, move_cost = (np.empty(size) for _ in range(4))
    terminated = np.empty(size, dtype=bool)
    truncated = np.empty(size, dtype=bool)
    kernels.finish_steps(
        rows,
        n - 2,
        config.reward == "log_area",
        AREA_FLOOR,
        config.area_cap,
        config.target_area,
        config.max_moves,
        config.path_cost,
        config.move_cost,
        travelled,
        batch.areas,
        batch.counts,
        state.potentials,
        state.moves,
        state.done,
        reward,
        uncertainty,
        path_cost,
        move_cost,
        terminated,
        truncated,
    )
    return StepOutcome(
        rewards=reward,
        terminated=terminated,
        truncated=truncated,
        frame_changed=frame_changed,
        inconsistent=inconsistent,
        travelled=travelled,
        uncertainty=uncertainty,
        path_cost=path_cost,
        move_cost=move_cost,
    )


def _draws_as_arrays(draws: NoiseDraws) -> tuple[FloatArray, BoolArray, FloatArray]:
    """(offsets, outlier mask, replacements) for the kernel; no outliers: all False."""
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


def potentials(state_rows: IntArray, batch: BatchedPolygonSLAM, config: EnvConfig) -> FloatArray:
    """The uncertainty potential Phi of the rows' maps (see the env's Rewards section)."""
    out = np.empty(state_rows.size)
    kernels.potentials(
        state_rows,
        batch.areas,
        batch.n_landmarks - 2,
        config.reward == "log_area",
        AREA_FLOOR,
        config.area_cap,
        out,
    )
    return out


def observations(
    state: BatchState, rows: IntArray, config: EnvConfig, maps: MapBank
) -> NDArray[np.float32]:
    """Observations (len(rows), observation_size) of a group (see the env's Observation
    Space section)."""
    n = int(state.n_landmarks[rows[0]])
    batch = maps.batch(n, config)
    out = np.zeros((rows.size, observation_size(config.max_landmarks)), dtype=np.float32)
    kernels.write_observations(
        rows,
        n,
        config.max_landmarks,
        AREA_FLOOR,
        config.area_cap,
        config.max_moves,
        FL_COORD_LIMIT,
        batch.robot_centroid,
        batch.robot_counts,
        batch.robot_area,
        batch.robot_heading,
        batch.counts,
        batch.centroids,
        batch.areas,
        state.moves,
        state.frame_changed,
        state.blocked,
        state.latest_bearings,
        out,
    )
    return out


def infos(
    state: BatchState,
    rows: IntArray,
    config: EnvConfig,
    maps: MapBank,
    outcome: StepOutcome,
) -> dict[str, Any]:
    """The group's infos, batched along a first axis (see the env's Info section)."""
    n = int(state.n_landmarks[rows[0]])
    batch = maps.batch(n, config)
    size, n_mapped = rows.size, n - 2
    areas = np.empty((size, n_mapped))
    errors = np.empty((size, n_mapped))
    contains = np.empty((size, n_mapped), dtype=bool)
    total_area = np.empty(size)
    robot_error = np.empty(size)
    kernels.write_infos(
        rows,
        n_mapped,
        CONTAINMENT_TOLERANCE,
        batch.areas,
        batch.counts,
        batch.centroids,
        batch.vertices,
        state.landmarks_fl,
        state.positions,
        state.frame_origin,
        state.frame_unit,
        batch.robot_centroid,
        areas,
        errors,
        contains,
        total_area,
        robot_error,
    )
    return {
        "landmark_area": areas,
        "landmark_error": errors,
        "landmark_contains_truth": contains,
        "total_area": total_area,
        "robot_error": robot_error,
        "frame_changed": outcome.frame_changed,
        "inconsistent": outcome.inconsistent,
        "outliers": batch.outliers[rows],
        "path_length": outcome.travelled,
        robot_map.KEY: robot_map.encode(batch, rows, config.max_landmarks - 2),
        "rewards": {
            "uncertainty": outcome.uncertainty,
            "path_cost": outcome.path_cost,
            "move_cost": outcome.move_cost,
        },
    }


def row_info(batched: dict[str, Any], row: int) -> dict[str, Any]:
    """One env's info dict (Python scalars, per-landmark arrays) from batched infos."""
    info: dict[str, Any] = {}
    for key, value in batched.items():
        if type(value) is dict:
            info[key] = row_info(value, row)
        elif value.ndim > 1:
            info[key] = value[row].copy()
        else:
            info[key] = value[row].item()
    return info


# ----------------------------------------------------------------------------------------
# Rendering
# ----------------------------------------------------------------------------------------


def scene(state: BatchState, row: int, config: EnvConfig, slam: PolygonSLAM) -> Any:
    """What the renderer draws for one row (pygame is only imported here)."""
    from bearing_env.rendering import Scene
    from bearing_env.slam import fl_to_world

    n = int(state.n_landmarks[row])
    landmarks = state.landmarks[row, :n].copy()
    l1, l2 = landmarks[0], landmarks[1]

    def to_world(points: FloatArray | None) -> FloatArray | None:
        return None if points is None else fl_to_world(points, l1, l2)

    has_moved = bool(np.all(np.isfinite(state.start_positions[row])))
    areas = slam.areas
    return Scene(
        arena=config.arena,
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
        max_moves=config.max_moves,
        total_area=float(np.sum(areas)),
        n_initialised=int(np.sum(slam.initialised)),
        frame_changed=bool(state.frame_changed[row]),
        robot_radius=config.arena.wall_margin,
    )
