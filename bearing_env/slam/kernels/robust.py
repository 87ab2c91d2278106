"""The robust fusion (``fusion="robust"``): nested relaxed sets over a landmark's whole
history, and how many regions to leave out from a risk target.

Landmark ``j`` of a map keeps ``ROBUST_LEVELS`` convex polygons ``X(0), ..., X(Q)``:
``X(k)`` holds every point that lies in all but at most ``k`` of the landmark's regions
so far (the q-relaxed intersection with q = k), as its convex hull. A new region ``C``
updates them from the top down, each by one clip and one hull:

    X(k) <- hull((X(k) ∩ C) ∪ X(k - 1)),    X(0) <- X(0) ∩ C,

since a point missing ``C`` must miss at most ``k - 1`` of the earlier regions. Each
level only grows by the hull, so it stays a superset of the exact relaxed set: nothing
is re-intersected from scratch, and no window is needed. ``X(0)`` is the strict
intersection, computed by the same clip as ``fusion="intersect"``.

The reported region is a level chosen per landmark after each movement:

* ``k_min``, the smallest non-empty level, is the fewest regions that must be left out
  (the contradictions seen): the *likely* set (``robust_set="likely"``);
* ``q``, the smallest level whose binomial tail ``P(Bin(n, p) > q)`` over the
  landmark's ``n`` regions is below ``risk``, for ``p`` the map's contamination rate
  estimated from its contradictions (:func:`contamination`): the *guaranteed* set
  ``X(max(q, k_min))`` (``robust_set="guaranteed"``, the default).

With no contradiction the estimated rate stays at its prior, far below what makes
``q > 0`` for the risk, so on clean data the reported region is ``X(0)``: the strict
intersection bit for bit.

**The noise bound** (``Params.estimate_bound``). A bound that is too small on every
reading rarely empties an intersection: the regions still overlap, just not around the
truth. Measured on the Khepera field with a true bound of 3 degrees at epsilon = 2, only
5 of the 27 random-policy episodes that lost a landmark had any contradiction. So each
map also fuses a *probe*: the strict intersection of its regions derived at
``PROBE_SHRINK`` times the bound in use, which keeps its region when a movement
contradicts it. Replaying logged episodes, the smallest bound at which the strict
intersection contradicts nothing was 0.50-0.75 epsilon (5th-95th percentile) on clean
data, against 0.70-1.05 epsilon with the 3-degree bound: a probe at 0.8 epsilon rarely
contradicts clean data and often contradicts data whose bound is 1.5 epsilon.

A probe contradiction where the landmark's own region was fused consistently is
evidence that the bound is too small (an outlier far off contradicts both). Then the map
multiplies its bound by ``BOUND_GROWTH`` (up to ``MAX_NOISE_SCALE`` times epsilon) and
rebuilds its regions, levels and probe from the bearings of its last ``HISTORY``
movements at the new bound. Each such event also counts as one contradiction in the
contamination rate: it may as well be an outlier that overlaps the truth's region only
partly. On clean data the probe that rarely contradicts leaves the map as without it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from bearing_env.slam.kernels.common import _JIT
from bearing_env.slam.kernels.frames import FrameChange, transfer_region
from bearing_env.slam.kernels.fusion import _copy_polygon, _merge_hull
from bearing_env.slam.kernels.polygons import area_centroid, clip_convex
from bearing_env.slam.kernels.state import Params, Scratch, State

#: Levels X(0..6) per landmark: at most 6 regions are left out.
ROBUST_LEVELS = 7
#: The contamination prior: PRIOR_CONTRADICTIONS contradictions in PRIOR_REGIONS
#: regions. Its rate must stay far below risk / n so that clean data keep q = 0.
PRIOR_CONTRADICTIONS = 0.001
PRIOR_REGIONS = 10.0
#: Contaminated regions per contradiction seen: a contaminated region that still
#: overlaps the others is not seen as a contradiction. A chosen value, not a measured
#: one; ``risk`` moves the same trade-off (the robustness figure shows 0.05 and 0.2).
UNSEEN_FACTOR = 2.0
#: The probe's bound, as a share of the bound in use (see the module doc).
PROBE_SHRINK = 0.8
#: The factor a map's bound grows by on each piece of evidence that it is too small.
BOUND_GROWTH = 1.1
#: The largest bound a map grows to, over the nominal epsilon.
MAX_NOISE_SCALE = 4.0
#: The largest bound a map grows to, radians: a wider cone bounds almost nothing.
MAX_BOUND = 0.25 * math.pi
#: Movements whose bearings each map keeps, to rebuild its regions at a new bound.
HISTORY = 16


@njit(**_JIT)
def binomial_q(n: int, p: float, risk: float, q_cap: int) -> int:
    """The smallest ``q`` (at most ``q_cap``) with ``P(Bin(n, p) > q) < risk``."""
    if p <= 0.0 or n <= 0:
        return 0
    p = min(p, 0.999)
    term = (1.0 - p) ** n  # P(X = 0)
    below = term  # P(X <= q)
    q = 0
    while q < q_cap and 1.0 - below >= risk:
        term *= (n - q) / (q + 1.0) * p / (1.0 - p)
        q += 1
        below += term
    return q


@njit(**_JIT)
def contamination(state: State, row: int) -> float:
    """Map ``row``'s estimated share of contaminated regions: its contradictions (the
    regions each landmark must leave out, and the probe's evidence) over its regions,
    with the prior, times :data:`UNSEEN_FACTOR`."""
    contradictions = PRIOR_CONTRADICTIONS + bound_growths(state, row)
    regions = PRIOR_REGIONS
    for j in range(state.n_regions.shape[1]):
        contradictions += state.outliers[row, j]
        regions += state.n_regions[row, j]
    return UNSEEN_FACTOR * contradictions / regions


@njit(**_JIT)
def update_levels(state: State, row: int, j: int, n_new: int, scratch: Scratch) -> None:
    """Fuse the new region ``scratch.fresh[:n_new]`` into landmark ``j``'s levels."""
    levels, counts = state.level_vertices[row, j], state.level_counts[row, j]
    fresh, fused = scratch.fresh, scratch.fused
    seen = state.n_regions[row, j]
    # Level ``seen`` (if kept) was the whole plane: its clip is the new region itself.
    for k in range(min(seen, counts.shape[0] - 1), -1, -1):
        if k == seen:
            _copy_polygon(fresh, n_new, levels[k])
            n = n_new
        elif counts[k] > 0:
            n = clip_convex(levels[k], counts[k], fresh, n_new, fused, scratch.work)
            _copy_polygon(fused, n, levels[k])
        else:
            n = 0
        if k > 0 and counts[k - 1] > 0:
            if n == 0:
                n = counts[k - 1]
                _copy_polygon(levels[k - 1], n, levels[k])
            else:
                n = _merge_hull(
                    levels[k], n, levels[k - 1], counts[k - 1], scratch.cloud, scratch.hull
                )
        counts[k] = n
    state.n_regions[row, j] = seen + 1


@njit(**_JIT)
def robust_landmark(
    state: State,
    row: int,
    j: int,
    n_new: int,
    rate: float,
    params: Params,
    scratch: Scratch,
) -> bool:
    """Fuse the new region ``scratch.fresh[:n_new]`` into landmark ``j`` of map ``row``
    (see the module doc; ``rate`` is the map's :func:`contamination` before this
    movement); returns False when it contradicts the landmark's regions (``k_min``
    grows), as the strict intersection does when it misses."""
    counts = state.level_counts[row, j]
    before = state.outliers[row, j]
    update_levels(state, row, j, n_new, scratch)
    seen = state.n_regions[row, j]
    top = min(seen, counts.shape[0]) - 1
    k_min = 0
    while k_min <= top and counts[k_min] == 0:
        k_min += 1
    consistent = k_min <= before
    if k_min > top:
        # More contradictions than levels: restart from the new region alone.
        _copy_polygon(scratch.fresh, n_new, state.level_vertices[row, j, 0])
        counts[:] = 0
        counts[0] = n_new
        state.n_regions[row, j] = 1
        k_min = 0
        top = 0
    state.outliers[row, j] = k_min
    level = k_min
    if not params.likely:
        level = max(level, binomial_q(seen, rate, params.risk, top))
    n = counts[level]
    _copy_polygon(state.level_vertices[row, j, level], n, state.vertices[row, j])
    state.counts[row, j] = n
    state.areas[row, j], state.centroids[row, j] = area_centroid(state.vertices[row, j], n)
    return consistent


@njit(**_JIT)
def frame_contradicts_robot(state: State, row: int, frame: FrameChange, scratch: Scratch) -> bool:
    """Whether the movement's start R1 (the FR origin), seen through its change of
    frames, misses the map's robot region, which is where the previous movement ended:
    the robot did not jump, so one of the two frames is wrong, and since a wrong frame
    (a misread L1 or L2) would have been caught at the previous movement, it is this
    one. False when the robot's region is unknown or older than the previous movement
    (whose frame could not be changed, or which was simulated without the robot)."""
    n_robot = state.robot_counts[row]
    if n_robot == 0 or state.robot_fixed_at[row] != state.n_updates[row] - 1:
        return False
    origin = np.zeros(1, dtype=np.complex128)
    # origin.size, not 1: a literal argument compiles one more specialisation.
    n_start = transfer_region(
        origin, origin.size, frame, scratch.cloud, scratch.hull, scratch.fresh
    )
    if n_start < 3:
        return False
    n = clip_convex(
        state.robot_vertices[row], n_robot, scratch.fresh, n_start, scratch.fused, scratch.work
    )
    return n == 0


@njit(**_JIT)
def probe_landmark(state: State, row: int, j: int, n_new: int, scratch: Scratch) -> bool:
    """Intersect the probe's new region ``scratch.fresh[:n_new]`` into its region of
    landmark ``j``; returns False when they miss each other, and then keeps the old one."""
    counts = state.probe_counts[row]
    n = n_new
    source = scratch.fresh
    if counts[j] > 0:
        n = clip_convex(
            state.probe_vertices[row, j],
            counts[j],
            scratch.fresh,
            n_new,
            scratch.fused,
            scratch.work,
        )
        if n == 0:
            return False
        source = scratch.fused
    _copy_polygon(source, n, state.probe_vertices[row, j])
    counts[j] = n
    return True


@njit(**_JIT)
def bound_growths(state: State, row: int) -> int:
    """How many times map ``row``'s bound has grown."""
    return round(math.log(state.noise_scale[row]) / math.log(BOUND_GROWTH))


@njit(**_JIT)
def grow_bound(state: State, row: int, epsilon: float) -> bool:
    """Grow map ``row``'s bound by :data:`BOUND_GROWTH` when its probe's evidence
    (``bound_events``) reaches half its mapped landmarks (at least one) per growth, unless
    that passes :data:`MAX_NOISE_SCALE` times ``epsilon`` (the nominal bound) or
    ``MAX_BOUND``; returns whether it grew."""
    per_growth = max(1, (state.counts.shape[1] + 1) // 2)
    if state.bound_events[row] < per_growth * (bound_growths(state, row) + 1):
        return False
    scale = state.noise_scale[row] * BOUND_GROWTH
    if scale > MAX_NOISE_SCALE * (1.0 + 1e-9) or scale * epsilon >= MAX_BOUND:
        return False
    state.noise_scale[row] = scale
    return True


@njit(**_JIT)
def push_history(state: State, row: int, start: np.ndarray, end: np.ndarray) -> None:
    """Keep one movement's bearings (``start`` at R1, ``end`` at R2, every landmark) in
    map ``row``'s history, dropping the oldest when it is full."""
    slot = state.history_next[row]
    frame, landmarks = state.history_frame_bearings[row, slot], state.history_bearings[row, slot]
    for j in range(2):
        frame[0, j], frame[1, j] = start[j], end[j]
    for j in range(landmarks.shape[1]):
        landmarks[0, j], landmarks[1, j] = start[j + 2], end[j + 2]
    size = state.history_bearings.shape[1]
    state.history_next[row] = (slot + 1) % size
    state.history_length[row] = min(size, state.history_length[row] + 1)


@njit(**_JIT)
def history_movement(state: State, row: int, k: int, start: np.ndarray, end: np.ndarray) -> None:
    """The bearings of map ``row``'s ``k``-th oldest kept movement, into ``start`` and
    ``end``."""
    size = state.history_bearings.shape[1]
    slot = (state.history_next[row] - state.history_length[row] + k) % size
    frame, landmarks = state.history_frame_bearings[row, slot], state.history_bearings[row, slot]
    for j in range(2):
        start[j], end[j] = frame[0, j], frame[1, j]
    for j in range(landmarks.shape[1]):
        start[j + 2], end[j + 2] = landmarks[0, j], landmarks[1, j]


@njit(**_JIT)
def forget_regions(state: State, row: int) -> None:
    """Clear map ``row``'s regions, levels, probe and robot region (not its counters,
    history or bound): what a rebuild at a new bound starts from."""
    state.counts[row] = 0
    state.areas[row] = np.inf
    state.centroids[row] = complex(np.nan, np.nan)
    state.robot_counts[row] = 0
    state.robot_area[row] = np.inf
    state.robot_centroid[row] = complex(np.nan, np.nan)
    state.robot_heading[row] = np.nan
    state.outliers[row] = 0
    state.level_counts[row] = 0
    state.n_regions[row] = 0
    state.probe_counts[row] = 0
