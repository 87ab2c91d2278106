"""Change of frames FR -> FL under uncertain L1 and L2 (the paper's Section 3.1).

For hypotheses ``h1`` in ``A_L1`` and ``h2`` in ``A_L2`` (regions in FR), the similarity
``T(h1, h2)(z) = (z - h1) / (h2 - h1)`` maps FR to FL. A point or region ``A`` of FR
becomes the union of ``T(h1, h2)(A)`` over all hypotheses.

Two transfers are offered:

``"paper"``
    The paper's approximation: the convex hull of the images of the vertices of ``A``
    under the 4 x 4 vertex hypotheses. It can miss the truth (about 3% of single moves
    on random layouts), because the image of an edge of ``A_L1`` or ``A_L2`` is a circular
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
    samples per edge. The growth is a true outward offset: every edge of the hull moves
    out by ``r`` (:func:`~bearing_env.slam.kernels.offset_outward`), so the region
    contains every point within ``r`` of the hull.

The kernels are in :mod:`bearing_env.slam.kernels`; :func:`transfer_vertices` runs one
movement's transfer for inspection and tests.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env.slam import kernels
from bearing_env.slam.kernels import MAX_EDGE_SAMPLES

TRANSFERS = ("conservative", "paper")

__all__ = ["MAX_EDGE_SAMPLES", "TRANSFERS", "transfer_vertices"]


def transfer_vertices(
    target_fr: ArrayLike,
    a1: ArrayLike,
    a2: ArrayLike,
    transfer: str = "conservative",
    edge_samples: int = 3,
) -> NDArray[np.complex128] | str:
    """The FL region (CCW complex vertices) of one FR region or point, for one movement.

    Args:
        target_fr: complex vertices of a convex FR region (CCW), or a single point.
        a1, a2: complex vertices (CCW) of the FR regions of L1 and L2 (1 to 4 each).
        transfer: ``"paper"`` or ``"conservative"``.
        edge_samples: samples per edge for the conservative transfer (1..8).

    Returns:
        The vertices, or why the frame cannot be changed: ``"l1_l2_overlap"`` or
        ``"l1_l2_too_close"``.
    """
    if transfer not in TRANSFERS:
        raise ValueError(f"transfer must be one of {TRANSFERS}, got {transfer!r}")
    if not 1 <= edge_samples <= MAX_EDGE_SAMPLES:
        raise ValueError(f"edge_samples must be in 1..{MAX_EDGE_SAMPLES}, got {edge_samples!r}")
    target = np.atleast_1d(np.asarray(target_fr, dtype=np.complex128))
    p1 = _small_polygon(a1, "a1")
    p2 = _small_polygon(a2, "a2")
    conservative = transfer == "conservative"
    status, per_edge, distance, delta1, delta2 = kernels.frame_plan(
        p1, p1.size, p2, p2.size, conservative, int(edge_samples)
    )
    if status == kernels.FRAME_L1_L2_OVERLAP:
        return "l1_l2_overlap"
    if status == kernels.FRAME_L1_L2_TOO_CLOSE:
        return "l1_l2_too_close"
    h1 = np.empty(kernels.MAX_PAIRS, dtype=np.complex128)
    inv_d = np.empty(kernels.MAX_PAIRS, dtype=np.complex128)
    n_pairs = kernels.sample_hypotheses(p1, p1.size, p2, p2.size, per_edge, h1, inv_d)
    cloud = np.empty(target.size * n_pairs, dtype=np.complex128)
    hull = np.empty(cloud.size + 1, dtype=np.complex128)
    out = np.empty(max(cloud.size + 1, kernels.SCRATCH), dtype=np.complex128)
    frame = kernels.FrameChange(
        p1,
        int(p1.size),
        p2,
        int(p2.size),
        h1,
        inv_d,
        int(n_pairs),
        conservative,
        float(distance),
        float(delta1),
        float(delta2),
    )
    n = kernels.transfer_region(target, target.size, frame, cloud, hull, out)
    return out[:n].copy()


def _small_polygon(vertices: ArrayLike, name: str) -> NDArray[np.complex128]:
    poly = np.atleast_1d(np.asarray(vertices, dtype=np.complex128)).ravel()
    if not 1 <= poly.size <= kernels.FR_VERTICES:
        raise ValueError(f"{name} must have 1 to {kernels.FR_VERTICES} vertices, got {poly.size}")
    return np.ascontiguousarray(poly)
