"""Compiled halves of the envs' step (numba): the move, the rewards, the observation and
the info, for a group of rows at once.

These do in one call what would otherwise be dozens of small numpy operations per step;
:mod:`bearing_env.envs.core` calls them for the single env (a group of one row) and the
vector env alike, so both compute every number with the same code. Random draws stay
in Python, where each row's own generator makes them (see ``core.step``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from bearing_env.envs.observations import BEARING_FEATURES, LANDMARK_FEATURES, ROBOT_FEATURES
from bearing_env.numerics import JIT_OPTIONS as _JIT
from bearing_env.numerics import wrap
from bearing_env.slam.kernels import contains_point
from bearing_env.world import bearing, straight_move

#: The flat observation's block sizes (numba compile-time constants), from the feature
#: tuples of :mod:`bearing_env.envs.observations`; :func:`write_observations` writes the
#: blocks in that module's order.
_ROBOT_FEATURES = len(ROBOT_FEATURES)
_LANDMARK_FEATURES = len(LANDMARK_FEATURES)
_BEARING_FEATURES = len(BEARING_FEATURES)


@njit(**_JIT)
def _noisy(true_bearing: float, offset: float, is_outlier: bool, replacement: float) -> float:
    return wrap(replacement if is_outlier else true_bearing + offset)


@njit(**_JIT)
def move_and_read(
    rows: np.ndarray,
    turns: np.ndarray,
    lengths: np.ndarray,
    n: int,
    width: float,
    height: float,
    margin: float,
    min_baseline: float,
    offsets_start: np.ndarray,
    outlier_start: np.ndarray,
    replacement_start: np.ndarray,
    offsets_end: np.ndarray,
    outlier_end: np.ndarray,
    replacement_end: np.ndarray,
    positions: np.ndarray,
    headings: np.ndarray,
    landmarks: np.ndarray,
    start_positions: np.ndarray,
    start_bearings: np.ndarray,
    latest_bearings: np.ndarray,
    moves: np.ndarray,
    blocked: np.ndarray,
    travelled: np.ndarray,
    reading_start: np.ndarray,
    reading_end: np.ndarray,
) -> None:
    """Turn, read, move straight until the wall margin, read again; for each row.

    The readings are the true bearings plus the rows' pre-drawn noise (see
    :meth:`~bearing_env.world.NoiseModel.draw_rows`), wrapped; out in ``reading_start``
    and ``reading_end`` (len(rows), n) and ``travelled``. In place: the rows' pose,
    start position, readings, move count and blocked flag. A robot that could not move
    at least ``min_baseline`` does not move (see :func:`~bearing_env.world.straight_move`).
    """
    for i in range(rows.shape[0]):
        row = rows[i]
        heading = wrap(headings[row] + turns[i])
        x, y = positions[row, 0], positions[row, 1]
        new_x, new_y, distance, stopped = straight_move(
            x, y, heading, lengths[i], width, height, margin, min_baseline
        )
        for j in range(n):
            lx, ly = landmarks[row, j, 0], landmarks[row, j, 1]
            first = _noisy(
                bearing(lx, ly, x, y, heading),
                offsets_start[i, j], outlier_start[i, j], replacement_start[i, j],
            )
            second = _noisy(
                bearing(lx, ly, new_x, new_y, heading),
                offsets_end[i, j], outlier_end[i, j], replacement_end[i, j],
            )
            reading_start[i, j] = start_bearings[row, j] = first
            reading_end[i, j] = latest_bearings[row, j] = second
        start_positions[row, 0], start_positions[row, 1] = x, y
        positions[row, 0], positions[row, 1] = new_x, new_y
        headings[row] = heading
        blocked[row] = stopped
        moves[row] += 1
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
def potentials(
    rows: np.ndarray, areas: np.ndarray, n_mapped: int, log_area: bool, floor: float,
    cap: float, out: np.ndarray,
) -> None:
    for i in range(rows.shape[0]):
        out[i] = potential_of(areas[rows[i]], n_mapped, log_area, floor, cap)


@njit(**_JIT)
def finish_steps(
    rows: np.ndarray,
    n_mapped: int,
    log_area: bool,
    floor: float,
    cap: float,
    target_area: float,
    max_moves: int,
    path_cost: float,
    move_cost: float,
    travelled: np.ndarray,
    areas: np.ndarray,
    counts: np.ndarray,
    state_potentials: np.ndarray,
    moves: np.ndarray,
    done: np.ndarray,
    reward: np.ndarray,
    uncertainty: np.ndarray,
    path: np.ndarray,
    move: np.ndarray,
    terminated: np.ndarray,
    truncated: np.ndarray,
) -> None:
    """Rewards (with their named parts), terminations and truncations after the map
    update; the rows' potentials and done flags are updated in place."""
    for i in range(rows.shape[0]):
        row = rows[i]
        potential = potential_of(areas[row], n_mapped, log_area, floor, cap)
        uncertainty[i] = state_potentials[row] - potential
        path[i] = -path_cost * travelled[i]
        move[i] = -move_cost
        # 0.0 + turns an uncertainty of -0.0 into 0.0; the order of the sum is fixed.
        reward[i] = ((0.0 + uncertainty[i]) + path[i]) + move[i]
        state_potentials[row] = potential
        success = True
        for j in range(n_mapped):
            if counts[row, j] == 0 or not areas[row, j] <= target_area:
                success = False
                break
        terminated[i] = success
        truncated[i] = not success and moves[row] >= max_moves
        done[row] = terminated[i] or truncated[i]


@njit(**_JIT)
def _coordinate(value: float, limit: float) -> float:
    return min(max(value, -limit), limit)


@njit(**_JIT)
def write_observations(
    rows: np.ndarray,
    n: int,
    n_slots: int,
    floor: float,
    cap: float,
    max_moves: int,
    coordinate_limit: float,
    robot_centroid: np.ndarray,
    robot_counts: np.ndarray,
    robot_area: np.ndarray,
    robot_heading: np.ndarray,
    counts: np.ndarray,
    centroids: np.ndarray,
    areas: np.ndarray,
    moves: np.ndarray,
    frame_changed: np.ndarray,
    blocked: np.ndarray,
    latest_bearings: np.ndarray,
    out: np.ndarray,
) -> None:
    """The observations (len(rows), size) of a group, float32 (the env's Observation
    Space section documents every element); ``out`` must be zeros."""
    bearings_at = _ROBOT_FEATURES + _LANDMARK_FEATURES * (n_slots - 2)
    log_cap = math.log(cap)
    for i in range(rows.shape[0]):
        row = rows[i]
        centroid = robot_centroid[row]
        known = robot_counts[row] > 0 and np.isfinite(centroid.real) and np.isfinite(centroid.imag)
        if known:
            out[i, 0] = _coordinate(centroid.real, coordinate_limit)
            out[i, 1] = _coordinate(centroid.imag, coordinate_limit)
            out[i, 2] = math.log(capped(robot_area[row], floor, cap))
        else:
            out[i, 2] = log_cap
            out[i, 3] = 1.0
        heading = robot_heading[row]
        if np.isfinite(heading):
            out[i, 4] = math.cos(heading)
            out[i, 5] = math.sin(heading)
        out[i, 6] = min(moves[row] / max_moves, 1.0)
        out[i, 7] = 1.0 if frame_changed[row] else 0.0
        out[i, 8] = 1.0 if blocked[row] else 0.0
        for j in range(n - 2):
            at = _ROBOT_FEATURES + _LANDMARK_FEATURES * j
            out[i, at] = 1.0
            if counts[row, j] > 0:
                out[i, at + 2] = _coordinate(centroids[row, j].real, coordinate_limit)
                out[i, at + 3] = _coordinate(centroids[row, j].imag, coordinate_limit)
            else:
                out[i, at + 1] = 1.0
            out[i, at + 4] = math.log(capped(areas[row, j], floor, cap))
        for k in range(n):
            at = bearings_at + _BEARING_FEATURES * k
            out[i, at] = 1.0
            if not math.isnan(latest_bearings[row, k]):  # a missed reading reads (0, 0)
                out[i, at + 1] = math.cos(latest_bearings[row, k])
                out[i, at + 2] = math.sin(latest_bearings[row, k])


@njit(**_JIT)
def write_infos(
    rows: np.ndarray,
    n_mapped: int,
    relative_tolerance: float,
    areas: np.ndarray,
    counts: np.ndarray,
    centroids: np.ndarray,
    vertices: np.ndarray,
    landmarks_fl: np.ndarray,
    positions: np.ndarray,
    frame_origin: np.ndarray,
    frame_unit: np.ndarray,
    robot_centroid: np.ndarray,
    landmark_area: np.ndarray,
    landmark_error: np.ndarray,
    contains_truth: np.ndarray,
    total_area: np.ndarray,
    robot_error: np.ndarray,
) -> None:
    """The ground-truth parts of a group's infos (see the env's Info section)."""
    for i in range(rows.shape[0]):
        row = rows[i]
        total = 0.0
        for j in range(n_mapped):
            area = areas[row, j]
            landmark_area[i, j] = area
            total += area
            count = counts[row, j]
            if count > 0:
                truth = landmarks_fl[row, j]
                landmark_error[i, j] = abs(centroids[row, j] - truth)
                contains_truth[i, j] = contains_point(
                    vertices[row, j], count, truth, relative_tolerance
                )
            else:
                landmark_error[i, j] = np.inf
                contains_truth[i, j] = False
        total_area[i] = total
        centroid = robot_centroid[row]
        if np.isfinite(centroid.real) and np.isfinite(centroid.imag):
            truth = (complex(positions[row, 0], positions[row, 1]) - frame_origin[row]) / (
                frame_unit[row]
            )
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
