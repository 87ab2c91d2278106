"""Convex polygons as numpy arrays: the compiled kernels' entry points for Python code.

Points are complex numbers (x + iy); a polygon is a complex vertex array in
counter-clockwise order. The map itself calls :mod:`bearing_env.slam.kernels` directly;
these wrappers serve one-off geometry (the shapely API, plots, tests).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env.numerics import wrap_angle
from bearing_env.slam import kernels
from bearing_env.slam.batch import BatchedPolygonSLAM
from bearing_env.slam.kernels import FR_BOUNDED, FR_EMPTY, FR_UNBOUNDED, MAX_FR_EXTENT
from bearing_env.validation import int_at_least

ComplexArray = NDArray[np.complex128]

__all__ = [
    "FR_BOUNDED",
    "FR_EMPTY",
    "FR_UNBOUNDED",
    "MAX_FR_EXTENT",
    "area_centroid",
    "cone_region",
    "convex_hull",
    "intersect",
    "offset_outward",
    "relaxed_intersection",
    "robust_levels",
    "wrap_angle",
]


def cone_region(
    bearing_start: float, bearing_end: float, epsilon: float
) -> tuple[ComplexArray, int]:
    """The FR region of one landmark and its status (:data:`FR_BOUNDED`, ...)."""
    out = np.empty(kernels.FR_VERTICES, dtype=np.complex128)
    n, status = kernels.cone_region(float(bearing_start), float(bearing_end), float(epsilon), out)
    return out[:n].copy(), int(status)


def convex_hull(points: ArrayLike) -> ComplexArray:
    """Convex hull (CCW, no collinear vertices) of complex points."""
    pts = _polygon(points)
    out = np.empty(pts.size + 1, dtype=np.complex128)
    return out[: kernels.convex_hull(pts, pts.size, out)].copy()


def intersect(p: ArrayLike, q: ArrayLike) -> ComplexArray:
    """Intersection of two convex polygons (CCW); empty when they only touch or miss."""
    a, b = _polygon(p), _polygon(q)
    size = max(kernels.SCRATCH, a.size + b.size + 8)
    out = np.empty(size, dtype=np.complex128)
    work = np.empty(size, dtype=np.complex128)
    if a.size > kernels.CAPACITY or b.size > kernels.CAPACITY:
        raise ValueError(f"polygons must have at most {kernels.CAPACITY} vertices")
    n = kernels.clip_convex(a, a.size, b, b.size, out, work)
    return out[:n].copy()


def offset_outward(p: ArrayLike, radius: float) -> ComplexArray:
    """Every edge of a convex polygon (CCW) moved outward by ``radius`` (a point or a
    segment becomes the rectangle around it)."""
    a = _polygon(p)
    if a.size == 0:
        raise ValueError("offset_outward needs at least one vertex")
    out = np.empty(a.size + 3, dtype=np.complex128)
    return out[: kernels.offset_outward(a, a.size, float(radius), out)].copy()


def area_centroid(p: ArrayLike) -> tuple[float, complex]:
    """Area and centroid of a convex polygon (CCW)."""
    a = _polygon(p)
    area, centroid = kernels.area_centroid(a, a.size)
    return float(area), complex(centroid)


def relaxed_intersection(
    polygons: list[ArrayLike], max_outliers: int
) -> tuple[ComplexArray, int, NDArray[np.bool_]]:
    """The convex hull of the q-relaxed intersection of convex polygons (CCW): the
    points in all of them but at most ``q``, for the smallest ``q <= max_outliers`` that
    makes that set non-empty (the relaxed fusion's rule, on one landmark's regions).

    Returns ``(vertices, q, inliers)``: the hull (empty if no ``q`` up to the cap
    works), ``q``, and for each polygon whether some non-empty intersection kept it.
    """
    k = len(polygons)
    if not 1 <= k <= kernels.MAX_WINDOW:
        raise ValueError(f"relaxed_intersection needs 1..{kernels.MAX_WINDOW} polygons, got {k}")
    max_outliers = int_at_least(max_outliers, 0, "max_outliers")
    # One map of one landmark whose window holds the polygons (the map's own limit on
    # max_outliers does not apply: the kernel takes the cap as an argument).
    maps = BatchedPolygonSLAM(1, 3, 0.1, fusion="relaxed", max_outliers=0, window=k)
    for i, polygon in enumerate(polygons):
        vertices = _polygon(polygon)
        if not 3 <= vertices.size <= kernels.CAPACITY:
            raise ValueError(
                f"polygon {i} must have 3..{kernels.CAPACITY} vertices, got {vertices.size}"
            )
        maps.window_vertices[0, i, 0, : vertices.size] = vertices
        maps.window_counts[0, i, 0] = vertices.size
    union = np.empty(kernels.SCRATCH, dtype=np.complex128)
    slots = np.arange(k, dtype=np.int64)
    n, q = kernels.relaxed_region(maps._kernel_state(), 0, 0, slots, False, max_outliers, union)
    return union[:n].copy(), int(q), maps.window_inlier[0, :, 0].copy()


def robust_levels(polygons: list[ArrayLike]) -> list[ComplexArray]:
    """The robust fusion's nested sets of one landmark's regions ``polygons`` (convex,
    CCW), fused in order: level ``k`` is a convex superset of the points in all of them
    but at most ``k`` (see :mod:`bearing_env.slam.kernels.robust`), for ``k`` below
    ``min(len(polygons), ROBUST_LEVELS)``; an empty array where that set is empty."""
    if not polygons:
        raise ValueError("robust_levels needs at least one polygon, got none")
    maps = BatchedPolygonSLAM(1, 3, 0.1, fusion="robust")
    state = maps._kernel_state()
    for i, polygon in enumerate(polygons):
        vertices = _polygon(polygon)
        if not 3 <= vertices.size <= kernels.CAPACITY:
            raise ValueError(
                f"polygon {i} must have 3..{kernels.CAPACITY} vertices, got {vertices.size}"
            )
        kernels.update_levels(state, 0, 0, vertices)
    levels = min(len(polygons), kernels.ROBUST_LEVELS)
    return [
        maps.level_vertices[0, 0, k, : maps.level_counts[0, 0, k]].copy() for k in range(levels)
    ]


def _polygon(points: ArrayLike) -> ComplexArray:
    return np.ascontiguousarray(np.atleast_1d(np.asarray(points, dtype=np.complex128)).ravel())
