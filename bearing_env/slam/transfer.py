"""Change of frames FR -> FL under uncertain L1 and L2 (the paper's Section 3.1).

For hypotheses ``h1`` in ``A_L1`` and ``h2`` in ``A_L2`` (regions in FR), the similarity
``T(h1, h2)(z) = (z - h1) / (h2 - h1)`` maps FR to FL. A point or region ``A`` of FR
becomes the union of ``T(h1, h2)(A)`` over all hypotheses.

Two transfers are offered:

``"paper"``
    The paper's approximation: the convex hull of the images of the vertices of ``A``
    under the 4 x 4 vertex hypotheses. It can miss the truth (DESIGN.md measures 3.3%
    of single moves), because the image of an edge of ``A_L1`` or ``A_L2`` is a circular
    arc that bulges beyond the vertex images.

``"conservative"``
    Provably contains the union. Three facts make it exact up to a bound:

    1. ``T`` is affine in ``z`` for fixed hypotheses, so the vertices of ``A`` suffice.
    2. For fixed ``h2``, ``h1 -> <u, T(h1, h2)(z)>`` is the real part of a Moebius map with
       its pole outside ``A_L1``, hence harmonic: its maximum over ``A_L1`` lies on the
       boundary. The same holds in ``h2``. So the hull of the union is the hull of the
       images of ``boundary(A_L1) x boundary(A_L2)``.
    3. Each boundary edge is cut into pieces of length ``delta``. Moving one hypothesis
       along a piece traces a circular arc (a Moebius image of a segment) whose distance
       to its chord is its sagitta ``(c / 2) tan(alpha / 2)``, with chord
       ``c <= V delta / D**2`` and ``tan(alpha / 2) <= delta / (2 D)``, where ``D`` is the
       distance between ``A_L1`` and ``A_L2`` and ``V`` the largest distance from ``z`` to
       the other region. Applying this once per hypothesis, every image lies within
       ``r = (V2 delta1**2 + V1 delta2**2) / (4 D**3)`` of the hull of the sampled images.

    The sagitta bound needs ``delta <= 2 D`` (arcs under a half circle). Edges are cut
    finely enough for that, up to :data:`MAX_EDGE_SAMPLES` pieces; a movement whose L1
    and L2 regions are closer still, relative to their size, is refused
    (``"l1_l2_too_close"``): its frame change is too uncertain to be useful. The region
    is the sampled hull grown by ``r``, which shrinks with the square of the number of
    samples per edge.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from bearing_env.slam.geometry import (
    ComplexArray,
    FloatArray,
    KGon,
    boundary_samples,
    max_edge_length,
    polygon_distance,
)

TRANSFERS = ("conservative", "paper")

#: Most samples per edge of A_L1 and A_L2 the conservative transfer uses (it uses more
#: than ``edge_samples`` only when L1 and L2 are close relative to their regions' size).
MAX_EDGE_SAMPLES = 8

#: Outcomes of :func:`plan_frame_changes`.
PLAN_OK = 0
PLAN_OVERLAP = 1
PLAN_TOO_CLOSE = 2

#: Elements per temporary array in :func:`transfer_support`; chunks of this size stay in
#: the CPU cache however many maps are batched.
_CHUNK_ELEMENTS = 1 << 17


@dataclass(frozen=True)
class FramePlan:
    """How each movement of a batch changes frames (arrays over the batch).

    ``status`` is :data:`PLAN_OK`, :data:`PLAN_OVERLAP` (the regions of L1 and L2 touch, so
    ``h2 - h1`` can be 0) or :data:`PLAN_TOO_CLOSE` (the conservative bound does not
    apply: an edge piece would be longer than twice their distance). ``per_edge`` is the
    number of samples per edge of A_L1 and A_L2 (1 for the paper transfer: the vertices).
    """

    status: NDArray[np.int8]
    distance: FloatArray
    per_edge: NDArray[np.int64]
    longest1: FloatArray
    longest2: FloatArray

    def take(self, index: NDArray[np.int64]) -> FramePlan:
        """The plan of the movements ``index``."""
        return FramePlan(
            self.status[index],
            self.distance[index],
            self.per_edge[index],
            self.longest1[index],
            self.longest2[index],
        )


def plan_frame_changes(
    a1: ComplexArray, a2: ComplexArray, transfer: str, edge_samples: int
) -> FramePlan:
    """Decide, per movement, whether and how finely to sample the hypotheses.

    Args:
        a1, a2: vertex arrays (N, V) of the FR regions of L1 and L2 (bounded).
        transfer: ``"paper"`` or ``"conservative"``.
        edge_samples: the fewest samples per edge for the conservative transfer.
    """
    if transfer not in TRANSFERS:
        raise ValueError(f"transfer must be one of {TRANSFERS}, got {transfer!r}")
    distance = polygon_distance(a1, a2)
    longest1, longest2 = max_edge_length(np.stack([a1, a2]))
    overlap = ~(distance > 0.0)
    if transfer == "paper":
        per_edge = np.ones(distance.shape, dtype=np.int64)
        too_close = np.zeros(distance.shape, dtype=bool)
    else:
        with np.errstate(divide="ignore", invalid="ignore"):
            needed = np.ceil(np.maximum(longest1, longest2) / (2.0 * distance))
        needed = np.where(overlap, 1.0, needed)
        too_close = ~overlap & (needed > MAX_EDGE_SAMPLES)
        per_edge = np.maximum(edge_samples, np.where(too_close, 1.0, needed)).astype(np.int64)
    status = np.where(overlap, PLAN_OVERLAP, np.where(too_close, PLAN_TOO_CLOSE, PLAN_OK))
    return FramePlan(status.astype(np.int8), distance, per_edge, longest1, longest2)


@dataclass(frozen=True)
class Hypotheses:
    """The sampled frame changes of a batch of movements with equal ``per_edge``.

    ``inv_d[g, p] = 1 / (h2 - h1)`` and ``h1[g, p]`` for the sampled hypothesis pairs
    ``p`` of movement ``g``; ``T(z) = (z - h1) * inv_d``.
    """

    h1: ComplexArray
    inv_d: ComplexArray
    a1: ComplexArray
    a2: ComplexArray
    distance: FloatArray
    delta1: FloatArray
    delta2: FloatArray
    conservative: bool

    def images(self, points: ComplexArray) -> ComplexArray:
        """FL images of FR points (G, ...) under every sampled hypothesis: (G, ..., P)."""
        extra = (None,) * (points.ndim - 1)
        h1 = self.h1[(slice(None), *extra)]
        inv_d = self.inv_d[(slice(None), *extra)]
        return (points[..., None] - h1) * inv_d

    def inflation(self, targets: ComplexArray) -> FloatArray:
        """Radius ``r`` that makes the sampled hull conservative: (G, m) for targets (G, m, V)."""
        if not self.conservative:
            return np.zeros(targets.shape[:-1])
        v1 = np.abs(targets[..., :, None] - self.a1[:, None, None, :]).max(axis=(-1, -2))
        v2 = np.abs(targets[..., :, None] - self.a2[:, None, None, :]).max(axis=(-1, -2))
        distance = self.distance[:, None]
        r = (v2 * self.delta1[:, None] ** 2 + v1 * self.delta2[:, None] ** 2) / (
            4.0 * distance**3
        )
        # A relative margin far above rounding error keeps the bound a bound in floats.
        return r + 1e-9 * (1.0 + v1 / distance)


def sample_hypotheses(
    a1: ComplexArray, a2: ComplexArray, plan: FramePlan, per_edge: int, conservative: bool
) -> Hypotheses:
    """The hypothesis pairs of movements (rows of ``a1``/``a2``/``plan``) sharing ``per_edge``."""
    h1, h2 = boundary_samples(a1, per_edge), boundary_samples(a2, per_edge)
    n_rows, n_samples = h1.shape
    if conservative:
        delta1, delta2 = plan.longest1 / per_edge, plan.longest2 / per_edge
    else:
        delta1 = delta2 = np.zeros(n_rows)
    return Hypotheses(
        h1=np.repeat(h1, n_samples, axis=-1),
        inv_d=(1.0 / (h2[:, None, :] - h1[:, :, None])).reshape(n_rows, -1),
        a1=a1,
        a2=a2,
        distance=plan.distance,
        delta1=delta1,
        delta2=delta2,
        conservative=conservative,
    )


def make_hypotheses(
    a1: ComplexArray, a2: ComplexArray, transfer: str, edge_samples: int
) -> Hypotheses | str:
    """Sample the hypotheses ``(h1, h2)`` of one movement (a batch of one).

    Args:
        a1, a2: vertex arrays (V,) of the FR regions of L1 and L2.
        transfer: ``"paper"`` (vertex pairs) or ``"conservative"``.
        edge_samples: samples per edge for the conservative transfer.

    Returns:
        The hypotheses, or why the frame cannot be changed: ``"l1_l2_overlap"`` or
        ``"l1_l2_too_close"`` (see :class:`FramePlan`).
    """
    if a1.shape != a2.shape:  # pad the shorter by repeating its last vertex
        size = max(a1.size, a2.size)
        a1 = np.concatenate([a1, np.repeat(a1[-1:], size - a1.size)])
        a2 = np.concatenate([a2, np.repeat(a2[-1:], size - a2.size)])
    a1, a2 = a1[None], a2[None]
    plan = plan_frame_changes(a1, a2, transfer, edge_samples)
    if plan.status[0] == PLAN_OVERLAP:
        return "l1_l2_overlap"
    if plan.status[0] == PLAN_TOO_CLOSE:
        return "l1_l2_too_close"
    return sample_hypotheses(a1, a2, plan, int(plan.per_edge[0]), transfer == "conservative")


def transfer_support(
    kgon: KGon, hyp: Hypotheses, regions: ComplexArray
) -> tuple[FloatArray, FloatArray]:
    """FL support K-gons of the robot's position R2 = 1 and of FR regions.

    Args:
        kgon: the K fixed normals.
        hyp: the hypotheses of G movements.
        regions: vertex arrays (G, m, V) of convex FR regions, one row per landmark.

    Returns:
        ``(robot, landmarks)``: supports (G, K) and (G, m, K). Each is the tight K-gon
        circumscribing the hull of the images, grown by the conservative inflation radius.

    A map's numbers come from matrix products of the same shape whatever the batch (numpy
    multiplies a stack matrix by matrix) and from maxima, which are exact, so a map's
    result does not depend on the other maps in its batch. Chunks of maps keep the
    products in the CPU cache.
    """
    n_rows, m, n_vert = regions.shape
    n_pairs, k = hyp.h1.shape[1], kgon.k
    half = k // 2
    # <u_k, (z - h1) g> = Re(z) Re(conj(u) g) - Im(z) Im(conj(u) g) - Re(conj(u) g h1):
    # one real matrix product over all (vertex, hypothesis, direction) triples, for the
    # first half of the directions only: u_{k + K/2} = -u_k exactly, so the support in
    # the other half is minus the minimum.
    rot = np.conj(kgon.normals[:half])[:, None] * hyp.inv_d[:, None, :]  # (G, K/2, P)
    basis = np.empty((n_rows, 3, half, n_pairs))
    basis[:, 0] = rot.real
    basis[:, 1] = rot.imag
    basis[:, 2] = (rot * hyp.h1[:, None, :]).real
    basis = basis.reshape(n_rows, 3, half * n_pairs)
    # Row 0 is R2 = 1; then the regions' vertices.
    coeff = np.empty((n_rows, 1 + m * n_vert, 3))
    coeff[:, 0] = (1.0, 0.0, -1.0)
    flat = regions.reshape(n_rows, m * n_vert)
    coeff[:, 1:, 0] = flat.real
    coeff[:, 1:, 1] = -flat.imag
    coeff[:, 1:, 2] = -1.0
    robot_values = (coeff[:, :1] @ basis).reshape(n_rows, half, n_pairs)
    robot = np.empty((n_rows, k))
    robot[:, :half] = robot_values.max(axis=-1)
    robot[:, half:] = -robot_values.min(axis=-1)
    # Small products, by chunks of maps and of landmarks: they stay in the CPU cache and
    # below the size where BLAS starts threads, which only contend with other envs.
    # Chunks depend on one map's sizes only, so a map is cut the same way in any batch.
    per_landmark = n_vert * half * n_pairs
    landmark_step = max(1, _CHUNK_ELEMENTS // per_landmark)
    map_step = max(1, _CHUNK_ELEMENTS // (m * per_landmark))
    landmarks = np.empty((n_rows, m, k))
    for lo in range(0, n_rows, map_step):
        maps = slice(lo, lo + map_step)
        for first in range(0, m, landmark_step):
            last = min(m, first + landmark_step)
            rows = slice(1 + first * n_vert, 1 + last * n_vert)
            values = coeff[maps, rows] @ basis[maps]  # (c, landmarks x V, K/2 x P)
            # One reduction over vertices and hypotheses: faster than two.
            values = values.reshape(-1, last - first, n_vert, half, n_pairs)
            landmarks[maps, first:last, :half] = values.max(axis=(2, 4))
            landmarks[maps, first:last, half:] = -values.min(axis=(2, 4))
    robot += hyp.inflation(np.ones((n_rows, 1, 1)))
    landmarks += hyp.inflation(regions)[..., None]
    return robot, landmarks


def transfer_points_fl(
    points_fr: ComplexArray,
    a1: ComplexArray,
    a2: ComplexArray,
    transfer: str = "conservative",
    edge_samples: int = 3,
) -> tuple[ComplexArray, float] | None:
    """The FL point cloud and inflation radius for one FR region (vertex array).

    The transferred region is ``hull(cloud)`` grown by ``radius`` (``radius == 0`` for
    the paper transfer, whose region is exactly the hull). None when the frame cannot be
    changed (see :func:`make_hypotheses`).
    """
    hyp = make_hypotheses(np.asarray(a1, complex), np.asarray(a2, complex), transfer, edge_samples)
    if isinstance(hyp, str):
        return None
    pts = np.atleast_1d(np.asarray(points_fr, complex))
    cloud = hyp.images(pts[None])[0].reshape(-1)
    return cloud, float(hyp.inflation(pts[None, None, :])[0, 0])
