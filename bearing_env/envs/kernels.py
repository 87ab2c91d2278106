"""The envs' compiled step (numba): a group of rows moves, reads, updates its maps,
and gets its rewards, terminations, observations and infos in one call.

:func:`step_rows` is the whole step; :func:`report_rows` the observations and infos
alone (after a reset). :mod:`bearing_env.envs.core` calls them for the single env (a
group of one row) and the vector env alike, so both compute every number with the same
code. The noise of the readings is drawn ahead, in blocks, by each row's own generator
(``core.fill_noise``) into the rows' noise buffers, which the step reads by index.

Each kernel takes the group's rows, one :class:`InputsRef` (the group's
:class:`Settings`, its maps' update settings, its map batch's state and the envs'
``BatchState``: long-lived, so made once and typed by numba in about 1 us per call) and
its per-call arrays positionally (positional arrays are typed fastest: 5 arrays cost
0.6 us positionally, 2.2 us as a namedtuple). The step writes into output arrays made
once per group and reused (``core`` calls it through its compiled function, which
unboxes 16 arrays in about 1.4 us, where returning 16 new ones cost about 18 us): what
an env hands out of them, it copies.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numba import njit
from numba.core import types
from numba.experimental import structref
from numpy.typing import NDArray

from bearing_env.envs.observations import (
    BEARING_FEATURES,
    ELONGATION_LIMIT,
    LANDMARK_FEATURES,
    ROBOT_FEATURES,
    SHAPE_FEATURES,
)
from bearing_env.envs.robot_map import encode_map, encode_map_into
from bearing_env.numerics import JIT_OPTIONS as _JIT
from bearing_env.numerics import wrap
from bearing_env.sensing import visible
from bearing_env.slam.batch import PARALLEL_MIN_MAPS
from bearing_env.slam.kernels import FRAME_OK, contains_point, update_maps, update_maps_parallel
from bearing_env.slam.kernels import Outputs as MapOutputs
from bearing_env.slam.kernels import Params as MapParams
from bearing_env.slam.kernels import State as MapState
from bearing_env.world import bearing, obstructed_move

if TYPE_CHECKING:  # only for annotations: that module imports this one
    from bearing_env.envs.state import BatchState

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: The flat observation's block sizes (numba compile-time constants), from the feature
#: tuples of :mod:`bearing_env.envs.observations`; :func:`_write_observation` writes the
#: blocks in that module's order.
_ROBOT_FEATURES = len(ROBOT_FEATURES)
_LANDMARK_FEATURES = len(LANDMARK_FEATURES)
_BEARING_FEATURES = len(BEARING_FEATURES)
_SHAPE_FEATURES = len(SHAPE_FEATURES)


class Settings(NamedTuple):
    """A group's settings (one config, one landmark count), as the kernels take them."""

    n: int  #: landmarks of the group's rows
    n_slots: int  #: the observation's landmark slots (max_landmarks)
    shape_features: bool  #: the flat vector ends with the regions' shapes ("shapes" kind)
    width: float  #: the arena, metres
    height: float
    margin: float  #: the wall margin
    min_baseline: float  #: shortest move that changes frames
    log_area: bool  #: the reward's potential sums log-areas (else areas)
    floor: float  #: areas are floored here before taking logs
    cap: float  #: and capped here (area_cap)
    target_area: float  #: success: every landmark's area at most this
    max_moves: int
    path_cost: float  #: per metre
    move_cost: float  #: per move
    coordinate_limit: float  #: FL coordinates are clipped to +-this in the observation
    tolerance: float  #: relative tolerance of the info's containment test
    half_fov: float  #: half the sensor's field of view, radians (pi: panoramic)
    max_range: float  #: the sensor's range, metres (inf: no limit)
    obstacle_vertices: FloatArray  #: the obstacles, packed (see bearing_env.sensing)
    obstacle_starts: NDArray[np.int64]


class Inputs(NamedTuple):
    """What a group's kernels read and write besides their per-call arrays."""

    settings: Settings
    params: MapParams  #: the group's map update settings (the robot transferred)
    maps: MapState  #: the group's map batch (its slam kernels ``StateRef``)
    state: BatchState  #: the envs' state (its ``BatchStateRef``)


@structref.register
class InputsType(types.StructRef):
    """numba's type of an :class:`InputsRef`: one field per :class:`Inputs` field."""

    def preprocess_fields(self, fields: Any) -> tuple[tuple[str, Any], ...]:
        # why (each ignore below): these numba functions carry no annotations
        return tuple((name, types.unliteral(typ)) for name, typ in fields)  # type: ignore[no-untyped-call]


class InputsRef(structref.StructRefProxy):
    """:class:`Inputs` as the kernels take them: one structref, made once per group and
    state (see ``core.MapBank.group``). numba types a structref argument once per call
    (about 1 us here) but a namedtuple field by field, and positional arrays cheaply:
    so the long-lived inputs travel as this one reference and each call's fresh output
    arrays positionally."""


structref.define_constructor(InputsRef, InputsType, Inputs._fields)  # type: ignore[no-untyped-call]
structref.define_boxing(InputsType, InputsRef)  # type: ignore[no-untyped-call]


@njit(**_JIT)
def inputs_ref(inputs: Inputs) -> Inputs:
    """The :class:`InputsRef` of ``inputs`` (annotated as Inputs: the same fields)."""
    return InputsRef(*inputs)  # type: ignore[no-untyped-call, return-value]


@njit(**_JIT)
def _noisy(true_bearing: float, state: BatchState, row: int, value: int) -> float:
    """A reading of ``true_bearing`` with the row's pre-drawn noise value ``value``."""
    if state.noise_is_outlier[row, value]:
        return wrap(state.noise_replacement[row, value])
    return wrap(true_bearing + state.noise_offsets[row, value])


@njit(**_JIT)
def _read(
    settings: Settings, x: float, y: float, heading: float, lx: float, ly: float, reading: float
) -> float:
    """The reading of the landmark at (lx, ly) from a pose: NaN (missed) unless the
    sensor sees it (field of view, range, line of sight)."""
    if visible(
        x,
        y,
        heading,
        lx,
        ly,
        settings.half_fov,
        settings.max_range,
        settings.obstacle_vertices,
        settings.obstacle_starts,
    ):
        return reading
    return math.nan


@njit(**_JIT)
def move_and_read(
    row: int,
    turn: float,
    length: float,
    inputs: Inputs,
    reading_start: np.ndarray,
    reading_end: np.ndarray,
) -> float:
    """Turn, read, move straight until the wall margin or an obstacle's, read again: one
    row's movement; returns the distance travelled.

    The readings (out in ``reading_start`` and ``reading_end``, (n,)) are the true
    bearings plus the row's next pre-drawn noise values (the first reading's ``n``, then
    the second's), wrapped, or NaN for a landmark the sensor does not see (:func:`_read`;
    the noise values are spent either way, so the stream does not depend on what is
    seen). In place: the row's pose, start position, readings, move
    count, blocked flag and spent noise. A robot that could not move at least
    ``min_baseline`` does not move (see :func:`~bearing_env.world.straight_move`).
    """
    settings, state = inputs.settings, inputs.state
    n = settings.n
    heading = wrap(state.headings[row] + turn)
    x, y = state.positions[row, 0], state.positions[row, 1]
    new_x, new_y, distance, stopped = obstructed_move(
        x,
        y,
        heading,
        length,
        (settings.width, settings.height, settings.margin, settings.min_baseline),
        settings.obstacle_vertices,
        settings.obstacle_starts,
    )
    first = state.noise_used[row]
    for j in range(n):
        lx, ly = state.landmarks[row, j, 0], state.landmarks[row, j, 1]
        reading = _noisy(bearing(lx, ly, x, y, heading), state, row, first + j)
        reading = _read(settings, x, y, heading, lx, ly, reading)
        reading_start[j] = state.start_bearings[row, j] = reading
        reading = _noisy(bearing(lx, ly, new_x, new_y, heading), state, row, first + n + j)
        reading = _read(settings, new_x, new_y, heading, lx, ly, reading)
        reading_end[j] = state.latest_bearings[row, j] = reading
    state.noise_used[row] = first + 2 * n
    state.start_positions[row, 0], state.start_positions[row, 1] = x, y
    state.positions[row, 0], state.positions[row, 1] = new_x, new_y
    state.headings[row] = heading
    state.blocked[row] = stopped
    state.moves[row] += 1
    return distance


@njit(**_JIT)
def append_positions(
    rows: np.ndarray, positions: np.ndarray, trajectory: np.ndarray, lengths: np.ndarray
) -> bool:
    """Append each row's position to its trajectory; False (and nothing written) when
    some row's trajectory is full."""
    capacity = trajectory.shape[1]
    for row in rows:
        if lengths[row] >= capacity:
            return False
    for row in rows:
        trajectory[row, lengths[row], 0] = positions[row, 0]
        trajectory[row, lengths[row], 1] = positions[row, 1]
        lengths[row] += 1
    return True


@njit(**_JIT)
def capped(area: float, floor: float, cap: float) -> float:
    return min(max(area, floor), cap)


@njit(**_JIT)
def potential_of(
    areas: np.ndarray, n_mapped: int, log_area: bool, floor: float, cap: float
) -> float:
    """The uncertainty potential of one map's landmark areas (see the env's Rewards)."""
    total = 0.0
    for j in range(n_mapped):
        value = capped(areas[j], floor, cap)
        total += math.log(value) if log_area else value
    return total


@njit(**_JIT)
def _potential(settings: Settings, areas: np.ndarray) -> float:
    return potential_of(areas, settings.n - 2, settings.log_area, settings.floor, settings.cap)


@njit(**_JIT)
def potentials(rows: np.ndarray, inputs: Inputs, out: np.ndarray) -> None:
    for i in range(rows.shape[0]):
        out[i] = _potential(inputs.settings, inputs.maps.areas[rows[i]])


#: Outcomes of :func:`step_rows`: done, or nothing done because some row needs more
#: pre-drawn noise (``core.fill_noise``) or a longer trajectory array.
STEP_DONE = 0
STEP_NEEDS_NOISE = 1
STEP_NEEDS_TRAJECTORY = 2


class Report(NamedTuple):
    """What a step (or a reset) of a group gives, per row (arrays of the group's length):
    the observations, the rewards and episode ends, and the infos' arrays (see the env's
    Info section; the reward parts sum to the reward)."""

    observations: NDArray[np.float32]
    rewards: FloatArray
    terminated: BoolArray
    truncated: BoolArray
    frame_changed: BoolArray
    inconsistent: NDArray[np.int64]
    path_length: FloatArray
    uncertainty: FloatArray
    path_cost: FloatArray
    move_cost: FloatArray
    landmark_area: FloatArray
    landmark_error: FloatArray
    landmark_contains_truth: BoolArray
    total_area: FloatArray
    robot_error: FloatArray
    outliers: NDArray[np.int64]


@njit(**_JIT)
def _new_report(size: int, n_mapped: int, observation_size: int) -> Report:
    """A report of ``size`` rows: zero observations and reward parts, no episode end."""
    return Report(
        np.zeros((size, observation_size), np.float32),
        np.zeros(size),
        np.zeros(size, np.bool_),
        np.zeros(size, np.bool_),
        np.zeros(size, np.bool_),
        np.zeros(size, np.int64),
        np.zeros(size),
        np.zeros(size),
        np.zeros(size),
        np.zeros(size),
        np.empty((size, n_mapped)),
        np.empty((size, n_mapped)),
        np.empty((size, n_mapped), np.bool_),
        np.empty(size),
        np.empty(size),
        np.empty((size, n_mapped), np.int64),
    )


@njit(**_JIT)
def _clear_report(report: Report) -> None:
    """``report`` as :func:`_new_report` makes it (for a report reused from an earlier
    step): zero observations and reward parts, no episode end. The rest is written row by
    row before it is read."""
    report.observations[:] = 0.0
    report.rewards[:] = 0.0
    report.terminated[:] = False
    report.truncated[:] = False
    report.frame_changed[:] = False
    report.inconsistent[:] = 0
    report.path_length[:] = 0.0
    report.uncertainty[:] = 0.0
    report.path_cost[:] = 0.0
    report.move_cost[:] = 0.0


@njit(**_JIT)
def _finish_row(i: int, row: int, inputs: Inputs, report: Report) -> None:
    """Row ``row``'s reward (with its named parts), termination and truncation after its
    map update; its potential and done flag are updated in place."""
    settings, maps, state = inputs.settings, inputs.maps, inputs.state
    potential = _potential(settings, maps.areas[row])
    report.uncertainty[i] = state.potentials[row] - potential
    report.path_cost[i] = -settings.path_cost * report.path_length[i]
    report.move_cost[i] = -settings.move_cost
    # 0.0 + turns an uncertainty of -0.0 into 0.0; the order of the sum is fixed.
    report.rewards[i] = ((0.0 + report.uncertainty[i]) + report.path_cost[i]) + report.move_cost[i]
    state.potentials[row] = potential
    success = True
    for j in range(settings.n - 2):
        if maps.counts[row, j] == 0 or not maps.areas[row, j] <= settings.target_area:
            success = False
            break
    report.terminated[i] = success
    report.truncated[i] = not success and state.moves[row] >= settings.max_moves
    state.done[row] = report.terminated[i] or report.truncated[i]


@njit(**_JIT)
def _coordinate(value: float, limit: float) -> float:
    return min(max(value, -limit), limit)


@njit(**_JIT)
def _write_observation(row: int, inputs: Inputs, out: np.ndarray) -> None:
    """Row ``row``'s observation, float32, into ``out`` (zeros); the env's Observation
    Space section documents every element."""
    settings, maps, state = inputs.settings, inputs.maps, inputs.state
    floor, cap, limit = settings.floor, settings.cap, settings.coordinate_limit
    bearings_at = _ROBOT_FEATURES + _LANDMARK_FEATURES * (settings.n_slots - 2)
    centroid = maps.robot_centroid[row]
    known = maps.robot_counts[row] > 0 and np.isfinite(centroid.real) and np.isfinite(centroid.imag)
    if known:
        out[0] = _coordinate(centroid.real, limit)
        out[1] = _coordinate(centroid.imag, limit)
        out[2] = math.log(capped(maps.robot_area[row], floor, cap))
    else:
        out[2] = math.log(cap)
        out[3] = 1.0
    heading = maps.robot_heading[row]
    if np.isfinite(heading):
        out[4] = math.cos(heading)
        out[5] = math.sin(heading)
    out[6] = min(state.moves[row] / settings.max_moves, 1.0)
    out[7] = 1.0 if state.frame_changed[row] else 0.0
    out[8] = 1.0 if state.blocked[row] else 0.0
    for j in range(settings.n - 2):
        at = _ROBOT_FEATURES + _LANDMARK_FEATURES * j
        out[at] = 1.0
        if maps.counts[row, j] > 0:
            out[at + 2] = _coordinate(maps.centroids[row, j].real, limit)
            out[at + 3] = _coordinate(maps.centroids[row, j].imag, limit)
        else:
            out[at + 1] = 1.0
        out[at + 4] = math.log(capped(maps.areas[row, j], floor, cap))
    latest = state.latest_bearings
    for k in range(settings.n):
        at = bearings_at + _BEARING_FEATURES * k
        out[at] = 1.0
        if not math.isnan(latest[row, k]):  # a missed reading reads (0, 0)
            out[at + 1] = math.cos(latest[row, k])
            out[at + 2] = math.sin(latest[row, k])
    if settings.shape_features:
        shapes_at = bearings_at + _BEARING_FEATURES * settings.n_slots
        for j in range(settings.n - 2):
            if maps.counts[row, j] >= 3:
                _write_shape(maps.vertices[row, j], maps.counts[row, j], out[shapes_at:], j)


@njit(**_JIT)
def _write_shape(vertices: np.ndarray, count: int, out: np.ndarray, j: int) -> None:
    """Region ``j``'s shape block (:data:`SHAPE_FEATURES`) into ``out``: from the second
    moments of the polygon's area, its elongation (half the log of the ratio of the
    principal moments, 0 for a round region, at most ``ELONGATION_LIMIT``) and its long
    axis as (cos 2 theta, sin 2 theta) (an axis has no sign; (0, 0) when round).
    Degenerate regions (no area) leave the block at zeros."""
    origin = vertices[0]
    area2 = sx = sy = sxx = syy = sxy = 0.0
    for k in range(count):
        p, q = vertices[k] - origin, vertices[(k + 1) % count] - origin
        c = p.real * q.imag - q.real * p.imag
        area2 += c
        sx += c * (p.real + q.real)
        sy += c * (p.imag + q.imag)
        sxx += c * (p.real * p.real + p.real * q.real + q.real * q.real)
        syy += c * (p.imag * p.imag + p.imag * q.imag + q.imag * q.imag)
        cross_terms = p.real * q.imag + q.real * p.imag
        sxy += c * (2.0 * p.real * p.imag + cross_terms + 2.0 * q.real * q.imag)
    if not abs(area2) > 0.0:
        return
    # Central moments per unit area (the signs of a clockwise ring cancel).
    cx, cy = sx / (3.0 * area2), sy / (3.0 * area2)
    a = sxx / (6.0 * area2) - cx * cx
    b = sxy / (12.0 * area2) - cx * cy
    d = syy / (6.0 * area2) - cy * cy
    half_difference = 0.5 * (a - d)
    radius = math.sqrt(half_difference * half_difference + b * b)
    mean = 0.5 * (a + d)
    longest, shortest = mean + radius, mean - radius
    at = _SHAPE_FEATURES * j
    if not shortest > 0.0 or longest > shortest * math.exp(2.0 * ELONGATION_LIMIT):
        out[at] = ELONGATION_LIMIT
    else:
        out[at] = 0.5 * math.log(longest / shortest)
    if radius > 0.0:
        out[at + 1] = half_difference / radius
        out[at + 2] = b / radius


@njit(**_JIT)
def _write_info(i: int, row: int, inputs: Inputs, report: Report) -> None:
    """The ground-truth parts of row ``row``'s info (see the env's Info section)."""
    settings, maps, state = inputs.settings, inputs.maps, inputs.state
    total = 0.0
    for j in range(settings.n - 2):
        area = maps.areas[row, j]
        report.landmark_area[i, j] = area
        total += area
        report.outliers[i, j] = maps.outliers[row, j]
        count = maps.counts[row, j]
        if count > 0:
            truth = state.landmarks_fl[row, j]
            report.landmark_error[i, j] = abs(maps.centroids[row, j] - truth)
            report.landmark_contains_truth[i, j] = contains_point(
                maps.vertices[row, j], count, truth, settings.tolerance
            )
        else:
            report.landmark_error[i, j] = np.inf
            report.landmark_contains_truth[i, j] = False
    report.total_area[i] = total
    centroid = maps.robot_centroid[row]
    if np.isfinite(centroid.real) and np.isfinite(centroid.imag):
        position = complex(state.positions[row, 0], state.positions[row, 1])
        truth = (position - state.frame_origin[row]) / state.frame_unit[row]
        report.robot_error[i] = abs(centroid - truth)
    else:
        report.robot_error[i] = np.inf


@njit(**_JIT)
def _observe(rows: np.ndarray, inputs: Inputs, report: Report) -> None:
    """Observations and infos of ``rows`` into ``report``."""
    for i in range(rows.shape[0]):
        _write_observation(rows[i], inputs, report.observations[i])
        _write_info(i, rows[i], inputs, report)


@njit(**_JIT)
def _observation_size(settings: Settings) -> int:
    slots = settings.n_slots
    size = _ROBOT_FEATURES + _LANDMARK_FEATURES * (slots - 2) + _BEARING_FEATURES * slots
    return size + _SHAPE_FEATURES * (slots - 2) if settings.shape_features else size


@njit(**_JIT)
def new_report(size: int, inputs: Inputs) -> Report:
    """A report of ``size`` rows for the group of ``inputs``, for :func:`step_rows` to
    write into."""
    settings = inputs.settings
    return _new_report(size, settings.n - 2, _observation_size(settings))


@njit(**_JIT)
def report_rows(rows: np.ndarray, inputs: Inputs, map_slots: int) -> Any:
    """The report of ``rows`` as they stand (after a reset: nothing moved, nothing
    earned), with their robot map's encoded arrays (``robot_map.encode``'s, with
    ``map_slots`` landmark slots, the relaxed fusion's window aside)."""
    settings = inputs.settings
    report = _new_report(rows.shape[0], settings.n - 2, _observation_size(settings))
    _observe(rows, inputs, report)
    return report, encode_map(inputs.maps, rows, max(map_slots, settings.n - 2))


@njit(**_JIT)
def _room_for_step(
    rows: np.ndarray, inputs: Inputs, trajectory_length: np.ndarray, capacity: int
) -> int:
    """:data:`STEP_DONE` if every row has the noise and trajectory room for one more move,
    else what is missing."""
    state, n = inputs.state, inputs.settings.n
    for row in rows:
        if state.noise_used[row] + 2 * n > state.noise_filled[row]:
            return STEP_NEEDS_NOISE
    for row in rows:
        if trajectory_length[row] >= capacity:
            return STEP_NEEDS_TRAJECTORY
    return STEP_DONE


@njit(inline="always", **_JIT)
def _update_maps(
    start: np.ndarray,
    end: np.ndarray,
    rows: np.ndarray,
    inputs: Inputs,
    threads: int,
    report: Report,
) -> None:
    """Fuse the movements of ``rows`` that changed frames (travelled at least
    ``min_baseline``: a move that could not start took both readings from the same place,
    so there is no robot frame and the map must not see it) into their maps, on
    ``threads`` threads for batches of at least ``PARALLEL_MIN_MAPS`` maps."""
    moving = np.flatnonzero(report.path_length >= inputs.settings.min_baseline)
    size, n = moving.shape[0], start.shape[1]
    if size == 0:
        return
    out = MapOutputs(
        np.empty(size, np.int8), np.empty((size, n - 2), np.int8), np.empty(size, np.int64)
    )
    if size < rows.shape[0]:
        start, end = start[moving], end[moving]
    if threads > 1 and size >= PARALLEL_MIN_MAPS:
        update_maps_parallel(
            min(size, threads), start, end, rows[moving], inputs.params, inputs.maps, out
        )
    else:
        update_maps(start, end, rows[moving], inputs.params, inputs.maps, out)
    for k in range(size):
        report.frame_changed[moving[k]] = out.frame_status[k] == FRAME_OK
        report.inconsistent[moving[k]] = out.n_bad[k]


@njit(inline="always", **_JIT)
def step_rows_bare(
    rows: np.ndarray,
    turns: np.ndarray,
    lengths: np.ndarray,
    inputs: Inputs,
    trajectory: np.ndarray,
    threads: int,
    report: Report,
) -> int:
    """One movement of every row of a group: turn, read, move straight (stopped at the
    wall), read, update the map; then rewards, terminations, truncations, observations
    and infos, written into ``report`` (arrays of ``len(rows)`` rows, reused from step to
    step: :func:`new_report` makes one). Returns the status; unless it is
    :data:`STEP_DONE`, nothing was done (and nothing written). ``turns`` and ``lengths``
    are the decoded actions (radians, metres); ``trajectory`` is the state's (replaced
    when it grows). Maps of at least ``PARALLEL_MIN_MAPS`` rows are updated on
    ``threads`` threads."""
    settings, state = inputs.settings, inputs.state
    size, n = rows.shape[0], settings.n
    status = _room_for_step(rows, inputs, state.trajectory_length, trajectory.shape[1])
    if status != STEP_DONE:
        return status
    _clear_report(report)
    start, end = np.empty((size, n)), np.empty((size, n))
    for i in range(size):
        row = rows[i]
        report.path_length[i] = move_and_read(row, turns[i], lengths[i], inputs, start[i], end[i])
        at = state.trajectory_length[row]
        trajectory[row, at, 0] = state.positions[row, 0]
        trajectory[row, at, 1] = state.positions[row, 1]
        state.trajectory_length[row] = at + 1
    _update_maps(start, end, rows, inputs, threads, report)
    for i in range(size):
        state.frame_changed[rows[i]] = report.frame_changed[i]
        _finish_row(i, rows[i], inputs, report)
    _observe(rows, inputs, report)
    return STEP_DONE


@njit(**_JIT)
def step_rows(
    rows: np.ndarray,
    turns: np.ndarray,
    lengths: np.ndarray,
    inputs: Inputs,
    trajectory: np.ndarray,
    threads: int,
    report: Report,
    encoded: Any,
) -> int:
    """:func:`step_rows_bare`, with the robot map's encoded arrays written into
    ``encoded`` too (``robot_map.encode_map``'s arrays, of ``len(rows)`` rows, reused)."""
    status = step_rows_bare(rows, turns, lengths, inputs, trajectory, threads, report)
    if status == STEP_DONE:
        encode_map_into(inputs.maps, rows, encoded)
    return status


#: Outcomes of :func:`decode_continuous`.
ACTIONS_OK = 0
ACTIONS_NOT_FINITE = 1
ACTIONS_OUTSIDE = 2


@njit(**_JIT)
def decode_continuous(
    actions: np.ndarray, lo: float, hi: float, turns: np.ndarray, lengths: np.ndarray
) -> int:
    """Turn angles and move lengths of continuous actions (N, 2) in [-1, 1]^2.

    Returns :data:`ACTIONS_OK`, or why not (then the outputs are incomplete). float32
    rounding of +-1 is accepted: values within 1e-6 outside are clipped.
    """
    for i in range(actions.shape[0]):
        a, b = float(actions[i, 0]), float(actions[i, 1])
        if not (np.isfinite(a) and np.isfinite(b)):
            return ACTIONS_NOT_FINITE
        if abs(a) > 1.0 + 1e-6 or abs(b) > 1.0 + 1e-6:
            return ACTIONS_OUTSIDE
        a, b = min(max(a, -1.0), 1.0), min(max(b, -1.0), 1.0)
        turns[i] = math.pi * a
        lengths[i] = lo + 0.5 * (b + 1.0) * (hi - lo)
    return ACTIONS_OK
