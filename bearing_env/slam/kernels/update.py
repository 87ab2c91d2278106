"""One movement per map: the batched update, serial and parallel, and batch helpers."""

from __future__ import annotations

import math

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
    MAX_CLOUD,
    MAX_PAIRS,
    SCRATCH,
)
from bearing_env.slam.kernels.frames import (
    cone_region,
    frame_plan,
    sample_hypotheses,
    transfer_region,
)
from bearing_env.slam.kernels.fusion import (
    _age_out_oldest,
    _copy_polygon,
    relaxed_movement,
)
from bearing_env.slam.kernels.polygons import (
    area_centroid,
    clip_convex,
    contains_point,
)

# --------------------------------------------------------------------------------------
# One movement per map
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def _update_rows(
    first: int,
    stop: int,
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    rows: np.ndarray,
    epsilon: float,
    conservative: bool,
    edge_samples: int,
    keep_on_inconsistency: bool,
    with_robot: bool,
    max_outliers: int,
    vertices: np.ndarray,
    counts: np.ndarray,
    areas: np.ndarray,
    centroids: np.ndarray,
    robot_vertices: np.ndarray,
    robot_counts: np.ndarray,
    robot_area: np.ndarray,
    robot_centroid: np.ndarray,
    robot_heading: np.ndarray,
    n_updates: np.ndarray,
    n_frame_changes: np.ndarray,
    n_inconsistent: np.ndarray,
    window_vertices: np.ndarray,
    window_counts: np.ndarray,
    window_inlier: np.ndarray,
    window_rejected: np.ndarray,
    window_length: np.ndarray,
    window_next: np.ndarray,
    base_vertices: np.ndarray,
    base_counts: np.ndarray,
    n_dropped: np.ndarray,
    outliers: np.ndarray,
    frame_status: np.ndarray,
    landmark_status: np.ndarray,
    inconsistent_now: np.ndarray,
) -> None:
    """:func:`update_maps` for bearings rows ``first`` to ``stop``, with scratch of its own."""
    n_landmarks = bearings_start.shape[1]
    relaxed = window_counts.shape[1] > 0
    fresh_counts = np.zeros(n_landmarks, dtype=np.int64)
    fr = np.empty((n_landmarks, FR_VERTICES), dtype=np.complex128)
    fr_count = np.empty(n_landmarks, dtype=np.int64)
    fr_status = np.empty(n_landmarks, dtype=np.int64)
    h1 = np.empty(MAX_PAIRS, dtype=np.complex128)
    inv_d = np.empty(MAX_PAIRS, dtype=np.complex128)
    cloud = np.empty(MAX_CLOUD, dtype=np.complex128)
    hull = np.empty(MAX_CLOUD + 1, dtype=np.complex128)
    fresh = np.empty(max(MAX_CLOUD + 1, SCRATCH), dtype=np.complex128)
    fused = np.empty(SCRATCH, dtype=np.complex128)
    work = np.empty(SCRATCH, dtype=np.complex128)
    robot_point = np.ones(1, dtype=np.complex128)
    newest = 0
    for i in range(first, stop):
        row = rows[i]
        n_updates[row] += 1
        inconsistent_now[i] = 0
        for j in range(n_landmarks - 2):
            landmark_status[i, j] = LANDMARK_SKIPPED
        for j in range(n_landmarks):
            if math.isnan(bearings_start[i, j]) or math.isnan(bearings_end[i, j]):
                fr_count[j], fr_status[j] = 0, FR_MISSING
                continue
            fr_count[j], fr_status[j] = cone_region(
                bearings_start[i, j], bearings_end[i, j], epsilon, fr[j]
            )
        if fr_status[0] == FR_MISSING:
            frame_status[i] = FRAME_L1_MISSING
            continue
        if fr_status[1] == FR_MISSING:
            frame_status[i] = FRAME_L2_MISSING
            continue
        if fr_status[0] != FR_BOUNDED:
            frame_status[i] = FRAME_L1_UNBOUNDED
            continue
        if fr_status[1] != FR_BOUNDED:
            frame_status[i] = FRAME_L2_UNBOUNDED
            continue
        a1, n1, a2, n2 = fr[0], fr_count[0], fr[1], fr_count[1]
        status, per_edge, distance, delta1, delta2 = frame_plan(
            a1, n1, a2, n2, conservative, edge_samples
        )
        frame_status[i] = status
        if status != FRAME_OK:
            continue
        n_pairs = sample_hypotheses(a1, n1, a2, n2, per_edge, h1, inv_d)
        if relaxed:
            window = window_counts.shape[1]
            if window_length[row] == window:
                _age_out_oldest(
                    row, window_vertices, window_counts, window_inlier, window_rejected,
                    window_length, window_next, base_vertices, base_counts, n_dropped,
                    fused, work,
                )
            newest = window_next[row]
            window_rejected[row, newest] = False
            window_counts[row, newest, :] = 0
            window_next[row] = (newest + 1) % window
            window_length[row] += 1
        for j in range(2, n_landmarks):
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
                fr[j], fr_count[j], a1, n1, a2, n2, h1, inv_d, n_pairs, conservative,
                distance, delta1, delta2, cloud, hull, fresh,
            )
            if n_new < 3:
                landmark_status[i, slot] = LANDMARK_UNBOUNDED
                continue
            landmark_status[i, slot] = LANDMARK_UPDATED
            if relaxed:
                _copy_polygon(fresh, n_new, window_vertices[row, newest, slot])
                window_counts[row, newest, slot] = n_new
                fresh_counts[slot] = n_new
                continue
            n_old = counts[row, slot]
            source = fresh
            n_result = n_new
            if n_old > 0:
                n_result = clip_convex(
                    vertices[row, slot], n_old, fresh, n_new, fused, work
                )
                if n_result > 0:
                    source = fused
                else:
                    landmark_status[i, slot] = LANDMARK_INCONSISTENT
                    if keep_on_inconsistency:
                        continue
                    n_result = n_new
            for v in range(n_result):
                vertices[row, slot, v] = source[v]
            counts[row, slot] = n_result
            area, centroid = area_centroid(vertices[row, slot], n_result)
            areas[row, slot] = area
            centroids[row, slot] = centroid
        if relaxed:
            rejected = relaxed_movement(
                row, fresh_counts, max_outliers, keep_on_inconsistency, vertices, counts,
                areas, centroids, window_vertices, window_counts, window_inlier,
                window_rejected, window_length, window_next, base_vertices, base_counts,
                n_dropped, outliers, landmark_status, i, fused, work, fresh,
                cloud, hull,
            )
            if rejected:
                frame_status[i] = FRAME_REJECTED
        n_frame_changes[row] += frame_status[i] == FRAME_OK
        bad = 0
        for j in range(n_landmarks - 2):
            if landmark_status[i, j] == LANDMARK_INCONSISTENT:
                bad += 1
        inconsistent_now[i] = bad
        n_inconsistent[row] += bad
        if not with_robot:
            continue
        if frame_status[i] == FRAME_REJECTED:
            # The frame change itself is the outlier: the robot's region is unknown.
            robot_counts[row] = 0
            robot_area[row], robot_centroid[row] = np.inf, complex(np.nan, np.nan)
            robot_heading[row] = np.nan
            continue
        n_robot = transfer_region(
            robot_point, 1, a1, n1, a2, n2, h1, inv_d, n_pairs, conservative,
            distance, delta1, delta2, cloud, hull, fresh,
        )
        for v in range(n_robot):
            robot_vertices[row, v] = fresh[v]
        robot_counts[row] = n_robot
        if n_robot > 0:
            robot_area[row], robot_centroid[row] = area_centroid(fresh, n_robot)
        else:
            robot_area[row], robot_centroid[row] = np.inf, complex(np.nan, np.nan)
        # Heading: the FR x-axis seen through T at the vertex means of A_L1 and A_L2.
        mean1 = 0j
        for v in range(n1):
            mean1 += a1[v]
        mean2 = 0j
        for v in range(n2):
            mean2 += a2[v]
        chord = mean2 / n2 - mean1 / n1
        robot_heading[row] = -math.atan2(chord.imag, chord.real)


@njit(**_JIT)
def update_maps(
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    rows: np.ndarray,
    epsilon: float,
    conservative: bool,
    edge_samples: int,
    keep_on_inconsistency: bool,
    with_robot: bool,
    max_outliers: int,
    vertices: np.ndarray,
    counts: np.ndarray,
    areas: np.ndarray,
    centroids: np.ndarray,
    robot_vertices: np.ndarray,
    robot_counts: np.ndarray,
    robot_area: np.ndarray,
    robot_centroid: np.ndarray,
    robot_heading: np.ndarray,
    n_updates: np.ndarray,
    n_frame_changes: np.ndarray,
    n_inconsistent: np.ndarray,
    window_vertices: np.ndarray,
    window_counts: np.ndarray,
    window_inlier: np.ndarray,
    window_rejected: np.ndarray,
    window_length: np.ndarray,
    window_next: np.ndarray,
    base_vertices: np.ndarray,
    base_counts: np.ndarray,
    n_dropped: np.ndarray,
    outliers: np.ndarray,
    frame_status: np.ndarray,
    landmark_status: np.ndarray,
    inconsistent_now: np.ndarray,
) -> None:
    """Fuse one movement into each map ``rows[i]`` (bearings row ``i``), in place.

    A map's state is its regions (``vertices[map, j, :counts[map, j]]``; count 0 means
    not initialised), their areas and centroids, and the robot's region and heading
    (left as they were when ``with_robot`` is False). Each map is updated on its own, so
    its result never depends on the other maps of the batch.
    """
    _update_rows(
        0,
        rows.shape[0],
        bearings_start,
        bearings_end,
        rows,
        epsilon,
        conservative,
        edge_samples,
        keep_on_inconsistency,
        with_robot,
        max_outliers,
        vertices,
        counts,
        areas,
        centroids,
        robot_vertices,
        robot_counts,
        robot_area,
        robot_centroid,
        robot_heading,
        n_updates,
        n_frame_changes,
        n_inconsistent,
        window_vertices,
        window_counts,
        window_inlier,
        window_rejected,
        window_length,
        window_next,
        base_vertices,
        base_counts,
        n_dropped,
        outliers,
        frame_status,
        landmark_status,
        inconsistent_now,
    )


@njit(parallel=True, **_JIT)
def update_maps_parallel(
    blocks: int,
    bearings_start: np.ndarray,
    bearings_end: np.ndarray,
    rows: np.ndarray,
    epsilon: float,
    conservative: bool,
    edge_samples: int,
    keep_on_inconsistency: bool,
    with_robot: bool,
    max_outliers: int,
    vertices: np.ndarray,
    counts: np.ndarray,
    areas: np.ndarray,
    centroids: np.ndarray,
    robot_vertices: np.ndarray,
    robot_counts: np.ndarray,
    robot_area: np.ndarray,
    robot_centroid: np.ndarray,
    robot_heading: np.ndarray,
    n_updates: np.ndarray,
    n_frame_changes: np.ndarray,
    n_inconsistent: np.ndarray,
    window_vertices: np.ndarray,
    window_counts: np.ndarray,
    window_inlier: np.ndarray,
    window_rejected: np.ndarray,
    window_length: np.ndarray,
    window_next: np.ndarray,
    base_vertices: np.ndarray,
    base_counts: np.ndarray,
    n_dropped: np.ndarray,
    outliers: np.ndarray,
    frame_status: np.ndarray,
    landmark_status: np.ndarray,
    inconsistent_now: np.ndarray,
) -> None:
    """:func:`update_maps` with the maps split into ``blocks`` blocks, one per thread.

    Each map is computed by the same code as in the serial kernel, so the results are
    the same bit for bit; only the order in which maps are done changes.
    """
    n_rows = rows.shape[0]
    for block in numba.prange(blocks):
        _update_rows(
            block * n_rows // blocks,
            (block + 1) * n_rows // blocks,
            bearings_start,
            bearings_end,
            rows,
            epsilon,
            conservative,
            edge_samples,
            keep_on_inconsistency,
            with_robot,
            max_outliers,
            vertices,
            counts,
            areas,
            centroids,
            robot_vertices,
            robot_counts,
            robot_area,
            robot_centroid,
            robot_heading,
            n_updates,
            n_frame_changes,
            n_inconsistent,
            window_vertices,
            window_counts,
            window_inlier,
            window_rejected,
            window_length,
            window_next,
            base_vertices,
            base_counts,
            n_dropped,
            outliers,
            frame_status,
            landmark_status,
            inconsistent_now,
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
    vertices: np.ndarray, counts: np.ndarray, rows: np.ndarray, points: np.ndarray,
    relative: float, out: np.ndarray,
) -> None:
    """``out[i, j]``: region ``j`` of map ``rows[i]`` contains ``points[i, j]``."""
    for i in range(rows.shape[0]):
        for j in range(points.shape[1]):
            n = counts[rows[i], j]
            out[i, j] = n > 0 and contains_point(vertices[rows[i], j], n, points[i, j], relative)
