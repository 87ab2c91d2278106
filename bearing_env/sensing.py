"""Native geometry of a limited sensor among obstacles (C++, ``csrc/sim/sensing.cpp``:
pure functions on arrays).

The simulator's obstacles are polygons, packed for the kernels as one array of vertices
``(V, 2)`` (metres) and the offsets ``(k + 1,)`` where each polygon's vertices start
(polygon ``p`` is ``vertices[starts[p]:starts[p + 1]]``, closed implicitly). No
obstacles are ``(0, 2)`` and ``[0]``.

- :func:`free_length` is how far a robot can go along a ray before its centre comes
  within ``margin`` of an obstacle (the robot's radius, as at the arena walls);
- :func:`line_of_sight` is whether the segment from the robot to a landmark is clear;
- :func:`visible` adds the field of view (about the heading) and the range.

These belong to the simulator (:mod:`bearing_env.world`, the envs' kernels) and to the
planners that predict what the robot will see; the estimator never sees them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env._core import _cross as _cross
from bearing_env._core import _disc_entry as _disc_entry
from bearing_env._core import _edge_entry as _edge_entry
from bearing_env._core import _on_segment as _on_segment
from bearing_env._core import _segment_distance as _segment_distance
from bearing_env._core import clearance as clearance
from bearing_env._core import free_length as free_length
from bearing_env._core import inside_polygon as inside_polygon
from bearing_env._core import line_of_sight as line_of_sight
from bearing_env._core import segments_cross as segments_cross
from bearing_env._core import visible as visible
from bearing_env._core import visible_rows as visible_rows

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
#: Obstacles as the kernels take them: ``(vertices (V, 2), starts (k + 1,))``.
Packed = tuple[FloatArray, IntArray]

#: Rounding slack (metres) of the contact tests: a robot left a hair inside an obstacle's
#: margin by rounding counts as touching it (the native core's value, read from it).
CONTACT_SLACK: float = _core.CONTACT_SLACK


def pack_polygons(polygons: tuple[tuple[tuple[float, float], ...], ...]) -> Packed:
    """Polygons (each a tuple of ``(x, y)`` vertices) as the kernels take them:
    ``(vertices (V, 2), starts (k + 1,))``."""
    starts = np.zeros(len(polygons) + 1, dtype=np.int64)
    for index, polygon in enumerate(polygons):
        starts[index + 1] = starts[index] + len(polygon)
    vertices = np.zeros((int(starts[-1]), 2))
    for index, polygon in enumerate(polygons):
        vertices[starts[index] : starts[index + 1]] = polygon
    return vertices, starts


def landmarks_seen(
    landmarks: FloatArray,
    positions: FloatArray,
    headings: FloatArray,
    half_fov: float,
    max_range: float,
    obstacles: Packed,
) -> NDArray[np.bool_]:
    """:func:`visible_rows` of one set of landmarks (n, 2) from many poses (N, 2), (N,):
    which landmarks each pose sees, (N, n)."""
    count = len(positions)
    out = np.empty((count, len(landmarks)), dtype=bool)
    visible_rows(
        np.ascontiguousarray(np.broadcast_to(landmarks, (count, *np.shape(landmarks)))),
        np.ascontiguousarray(positions, dtype=np.float64),
        np.ascontiguousarray(headings, dtype=np.float64),
        half_fov, max_range, obstacles[0], obstacles[1], out,
    )  # fmt: skip
    return out
