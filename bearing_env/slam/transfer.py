"""Change of frames FR -> FL under uncertain L1 and L2 (the paper's Section 3.1).

For hypotheses ``h1`` in ``A_L1`` and ``h2`` in ``A_L2`` (regions in FR), the similarity
``T(h1, h2)(z) = (z - h1) / (h2 - h1)`` maps FR to FL. A point or region ``A`` of FR
becomes the union of ``T(h1, h2)(A)`` over all hypotheses.

Three transfers are offered:

``"paper"``
    The paper's approximation: the convex hull of the images of the vertices of ``A``
    under the 4 x 4 vertex hypotheses. It can miss the truth (about 3% of single moves
    on random layouts), because the image of an edge of ``A_L1`` or ``A_L2`` is a circular
    arc that bulges beyond the vertex images.

``"conservative"`` (the default)
    Provably contains the union. Three facts make it exact up to a bound:

    1. ``T`` is affine in ``z`` for fixed hypotheses, so the vertices of ``A`` suffice.
    2. For fixed ``h2``, ``h1 -> <u, T(h1, h2)(z)>`` is the real part of a Moebius map with
       its pole outside ``A_L1``, hence harmonic: its maximum over ``A_L1`` lies on the
       boundary. The same holds in ``h2``. So the hull of the union is the hull of the
       images of ``boundary(A_L1) x boundary(A_L2)``.
    3. Each boundary is cut into pieces between samples (``edge_samples`` per edge). For
       one piece of each boundary (a sub-square), every image lies within a local bound
       ``sigma`` of the hull of the four corner images. ``sigma`` is a sagitta argument
       applied twice: moving one hypothesis along its piece traces a circular arc, whose
       distance to its chord is computed exactly at the sample points, then the other
       hypothesis moves, bounded with the piece-to-piece distances; the better of the two
       orders is kept. The proof, its conditions and its floating-point margin are in
       ``docs/world_model.md`` ("The local bound").

    The region is the sampled hull grown by the largest ``sigma`` over the sub-squares
    and the vertices of ``A`` (never more than the global radius below). The growth is a
    true outward offset: every edge of the hull moves out by it
    (:func:`~bearing_env.slam.kernels.offset_outward`).

``"conservative_global"``
    The same hull grown by one global radius per movement,
    ``r = (V2 delta1**2 + V1 delta2**2) / (4 D**3)``, with ``D`` the distance between
    ``A_L1`` and ``A_L2`` and ``V`` the largest distance from ``A`` to the other region:
    the bound of bearing_env 0.1, which the ``-v0`` task ids keep so that their published
    figures reproduce. It is larger than the local bound wherever the L1 and L2 regions
    come close somewhere, as ``D`` is their smallest distance.

Edges are cut into pieces at most twice the distance between the L1 and L2 regions
(``delta <= 2 D``), up to :data:`MAX_EDGE_SAMPLES` pieces, which keeps both bounds small;
a movement whose L1 and L2 regions are closer still, relative to their size, is refused
(``"l1_l2_too_close"``): its frame change is too uncertain to be useful.

The kernels are in :mod:`bearing_env.slam.kernels`; :func:`transfer_vertices` runs one
movement's transfer for inspection and tests.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env.slam import kernels
from bearing_env.slam.kernels import MAX_EDGE_SAMPLES

#: The transfers, in the order of the kernels' codes (``TRANSFER_CONSERVATIVE`` = 0, ...).
TRANSFERS = ("conservative", "paper", "conservative_global")

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
        transfer: ``"conservative"``, ``"conservative_global"`` or ``"paper"``.
        edge_samples: samples per edge for the conservative transfer (1..8).

    Returns:
        The vertices, or why the frame cannot be changed: ``"l1_l2_overlap"`` or
        ``"l1_l2_too_close"``.
    """
    if transfer not in TRANSFERS:
        raise ValueError(f"transfer must be one of {TRANSFERS}, got {transfer!r}")
    if not 1 <= edge_samples <= MAX_EDGE_SAMPLES:
        raise ValueError(f"edge_samples must be in 1..{MAX_EDGE_SAMPLES}, got {edge_samples!r}")
    target = np.ascontiguousarray(np.atleast_1d(np.asarray(target_fr, dtype=np.complex128)))
    out = np.empty(kernels.SCRATCH, dtype=np.complex128)
    status, n = kernels.transfer_polygon(
        target.ravel(),
        _small_polygon(a1, "a1"),
        _small_polygon(a2, "a2"),
        TRANSFERS.index(transfer),
        int(edge_samples),
        out,
    )
    if status == kernels.FRAME_L1_L2_OVERLAP:
        return "l1_l2_overlap"
    if status == kernels.FRAME_L1_L2_TOO_CLOSE:
        return "l1_l2_too_close"
    return out[:n].copy()


def _small_polygon(vertices: ArrayLike, name: str) -> NDArray[np.complex128]:
    poly = np.atleast_1d(np.asarray(vertices, dtype=np.complex128)).ravel()
    if not 1 <= poly.size <= kernels.FR_VERTICES:
        raise ValueError(f"{name} must have 1 to {kernels.FR_VERTICES} vertices, got {poly.size}")
    return np.ascontiguousarray(poly)
