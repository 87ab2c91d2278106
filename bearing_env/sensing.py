"""Compiled geometry of a limited sensor among obstacles (numba, pure functions on arrays).

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

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from bearing_env.numerics import JIT_OPTIONS as _JIT
from bearing_env.numerics import wrap

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
#: Obstacles as the kernels take them: ``(vertices (V, 2), starts (k + 1,))``.
Packed = tuple[FloatArray, IntArray]

#: Rounding slack (metres) of the contact tests: a robot left a hair inside an obstacle's
#: margin by rounding counts as touching it.
CONTACT_SLACK = 1e-12


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


@njit(**_JIT)
def _edge_entry(
    x: float,
    y: float,
    dx: float,
    dy: float,
    ax: float,
    ay: float,
    bx: float,
    by: float,
    margin: float,
) -> float:
    """Distance along the ray (unit direction) to where it enters the band of half-width
    ``margin`` on either side of segment ab, through the band's long sides; inf if never."""
    ex, ey = bx - ax, by - ay
    length = math.hypot(ex, ey)
    if length == 0.0:
        return math.inf
    best = math.inf
    for side in (1.0, -1.0):
        nx, ny = -side * ey / length, side * ex / length  # unit normal on this side
        approach = dx * nx + dy * ny
        if approach >= 0.0:
            continue  # moving away from (or along) the edge on this side
        offset = (x - ax) * nx + (y - ay) * ny  # signed distance from the edge's line
        if offset < -CONTACT_SLACK:
            continue  # on the other side: that side's band is the one that counts
        t = max(0.0, (margin - offset) / approach)
        px, py = x + t * dx - ax, y + t * dy - ay
        along = (px * ex + py * ey) / length
        if 0.0 <= along <= length and t < best:
            best = t
    return best


@njit(**_JIT)
def _disc_entry(x: float, y: float, dx: float, dy: float, cx: float, cy: float, r: float) -> float:
    """Distance along the ray (unit direction) to where it enters the disc of radius
    ``r`` about c (0 if it starts inside, heading further in); inf if never."""
    px, py = x - cx, y - cy
    b = px * dx + py * dy
    if b >= 0.0:
        return math.inf  # moving away from the centre
    c = px * px + py * py - r * r
    if c <= CONTACT_SLACK:
        return 0.0
    disc = b * b - c
    if disc < 0.0:
        return math.inf
    return -b - math.sqrt(disc)


@njit(**_JIT)
def free_length(
    x: float, y: float, heading: float, vertices: FloatArray, starts: IntArray, margin: float
) -> float:
    """How far (metres) a robot at (x, y) can go along ``heading`` before its centre comes
    within ``margin`` of an obstacle: the ray's first entry into the obstacles grown by
    ``margin`` (edges shifted out, discs at the vertices); inf without contact."""
    dx, dy = math.cos(heading), math.sin(heading)
    best = math.inf
    for p in range(starts.shape[0] - 1):
        first, last = starts[p], starts[p + 1]
        for k in range(first, last):
            following = k + 1 if k + 1 < last else first
            ax, ay = vertices[k, 0], vertices[k, 1]
            bx, by = vertices[following, 0], vertices[following, 1]
            best = min(best, _edge_entry(x, y, dx, dy, ax, ay, bx, by, margin))
            best = min(best, _disc_entry(x, y, dx, dy, ax, ay, margin))
    return best


@njit(**_JIT)
def _cross(ox: float, oy: float, ax: float, ay: float, bx: float, by: float) -> float:
    return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox)


@njit(**_JIT)
def segments_cross(
    px: float, py: float, qx: float, qy: float, ax: float, ay: float, bx: float, by: float
) -> bool:
    """Whether segments pq and ab share a point (touching counts)."""
    d1, d2 = _cross(ax, ay, bx, by, px, py), _cross(ax, ay, bx, by, qx, qy)
    d3, d4 = _cross(px, py, qx, qy, ax, ay), _cross(px, py, qx, qy, bx, by)
    if ((d1 > 0.0 and d2 < 0.0) or (d1 < 0.0 and d2 > 0.0)) and (
        (d3 > 0.0 and d4 < 0.0) or (d3 < 0.0 and d4 > 0.0)
    ):
        return True
    return (
        (d1 == 0.0 and _on_segment(ax, ay, bx, by, px, py))
        or (d2 == 0.0 and _on_segment(ax, ay, bx, by, qx, qy))
        or (d3 == 0.0 and _on_segment(px, py, qx, qy, ax, ay))
        or (d4 == 0.0 and _on_segment(px, py, qx, qy, bx, by))
    )


@njit(**_JIT)
def _on_segment(ax: float, ay: float, bx: float, by: float, px: float, py: float) -> bool:
    """Whether p, collinear with ab, lies within ab's bounding box."""
    return min(ax, bx) <= px <= max(ax, bx) and min(ay, by) <= py <= max(ay, by)


@njit(**_JIT)
def line_of_sight(
    x: float, y: float, target_x: float, target_y: float, vertices: FloatArray, starts: IntArray
) -> bool:
    """Whether the segment from (x, y) to the target crosses no obstacle edge (both ends
    are outside every obstacle, so crossing an edge is entering an obstacle)."""
    for p in range(starts.shape[0] - 1):
        first, last = starts[p], starts[p + 1]
        for k in range(first, last):
            following = k + 1 if k + 1 < last else first
            if segments_cross(
                x,
                y,
                target_x,
                target_y,
                vertices[k, 0],
                vertices[k, 1],
                vertices[following, 0],
                vertices[following, 1],
            ):
                return False
    return True


@njit(**_JIT)
def visible(
    x: float,
    y: float,
    heading: float,
    target_x: float,
    target_y: float,
    half_fov: float,
    max_range: float,
    vertices: FloatArray,
    starts: IntArray,
) -> bool:
    """Whether a sensor at (x, y) facing ``heading`` sees the target: within ``half_fov``
    (radians; pi or more: panoramic) of the heading, within ``max_range`` metres, and in
    line of sight."""
    if half_fov < math.pi:
        angle = wrap(math.atan2(target_y - y, target_x - x) - heading)
        if abs(angle) > half_fov:
            return False
    if max_range < math.inf and math.hypot(target_x - x, target_y - y) > max_range:
        return False
    return line_of_sight(x, y, target_x, target_y, vertices, starts)


@njit(**_JIT)
def inside_polygon(x: float, y: float, vertices: FloatArray, first: int, last: int) -> bool:
    """Whether (x, y) lies inside the polygon ``vertices[first:last]`` (even-odd rule)."""
    inside = False
    for k in range(first, last):
        following = k + 1 if k + 1 < last else first
        ax, ay = vertices[k, 0], vertices[k, 1]
        bx, by = vertices[following, 0], vertices[following, 1]
        if (ay > y) != (by > y) and x < ax + (y - ay) * (bx - ax) / (by - ay):
            inside = not inside
    return inside


@njit(**_JIT)
def _segment_distance(x: float, y: float, ax: float, ay: float, bx: float, by: float) -> float:
    ex, ey = bx - ax, by - ay
    squared = ex * ex + ey * ey
    t = 0.0 if squared == 0.0 else min(max(((x - ax) * ex + (y - ay) * ey) / squared, 0.0), 1.0)
    return math.hypot(x - ax - t * ex, y - ay - t * ey)


@njit(**_JIT)
def clearance(x: float, y: float, vertices: FloatArray, starts: IntArray) -> float:
    """Distance (metres) from (x, y) to the nearest obstacle; 0 inside one, inf without."""
    best = math.inf
    for p in range(starts.shape[0] - 1):
        first, last = starts[p], starts[p + 1]
        if inside_polygon(x, y, vertices, first, last):
            return 0.0
        for k in range(first, last):
            following = k + 1 if k + 1 < last else first
            best = min(
                best,
                _segment_distance(
                    x,
                    y,
                    vertices[k, 0],
                    vertices[k, 1],
                    vertices[following, 0],
                    vertices[following, 1],
                ),
            )
    return best


@njit(**_JIT)
def visible_rows(
    landmarks: FloatArray,
    positions: FloatArray,
    headings: FloatArray,
    half_fov: float,
    max_range: float,
    vertices: FloatArray,
    starts: IntArray,
    out: NDArray[np.bool_],
) -> None:
    """:func:`visible` for landmarks (N, n, 2) from poses (N, 2), (N,), into ``out`` (N, n)."""
    for i in range(landmarks.shape[0]):
        for j in range(landmarks.shape[1]):
            out[i, j] = visible(
                positions[i, 0],
                positions[i, 1],
                headings[i],
                landmarks[i, j, 0],
                landmarks[i, j, 1],
                half_fov,
                max_range,
                vertices,
                starts,
            )


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
