"""Cones in the robot frame FR and the change of frames FR -> FL (see
:mod:`bearing_env.slam.transfer` for the method and its proof).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit
from numpy.typing import NDArray

from bearing_env.numerics import wrap
from bearing_env.slam.kernels.common import (
    _JIT,
    CAPACITY,
    FR_BOUNDED,
    FR_EMPTY,
    FR_UNBOUNDED,
    FR_VERTICES,
    FRAME_L1_L2_OVERLAP,
    FRAME_L1_L2_TOO_CLOSE,
    FRAME_OK,
    MAX_EDGE_SAMPLES,
    MAX_FR_EXTENT,
    MAX_SAMPLES,
    SCRATCH,
    scale_of,
    tolerance_of,
)
from bearing_env.slam.kernels.polygons import (
    convex_hull,
    drop_edges_outward,
    longest_edge,
    offset_outward,
    polygon_distance,
    simplify,
    small_convex_hull,
    small_hull_indices,
)

ComplexArray = NDArray[np.complex128]


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
    convex hull can give a vertex of a transferred region. Symmetrically, for one ``h2``
    the images are ``1 + (z - h2) / (h2 - h1)``: only the ``h1`` whose ``1 / (h2 - h1)``
    is a vertex of the hull over the samples ``h1`` count. Pairs that fail either test
    are left out (about half of them, typically), which changes no region.
    """
    s1 = np.empty(MAX_SAMPLES, dtype=np.complex128)
    s2 = np.empty(MAX_SAMPLES, dtype=np.complex128)
    m1 = boundary_samples(a1, n1, per_edge, s1)
    m2 = boundary_samples(a2, n2, per_edge, s2)
    inverses = np.empty((m1, m2), dtype=np.complex128)
    for i in range(m1):
        for j in range(m2):
            inverses[i, j] = 1.0 / (s2[j] - s1[i])
    column = np.empty(m1, dtype=np.complex128)
    extreme = np.empty(MAX_SAMPLES + 1, dtype=np.int64)
    # column_extreme[i, j]: h1 = s1[i] gives a hull vertex among the pairs with h2 = s2[j].
    column_extreme = np.zeros((m1, m2), dtype=np.bool_)
    for j in range(m2):
        for i in range(m1):
            column[i] = inverses[i, j]
        for v in range(small_hull_indices(column, m1, extreme, 0.0)):
            column_extreme[extreme[v], j] = True
    k = 0
    for i in range(m1):
        for v in range(small_hull_indices(inverses[i], m2, extreme, 0.0)):
            j = extreme[v]
            if column_extreme[i, j]:
                h1[k] = s1[i]
                inv_d[k] = inverses[i, j]
                k += 1
    return k


class FrameChange(NamedTuple):
    """One movement's change of frames FR -> FL, as :func:`transfer_region` applies it:
    the FR regions of L1 and L2, the hypothesis pairs of :func:`sample_hypotheses`, and
    the conservative bound's terms from :func:`frame_plan`."""

    a1: ComplexArray  #: the FR region of L1 (``a1[:n1]``)
    n1: int
    a2: ComplexArray  #: the FR region of L2 (``a2[:n2]``)
    n2: int
    h1: ComplexArray  #: hypotheses ``h1`` (``h1[:n_pairs]``)
    inv_d: ComplexArray  #: their ``1 / (h2 - h1)``
    n_pairs: int
    conservative: bool  #: grow the hull by the bound (else the paper's hull)
    distance: float  #: distance between the regions of L1 and L2
    delta1: float  #: sample spacing on L1's edges
    delta2: float  #: sample spacing on L2's edges


@njit(**_JIT)
def transfer_region(
    target: np.ndarray,
    n_target: int,
    frame: FrameChange,
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
    a1, n1, a2, n2 = frame.a1, frame.n1, frame.a2, frame.n2
    h1, inv_d, n_pairs = frame.h1, frame.inv_d, frame.n_pairs
    distance, delta1, delta2 = frame.distance, frame.delta1, frame.delta2
    k = np.int64(0)  # not 0: a literal start value compiles convex_hull once more
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
    if frame.conservative:
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
