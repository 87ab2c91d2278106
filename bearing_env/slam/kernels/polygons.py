"""Convex polygons in fixed-capacity arrays: hulls, area, containment, distances,
simplification, capacity reduction, clipping and outward offsets.

A convex polygon is a complex vertex array in counter-clockwise order plus a vertex
count ``n``: only ``vertices[:n]`` is meaningful. ``n == 1`` or ``n == 2`` are
degenerate polygons (a point or a segment), which the robot-frame regions may be when
two cones only touch.

**Tolerances.** Geometric predicates compare signed distances against a tolerance that
is relative to the polygons' scale (their bounding-box size), plus a rounding term for
their distance from the origin, so that tiny regions are treated as finely as large ones.

**Capacity.** Polygons that would exceed :data:`CAPACITY` vertices (an intersection of
two full polygons, or a conservative hull of many sampled images) are reduced by
:func:`drop_edges_outward`: it repeatedly removes the edge whose removal adds the least
area, extending its two neighbouring edges until they meet. Removing an edge of a convex
polygon only ever grows it, so a reduced region still contains everything the exact
one does.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from bearing_env.slam.kernels.common import (
    _JIT,
    CAPACITY,
    SCRATCH,
    cross,
    dot,
    scale_of,
    tolerance_of,
)

# --------------------------------------------------------------------------------------
# Convex hulls
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def convex_hull(points: np.ndarray, n_points: int, out: np.ndarray) -> int:
    """Convex hull of ``points[:n_points]`` into ``out`` (CCW, no repeated or collinear
    vertices); returns its vertex count. ``out`` must hold ``n_points + 1`` points.

    Quickhull, which costs about n log h for h hull vertices: the conservative transfer's
    clouds have hundreds of points but a few dozen hull vertices. A chain from ``a`` to
    ``b`` owns the points strictly to the right of ``a -> b`` (outside the hull so far);
    its farthest point ``c`` is a hull vertex, and the chains ``a -> c`` and ``c -> b``
    own what lies right of them.

    Quickhull only filters: it decides sides with rounded cross products, so among
    nearly collinear points it can emit several, out of order (a zig-zag along one
    edge that no left-turn test can see, since it turns by 0 or 180 degrees). Those
    candidates are finished by :func:`small_convex_hull`, whose chains are monotone in
    x and so always make a simple polygon, dropping each point within the polygons'
    tolerance of its neighbours' chord.
    """
    if n_points == 0:
        return 0
    first = last = 0
    for i in range(1, n_points):
        p = points[i]
        lo, hi = points[first], points[last]
        if p.real < lo.real or (p.real == lo.real and p.imag < lo.imag):
            first = i
        if p.real > hi.real or (p.real == hi.real and p.imag > hi.imag):
            last = i
    a, b = points[first], points[last]
    out[0] = a
    if a == b:
        return 1
    # Candidate indices, the lower side (right of a -> b) first, then the upper side.
    index = np.empty(n_points, dtype=np.int64)
    n_lower = 0
    n_upper = 0
    for i in range(n_points):
        side = cross(b - a, points[i] - a)
        if side < 0.0:
            index[n_lower] = i
            n_lower += 1
    for i in range(n_points):
        side = cross(b - a, points[i] - a)
        if side > 0.0:
            index[n_lower + n_upper] = i
            n_upper += 1
    # A stack of tasks: hull the chain from point `chain_from` to `chain_to` over the
    # candidates index[start:end]; a task with start < 0 emits point `chain_from` instead.
    size = 2 * n_points + 4
    task_start = np.empty(size, dtype=np.int64)
    task_end = np.empty(size, dtype=np.int64)
    chain_from = np.empty(size, dtype=np.int64)
    chain_to = np.empty(size, dtype=np.int64)
    task_start[0], task_end[0], chain_from[0], chain_to[0] = n_lower, n_lower + n_upper, last, first
    task_start[1], chain_from[1] = -1, last
    task_start[2], task_end[2], chain_from[2], chain_to[2] = 0, n_lower, first, last
    top = 3
    k = np.int64(1)  # not 1: a literal start value compiles the small hull once more
    while top > 0:
        top -= 1
        start, end, i_from, i_to = task_start[top], task_end[top], chain_from[top], chain_to[top]
        if start < 0:
            out[k] = points[i_from]
            k += 1
            continue
        if end <= start:
            continue
        ax, ay = points[i_from].real, points[i_from].imag
        bx, by = points[i_to].real - ax, points[i_to].imag - ay
        far = start
        far_side = 0.0
        for j in range(start, end):
            p = points[index[j]]
            side = bx * (p.imag - ay) - by * (p.real - ax)
            if side < far_side:
                far_side = side
                far = j
        i_far = index[far]
        cx, cy = points[i_far].real, points[i_far].imag
        # Right of a -> c to the front, then right of c -> b; the rest is inside.
        ux, uy = cx - ax, cy - ay
        n_left = 0
        for j in range(start, end):
            p = points[index[j]]
            if ux * (p.imag - ay) - uy * (p.real - ax) < 0.0:
                index[start + n_left], index[j] = index[j], index[start + n_left]
                n_left += 1
        vx, vy = points[i_to].real - cx, points[i_to].imag - cy
        n_right = 0
        for j in range(start + n_left, end):
            p = points[index[j]]
            if vx * (p.imag - cy) - vy * (p.real - cx) < 0.0:
                slot = start + n_left + n_right
                index[slot], index[j] = index[j], index[slot]
                n_right += 1
        mid = start + n_left
        task_start[top], task_end[top], chain_from[top], chain_to[top] = (
            mid,
            mid + n_right,
            i_far,
            i_to,
        )
        task_start[top + 1], chain_from[top + 1] = -1, i_far
        task_start[top + 2], task_end[top + 2], chain_from[top + 2], chain_to[top + 2] = (
            start,
            mid,
            i_from,
            i_far,
        )
        top += 3
    candidates = out[:k].copy()
    extent, magnitude = scale_of(candidates, k)
    return small_convex_hull(candidates, k, out, tolerance_of(extent, magnitude))


@njit(**_JIT)
def small_convex_hull(points: np.ndarray, n_points: int, out: np.ndarray, tol: float) -> int:
    """:func:`convex_hull` for a few points (up to a few dozen), without its set-up:
    Andrew's monotone chain over an insertion sort, into ``out`` (``n_points + 1``).

    A point within ``tol`` of the chord from the previous hull vertex to the next
    candidate is dropped (``tol = 0`` drops exactly collinear points only). The lower
    chain runs left to right and the upper one back, each monotone in x, so the result
    is a simple polygon whatever the rounding, and with ``tol > 0`` each of its turns
    is a clear left turn.
    """
    chosen = np.empty(n_points + 1, dtype=np.int64)
    k = small_hull_indices(points, n_points, chosen, tol)
    for v in range(k):
        out[v] = points[chosen[v]]
    return k


@njit(**_JIT)
def small_hull_indices(points: np.ndarray, n_points: int, out: np.ndarray, tol: float) -> int:
    """:func:`small_convex_hull` as indices into ``points`` (``out`` holds ``n_points + 1``):
    for callers that need to know which inputs are hull vertices."""
    if n_points == 0:
        return 0
    order = np.empty(n_points, dtype=np.int64)
    for i in range(n_points):  # insertion sort by (x, y)
        p = points[i]
        j = i
        while j > 0:
            q = points[order[j - 1]]
            if q.real < p.real or (q.real == p.real and q.imag <= p.imag):
                break
            order[j] = order[j - 1]
            j -= 1
        order[j] = i
    k = 0
    for j in range(n_points):  # lower chain
        p = points[order[j]]
        while k >= 2 and _within_chord(points[out[k - 2]], points[out[k - 1]], p, tol):
            k -= 1
        out[k] = order[j]
        k += 1
    lower = k + 1
    for j in range(n_points - 2, -1, -1):  # upper chain
        p = points[order[j]]
        while k >= lower and _within_chord(points[out[k - 2]], points[out[k - 1]], p, tol):
            k -= 1
        out[k] = order[j]
        k += 1
    k -= 1  # the last point repeats the first
    if k == 2 and points[out[0]] == points[out[1]]:
        return 1
    return max(k, 1)


@njit(**_JIT)
def _within_chord(a: complex, b: complex, c: complex, tol: float) -> bool:
    """Whether ``b`` fails to turn left by more than ``tol`` on the way from ``a`` to ``c``:
    it lies right of the chord ``a -> c``, or within ``tol`` of it."""
    turn = cross(b - a, c - a)
    if tol == 0.0:  # skips a square root per test in the hulls of the hypotheses
        return turn <= 0.0
    return turn <= tol * abs(c - a)


# --------------------------------------------------------------------------------------
# Area, centroid, containment, distance
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def area_centroid(poly: np.ndarray, n: int) -> tuple[float, complex]:
    """Area and centroid of a convex polygon (the vertex mean if degenerate)."""
    origin = poly[0]
    twice_area = 0.0
    weighted = 0j
    for i in range(1, n - 1):
        a = poly[i] - origin
        b = poly[i + 1] - origin
        c = cross(a, b)
        twice_area += c
        weighted += (a + b) * c
    if twice_area > 0.0:
        return 0.5 * twice_area, origin + weighted / (3.0 * twice_area)
    mean = 0j
    for i in range(n):
        mean += poly[i]
    return 0.0, mean / n


@njit(**_JIT)
def contains_point(poly: np.ndarray, n: int, point: complex, relative: float) -> bool:
    """Whether ``point`` lies in the convex polygon, boundary included, to within
    ``relative`` times the polygon's size."""
    size, magnitude = scale_of(poly, n)
    tol = relative * size + 4e-16 * max(magnitude, abs(point))
    if n == 1:
        return abs(point - poly[0]) <= tol
    for i in range(n):
        a = poly[i]
        edge = poly[(i + 1) % n] - a
        length = abs(edge)
        if length == 0.0:
            continue
        if cross(edge, point - a) / length < -tol:
            return False
    if n == 2:  # a segment: also within its ends
        edge = poly[1] - poly[0]
        t = dot(point - poly[0], edge) / dot(edge, edge)
        length = abs(edge)
        return -tol / length <= t <= 1.0 + tol / length
    return True


@njit(**_JIT)
def _point_segment_distance(z: complex, a: complex, b: complex) -> float:
    d = b - a
    len2 = dot(d, d)
    if len2 == 0.0:
        return abs(z - a)
    t = min(max(dot(z - a, d) / len2, 0.0), 1.0)
    return abs(z - (a + t * d))


@njit(**_JIT)
def _separated(p: np.ndarray, n_p: int, q: np.ndarray, n_q: int, axis: complex) -> bool:
    lo_p = hi_p = dot(axis, p[0])
    for i in range(1, n_p):
        v = dot(axis, p[i])
        lo_p, hi_p = min(lo_p, v), max(hi_p, v)
    lo_q = hi_q = dot(axis, q[0])
    for i in range(1, n_q):
        v = dot(axis, q[i])
        lo_q, hi_q = min(lo_q, v), max(hi_q, v)
    return lo_q > hi_p or lo_p > hi_q


@njit(**_JIT)
def polygon_distance(p: np.ndarray, n_p: int, q: np.ndarray, n_q: int) -> float:
    """Distance between two small convex polygons; 0 if they touch or overlap.

    The separating-axis test decides whether they are disjoint: the edge normals, and
    the directions between vertices, which separate the degenerate polygons (points and
    segments) too. Disjoint polygons are at the smallest vertex-to-edge distance.
    """
    separated = False
    for i in range(n_p):
        if _separated(p, n_p, q, n_q, -1j * (p[(i + 1) % n_p] - p[i])):
            separated = True
            break
    if not separated:
        for i in range(n_q):
            if _separated(p, n_p, q, n_q, -1j * (q[(i + 1) % n_q] - q[i])):
                separated = True
                break
    if not separated:
        for i in range(n_p):
            for j in range(n_q):
                if _separated(p, n_p, q, n_q, q[j] - p[i]):
                    separated = True
                    break
            if separated:
                break
    if not separated:
        return 0.0
    gap = np.inf
    for i in range(n_p):
        for j in range(n_q):
            gap = min(gap, _point_segment_distance(p[i], q[j], q[(j + 1) % n_q]))
            gap = min(gap, _point_segment_distance(q[j], p[i], p[(i + 1) % n_p]))
    return gap


@njit(**_JIT)
def longest_edge(poly: np.ndarray, n: int) -> float:
    longest = 0.0
    for i in range(n):
        longest = max(longest, abs(poly[(i + 1) % n] - poly[i]))
    return longest


# --------------------------------------------------------------------------------------
# Cleaning, capacity and clipping
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def simplify(poly: np.ndarray, n: int, tol: float) -> int:
    """Drop repeated vertices and vertices within ``tol`` of the line of their
    neighbours, in place; returns the new count."""
    changed = True
    while changed and n >= 3:
        changed = False
        k = 0
        for i in range(n):
            prev = poly[k - 1] if k > 0 else poly[n - 1]
            nxt = poly[(i + 1) % n]
            v = poly[i]
            chord = nxt - prev
            length = abs(chord)
            if abs(v - prev) <= tol or (
                length > 0.0
                and abs(cross(chord, v - prev)) <= tol * length
                and dot(v - prev, chord) >= 0.0
                and dot(nxt - v, chord) >= 0.0
            ):
                changed = True
                continue
            poly[k] = v
            k += 1
        n = k
    if n == 2 and abs(poly[1] - poly[0]) <= tol:
        n = 1
    return n


@njit(**_JIT)
def drop_edges_outward(poly: np.ndarray, n: int, capacity: int) -> int:
    """Reduce a convex polygon to at most ``capacity`` vertices by removing edges.

    Removing edge ``i`` (from vertex i to i+1) replaces its two vertices by the meeting
    point of the lines of edges i-1 and i+1: the polygon can only grow. The edge whose
    removal adds the least area goes first; an edge whose neighbours do not meet on its
    outer side cannot be removed.
    """
    while n > capacity:
        best = -1
        best_area = np.inf
        best_point = 0j
        for i in range(n):
            a = poly[(i - 1) % n]
            b = poly[i]
            c = poly[(i + 1) % n]
            d = poly[(i + 2) % n]
            u = b - a
            w = d - c
            denom = cross(u, w)
            if not denom > 0.0:  # the neighbouring edges turn by half a circle or more
                continue
            t = cross(c - b, w) / denom
            meet = b + t * u
            added = 0.5 * abs(cross(c - b, meet - b))
            if added < best_area:
                best, best_area, best_point = i, added, meet
        if best < 0:
            break
        poly[best] = best_point
        for j in range(best + 1, n - 1):
            poly[j] = poly[j + 1]
        if best == n - 1:  # the removed edge wrapped around: its second vertex was poly[0]
            for j in range(n - 1):
                poly[j] = poly[j + 1]
        n -= 1
    return n


@njit(**_JIT)
def clip_convex(
    subject: np.ndarray,
    n_subject: int,
    clipper: np.ndarray,
    n_clipper: int,
    out: np.ndarray,
    work: np.ndarray,
) -> int:
    """Intersection of two convex polygons (CCW) into ``out``; returns its vertex count,
    0 when the intersection is empty or has no area (the regions only touch).

    Sutherland-Hodgman against each edge of ``clipper``. A vertex within the tolerance
    of a clipping line counts as on it, so shared vertices and collinear or overlapping
    edges create no spurious slivers. ``out`` and ``work`` must hold :data:`SCRATCH`
    points; the result is reduced to :data:`CAPACITY` vertices (only ever outward).
    """
    size_s, mag_s = scale_of(subject, n_subject)
    size_c, mag_c = scale_of(clipper, n_clipper)
    size = min(size_s, size_c)
    tol = tolerance_of(size, max(mag_s, mag_c))
    for i in range(n_subject):
        out[i] = subject[i]
    n = n_subject
    in_out = True  # whether the current polygon is in ``out`` (else in ``work``)
    distances = np.empty(SCRATCH)
    for e in range(n_clipper):
        a = clipper[e]
        edge = clipper[(e + 1) % n_clipper] - a
        length = abs(edge)
        if length == 0.0:
            continue
        current = out if in_out else work
        other = work if in_out else out
        all_in = True
        any_in = False
        for i in range(n):
            d = cross(edge, current[i] - a) / length
            distances[i] = d
            if d < -tol:
                all_in = False
            else:
                any_in = True
        if all_in:
            continue
        if not any_in:
            return 0
        k = 0
        for i in range(n):
            j = (i + 1) % n
            di, dj = distances[i], distances[j]
            if di >= -tol:
                other[k] = current[i]
                k += 1
                if dj < -tol and di > tol:
                    other[k] = current[i] + (di / (di - dj)) * (current[j] - current[i])
                    k += 1
            elif dj > tol:
                other[k] = current[i] + (di / (di - dj)) * (current[j] - current[i])
                k += 1
        in_out = not in_out
        n = k
        if n == 0:
            return 0
    if not in_out:
        for i in range(n):
            out[i] = work[i]
    n = simplify(out, n, tol)
    if n < 3:
        return 0
    area, _ = area_centroid(out, n)
    if not area > tol * size:
        return 0
    return drop_edges_outward(out, n, CAPACITY)


# --------------------------------------------------------------------------------------
# Growing a polygon outward
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def offset_outward(poly: np.ndarray, n: int, radius: float, out: np.ndarray) -> int:
    """Every edge of a convex polygon (CCW, n >= 3) moved outward by ``radius``.

    Neighbouring edges meet at their mitre point where they turn by at most 90 degrees;
    a sharper corner is cut by a third line at distance ``radius`` from the vertex
    (normal to the corner's bisector). Every line is a supporting line of the polygon
    moved out by ``radius``, so the result contains every point within ``radius`` of the
    polygon. ``out`` must hold ``n + 3`` points (a convex polygon has at most three
    corners sharper than 90 degrees). A point or a segment (``n`` of 1 or 2) becomes
    the rectangle of the points within ``radius`` of it, grown along it too.
    """
    if n <= 2:
        along = poly[n - 1] - poly[0]
        tangent = along / abs(along) if abs(along) > 0.0 else 1.0 + 0j
        normal = -1j * tangent
        start = poly[0] - radius * tangent
        end = poly[n - 1] + radius * tangent
        out[0] = start + radius * normal
        out[1] = end + radius * normal
        out[2] = end - radius * normal
        out[3] = start - radius * normal
        return 4
    k = 0
    for i in range(n):
        prev_edge = poly[i] - poly[(i - 1) % n]
        next_edge = poly[(i + 1) % n] - poly[i]
        t_in = prev_edge / abs(prev_edge)
        t_out = next_edge / abs(next_edge)
        n_in = -1j * t_in  # outward normals (CCW polygon)
        n_out = -1j * t_out
        cos_turn = dot(n_in, n_out)
        if cos_turn >= 0.0:
            out[k] = poly[i] + radius * (n_in + n_out) / (1.0 + cos_turn)
            k += 1
        else:
            # tan(turn / 4) from the half-angle formulas, turn in (90, 180) degrees.
            half_cos = math.sqrt(max(0.0, 0.5 * (1.0 + cos_turn)))
            half_sin = math.sqrt(max(0.0, 0.5 * (1.0 - cos_turn)))
            quarter_tan = half_sin / (1.0 + half_cos)
            out[k] = poly[i] + radius * (n_in + quarter_tan * t_in)
            out[k + 1] = poly[i] + radius * (n_out - quarter_tan * t_out)
            k += 2
    return k
