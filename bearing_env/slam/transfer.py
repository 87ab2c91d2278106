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

import math
from dataclasses import dataclass

import numpy as np

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

@dataclass(frozen=True)
class Hypotheses:
    """The sampled frame changes of one movement, shared by every target.

    ``inv_d[p] = 1 / (h2 - h1)`` and ``h1[p]`` for the sampled hypothesis pairs ``p``;
    ``T(z) = (z - h1) * inv_d``.
    """

    h1: ComplexArray
    inv_d: ComplexArray
    a1: ComplexArray
    a2: ComplexArray
    distance: float
    delta1: float
    delta2: float
    conservative: bool

    def images(self, points: ComplexArray) -> ComplexArray:
        """FL images of FR points under every sampled hypothesis: (..., n_hypotheses)."""
        return (points[..., None] - self.h1) * self.inv_d

    def inflation(self, targets: ComplexArray) -> FloatArray:
        """Radius ``r`` that makes the sampled hull conservative, per target row."""
        if not self.conservative:
            return np.zeros(targets.shape[:-1])
        v1 = np.abs(targets[..., :, None] - self.a1).max(axis=(-1, -2))
        v2 = np.abs(targets[..., :, None] - self.a2).max(axis=(-1, -2))
        r = (v2 * self.delta1**2 + v1 * self.delta2**2) / (4.0 * self.distance**3)
        # A relative margin far above rounding error keeps the bound a bound in floats.
        return r + 1e-9 * (1.0 + v1 / self.distance)


def make_hypotheses(
    a1: ComplexArray, a2: ComplexArray, transfer: str, edge_samples: int
) -> Hypotheses | str:
    """Sample the hypotheses ``(h1, h2)`` of one movement.

    Args:
        a1, a2: vertex arrays (4,) of the FR regions of L1 and L2.
        transfer: ``"paper"`` (vertex pairs) or ``"conservative"``.
        edge_samples: samples per edge for the conservative transfer.

    Returns:
        The hypotheses, or why the frame cannot be changed: ``"l1_l2_overlap"`` when the
        regions touch (``h2 - h1`` can be 0), ``"l1_l2_too_close"`` when the conservative
        bound does not apply (a sampled edge piece is longer than twice the distance).
    """
    if transfer not in TRANSFERS:
        raise ValueError(f"transfer must be one of {TRANSFERS}, got {transfer!r}")
    if a1.shape != a2.shape:  # pad the shorter by repeating its last vertex
        size = max(a1.size, a2.size)
        a1 = np.concatenate([a1, np.repeat(a1[-1:], size - a1.size)])
        a2 = np.concatenate([a2, np.repeat(a2[-1:], size - a2.size)])
    distance = polygon_distance(a1, a2)
    if not distance > 0.0:
        return "l1_l2_overlap"
    if transfer == "paper":
        h1, h2 = a1, a2
        delta1 = delta2 = 0.0
    else:
        longest1, longest2 = max_edge_length(a1), max_edge_length(a2)
        per_edge = max(edge_samples, math.ceil(max(longest1, longest2) / (2.0 * distance)))
        if per_edge > MAX_EDGE_SAMPLES:
            return "l1_l2_too_close"
        delta1, delta2 = longest1 / per_edge, longest2 / per_edge
        h1, h2 = boundary_samples(np.stack([a1, a2]), per_edge)
    h1_pairs = np.repeat(h1, h2.shape[-1])
    return Hypotheses(
        h1=h1_pairs,
        inv_d=1.0 / (h2[None, :] - h1[:, None]).reshape(-1),
        a1=a1,
        a2=a2,
        distance=distance,
        delta1=delta1,
        delta2=delta2,
        conservative=transfer == "conservative",
    )


def transfer_support(kgon: KGon, hyp: Hypotheses, targets: ComplexArray) -> FloatArray:
    """FL support K-gons of FR regions (vertex arrays ``(m, V)``): shape (m, K).

    Every target row is the vertex array of one convex FR region (a point is a row of
    one vertex). The result is the tight K-gon circumscribing the hull of the images,
    grown by the conservative inflation radius.
    """
    m, n_vert = targets.shape
    # <u_k, (v - h1) g> = Re(v) Re(conj(u) g) - Im(v) Im(conj(u) g) - Re(conj(u) h1 g):
    # one real matrix product over all (vertex, hypothesis, direction) triples.
    rot = np.conj(kgon.normals)[:, None] * hyp.inv_d  # (K, P)
    offset = (np.conj(kgon.normals)[:, None] * (hyp.h1 * hyp.inv_d)).real
    basis = np.stack([rot.real, rot.imag, offset]).reshape(3, -1)  # (3, K*P)
    flat = targets.reshape(-1)
    coeff = np.stack([flat.real, -flat.imag, -np.ones(flat.shape)], axis=-1)  # (m*V, 3)
    values = (coeff @ basis).reshape(m, n_vert, kgon.k, -1)
    support = values.max(axis=(1, 3))
    return support + hyp.inflation(targets)[:, None]


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
    cloud = hyp.images(pts).reshape(-1)
    return cloud, float(hyp.inflation(pts[None, :])[0])
