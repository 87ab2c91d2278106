"""One movement per map: the batched update, serial and parallel, and batch helpers."""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np
from numba import njit

from bearing_env.slam.kernels.common import (
    _JIT,
    FR_BOUNDED,
    FR_EMPTY,
    FR_MISSING,
    FR_VERTICES,
    FRAME_L1_MISSING,
    FRAME_L1_UNBOUNDED,
    FRAME_L2_MISSING,
    FRAME_L2_UNBOUNDED,
    FRAME_OK,
    FRAME_REJECTED,
    LANDMARK_INCONSISTENT,
    LANDMARK_MISSING,
    LANDMARK_SKIPPED,
    LANDMARK_UNBOUNDED,
    LANDMARK_UPDATED,
    MAX_PAIRS,
)
from bearing_env.slam.kernels.frames import (
    FrameChange,
    cone_region,
    frame_plan,
    sample_hypotheses,
    transfer_region,
)
from bearing_env.slam.kernels.fusion import (
    _copy_polygon,
    age_out_oldest,
    intersect_landmark,
    relaxed_movement,
)
from bearing_env.slam.kernels.polygons import (
    area_centroid,
    contains_point,
)
from bearing_env.slam.kernels.robust import (
    PROBE_SHRINK,
    contamination,
    forget_regions,
    frame_contradicts_robot,
    grow_bound,
    history_movement,
    probe_landmark,
    push_history,
    robust_landmark,
)
from bearing_env.slam.kernels.state import (
    FUSION_RELAXED,
    FUSION_ROBUST,
    INCONSISTENCY_KEEP,
    TRANSFER_CONSERVATIVE,
    Outputs,
    Params,
    Scratch,
    State,
    new_scratch,
)

# --------------------------------------------------------------------------------------
# One movement per map
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def _frame_of(
    fr: np.ndarray, fr_count: np.ndarray, params: Params, h1: np.ndarray, inv_d: np.ndarray
) -> tuple[int, FrameChange]:
    """One movement's frame code and, when it is :data:`FRAME_OK`, its change of frames
    (hypotheses sampled into ``h1`` and ``inv_d``) from the FR regions of L1 and L2."""
    a1, n1, a2, n2 = fr[0], fr_count[0], fr[1], fr_count[1]
    conservative = params.transfer == TRANSFER_CONSERVATIVE
    status, per_edge, distance, delta1, delta2 = frame_plan(
        a1, n1, a2, n2, conservative, params.edge_samples
    )
    n_pairs = 0
    if status == FRAME_OK:
        n_pairs = sample_hypotheses(a1, n1, a2, n2, per_edge, h1, inv_d)
    frame = FrameChange(a1, n1, a2, n2, h1, inv_d, n_pairs, conservative, distance, delta1, delta2)
    return status, frame


@njit(**_JIT)
def _open_window_slot(state: State, row: int, scratch: Scratch) -> int:
    """Make room in map ``row``'s window for a new movement (ageing out the oldest when
    it is full); returns the new movement's slot."""
    window = state.window_counts.shape[1]
    if state.window_length[row] == window:
        age_out_oldest(state, row, scratch)
    newest = state.window_next[row]
    state.window_rejected[row, newest] = False
    state.window_counts[row, newest, :] = 0
    state.window_next[row] = (newest + 1) % window
    state.window_length[row] += 1
    return newest


@njit(**_JIT)
def _transfer_robot(
    state: State, row: int, frame: FrameChange, scratch: Scratch, robot_point: np.ndarray
) -> None:
    """Map ``row``'s robot region (the FR point R2 = 1 in FL) and heading."""
    fresh = scratch.fresh
    # robot_point.size, not 1: a literal argument compiles one more specialisation.
    n_robot = transfer_region(
        robot_point, robot_point.size, frame, scratch.cloud, scratch.hull, fresh
    )
    for v in range(n_robot):
        state.robot_vertices[row, v] = fresh[v]
    state.robot_counts[row] = n_robot
    if n_robot > 0:
        state.robot_area[row], state.robot_centroid[row] = area_centroid(fresh, n_robot)
    else:
        state.robot_area[row], state.robot_centroid[row] = np.inf, complex(np.nan, np.nan)
    # Heading: the FR x-axis seen through T at the vertex means of A_L1 and A_L2.
    mean1 = 0j
    for v in range(frame.n1):
        mean1 += frame.a1[v]
    mean2 = 0j
    for v in range(frame.n2):
        mean2 += frame.a2[v]
    chord = mean2 / frame.n2 - mean1 / frame.n1
    state.robot_heading[row] = -math.atan2(chord.imag, chord.real)


@njit(**_JIT)
def _cone_regions(
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    epsilon: float,
    fr: np.ndarray,
    fr_count: np.ndarray,
    fr_status: np.ndarray,
) -> int:
    """Every landmark's FR region from one movement's bearings; returns the frame code
    the regions of L1 and L2 allow (:data:`FRAME_OK` if both are bounded)."""
    for j in range(bearings_start.shape[0]):
        if math.isnan(bearings_start[j]) or math.isnan(bearings_end[j]):
            fr_count[j], fr_status[j] = 0, FR_MISSING
            continue
        fr_count[j], fr_status[j] = cone_region(bearings_start[j], bearings_end[j], epsilon, fr[j])
    if fr_status[0] == FR_MISSING:
        return FRAME_L1_MISSING
    if fr_status[1] == FR_MISSING:
        return FRAME_L2_MISSING
    if fr_status[0] != FR_BOUNDED:
        return FRAME_L1_UNBOUNDED
    if fr_status[1] != FR_BOUNDED:
        return FRAME_L2_UNBOUNDED
    return FRAME_OK


class Buffers(NamedTuple):
    """What one thread of the update works in for one movement: the FR regions
    (``fr``, ``fr_count``, ``fr_status``), the sampled hypotheses (``h1``, ``inv_d``),
    the relaxed fusion's new-region counts, the FR robot point, a movement's bearings
    read back from a map's history (``start``, ``end``) and the polygon scratch."""

    fr: np.ndarray
    fr_count: np.ndarray
    fr_status: np.ndarray
    h1: np.ndarray
    inv_d: np.ndarray
    fresh_counts: np.ndarray
    robot_point: np.ndarray
    start: np.ndarray
    end: np.ndarray
    scratch: Scratch


@njit(**_JIT)
def _new_buffers(n_landmarks: int) -> Buffers:
    return Buffers(
        np.empty((n_landmarks, FR_VERTICES), dtype=np.complex128),
        np.empty(n_landmarks, dtype=np.int64),
        np.empty(n_landmarks, dtype=np.int64),
        np.empty(MAX_PAIRS, dtype=np.complex128),
        np.empty(MAX_PAIRS, dtype=np.complex128),
        np.zeros(n_landmarks, dtype=np.int64),
        np.ones(1, dtype=np.complex128),
        np.empty(n_landmarks),
        np.empty(n_landmarks),
        new_scratch(),
    )


@njit(**_JIT)
def _update_row(
    i: int,
    row: int,
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    epsilon: float,
    params: Params,
    state: State,
    out: Outputs,
    buf: Buffers,
) -> None:
    """Fuse one movement (bearings ``bearings_start`` and ``bearings_end``, read with the
    bound ``epsilon``) into map ``row``, reporting to ``out`` row ``i``."""
    n_landmarks = bearings_start.shape[0]
    relaxed = params.fusion == FUSION_RELAXED
    robust = params.fusion == FUSION_ROBUST
    keep = params.on_inconsistency == INCONSISTENCY_KEEP
    frame_status, landmark_status = out.frame_status, out.landmark_status
    fr, fr_count, fr_status, scratch = buf.fr, buf.fr_count, buf.fr_status, buf.scratch
    fresh_counts = buf.fresh_counts
    state.n_updates[row] += 1
    out.n_bad[i] = 0
    for j in range(n_landmarks - 2):
        landmark_status[i, j] = LANDMARK_SKIPPED
    frame_status[i] = _cone_regions(bearings_start, bearings_end, epsilon, fr, fr_count, fr_status)
    if frame_status[i] != FRAME_OK:
        return
    status, frame = _frame_of(fr, fr_count, params, buf.h1, buf.inv_d)
    frame_status[i] = status
    if status != FRAME_OK:
        return
    newest = 0
    if relaxed:
        newest = _open_window_slot(state, row, scratch)
    rate = contamination(state, row) if robust else 0.0
    last = n_landmarks
    if robust and params.with_robot and frame_contradicts_robot(state, row, frame, scratch):
        frame_status[i] = FRAME_REJECTED  # a misread L1 or L2: no landmark is fused
        last = 2
    for j in range(2, last):
        slot = j - 2
        fresh_counts[slot] = 0
        if fr_status[j] == FR_MISSING:
            landmark_status[i, slot] = LANDMARK_MISSING
            continue
        if fr_status[j] == FR_EMPTY:
            landmark_status[i, slot] = LANDMARK_INCONSISTENT
            continue
        if fr_status[j] != FR_BOUNDED:
            landmark_status[i, slot] = LANDMARK_UNBOUNDED
            continue
        n_new = transfer_region(
            fr[j], fr_count[j], frame, scratch.cloud, scratch.hull, scratch.fresh
        )
        if n_new < 3:
            landmark_status[i, slot] = LANDMARK_UNBOUNDED
            continue
        landmark_status[i, slot] = LANDMARK_UPDATED
        if relaxed:
            _copy_polygon(scratch.fresh, n_new, state.window_vertices[row, newest, slot])
            state.window_counts[row, newest, slot] = n_new
            fresh_counts[slot] = n_new
        elif robust:
            if not robust_landmark(state, row, slot, n_new, rate, params, scratch):
                landmark_status[i, slot] = LANDMARK_INCONSISTENT
        elif not intersect_landmark(state, row, slot, n_new, keep, scratch):
            landmark_status[i, slot] = LANDMARK_INCONSISTENT
    if relaxed and relaxed_movement(state, row, fresh_counts, params, out, i, scratch):
        frame_status[i] = FRAME_REJECTED
    state.n_frame_changes[row] += frame_status[i] == FRAME_OK
    bad = 0
    for j in range(n_landmarks - 2):
        if landmark_status[i, j] == LANDMARK_INCONSISTENT:
            bad += 1
    out.n_bad[i] = bad
    state.n_inconsistent[row] += bad
    if not params.with_robot:
        return
    if frame_status[i] == FRAME_REJECTED:
        # The frame change itself is the outlier: the robot's region is unknown.
        state.robot_counts[row] = 0
        state.robot_area[row], state.robot_centroid[row] = np.inf, complex(np.nan, np.nan)
        state.robot_heading[row] = np.nan
        return
    _transfer_robot(state, row, frame, scratch, buf.robot_point)
    state.robot_fixed_at[row] = state.n_updates[row]


@njit(**_JIT)
def _probe_row(
    i: int,
    row: int,
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    epsilon: float,
    params: Params,
    state: State,
    out: Outputs,
    buf: Buffers,
) -> int:
    """Fuse the movement just fused into map ``row`` (with the bound ``epsilon``, as
    ``out`` row ``i`` reports) into its probe, at ``PROBE_SHRINK * epsilon``; returns
    how many landmarks give evidence that the bound is too small: the probe contradicts
    them while the map fused them consistently."""
    if out.frame_status[i] != FRAME_OK:
        return 0
    fr, fr_count, fr_status, scratch = buf.fr, buf.fr_count, buf.fr_status, buf.scratch
    status = _cone_regions(
        bearings_start, bearings_end, PROBE_SHRINK * epsilon, fr, fr_count, fr_status
    )
    if status != FRAME_OK:
        return 0
    status, frame = _frame_of(fr, fr_count, params, buf.h1, buf.inv_d)
    if status != FRAME_OK:
        return 0
    evidence = 0
    for j in range(2, bearings_start.shape[0]):
        slot = j - 2
        consistent_here = out.landmark_status[i, slot] == LANDMARK_UPDATED
        if fr_status[j] == FR_EMPTY:
            evidence += consistent_here
            continue
        if fr_status[j] != FR_BOUNDED:
            continue
        n_new = transfer_region(
            fr[j], fr_count[j], frame, scratch.cloud, scratch.hull, scratch.fresh
        )
        if n_new >= 3 and not probe_landmark(state, row, slot, n_new, scratch):
            evidence += consistent_here
    return evidence


@njit(**_JIT)
def _rebuild_row(
    i: int, row: int, params: Params, state: State, out: Outputs, buf: Buffers
) -> None:
    """Fuse map ``row``'s kept movements again, oldest first, into empty regions, levels
    and probe at its (new) bound; ``out`` row ``i`` ends with what the newest one did.
    The counters end as if only the newest movement had been fused at that bound."""
    updates, changes, inconsistent = (
        state.n_updates[row] - 1,
        state.n_frame_changes[row] - (out.frame_status[i] == FRAME_OK),
        state.n_inconsistent[row] - out.n_bad[i],
    )
    epsilon = params.epsilon * state.noise_scale[row]
    forget_regions(state, row)
    for k in range(state.history_length[row]):
        history_movement(state, row, k, buf.start, buf.end)
        _update_row(i, row, buf.start, buf.end, epsilon, params, state, out, buf)
        _probe_row(i, row, buf.start, buf.end, epsilon, params, state, out, buf)
    fixed_by_newest = state.robot_fixed_at[row] == state.n_updates[row]
    state.n_updates[row] = updates + 1
    state.n_frame_changes[row] = changes + (out.frame_status[i] == FRAME_OK)
    state.n_inconsistent[row] = inconsistent + out.n_bad[i]
    # Older kept robot regions cannot be told apart from this movement's: none is older.
    state.robot_fixed_at[row] = state.n_updates[row] if fixed_by_newest else -1


@njit(**_JIT)
def _update_rows(
    first: int,
    stop: int,
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    rows: np.ndarray,
    params: Params,
    state: State,
    out: Outputs,
) -> None:
    """:func:`update_maps` for bearings rows ``first`` to ``stop``, with buffers of its own."""
    estimating = params.fusion == FUSION_ROBUST and params.estimate_bound
    buf = _new_buffers(bearings_start.shape[1])
    for i in range(first, stop):
        row = rows[i]
        epsilon = params.epsilon
        if estimating:
            epsilon *= state.noise_scale[row]
        _update_row(i, row, bearings_start[i], bearings_end[i], epsilon, params, state, out, buf)
        if not estimating:
            continue
        push_history(state, row, bearings_start[i], bearings_end[i])
        evidence = _probe_row(
            i, row, bearings_start[i], bearings_end[i], epsilon, params, state, out, buf
        )
        if evidence > 0:
            state.bound_events[row] += evidence
            if grow_bound(state, row, params.epsilon):
                _rebuild_row(i, row, params, state, out, buf)


@njit(inline="always", **_JIT)
def update_maps(
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    rows: np.ndarray,
    params: Params,
    state: State,
    out: Outputs,
) -> None:
    """Fuse one movement into each map ``rows[i]`` (bearings row ``i``), in place.

    A map's state (see :class:`~bearing_env.slam.kernels.state.State`) is its regions
    (``vertices[map, j, :counts[map, j]]``; count 0 means not initialised), their areas
    and centroids, the robot's region and heading (left as they were when
    ``params.with_robot`` is False), its counters and the relaxed fusion's window and
    bases. Each map is updated on its own, so its result never depends on the other
    maps of the batch. What each movement did goes to ``out``.
    """
    # np.int64(0), not 0: a literal argument would compile the whole update once more.
    first = np.int64(0)
    _update_rows(first, rows.shape[0], bearings_start, bearings_end, rows, params, state, out)


@njit(parallel=True, **_JIT)
def update_maps_parallel(
    blocks: int,
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    rows: np.ndarray,
    params: Params,
    state: State,
    out: Outputs,
) -> None:
    """:func:`update_maps` with the maps split into ``blocks`` blocks, one per thread.

    Each map is computed by the same code as in the serial kernel, so the results are
    the same bit for bit; only the order in which maps are done changes. (The prange
    body is one call: numba 0.68 silently dropped writes made through a namedtuple's
    field directly in a prange body, while a called function's writes land.)
    """
    n_rows = rows.shape[0]
    for block in numba.prange(blocks):
        _update_rows(
            block * n_rows // blocks,
            (block + 1) * n_rows // blocks,
            bearings_start,
            bearings_end,
            rows,
            params,
            state,
            out,
        )


#: Outcomes of :func:`check_indices`.
INDEX_OK = 0
INDEX_OUT_OF_RANGE = 1
INDEX_REPEATED = 2


@njit(**_JIT)
def check_indices(indices: np.ndarray, size: int, distinct: bool) -> int:
    """Whether ``indices`` are in ``[0, size)`` (and, if ``distinct``, none repeats)."""
    seen = np.zeros(size if distinct else 0, dtype=np.bool_)
    for index in indices:
        if index < 0 or index >= size:
            return INDEX_OUT_OF_RANGE
        if distinct:
            if seen[index]:
                return INDEX_REPEATED
            seen[index] = True
    return INDEX_OK


@njit(**_JIT)
def none_infinite(values: np.ndarray) -> bool:
    """Whether no element of a float array is +-inf (NaN allowed; one pass)."""
    for value in values.ravel():
        if np.isinf(value):
            return False
    return True


@njit(**_JIT)
def contains_points(
    vertices: np.ndarray,
    counts: np.ndarray,
    rows: np.ndarray,
    points: np.ndarray,
    relative: float,
    out: np.ndarray,
) -> None:
    """``out[i, j]``: region ``j`` of map ``rows[i]`` contains ``points[i, j]``."""
    for i in range(rows.shape[0]):
        for j in range(points.shape[1]):
            n = counts[rows[i], j]
            out[i, j] = n > 0 and contains_point(vertices[rows[i], j], n, points[i, j], relative)
