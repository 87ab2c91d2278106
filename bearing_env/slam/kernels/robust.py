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

The kernels are C++ (``csrc/slam/robust.cpp``); the constants are read from there.
"""

from __future__ import annotations

from bearing_env._core import (
    BOUND_GROWTH,
    HISTORY,
    MAX_BOUND,
    MAX_NOISE_SCALE,
    PRIOR_CONTRADICTIONS,
    PRIOR_REGIONS,
    PROBE_SHRINK,
    ROBUST_LEVELS,
    UNSEEN_FACTOR,
    binomial_q,
    update_levels,
)

__all__ = [
    "BOUND_GROWTH",
    "HISTORY",
    "MAX_BOUND",
    "MAX_NOISE_SCALE",
    "PRIOR_CONTRADICTIONS",
    "PRIOR_REGIONS",
    "PROBE_SHRINK",
    "ROBUST_LEVELS",
    "UNSEEN_FACTOR",
    "binomial_q",
    "update_levels",
]
