"""Batched convex geometry in pure numpy: bearing cones and fixed-normal convex polygons.

Points are complex numbers (x + iy). Every function works on arrays with arbitrary
leading batch dimensions, so one call handles all landmarks of a movement (and, through
:class:`~bearing_env.slam.batch.BatchedPolygonSLAM`, many maps).

Two polygon representations are used:

* **vertex arrays**: complex ``(..., V)`` arrays in counter-clockwise order, padded by
  repeating a vertex (zero-length edges are harmless everywhere below). Used for the
  small regions in the robot frame FR.
* **support K-gons**: the map's regions in the landmark frame FL are stored as the
  support values ``h`` of a convex set in ``K`` fixed, evenly spaced outward normals
  ``u_k = exp(2i pi k / K)``. The K-gon ``{x : <u_k, x> <= h_k}`` *contains* the set
  (it is circumscribed), intersection of two K-gons is exact, and all arrays have a
  fixed size. A K-gon is *tight* when every ``h_k`` is attained (each line touches the
  polygon); the functions below take and return tight K-gons.
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import NDArray

ComplexArray = NDArray[np.complex128]
FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: FR-region vertices farther than this (in FR units, |R1 R2| = 1) mean near-parallel
#: cones: the region is numerically unbounded and carries no usable information.
MAX_FR_EXTENT = 1e4


def wrap_angle(angle: NDArray[np.float64] | float) -> NDArray[np.float64]:
    """Wrap angles to [-pi, pi)."""
    return (np.asarray(angle, dtype=np.float64) + np.pi) % (2.0 * np.pi) - np.pi


def cross(a: ComplexArray, b: ComplexArray) -> FloatArray:
    """2-D cross product ``a.x * b.y - a.y * b.x`` of complex points."""
    return (np.conj(a) * b).imag


def dot(a: ComplexArray, b: ComplexArray) -> FloatArray:
    """2-D dot product of complex points."""
    return (np.conj(a) * b).real


# --------------------------------------------------------------------------------------
# Cones in the robot frame FR (R1 = 0, R2 = 1)
# --------------------------------------------------------------------------------------

FR_BOUNDED = 0
FR_UNBOUNDED = 1
FR_EMPTY = 2


def cone_intersections(
    bearings_start: FloatArray, bearings_end: FloatArray, epsilon: float
) -> tuple[ComplexArray, NDArray[np.int8]]:
    """Regions ``A_Li`` in FR: the cone at R1 = 0 intersected with the cone at R2 = 1.

    Args:
        bearings_start: bearings at R1, radians counter-clockwise from the motion.
        bearings_end: bearings at R2, same shape.
        epsilon: half-width of each cone (radians, 0 < epsilon < pi/2).

    Returns:
        ``(vertices, status)``: ``vertices`` is complex ``(..., 4)`` in counter-clockwise
        order (padded by repetition; ``nan`` where not bounded) and ``status`` is
        :data:`FR_BOUNDED`, :data:`FR_UNBOUNDED` (the cones' direction ranges overlap,
        or the region is numerically unbounded) or :data:`FR_EMPTY` (the cones miss each
        other: the bearings are inconsistent with epsilon).
    """
    a = np.asarray(bearings_start, dtype=np.float64)
    b = np.asarray(bearings_end, dtype=np.float64)
    shape = a.shape
    a, b = a.reshape(-1), b.reshape(-1)
    # Ray-ray intersections in the cyclic order (r-, q-), (r-, q+), (r+, q+), (r+, q-) of
    # the rays R1 + t exp(i alpha) and R2 + s exp(i beta): walking the quadrilateral's
    # boundary along r-, q+, r+ and q- in turn. With R1 = 0 and R2 = 1,
    # t = sin(beta) / sin(beta - alpha) and s = sin(alpha) / sin(beta - alpha).
    alpha = a[:, None] + epsilon * _R_SIGNS
    beta = b[:, None] + epsilon * _Q_SIGNS
    sin_gap = np.sin(beta - alpha)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.sin(beta) / sin_gap
        s = np.sin(alpha) / sin_gap
    quad = t * np.exp(1j * alpha)
    ray_ok = (t >= 0.0) & (s >= 0.0) & (np.abs(sin_gap) > 1e-12)
    n_rays = ray_ok.sum(axis=-1)
    # Wrapped parallax b - a, and the apex tests: R2 lies in cone 1 when |a| <= epsilon,
    # R1 lies in cone 2 when |pi - b| <= epsilon (angles wrapped).
    wrapped = wrap_angle(np.stack([b - a, a, np.pi - b]))
    parallax = wrapped[0]
    apex_in = np.abs(wrapped[1:]) <= epsilon
    with np.errstate(invalid="ignore"):
        unbounded = (np.abs(parallax) <= 2.0 * epsilon) | (
            np.abs(np.where(ray_ok, quad, 0.0)).max(axis=-1) > MAX_FR_EXTENT
        )
    simple = ~(apex_in[0] | apex_in[1])
    empty = ~unbounded & simple & (n_rays == 0)

    # Without an apex inside the other cone, a bounded non-empty intersection is exactly
    # the quadrilateral of the four ray intersections, clockwise iff the parallax is
    # positive.
    verts = np.where((parallax > 0.0)[:, None], quad[:, ::-1], quad)
    general = ~unbounded & ~(simple & ((n_rays == 4) | (n_rays == 0)))
    if general.any():
        verts[general] = _general_cone_vertices(
            quad[general], ray_ok[general], apex_in[1][general], apex_in[0][general]
        )
        empty |= general & ~(ray_ok.any(axis=-1) | apex_in[0] | apex_in[1])

    status = np.where(unbounded, FR_UNBOUNDED, np.where(empty, FR_EMPTY, FR_BOUNDED))
    status = status.astype(np.int8)
    if unbounded.any() or empty.any():
        verts[status != FR_BOUNDED] = np.nan
    return verts.reshape(*shape, 4), status.reshape(shape)


_R_SIGNS = np.array([-1.0, -1.0, 1.0, 1.0])
_Q_SIGNS = np.array([-1.0, 1.0, 1.0, -1.0])


def _general_cone_vertices(
    quad: ComplexArray, ray_ok: BoolArray, r1_in: BoolArray, r2_in: BoolArray
) -> ComplexArray:
    """Vertices when an apex lies inside the other cone (a landmark near the line of motion).

    The candidates are the valid ray intersections and the apexes; a bounded intersection
    of four half-planes has at most 4 distinct ones. Sort them counter-clockwise around
    their mean (equal points end up adjacent), drop repeats, pad with the first vertex.
    """
    n = quad.shape[0]
    cand = np.concatenate([quad, np.zeros((n, 1)), np.ones((n, 1))], axis=-1).astype(complex)
    ok = np.concatenate([ray_ok, r1_in[:, None], r2_in[:, None]], axis=-1)
    cand[~ok] = 0.0
    centre = cand.sum(axis=-1) / np.maximum(ok.sum(axis=-1), 1)
    angle = np.where(ok, np.angle(cand - centre[:, None]), np.inf)
    rows = np.arange(n)[:, None]
    order = np.argsort(angle, axis=-1)
    cand, ok = cand[rows, order], ok[rows, order]
    scale = 1e-12 * (1.0 + np.abs(cand).max(axis=-1, keepdims=True))
    ok[:, 1:] &= ~(ok[:, :-1] & (np.abs(cand[:, 1:] - cand[:, :-1]) <= scale))
    order = np.argsort(~ok, axis=-1, kind="stable")
    cand, ok = cand[rows, order], ok[rows, order]
    return np.where(ok[:, :4], cand[:, :4], cand[:, :1])


# --------------------------------------------------------------------------------------
# Convex polygons as vertex arrays
# --------------------------------------------------------------------------------------


def polygon_distance(p: ComplexArray, q: ComplexArray) -> FloatArray:
    """Distances between small convex polygons (vertex arrays (..., V), CCW); 0 if they touch.

    Batched over leading axes (``p`` and ``q`` of one shape). The separating-axis test
    decides whether they are disjoint (the edge normals, and the directions between
    vertices, which separate degenerate polygons: points and segments padded by repeated
    vertices); disjoint polygons are at the smallest vertex-to-edge distance either way.
    """
    both = np.stack([p, q]).astype(complex, copy=False)
    # Vertices of p against the edges of q, and of q against those of p, in one go.
    gaps = _point_edge_distances(both, both[::-1]).min(axis=(0, -1, -2))
    return np.where(_separating_axis_exists(both[0], both[1]), gaps, 0.0)


def _separating_axis_exists(p: ComplexArray, q: ComplexArray) -> BoolArray:
    """The separating-axis test for rows of small convex polygons (N, V)."""
    n_vertices = p.shape[-1] * q.shape[-1]
    axes = np.concatenate(
        [
            -1j * (_next_vertex(p) - p),
            -1j * (_next_vertex(q) - q),
            (q[..., None, :] - p[..., :, None]).reshape(*p.shape[:-1], n_vertices),
        ],
        axis=-1,
    )
    conj_axes = np.conj(axes)[..., :, None]
    proj_p = (conj_axes * p[..., None, :]).real
    proj_q = (conj_axes * q[..., None, :]).real
    # A zero axis projects both polygons to 0: never separating, no special case needed.
    return (
        (proj_q.min(axis=-1) > proj_p.max(axis=-1)) | (proj_p.min(axis=-1) > proj_q.max(axis=-1))
    ).any(axis=-1)


def _point_edge_distances(points: ComplexArray, poly: ComplexArray) -> FloatArray:
    """Distance from every point to every edge of ``poly``: (..., n_points, n_edges)."""
    a = poly[..., None, :]
    d = _next_vertex(poly)[..., None, :] - a
    z = points[..., :, None]
    len2 = d.real * d.real + d.imag * d.imag
    degenerate = len2 == 0.0  # a repeated vertex: the distance to the point itself
    along = ((z - a) * np.conj(d)).real / np.where(degenerate, 1.0, len2)
    t = np.where(degenerate, 0.0, np.minimum(np.maximum(along, 0.0), 1.0))
    return np.abs(z - (a + t * d))


def boundary_samples(poly: ComplexArray, per_edge: int) -> ComplexArray:
    """``per_edge`` evenly spaced points on each edge (vertex included): (..., V*per_edge)."""
    t = np.arange(per_edge) / per_edge
    nxt = _next_vertex(poly)
    pts = poly[..., :, None] + t * (nxt - poly)[..., :, None]
    return pts.reshape(*poly.shape[:-1], poly.shape[-1] * per_edge)


def max_edge_length(poly: ComplexArray) -> FloatArray:
    """Longest edge of small polygons (vertex arrays (..., V)): shape (...)."""
    return np.abs(_next_vertex(poly) - poly).max(axis=-1)


def _next_vertex(poly: ComplexArray) -> ComplexArray:
    return poly[..., _next_index(poly.shape[-1])]


@functools.cache
def _next_index(n: int) -> NDArray[np.intp]:
    return (np.arange(n) + 1) % n


# --------------------------------------------------------------------------------------
# Support K-gons in the landmark frame FL
# --------------------------------------------------------------------------------------


class KGon:
    """The fixed set of ``K`` outward normals and the operations on support K-gons."""

    def __init__(self, directions: int) -> None:
        if directions < 8 or directions % 2:
            raise ValueError(f"directions must be an even integer >= 8, got {directions!r}")
        self.k = directions
        self.theta = 2.0 * np.pi * np.arange(directions) / directions
        half = np.exp(1j * self.theta[: directions // 2])
        # Exactly antipodal pairs u_{k + K/2} = -u_k: a support in -u is minus the
        # minimum in u, which halves the transfer's products (see transfer_support).
        self.normals = np.concatenate([half, -half])
        self._conj_normals = np.conj(self.normals)
        self._step_sin = np.sin(2.0 * np.pi / directions)
        # Real matrix for supports of point clouds: <u_k, p> = x cos + y sin.
        self._proj = np.stack([self.normals.real, self.normals.imag])  # (2, K)
        self._next = (np.arange(directions) + 1) % directions
        self._prev = (np.arange(directions) - 1) % directions

    # -- construction ------------------------------------------------------------------

    def support_of_points(self, points: ComplexArray, axis: int = -1) -> FloatArray:
        """Tight circumscribed K-gon of a point cloud: ``max_p <u_k, p>``; shape (..., K)."""
        pts = np.moveaxis(points, axis, -1)
        xy = np.stack([pts.real, pts.imag], axis=-1)  # (..., P, 2)
        return (xy @ self._proj).max(axis=-2)

    # -- geometry of a K-gon -----------------------------------------------------------

    def vertices(self, h: FloatArray) -> ComplexArray:
        """Vertex ``k`` is where the lines of normals ``k`` and ``k+1`` meet: (..., K)."""
        u = self.normals
        return (h * u[self._next] - h[..., self._next] * u) / (1j * self._step_sin)

    def area_centroid(self, h: FloatArray) -> tuple[FloatArray, ComplexArray]:
        """Area and centroid of tight K-gons (shoelace over the K vertices)."""
        v = self.vertices(h)
        w = v[..., self._next]
        c = cross(v, w)
        area2 = c.sum(axis=-1)
        with np.errstate(divide="ignore", invalid="ignore"):
            centroid = ((v + w) * c).sum(axis=-1) / (3.0 * area2)
        # Degenerate (segment or point) regions: fall back to the vertex mean.
        degenerate = ~(np.abs(area2) > 1e-300)
        centroid = np.where(degenerate, v.mean(axis=-1), centroid)
        return 0.5 * area2, centroid

    def contains(self, h: FloatArray, points: ComplexArray, rtol: float = 1e-9) -> BoolArray:
        """Whether each point (shape ``h.shape[:-1]``) lies in its K-gon (boundary counts)."""
        proj = dot(self.normals, points[..., None])
        scale = 1.0 + np.abs(h).max(axis=-1, initial=0.0, where=np.isfinite(h))[..., None]
        return np.all(proj <= h + rtol * scale, axis=-1)

    def intersect(self, hp: FloatArray, hc: FloatArray) -> tuple[FloatArray, BoolArray]:
        """Exact intersection of two tight K-gons, returned tight.

        ``min(hp, hc)`` already describes the intersection as a set, but is not tight
        where the two boundaries cross. Each edge ``k`` of the intersection lies on the
        line of whichever polygon is lower in direction ``k`` (its *owner*): it is the
        owner's edge ``k`` clipped by the other polygon (Cyrus-Beck, all edges at once).
        A direction whose edge vanishes gets the support of the corner that replaces it,
        which is the end of the previous surviving edge.

        Returns:
            ``(h, empty)``: tight supports and a mask of empty intersections (where ``h``
            is undefined).
        """
        owner_p = hp <= hc
        # Nested K-gons (common: a new movement's region often covers the map's) need no
        # clipping: the inner one is the intersection, and it is tight. Decided per pair,
        # so a pair's result does not depend on the others in its batch.
        p_inside = owner_p.all(axis=-1)
        h = np.where(p_inside[..., None], hp, hc)
        empty = np.zeros(p_inside.shape, dtype=bool)
        crossing = ~(p_inside | (~owner_p).all(axis=-1))
        if crossing.any():
            h[crossing], empty[crossing] = self._clip(hp[crossing], hc[crossing])
        return h, empty

    def _clip(self, hp: FloatArray, hc: FloatArray) -> tuple[FloatArray, BoolArray]:
        """:meth:`intersect` for K-gons (N, K) whose boundaries cross."""
        owner_p = hp <= hc
        vp, vc = self.vertices(hp), self.vertices(hc)
        h_own = np.where(owner_p, hp, hc)
        # Edge k runs from vertex k-1 to vertex k of its owner.
        start = np.where(owner_p, vp[..., self._prev], vc[..., self._prev])
        seg = np.where(owner_p, vp, vc) - start
        h_other = np.where(owner_p[..., :, None], hc[..., None, :], hp[..., None, :])  # (.., K, K)
        # Constraint j on the point start + t seg: t * denom <= numer.
        denom = (self._conj_normals * seg[..., :, None]).real
        numer = h_other - (self._conj_normals * start[..., :, None]).real
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = numer / denom
        # A zero-length edge gives tiny denominators of either sign; the sign of each bound
        # still says on which side of constraint j the point is, so no threshold is needed.
        t_lo = np.where(denom < 0.0, ratio, 0.0).max(axis=-1)
        t_hi = np.where(denom > 0.0, ratio, 1.0).min(axis=-1)
        tol = 1e-9 * (1.0 + np.abs(h_own).max(axis=-1))
        parallel_out = ((denom == 0.0) & (numer < -tol[..., None, None])).any(axis=-1)
        survives = (t_lo <= t_hi + 1e-9) & ~parallel_out
        empty = ~survives.any(axis=-1)

        corner = start + np.clip(t_hi, 0.0, 1.0) * seg  # end of each (clipped) edge
        k = self.k
        idx = np.arange(k)
        # Index of the last surviving edge at or before k, cyclically: scan two laps, the
        # first lap shifted by -K, with a filler below every real index.
        filler = -(2 * k)
        doubled = np.concatenate(
            [np.where(survives, idx - k, filler), np.where(survives, idx, filler)], axis=-1
        )
        prev = np.maximum.accumulate(doubled, axis=-1)[..., k:] % k
        corner_prev = np.take_along_axis(corner, prev, axis=-1)
        h = np.where(survives, h_own, (self._conj_normals * corner_prev).real)
        return h, empty
