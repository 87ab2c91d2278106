"""One-movement functions returning shapely geometry: for inspection, plots and tests.

The map (:class:`~bearing_env.slam.PolygonSLAM`) calls the compiled kernels directly;
these wrappers give the exact polygons of a single movement. shapely is imported when
one of them is first called: making and stepping an env never needs it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from bearing_env.slam.geometry import FR_BOUNDED, cone_region
from bearing_env.slam.transfer import transfer_vertices
from bearing_env.validation import epsilon_radians

if TYPE_CHECKING:
    import shapely


def fr_region(bearing_start: float, bearing_end: float, epsilon: float) -> shapely.Polygon | None:
    """Region of one landmark in FR (R1 = (0, 0), R2 = (1, 0)); None if unbounded or empty.
    ``epsilon`` (radians) must be in (0, pi/2), as for ``PolygonSLAM`` (ValueError)."""
    verts, status = cone_region(bearing_start, bearing_end, epsilon_radians(epsilon))
    if status != FR_BOUNDED:
        return None
    return _polygon(verts)


def transfer_polygon(
    region_fr: shapely.Polygon | ArrayLike,
    l1_fr: shapely.Polygon | ArrayLike,
    l2_fr: shapely.Polygon | ArrayLike,
    transfer: str = "conservative",
    edge_samples: int = 3,
) -> shapely.Geometry | None:
    """The FL region of an FR region given the FR regions of L1 and L2.

    ``"paper"`` returns exactly the convex hull of the vertex-hypothesis images (a point
    or a segment if they have no area: exact L1, L2 and target); ``"conservative"``
    returns the sampled hull with every edge moved outward by the bound of
    :mod:`bearing_env.slam.transfer`. None when the frame cannot be changed.
    """
    verts = transfer_vertices(
        _vertices(region_fr), _vertices(l1_fr), _vertices(l2_fr), transfer, edge_samples
    )
    if isinstance(verts, str):
        return None
    return _polygon(verts)


def transfer_point(
    point_fr: ArrayLike,
    l1_fr: shapely.Polygon | ArrayLike,
    l2_fr: shapely.Polygon | ArrayLike,
    transfer: str = "conservative",
    edge_samples: int = 3,
) -> shapely.Geometry | None:
    """The FL region of an FR point (e.g. R1 = (0, 0) or R2 = (1, 0))."""
    p = np.asarray(point_fr, dtype=float).reshape(1, 2)
    return transfer_polygon(p, l1_fr, l2_fr, transfer, edge_samples)


def _vertices(region: shapely.Polygon | ArrayLike) -> np.ndarray:
    import shapely

    if isinstance(region, shapely.Polygon):
        xy = np.asarray(region.exterior.coords)[:-1]
        if shapely.is_ccw(region.exterior) is False:
            xy = xy[::-1]
    else:
        xy = np.asarray(region, dtype=float).reshape(-1, 2)
    return xy[:, 0] + 1j * xy[:, 1]


def _polygon(verts: np.ndarray) -> shapely.Geometry:
    """The polygon of CCW vertices; a point or a segment when it has no area."""
    import shapely

    xy = np.stack([verts.real, verts.imag], -1)
    if verts.size >= 3:
        return shapely.Polygon(xy)
    return shapely.convex_hull(shapely.multipoints(xy))
