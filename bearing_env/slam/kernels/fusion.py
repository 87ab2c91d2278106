"""Fusing one movement's region of a landmark into a map: the strict intersection
(:func:`intersect_landmark`) and the relaxed fusion's window and bases
(:func:`relaxed_movement`).

Both work on a map's :class:`~bearing_env.slam.kernels.state.StateRef` in place, in the
buffers of a :class:`~bearing_env.slam.kernels.state.Scratch`: the movement's new region
arrives in ``scratch.fresh``, and the relaxed fusion uses ``fused`` and ``fresh`` as its
two intersection buffers (the new regions are in the window by then).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from bearing_env.slam.kernels.common import (
    _JIT,
    CAPACITY,
    LANDMARK_INCONSISTENT,
    MAX_WINDOW,
)
from bearing_env.slam.kernels.polygons import (
    area_centroid,
    clip_convex,
    convex_hull,
    drop_edges_outward,
)
from bearing_env.slam.kernels.state import (
    INCONSISTENCY_KEEP,
    Outputs,
    Params,
    Scratch,
    State,
)


@njit(**_JIT)
def _copy_polygon(source: np.ndarray, n: int, out: np.ndarray) -> None:
    for v in range(n):
        out[v] = source[v]


# --------------------------------------------------------------------------------------
# The strict intersection (the paper's fusion)
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def intersect_landmark(
    state: State, row: int, j: int, n_new: int, keep: bool, scratch: Scratch
) -> bool:
    """Intersect the new region ``scratch.fresh[:n_new]`` into landmark ``j``'s region of
    map ``row``; returns False when they miss each other (the observations contradict
    epsilon). Then the region is left as it was if ``keep``, else restarted from the new
    region."""
    vertices, counts = state.vertices, state.counts
    fresh = scratch.fresh
    n_old = counts[row, j]
    source = fresh
    n_result = n_new
    consistent = True
    if n_old > 0:
        n_result = clip_convex(vertices[row, j], n_old, fresh, n_new, scratch.fused, scratch.work)
        if n_result > 0:
            source = scratch.fused
        else:
            consistent = False
            if keep:
                return consistent
            n_result = n_new
    for v in range(n_result):
        vertices[row, j, v] = source[v]
    counts[row, j] = n_result
    area, centroid = area_centroid(vertices[row, j], n_result)
    state.areas[row, j] = area
    state.centroids[row, j] = centroid
    return consistent


# --------------------------------------------------------------------------------------
# Relaxed fusion: the q-relaxed intersection over a window of movements
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def _merge_hull(
    acc: np.ndarray,
    n_acc: int,
    poly: np.ndarray,
    n_poly: int,
    cloud: np.ndarray,
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
def _window_slots(state: State, row: int, j: int, out: np.ndarray) -> int:
    """The window slots (oldest first) that hold a region of landmark ``j`` from a
    movement that was not rejected; returns how many."""
    window_counts, window_rejected = state.window_counts, state.window_rejected
    length, next_slot = state.window_length[row], state.window_next[row]
    size = window_counts.shape[1]
    k = 0
    for age in range(length):
        slot = (next_slot - length + age) % size
        if window_counts[row, slot, j] > 0 and not window_rejected[row, slot]:
            out[k] = slot
            k += 1
    return k


@njit(**_JIT)
def _intersect_kept(
    state: State,
    row: int,
    j: int,
    k: int,
    discarded: np.ndarray,
    use_base: bool,
    scratch: Scratch,
) -> tuple[int, bool]:
    """The intersection of the base (if used) and the kept regions of
    ``scratch.slots[:k]``.

    Returns ``(n, in_first)``: its vertex count (0 if empty) and whether it is in
    ``scratch.fused`` (else in ``scratch.fresh``).
    """
    window_vertices, window_counts = state.window_vertices, state.window_counts
    slots, first, second, work = scratch.slots, scratch.fused, scratch.fresh, scratch.work
    n = 0
    started = False
    in_first = True
    if use_base:
        n = state.base_counts[row, j]
        _copy_polygon(state.base_vertices[row, j], n, first)
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
    state: State, row: int, j: int, k: int, use_base: bool, q: int, scratch: Scratch
) -> int:
    """The hull of the union, over every choice of ``q`` of ``scratch.slots[:k]`` to
    leave out, of the intersection of the base (if used) and the other regions, into
    ``scratch.acc``; returns its vertex count (0: every such intersection is empty).
    Each region kept by a non-empty intersection is marked an inlier."""
    window_inlier, slots, acc = state.window_inlier, scratch.slots, scratch.acc
    discarded = np.zeros(MAX_WINDOW, dtype=np.bool_)
    combination = np.empty(MAX_WINDOW, dtype=np.int64)
    # np.int64(0), not 0: numba compiles calls it types before the loop widens a literal
    # start value, so a literal 0 would compile _merge_hull once more.
    n_acc = np.int64(0)
    for t in range(q):
        combination[t] = t
    while True:
        for t in range(k):
            discarded[t] = False
        for t in range(q):
            discarded[combination[t]] = True
        n, in_first = _intersect_kept(state, row, j, k, discarded, use_base, scratch)
        if n > 0:
            piece = scratch.fused if in_first else scratch.fresh
            if n_acc == 0:
                _copy_polygon(piece, n, acc)
                n_acc = n
            else:
                n_acc = _merge_hull(acc, n_acc, piece, n, scratch.cloud, scratch.hull)
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
    state: State,
    row: int,
    j: int,
    k: int,
    use_base: bool,
    max_outliers: int,
    scratch: Scratch,
) -> tuple[int, int]:
    """The hull of the q-relaxed intersection of the base and the window slots
    ``scratch.slots[:k]`` into ``scratch.acc``, for ``q`` the smallest number of
    left-out regions that makes it non-empty (at most ``max_outliers``; the base is
    never left out).

    No margin is added to ``q``: one more left-out region grew the median clean region
    by half while gaining little containment (measured; see docs/design.md).

    Returns ``(n, q)``: the vertex count (0 if no ``q`` up to the cap works) and ``q``.
    """
    # Without a base, at least one region must be kept.
    q_max = min(max_outliers, k if use_base else k - 1)
    for q in range(q_max + 1):
        n = _relaxed_union(state, row, j, k, use_base, q, scratch)
        if n > 0:
            return n, q
    return 0, q_max


@njit(**_JIT)
def _solve_landmark(state: State, row: int, j: int, params: Params, scratch: Scratch) -> None:
    """Landmark ``j``'s region from its base and window, from scratch (see
    :func:`relaxed_movement`)."""
    window_inlier, base_counts, slots = state.window_inlier, state.base_counts, scratch.slots
    vertices, counts, acc = state.vertices, state.counts, scratch.acc
    k = _window_slots(state, row, j, slots)
    for t in range(k):
        window_inlier[row, slots[t], j] = False
    use_base = base_counts[row, j] > 0
    n = 0
    if k > 0 or use_base:
        n, _ = relaxed_region(state, row, j, k, use_base, params.max_outliers, scratch)
        if n == 0 and use_base:
            # The base (everything older than the window) contradicts the window beyond
            # the cap: it is dropped.
            base_counts[row, j] = 0
            state.n_dropped[row, j] += 1
            # Not a literal False: a literal argument would compile the relaxed
            # region (and what it calls) a second time.
            no_base = bool(np.bool_(False))
            n, _ = relaxed_region(state, row, j, k, no_base, params.max_outliers, scratch)
    if n == 0 and k > 0:
        # More than max_outliers regions disagree: as the strict intersection does, keep
        # the old region, or restart from the newest movement's region alone.
        newest = slots[k - 1]
        if params.on_inconsistency == INCONSISTENCY_KEEP and counts[row, j] > 0:
            return  # every window region is left out, so the next update solves again
        n = state.window_counts[row, newest, j]
        _copy_polygon(state.window_vertices[row, newest, j], n, acc)
        window_inlier[row, newest, j] = True
    _copy_polygon(acc, n, vertices[row, j])
    counts[row, j] = n
    if n > 0:
        state.areas[row, j], state.centroids[row, j] = area_centroid(vertices[row, j], n)
    else:
        state.areas[row, j], state.centroids[row, j] = np.inf, complex(np.nan, np.nan)


@njit(**_JIT)
def age_out_oldest(state: State, row: int, scratch: Scratch) -> None:
    """Fold the oldest movement of a full window into the bases: each inlier region is
    intersected into its landmark's base for good, each outlier dropped for good."""
    window_counts, window_inlier = state.window_counts, state.window_inlier
    base_vertices, base_counts, n_dropped = state.base_vertices, state.base_counts, state.n_dropped
    size = window_counts.shape[1]
    slot = (state.window_next[row] - state.window_length[row]) % size
    for j in range(window_counts.shape[2]):
        n_region = window_counts[row, slot, j]
        if n_region == 0:
            continue
        if state.window_rejected[row, slot] or not window_inlier[row, slot, j]:
            n_dropped[row, j] += 1
            continue
        region = state.window_vertices[row, slot, j]
        n_base = base_counts[row, j]
        if n_base == 0:
            _copy_polygon(region, n_region, base_vertices[row, j])
            base_counts[row, j] = n_region
            continue
        n = clip_convex(
            base_vertices[row, j], n_base, region, n_region, scratch.fused, scratch.work
        )
        if n > 0:
            _copy_polygon(scratch.fused, n, base_vertices[row, j])
            base_counts[row, j] = n
        else:
            n_dropped[row, j] += 1  # kept by another of the relaxed set's pieces only
    window_counts[row, slot, :] = 0
    state.window_length[row] -= 1


@njit(**_JIT)
def _keeps_every_region(state: State, row: int, j: int) -> bool:
    """Whether landmark ``j``'s region leaves out none of its window regions (of movements
    not rejected): then it is the intersection of its base and all of them, and a new
    region is fused by one clip."""
    window_counts, window_inlier = state.window_counts, state.window_inlier
    window_rejected = state.window_rejected
    length, next_slot = state.window_length[row], state.window_next[row]
    size = window_counts.shape[1]
    for age in range(length):
        slot = (next_slot - length + age) % size
        if (
            window_counts[row, slot, j] > 0
            and not window_rejected[row, slot]
            and not window_inlier[row, slot, j]
        ):
            return False
    return True


@njit(**_JIT)
def _reject_outlier_movements(state: State, row: int, params: Params, scratch: Scratch) -> None:
    """Reject every window movement that is an outlier for more than half of the
    landmarks it has regions for, and solve again the landmarks it was kept by; repeat
    until no more are rejected (a rejection can make another movement an outlier)."""
    window_counts, window_inlier = state.window_counts, state.window_inlier
    window_rejected = state.window_rejected
    size = window_counts.shape[1]
    n_mapped = window_counts.shape[2]
    changed = True
    while changed:
        changed = False
        for age in range(state.window_length[row]):
            slot = (state.window_next[row] - state.window_length[row] + age) % size
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
                    _solve_landmark(state, row, j, params, scratch)


@njit(**_JIT)
def relaxed_movement(
    state: State,
    row: int,
    fresh_counts: np.ndarray,
    params: Params,
    out: Outputs,
    i: int,
    scratch: Scratch,
) -> bool:
    """Fuse the movement just written into window slot ``window_next[row] - 1`` (its
    regions' vertex counts are ``fresh_counts``; 0 where it has none) into map ``row``
    with the relaxed intersection, marking its inconsistent landmarks in
    ``out.landmark_status[i]``; returns whether the movement was rejected.

    Landmark ``j``'s region is the convex hull of the points that lie in its base (the
    intersection of its inlier regions older than the window) and in all but at most
    ``q`` of its window regions, for the smallest ``q <= max_outliers`` that makes that
    set non-empty. While ``q`` is 0 the region is updated by one clip, as the strict
    intersection is. A movement is one vote across landmarks: when it is an outlier for
    more than half of the landmarks it has regions for (a misread L1 or L2 corrupts them
    all), it is rejected and left out for every landmark.
    """
    vertices, counts = state.vertices, state.counts
    window_counts, window_inlier = state.window_counts, state.window_inlier
    window_rejected = state.window_rejected
    size = window_counts.shape[1]
    newest = (state.window_next[row] - 1) % size
    n_mapped = window_counts.shape[2]
    for j in range(n_mapped):
        n_new = fresh_counts[j]
        window_inlier[row, newest, j] = n_new > 0
        if n_new == 0:
            continue
        n_old = counts[row, j]
        if n_old > 0 and _keeps_every_region(state, row, j):
            n = clip_convex(
                vertices[row, j],
                n_old,
                state.window_vertices[row, newest, j],
                n_new,
                scratch.fused,
                scratch.work,
            )
            if n > 0:
                _copy_polygon(scratch.fused, n, vertices[row, j])
                counts[row, j] = n
                state.areas[row, j], state.centroids[row, j] = area_centroid(vertices[row, j], n)
                continue
        _solve_landmark(state, row, j, params, scratch)
    _reject_outlier_movements(state, row, params, scratch)
    rejected = window_rejected[row, newest]
    length, next_slot = state.window_length[row], state.window_next[row]
    for j in range(n_mapped):
        left_out = state.n_dropped[row, j]
        for age in range(length):
            slot = (next_slot - length + age) % size
            if window_counts[row, slot, j] > 0 and (
                window_rejected[row, slot] or not window_inlier[row, slot, j]
            ):
                left_out += 1
        state.outliers[row, j] = left_out
        if fresh_counts[j] > 0 and (rejected or not window_inlier[row, newest, j]):
            out.landmark_status[i, j] = LANDMARK_INCONSISTENT
    return rejected
