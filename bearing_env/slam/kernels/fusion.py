"""Fusing a movement's regions into a map: the relaxed fusion's window and bases."""

from __future__ import annotations

import numpy as np
from numba import njit

from bearing_env.slam.kernels.common import (
    _JIT,
    CAPACITY,
    LANDMARK_INCONSISTENT,
    MAX_WINDOW,
    SCRATCH,
)
from bearing_env.slam.kernels.polygons import (
    area_centroid,
    clip_convex,
    convex_hull,
    drop_edges_outward,
)

# --------------------------------------------------------------------------------------
# Relaxed fusion: the q-relaxed intersection over a window of movements
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def _copy_polygon(source: np.ndarray, n: int, out: np.ndarray) -> None:
    for v in range(n):
        out[v] = source[v]


@njit(**_JIT)
def _merge_hull(
    acc: np.ndarray, n_acc: int, poly: np.ndarray, n_poly: int, cloud: np.ndarray,
    hull: np.ndarray,
) -> int:
    """The convex hull of ``acc[:n_acc]`` and ``poly[:n_poly]`` into ``acc``."""
    for v in range(n_acc):
        cloud[v] = acc[v]
    for v in range(n_poly):
        cloud[n_acc + v] = poly[v]
    n = convex_hull(cloud, n_acc + n_poly, hull)
    n = drop_edges_outward(hull, n, CAPACITY)
    _copy_polygon(hull, n, acc)
    return n


@njit(**_JIT)
def _window_slots(
    row: int, j: int, window_counts: np.ndarray, window_rejected: np.ndarray,
    window_length: np.ndarray, window_next: np.ndarray, out: np.ndarray,
) -> int:
    """The window slots (oldest first) that hold a region of landmark ``j`` from a
    movement that was not rejected; returns how many."""
    size = window_counts.shape[1]
    k = 0
    for age in range(window_length[row]):
        slot = (window_next[row] - window_length[row] + age) % size
        if window_counts[row, slot, j] > 0 and not window_rejected[row, slot]:
            out[k] = slot
            k += 1
    return k


@njit(**_JIT)
def _intersect_kept(
    row: int, j: int, slots: np.ndarray, k: int, discarded: np.ndarray, use_base: bool,
    window_vertices: np.ndarray, window_counts: np.ndarray, base_vertices: np.ndarray,
    base_counts: np.ndarray, first: np.ndarray, second: np.ndarray, work: np.ndarray,
) -> tuple[int, bool]:
    """The intersection of the base (if used) and the kept regions of ``slots[:k]``.

    Returns ``(n, in_first)``: its vertex count (0 if empty) and whether it is in
    ``first`` (else in ``second``).
    """
    n = 0
    started = False
    in_first = True
    if use_base:
        n = base_counts[row, j]
        _copy_polygon(base_vertices[row, j], n, first)
        started = True
    for t in range(k):
        if discarded[t]:
            continue
        slot = slots[t]
        region = window_vertices[row, slot, j]
        n_region = window_counts[row, slot, j]
        if not started:
            _copy_polygon(region, n_region, first)
            n = n_region
            started = True
            continue
        if in_first:
            n = clip_convex(first, n, region, n_region, second, work)
        else:
            n = clip_convex(second, n, region, n_region, first, work)
        in_first = not in_first
        if n == 0:
            return 0, in_first
    return n, in_first


@njit(**_JIT)
def _relaxed_union(
    row: int, j: int, slots: np.ndarray, k: int, use_base: bool, q: int,
    window_vertices: np.ndarray, window_counts: np.ndarray, window_inlier: np.ndarray,
    base_vertices: np.ndarray, base_counts: np.ndarray, acc: np.ndarray,
    first: np.ndarray, second: np.ndarray, work: np.ndarray, cloud: np.ndarray,
    hull: np.ndarray,
) -> int:
    """The hull of the union, over every choice of ``q`` of ``slots[:k]`` to leave out,
    of the intersection of the base (if used) and the other regions, into ``acc``;
    returns its vertex count (0: every such intersection is empty). Each region kept
    by a non-empty intersection is marked an inlier."""
    discarded = np.zeros(MAX_WINDOW, dtype=np.bool_)
    combination = np.empty(MAX_WINDOW, dtype=np.int64)
    n_acc = 0
    for t in range(q):
        combination[t] = t
    while True:
        for t in range(k):
            discarded[t] = False
        for t in range(q):
            discarded[combination[t]] = True
        n, in_first = _intersect_kept(
            row, j, slots, k, discarded, use_base, window_vertices, window_counts,
            base_vertices, base_counts, first, second, work,
        )
        if n > 0:
            piece = first if in_first else second
            if n_acc == 0:
                _copy_polygon(piece, n, acc)
                n_acc = n
            else:
                n_acc = _merge_hull(acc, n_acc, piece, n, cloud, hull)
            for t in range(k):
                if not discarded[t]:
                    window_inlier[row, slots[t], j] = True
        # The next combination of q positions out of k, in lexicographic order.
        t = q - 1
        while t >= 0 and combination[t] == k - q + t:
            t -= 1
        if t < 0:
            return n_acc
        combination[t] += 1
        for u in range(t + 1, q):
            combination[u] = combination[u - 1] + 1


@njit(**_JIT)
def relaxed_region(
    row: int, j: int, slots: np.ndarray, k: int, use_base: bool, max_outliers: int,
    window_vertices: np.ndarray, window_counts: np.ndarray, window_inlier: np.ndarray,
    base_vertices: np.ndarray, base_counts: np.ndarray, acc: np.ndarray,
    first: np.ndarray, second: np.ndarray, work: np.ndarray, cloud: np.ndarray,
    hull: np.ndarray,
) -> tuple[int, int]:
    """The hull of the q-relaxed intersection of the base and ``slots[:k]`` into
    ``acc``, for ``q`` the smallest number of left-out regions that makes it non-empty
    (at most ``max_outliers``; the base is never left out).

    No margin is added to ``q``: one more left-out region grew the median clean region
    by half while gaining little containment (measured; see docs/design.md).

    Returns ``(n, q)``: the vertex count (0 if no ``q`` up to the cap works) and ``q``.
    """
    # Without a base, at least one region must be kept.
    q_max = min(max_outliers, k if use_base else k - 1)
    for q in range(q_max + 1):
        n = _relaxed_union(
            row, j, slots, k, use_base, q, window_vertices, window_counts, window_inlier,
            base_vertices, base_counts, acc, first, second, work, cloud, hull,
        )
        if n > 0:
            return n, q
    return 0, q_max


@njit(**_JIT)
def _solve_landmark(
    row: int, j: int, max_outliers: int, keep_on_inconsistency: bool,
    vertices: np.ndarray, counts: np.ndarray, areas: np.ndarray, centroids: np.ndarray,
    window_vertices: np.ndarray, window_counts: np.ndarray, window_inlier: np.ndarray,
    window_rejected: np.ndarray, window_length: np.ndarray, window_next: np.ndarray,
    base_vertices: np.ndarray, base_counts: np.ndarray, n_dropped: np.ndarray,
    slots: np.ndarray, acc: np.ndarray, first: np.ndarray, second: np.ndarray,
    work: np.ndarray, cloud: np.ndarray, hull: np.ndarray,
) -> None:
    """Landmark ``j``'s region from its base and window, from scratch (see
    :func:`relaxed_movement`)."""
    k = _window_slots(row, j, window_counts, window_rejected, window_length, window_next, slots)
    for t in range(k):
        window_inlier[row, slots[t], j] = False
    use_base = base_counts[row, j] > 0
    n = 0
    if k > 0 or use_base:
        n, _ = relaxed_region(
            row, j, slots, k, use_base, max_outliers, window_vertices, window_counts,
            window_inlier, base_vertices, base_counts, acc, first, second, work, cloud, hull,
        )
        if n == 0 and use_base:
            # The base (everything older than the window) contradicts the window beyond
            # the cap: it is dropped.
            base_counts[row, j] = 0
            n_dropped[row, j] += 1
            n, _ = relaxed_region(
                row, j, slots, k, False, max_outliers, window_vertices, window_counts,
                window_inlier, base_vertices, base_counts, acc, first, second, work,
                cloud, hull,
            )
    if n == 0 and k > 0:
        # More than max_outliers regions disagree: as the strict intersection does, keep
        # the old region, or restart from the newest movement's region alone.
        newest = slots[k - 1]
        if keep_on_inconsistency and counts[row, j] > 0:
            return  # every window region is left out, so the next update solves again
        n = window_counts[row, newest, j]
        _copy_polygon(window_vertices[row, newest, j], n, acc)
        window_inlier[row, newest, j] = True
    _copy_polygon(acc, n, vertices[row, j])
    counts[row, j] = n
    if n > 0:
        areas[row, j], centroids[row, j] = area_centroid(vertices[row, j], n)
    else:
        areas[row, j], centroids[row, j] = np.inf, complex(np.nan, np.nan)


@njit(**_JIT)
def _age_out_oldest(
    row: int, window_vertices: np.ndarray, window_counts: np.ndarray,
    window_inlier: np.ndarray, window_rejected: np.ndarray, window_length: np.ndarray,
    window_next: np.ndarray, base_vertices: np.ndarray, base_counts: np.ndarray,
    n_dropped: np.ndarray, first: np.ndarray, work: np.ndarray,
) -> None:
    """Fold the oldest movement of a full window into the bases: each inlier region is
    intersected into its landmark's base for good, each outlier dropped for good."""
    size = window_counts.shape[1]
    slot = (window_next[row] - window_length[row]) % size
    for j in range(window_counts.shape[2]):
        n_region = window_counts[row, slot, j]
        if n_region == 0:
            continue
        if window_rejected[row, slot] or not window_inlier[row, slot, j]:
            n_dropped[row, j] += 1
            continue
        region = window_vertices[row, slot, j]
        n_base = base_counts[row, j]
        if n_base == 0:
            _copy_polygon(region, n_region, base_vertices[row, j])
            base_counts[row, j] = n_region
            continue
        n = clip_convex(base_vertices[row, j], n_base, region, n_region, first, work)
        if n > 0:
            _copy_polygon(first, n, base_vertices[row, j])
            base_counts[row, j] = n
        else:
            n_dropped[row, j] += 1  # kept by another of the relaxed set's pieces only
    window_counts[row, slot, :] = 0
    window_length[row] -= 1


@njit(**_JIT)
def _keeps_every_region(
    row: int, j: int, window_counts: np.ndarray, window_inlier: np.ndarray,
    window_rejected: np.ndarray, window_length: np.ndarray, window_next: np.ndarray,
) -> bool:
    """Whether landmark ``j``'s region leaves out none of its window regions (of movements
    not rejected): then it is the intersection of its base and all of them, and a new
    region is fused by one clip."""
    size = window_counts.shape[1]
    for age in range(window_length[row]):
        slot = (window_next[row] - window_length[row] + age) % size
        if (
            window_counts[row, slot, j] > 0
            and not window_rejected[row, slot]
            and not window_inlier[row, slot, j]
        ):
            return False
    return True


@njit(**_JIT)
def relaxed_movement(
    row: int, fresh_counts: np.ndarray, max_outliers: int, keep_on_inconsistency: bool,
    vertices: np.ndarray, counts: np.ndarray, areas: np.ndarray, centroids: np.ndarray,
    window_vertices: np.ndarray, window_counts: np.ndarray, window_inlier: np.ndarray,
    window_rejected: np.ndarray, window_length: np.ndarray, window_next: np.ndarray,
    base_vertices: np.ndarray, base_counts: np.ndarray, n_dropped: np.ndarray,
    outliers: np.ndarray, landmark_status: np.ndarray, i: int,
    first: np.ndarray, second: np.ndarray, work: np.ndarray, cloud: np.ndarray,
    hull: np.ndarray,
) -> bool:
    """Fuse the movement just written into window slot ``window_next[row] - 1`` (its
    regions' vertex counts are ``fresh_counts``; 0 where it has none) into map ``row``
    with the relaxed intersection; returns whether the movement was rejected.

    Landmark ``j``'s region is the convex hull of the points that lie in its base (the
    intersection of its inlier regions older than the window) and in all but at most
    ``q`` of its window regions, for the smallest ``q <= max_outliers`` that makes that
    set non-empty. While ``q`` is 0 the region is updated by one clip, as the strict
    intersection is. A movement is one vote across landmarks: when it is an outlier for
    more than half of the landmarks it has regions for (a misread L1 or L2 corrupts them
    all), it is rejected and left out for every landmark.
    """
    size = window_counts.shape[1]
    newest = (window_next[row] - 1) % size
    n_mapped = window_counts.shape[2]
    slots = np.empty(MAX_WINDOW, dtype=np.int64)
    acc = np.empty(SCRATCH, dtype=np.complex128)
    for j in range(n_mapped):
        n_new = fresh_counts[j]
        window_inlier[row, newest, j] = n_new > 0
        if n_new == 0:
            continue
        n_old = counts[row, j]
        if n_old > 0 and _keeps_every_region(
            row, j, window_counts, window_inlier, window_rejected, window_length, window_next
        ):
            n = clip_convex(
                vertices[row, j], n_old, window_vertices[row, newest, j], n_new, first, work
            )
            if n > 0:
                _copy_polygon(first, n, vertices[row, j])
                counts[row, j] = n
                areas[row, j], centroids[row, j] = area_centroid(vertices[row, j], n)
                continue
        _solve_landmark(
            row, j, max_outliers, keep_on_inconsistency, vertices, counts, areas, centroids,
            window_vertices, window_counts, window_inlier, window_rejected, window_length,
            window_next, base_vertices, base_counts, n_dropped, slots, acc, first,
            second, work, cloud, hull,
        )
    changed = True
    while changed:
        changed = False
        for age in range(window_length[row]):
            slot = (window_next[row] - window_length[row] + age) % size
            if window_rejected[row, slot]:
                continue
            regions = 0
            votes_out = 0
            for j in range(n_mapped):
                if window_counts[row, slot, j] > 0:
                    regions += 1
                    if not window_inlier[row, slot, j]:
                        votes_out += 1
            if 2 * votes_out <= regions:
                continue
            window_rejected[row, slot] = True
            changed = True
            for j in range(n_mapped):
                if window_counts[row, slot, j] > 0 and window_inlier[row, slot, j]:
                    _solve_landmark(
                        row, j, max_outliers, keep_on_inconsistency, vertices, counts,
                        areas, centroids, window_vertices, window_counts, window_inlier,
                        window_rejected, window_length, window_next, base_vertices,
                        base_counts, n_dropped, slots, acc, first, second, work, cloud,
                        hull,
                    )
    rejected = window_rejected[row, newest]
    for j in range(n_mapped):
        left_out = n_dropped[row, j]
        for age in range(window_length[row]):
            slot = (window_next[row] - window_length[row] + age) % size
            if window_counts[row, slot, j] > 0 and (
                window_rejected[row, slot] or not window_inlier[row, slot, j]
            ):
                left_out += 1
        outliers[row, j] = left_out
        if fresh_counts[j] > 0 and (rejected or not window_inlier[row, newest, j]):
            landmark_status[i, j] = LANDMARK_INCONSISTENT
    return rejected
