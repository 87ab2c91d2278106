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

The kernels are C++ (``csrc/slam/polygons.cpp``); these are their bindings.
"""

from __future__ import annotations

from bearing_env._core import (
    area_centroid,
    clip_convex,
    contains_point,
    convex_hull,
    drop_edges_outward,
    longest_edge,
    offset_outward,
    polygon_distance,
    simplify,
    small_convex_hull,
    small_hull_indices,
)

__all__ = [
    "area_centroid",
    "clip_convex",
    "contains_point",
    "convex_hull",
    "drop_edges_outward",
    "longest_edge",
    "offset_outward",
    "polygon_distance",
    "simplify",
    "small_convex_hull",
    "small_hull_indices",
]
