"""Compiled halves of the envs' step (numba): the move, the rewards, the observation and
the info, for a group of rows at once.

These do in one call what would otherwise be dozens of small numpy operations per step;
:mod:`bearing_env.envs.core` calls them for the single env (a group of one row) and the
vector env alike, so both compute every number with the same code. Random draws stay
in Python, where each row's own generator makes them (see ``core.step``).

Each kernel takes the group's rows, one :class:`InputsRef` (the group's
:class:`Settings`, its map batch's state and the envs' ``BatchState``: long-lived, so
made once and typed by numba in about 1 us per call) and its per-call arrays
positionally (fresh each step; positional arrays are typed fastest: 5 arrays cost 0.6 us
positionally, 2.2 us as a namedtuple).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numba import njit
from numba.core import types
from numba.experimental import structref
from numpy.typing import NDArray

from bearing_env.envs.observations import BEARING_FEATURES, LANDMARK_FEATURES, ROBOT_FEATURES
from bearing_env.numerics import JIT_OPTIONS as _JIT
from bearing_env.numerics import wrap
from bearing_env.sensing import visible
from bearing_env.slam.kernels import State as MapState
from bearing_env.slam.kernels import contains_point
from bearing_env.world import bearing, obstructed_move

if TYPE_CHECKING:  # only for annotations: that module imports this one
    from bearing_env.envs.state import BatchState

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: The flat observation's block sizes (numba compile-time constants), from the feature
#: tuples of :mod:`bearing_env.envs.observations`; :func:`write_observations` writes the
#: blocks in that module's order.
_ROBOT_FEATURES = len(ROBOT_FEATURES)
_LANDMARK_FEATURES = len(LANDMARK_FEATURES)
_BEARING_FEATURES = len(BEARING_FEATURES)


class Settings(NamedTuple):
    """A group's settings (one config, one landmark count), as the kernels take them."""

    n: int  #: landmarks of the group's rows
    n_slots: int  #: the observation's landmark slots (max_landmarks)
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


#: One reading's pre-drawn noise per row, as :func:`move_and_read` takes it: a plain
#: tuple (offsets, is-outlier mask (all False without outliers), replacements), each
#: (len(rows), n); numba types a plain tuple of arrays faster than a namedtuple.
Draws = tuple[FloatArray, BoolArray, FloatArray]


@njit(**_JIT)
def _noisy(true_bearing: float, offset: float, is_outlier: bool, replacement: float) -> float:
    return wrap(replacement if is_outlier else true_bearing + offset)


@njit(**_JIT)
def _read(
    settings: Settings, x: float, y: float, heading: float, lx: float, ly: float, reading: float
) -> float:
    """The reading of the landmark at (lx, ly) from a pose: NaN (missed) unless the
    sensor sees it (field of view, range, line of sight)."""
    if visible(
        x, y, heading, lx, ly, settings.half_fov, settings.max_range,
        settings.obstacle_vertices, settings.obstacle_starts,
    ):
        return reading
    return math.nan


@njit(**_JIT)
def move_and_read(
    rows: np.ndarray,
    turns: np.ndarray,
    lengths: np.ndarray,
    inputs: Inputs,
    first: Draws,
    second: Draws,
    travelled: np.ndarray,
    reading_start: np.ndarray,
    reading_end: np.ndarray,
) -> None:
    """Turn, read, move straight until the wall margin or an obstacle's, read again; for
    each row.

    The readings are the true bearings plus the rows' pre-drawn noise (``first``,
    ``second``; see :meth:`~bearing_env.world.NoiseModel.draw_rows`), wrapped, or NaN
    for a landmark the sensor does not see (:func:`_read`); out in
    ``reading_start`` and ``reading_end`` (len(rows), n) and ``travelled``. In place:
    the rows' pose, start position, readings, move count and blocked flag. A robot that
    could not move at least ``min_baseline`` does not move (see
    :func:`~bearing_env.world.straight_move`).
    """
    settings, state = inputs.settings, inputs.state
    offsets_start, outlier_start, replacement_start = first
    offsets_end, outlier_end, replacement_end = second
    for i in range(rows.shape[0]):
        row = rows[i]
        heading = wrap(state.headings[row] + turns[i])
        x, y = state.positions[row, 0], state.positions[row, 1]
        new_x, new_y, distance, stopped = obstructed_move(
            x,
            y,
            heading,
            lengths[i],
            (settings.width, settings.height, settings.margin, settings.min_baseline),
            settings.obstacle_vertices,
            settings.obstacle_starts,
        )
        for j in range(settings.n):
            lx, ly = state.landmarks[row, j, 0], state.landmarks[row, j, 1]
            reading = _noisy(
                bearing(lx, ly, x, y, heading),
                offsets_start[i, j],
                outlier_start[i, j],
                replacement_start[i, j],
            )
            reading = _read(settings, x, y, heading, lx, ly, reading)
            reading_start[i, j] = state.start_bearings[row, j] = reading
            reading = _noisy(
                bearing(lx, ly, new_x, new_y, heading),
                offsets_end[i, j],
                outlier_end[i, j],
                replacement_end[i, j],
            )
            reading = _read(settings, new_x, new_y, heading, lx, ly, reading)
            reading_end[i, j] = state.latest_bearings[row, j] = reading
        state.start_positions[row, 0], state.start_positions[row, 1] = x, y
        state.positions[row, 0], state.positions[row, 1] = new_x, new_y
        state.headings[row] = heading
        state.blocked[row] = stopped
        state.moves[row] += 1
        travelled[i] = distance


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


@njit(**_JIT)
def finish_steps(
    rows: np.ndarray,
    inputs: Inputs,
    travelled: np.ndarray,
    reward: np.ndarray,
    uncertainty: np.ndarray,
    path: np.ndarray,
    move: np.ndarray,
    terminated: np.ndarray,
    truncated: np.ndarray,
) -> None:
    """Rewards (with their named parts), terminations and truncations after the map
    update; the rows' potentials and done flags are updated in place."""
    settings, maps, state = inputs.settings, inputs.maps, inputs.state
    for i in range(rows.shape[0]):
        row = rows[i]
        potential = _potential(settings, maps.areas[row])
        uncertainty[i] = state.potentials[row] - potential
        path[i] = -settings.path_cost * travelled[i]
        move[i] = -settings.move_cost
        # 0.0 + turns an uncertainty of -0.0 into 0.0; the order of the sum is fixed.
        reward[i] = ((0.0 + uncertainty[i]) + path[i]) + move[i]
        state.potentials[row] = potential
        success = True
        for j in range(settings.n - 2):
            if maps.counts[row, j] == 0 or not maps.areas[row, j] <= settings.target_area:
                success = False
                break
        terminated[i] = success
        truncated[i] = not success and state.moves[row] >= settings.max_moves
        state.done[row] = terminated[i] or truncated[i]


@njit(**_JIT)
def _coordinate(value: float, limit: float) -> float:
    return min(max(value, -limit), limit)


@njit(**_JIT)
def write_observations(rows: np.ndarray, inputs: Inputs, out: np.ndarray) -> None:
    """The observations (len(rows), size) of a group, float32 (the env's Observation
    Space section documents every element); ``out`` must be zeros."""
    settings, maps, state = inputs.settings, inputs.maps, inputs.state
    floor, cap, limit = settings.floor, settings.cap, settings.coordinate_limit
    bearings_at = _ROBOT_FEATURES + _LANDMARK_FEATURES * (settings.n_slots - 2)
    log_cap = math.log(cap)
    for i in range(rows.shape[0]):
        row = rows[i]
        centroid = maps.robot_centroid[row]
        known = (
            maps.robot_counts[row] > 0 and np.isfinite(centroid.real) and np.isfinite(centroid.imag)
        )
        if known:
            out[i, 0] = _coordinate(centroid.real, limit)
            out[i, 1] = _coordinate(centroid.imag, limit)
            out[i, 2] = math.log(capped(maps.robot_area[row], floor, cap))
        else:
            out[i, 2] = log_cap
            out[i, 3] = 1.0
        heading = maps.robot_heading[row]
        if np.isfinite(heading):
            out[i, 4] = math.cos(heading)
            out[i, 5] = math.sin(heading)
        out[i, 6] = min(state.moves[row] / settings.max_moves, 1.0)
        out[i, 7] = 1.0 if state.frame_changed[row] else 0.0
        out[i, 8] = 1.0 if state.blocked[row] else 0.0
        for j in range(settings.n - 2):
            at = _ROBOT_FEATURES + _LANDMARK_FEATURES * j
            out[i, at] = 1.0
            if maps.counts[row, j] > 0:
                out[i, at + 2] = _coordinate(maps.centroids[row, j].real, limit)
                out[i, at + 3] = _coordinate(maps.centroids[row, j].imag, limit)
            else:
                out[i, at + 1] = 1.0
            out[i, at + 4] = math.log(capped(maps.areas[row, j], floor, cap))
        latest = state.latest_bearings
        for k in range(settings.n):
            at = bearings_at + _BEARING_FEATURES * k
            out[i, at] = 1.0
            if not math.isnan(latest[row, k]):  # a missed reading reads (0, 0)
                out[i, at + 1] = math.cos(latest[row, k])
                out[i, at + 2] = math.sin(latest[row, k])


@njit(**_JIT)
def write_infos(
    rows: np.ndarray,
    inputs: Inputs,
    landmark_area: np.ndarray,
    landmark_error: np.ndarray,
    contains_truth: np.ndarray,
    total_area: np.ndarray,
    robot_error: np.ndarray,
) -> None:
    """The ground-truth parts of a group's infos (see the env's Info section)."""
    settings, maps, state = inputs.settings, inputs.maps, inputs.state
    for i in range(rows.shape[0]):
        row = rows[i]
        total = 0.0
        for j in range(settings.n - 2):
            area = maps.areas[row, j]
            landmark_area[i, j] = area
            total += area
            count = maps.counts[row, j]
            if count > 0:
                truth = state.landmarks_fl[row, j]
                landmark_error[i, j] = abs(maps.centroids[row, j] - truth)
                contains_truth[i, j] = contains_point(
                    maps.vertices[row, j], count, truth, settings.tolerance
                )
            else:
                landmark_error[i, j] = np.inf
                contains_truth[i, j] = False
        total_area[i] = total
        centroid = maps.robot_centroid[row]
        if np.isfinite(centroid.real) and np.isfinite(centroid.imag):
            position = complex(state.positions[row, 0], state.positions[row, 1])
            truth = (position - state.frame_origin[row]) / state.frame_unit[row]
            robot_error[i] = abs(centroid - truth)
        else:
            robot_error[i] = np.inf


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
