"""The compiled core of the world model: exact convex polygons in fixed-capacity arrays.

Every kernel here is compiled by numba (``cache=True``: the machine code is kept beside
this file, or in numba's user-wide cache directory when the package folder is read-only,
or in ``NUMBA_CACHE_DIR`` when that is set). Points are complex numbers (x + iy).

A convex polygon is a complex vertex array in counter-clockwise order plus a vertex
count ``n``: only ``vertices[:n]`` is meaningful. The map's regions live in arrays of
:data:`CAPACITY` vertices. ``n == 1`` or ``n == 2`` are degenerate polygons (a point or a
segment), which the robot-frame regions may be when two cones only touch.

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
import os
from typing import Literal, TypedDict

import numba
import numpy as np
from numba import njit

#: Most vertices a map region holds (conservative hulls measured up to 107).
CAPACITY = 128
#: Most samples per edge of A_L1 and A_L2 the conservative transfer uses.
MAX_EDGE_SAMPLES = 8
#: Vertices of a robot-frame region: the intersection of two cones has at most four.
FR_VERTICES = 4
#: Most hypotheses per region: (4 edges x MAX_EDGE_SAMPLES samples) per region of L1, L2.
MAX_SAMPLES = FR_VERTICES * MAX_EDGE_SAMPLES
MAX_PAIRS = MAX_SAMPLES * MAX_SAMPLES
#: Room for a polygon before it is reduced to CAPACITY (clipping two CAPACITY-gons gives at
#: most 2 * CAPACITY vertices; offsetting adds at most 3 bevels).
SCRATCH = 2 * CAPACITY + 8
#: Largest point cloud: a robot-frame region's vertices under every hypothesis pair.
MAX_CLOUD = FR_VERTICES * MAX_PAIRS

#: FR-region vertices farther than this (in FR units, |R1 R2| = 1) mean near-parallel
#: cones: the region is numerically unbounded and carries no usable information.
MAX_FR_EXTENT = 1e4

#: Relative tolerance of the polygon predicates (times the polygons' scale).
RELATIVE_TOLERANCE = 1e-12

FR_BOUNDED = 0
FR_UNBOUNDED = 1
FR_EMPTY = 2
FR_MISSING = 3

#: Frame-change codes (indices into batch.FRAME_STATUSES).
FRAME_OK = 0
FRAME_L1_UNBOUNDED = 1
FRAME_L2_UNBOUNDED = 2
FRAME_L1_L2_OVERLAP = 3
FRAME_L1_L2_TOO_CLOSE = 4
FRAME_L1_MISSING = 5
FRAME_L2_MISSING = 6
FRAME_REJECTED = 7

#: Landmark codes (indices into batch.LANDMARK_STATUSES).
LANDMARK_UPDATED = 0
LANDMARK_UNBOUNDED = 1
LANDMARK_INCONSISTENT = 2
LANDMARK_SKIPPED = 3
LANDMARK_MISSING = 4

#: The relaxed fusion keeps at most this many movements per map in its window.
MAX_WINDOW = 32


class JitOptions(TypedDict):
    """The keyword options every kernel is compiled with (typed for ``njit(**_JIT)``)."""

    cache: bool
    nogil: bool
    error_model: Literal["python", "numpy"]


_JIT: JitOptions = {"cache": True, "nogil": True, "error_model": "numpy"}

# OpenMP's default busy-waiting made prange several times slower than serial code on a
# 2-core machine; numba's own workqueue layer waits passively. A layer chosen by the user
# (NUMBA_THREADING_LAYER) is left alone.
if "NUMBA_THREADING_LAYER" not in os.environ:
    # why: numba.config defines its settings at import through globals(), unseen by mypy
    numba.config.THREADING_LAYER = "workqueue"  # type: ignore[attr-defined]


def threads() -> int:
    """Threads the batched update may use: numba's current thread count."""
    return int(numba.get_num_threads())
_TWO_PI = 2.0 * math.pi


@njit(**_JIT)
def wrap(angle: float) -> float:
    """Wrap an angle to [-pi, pi)."""
    return (angle + math.pi) % _TWO_PI - math.pi


@njit(**_JIT)
def cross(a: complex, b: complex) -> float:
    """2-D cross product ``a.x * b.y - a.y * b.x``."""
    return a.real * b.imag - a.imag * b.real


@njit(**_JIT)
def dot(a: complex, b: complex) -> float:
    return a.real * b.real + a.imag * b.imag


@njit(**_JIT)
def scale_of(poly: np.ndarray, n: int) -> tuple[float, float]:
    """(bounding-box size, largest coordinate magnitude) of ``poly[:n]``."""
    lo_x = hi_x = poly[0].real
    lo_y = hi_y = poly[0].imag
    for i in range(1, n):
        x, y = poly[i].real, poly[i].imag
        lo_x, hi_x = min(lo_x, x), max(hi_x, x)
        lo_y, hi_y = min(lo_y, y), max(hi_y, y)
    size = max(hi_x - lo_x, hi_y - lo_y)
    magnitude = max(max(abs(lo_x), abs(hi_x)), max(abs(lo_y), abs(hi_y)))
    return size, magnitude


@njit(**_JIT)
def tolerance_of(size: float, magnitude: float) -> float:
    """Distance below which two features count as touching, for polygons of that scale."""
    return RELATIVE_TOLERANCE * size + 4e-16 * magnitude


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
    k = 1
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
            mid, mid + n_right, i_far, i_to
        )
        task_start[top + 1], chain_from[top + 1] = -1, i_far
        task_start[top + 2], task_end[top + 2], chain_from[top + 2], chain_to[top + 2] = (
            start, mid, i_from, i_far
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
        while k >= 2 and _within_chord(out[k - 2], out[k - 1], p, tol):
            k -= 1
        out[k] = p
        k += 1
    lower = k + 1
    for j in range(n_points - 2, -1, -1):  # upper chain
        p = points[order[j]]
        while k >= lower and _within_chord(out[k - 2], out[k - 1], p, tol):
            k -= 1
        out[k] = p
        k += 1
    k -= 1  # the last point repeats the first
    if k == 2 and out[0] == out[1]:
        return 1
    return max(k, 1)


@njit(**_JIT)
def _within_chord(a: complex, b: complex, c: complex, tol: float) -> bool:
    """Whether ``b`` fails to turn left by more than ``tol`` on the way from ``a`` to ``c``:
    it lies right of the chord ``a -> c``, or within ``tol`` of it."""
    return cross(b - a, c - a) <= tol * abs(c - a)


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
                length > 0.0 and abs(cross(chord, v - prev)) <= tol * length
                and dot(v - prev, chord) >= 0.0 and dot(nxt - v, chord) >= 0.0
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


# --------------------------------------------------------------------------------------
# Cones in the robot frame FR (R1 = 0, R2 = 1)
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def cone_region(a: float, b: float, epsilon: float, out: np.ndarray) -> tuple[int, int]:
    """Region in FR of a landmark seen at bearing ``a`` from R1 = 0 and ``b`` from R2 = 1.

    The cone at R1 (rays at ``a +- epsilon``) intersected with the cone at R2. Its
    vertices are the ray-ray intersections that lie on both rays, plus an apex that lies
    inside the other cone; the region is their convex hull, exactly.

    Returns:
        ``(n, status)``: the vertex count in ``out`` (at most 4) and :data:`FR_BOUNDED`,
        :data:`FR_UNBOUNDED` (the cones' direction ranges overlap, or the region is
        numerically unbounded) or :data:`FR_EMPTY` (the cones miss each other).
    """
    if abs(wrap(b - a)) <= 2.0 * epsilon:
        return 0, FR_UNBOUNDED
    candidates = np.empty(6, dtype=np.complex128)
    n = 0
    for sign_a in (-1.0, 1.0):
        alpha = a + sign_a * epsilon
        for sign_b in (-1.0, 1.0):
            beta = b + sign_b * epsilon
            sin_gap = math.sin(beta - alpha)
            if abs(sin_gap) <= 1e-12:
                continue
            t = math.sin(beta) / sin_gap
            s = math.sin(alpha) / sin_gap
            if t >= 0.0 and s >= 0.0:
                candidates[n] = t * complex(math.cos(alpha), math.sin(alpha))
                n += 1
    if abs(wrap(a)) <= epsilon:  # R2 lies in the cone at R1
        candidates[n] = 1.0
        n += 1
    if abs(wrap(math.pi - b)) <= epsilon:  # R1 lies in the cone at R2
        candidates[n] = 0.0
        n += 1
    if n == 0:
        return 0, FR_EMPTY
    hull = np.empty(7, dtype=np.complex128)
    count = small_convex_hull(candidates, n, hull, 0.0)
    for i in range(count):
        if abs(hull[i]) > MAX_FR_EXTENT:
            return 0, FR_UNBOUNDED
    size, magnitude = scale_of(hull, count)
    count = simplify(hull, count, tolerance_of(size, magnitude))
    for i in range(min(count, FR_VERTICES)):
        out[i] = hull[i]
    return min(count, FR_VERTICES), FR_BOUNDED


# --------------------------------------------------------------------------------------
# The change of frames FR -> FL (see bearing_env.slam.transfer for the method and proof)
# --------------------------------------------------------------------------------------


@njit(**_JIT)
def boundary_samples(poly: np.ndarray, n: int, per_edge: int, out: np.ndarray) -> int:
    """``per_edge`` evenly spaced points on each edge, vertices included."""
    k = 0
    for i in range(n):
        a = poly[i]
        edge = poly[(i + 1) % n] - a
        for s in range(per_edge):
            out[k] = a + (s / per_edge) * edge
            k += 1
    return k


@njit(**_JIT)
def frame_plan(
    a1: np.ndarray, n1: int, a2: np.ndarray, n2: int, conservative: bool, edge_samples: int
) -> tuple[int, int, float, float, float]:
    """Whether and how finely one movement's frame change is sampled.

    Returns ``(status, per_edge, distance, delta1, delta2)``: a frame code
    (:data:`FRAME_OK`, :data:`FRAME_L1_L2_OVERLAP` when the regions of L1 and L2 touch, so
    ``h2 - h1`` can be 0, or :data:`FRAME_L1_L2_TOO_CLOSE` when the conservative bound
    needs more than :data:`MAX_EDGE_SAMPLES` pieces per edge), the samples per edge, the
    regions' distance and the sample spacings on L1's and L2's edges.
    """
    distance = polygon_distance(a1, n1, a2, n2)
    if not distance > 0.0:
        return FRAME_L1_L2_OVERLAP, 1, distance, 0.0, 0.0
    if not conservative:
        return FRAME_OK, 1, distance, 0.0, 0.0
    longest1, longest2 = longest_edge(a1, n1), longest_edge(a2, n2)
    needed = math.ceil(max(longest1, longest2) / (2.0 * distance))
    if needed > MAX_EDGE_SAMPLES:
        return FRAME_L1_L2_TOO_CLOSE, 1, distance, 0.0, 0.0
    per_edge = max(edge_samples, int(needed))
    return FRAME_OK, per_edge, distance, longest1 / per_edge, longest2 / per_edge


@njit(**_JIT)
def sample_hypotheses(
    a1: np.ndarray,
    n1: int,
    a2: np.ndarray,
    n2: int,
    per_edge: int,
    h1: np.ndarray,
    inv_d: np.ndarray,
) -> int:
    """Hypothesis pairs ``(h1, 1 / (h2 - h1))`` on the boundaries of A_L1 and A_L2.

    For one ``h1``, the images ``(z - h1) / (h2 - h1)`` of any point ``z`` over the
    samples ``h2`` are the points ``1 / (h2 - h1)`` times ``z - h1``: a rotation and
    scaling about 0. So only the ``h2`` whose ``1 / (h2 - h1)`` is a vertex of their
    convex hull can give a vertex of a transferred region; the others are left out (a
    third of them, typically), which changes no region.
    """
    s1 = np.empty(MAX_SAMPLES, dtype=np.complex128)
    s2 = np.empty(MAX_SAMPLES, dtype=np.complex128)
    inverses = np.empty(MAX_SAMPLES, dtype=np.complex128)
    extreme = np.empty(MAX_SAMPLES + 1, dtype=np.complex128)
    m1 = boundary_samples(a1, n1, per_edge, s1)
    m2 = boundary_samples(a2, n2, per_edge, s2)
    k = 0
    for i in range(m1):
        for j in range(m2):
            inverses[j] = 1.0 / (s2[j] - s1[i])
        for v in range(small_convex_hull(inverses, m2, extreme, 0.0)):
            h1[k] = s1[i]
            inv_d[k] = extreme[v]
            k += 1
    return k


@njit(**_JIT)
def transfer_region(
    target: np.ndarray,
    n_target: int,
    a1: np.ndarray,
    n1: int,
    a2: np.ndarray,
    n2: int,
    h1: np.ndarray,
    inv_d: np.ndarray,
    n_pairs: int,
    conservative: bool,
    distance: float,
    delta1: float,
    delta2: float,
    cloud: np.ndarray,
    hull: np.ndarray,
    out: np.ndarray,
) -> int:
    """The FL region of an FR region (or point) into ``out``; returns its vertex count
    (at most :data:`CAPACITY`; fewer than 3 for a paper-transfer region with no area,
    which happens only when A_L1, A_L2 and the target are all single points).

    The hull of the target's vertices under every hypothesis; for the conservative
    transfer, grown outward by the bound ``r`` of :mod:`bearing_env.slam.transfer`.
    ``cloud`` holds :data:`MAX_CLOUD` points, ``hull`` and ``out`` :data:`MAX_CLOUD` + 1.
    """
    k = 0
    for v in range(n_target):
        z = target[v]
        for p in range(n_pairs):
            cloud[k] = (z - h1[p]) * inv_d[p]
            k += 1
    n = convex_hull(cloud, k, hull)
    # Rounding can leave hull vertices a hair apart or off their neighbours' line; their
    # edge directions would be noise, and the offset needs true ones.
    size, magnitude = scale_of(hull, n)
    n = simplify(hull, n, tolerance_of(size, magnitude))
    if conservative:
        v1 = 0.0
        v2 = 0.0
        for v in range(n_target):
            for j in range(n1):
                v1 = max(v1, abs(target[v] - a1[j]))
            for j in range(n2):
                v2 = max(v2, abs(target[v] - a2[j]))
        radius = (v2 * delta1 * delta1 + v1 * delta2 * delta2) / (4.0 * distance**3)
        # A relative margin far above rounding error keeps the bound a bound in floats.
        radius += 1e-9 * (1.0 + v1 / distance)
        n = drop_edges_outward(hull, n, SCRATCH - 8)
        n = offset_outward(hull, n, radius, out)
    else:
        for i in range(n):
            out[i] = hull[i]
    return drop_edges_outward(out, n, CAPACITY)


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
