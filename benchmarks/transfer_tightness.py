"""How loose the conservative transfer is: single-movement regions against the exact
transferred sets they bound, measured on a grid.

A landmark's FR region A goes to the landmark frame FL through every pair of hypotheses
h1 in A_L1 and h2 in A_L2; the exact transferred set is
E = {(p - h1) / (h2 - h1) : p in A, h1 in A_L1, h2 in A_L2}. A point w is in E exactly
when A meets (1 - w) A_L1 + w A_L2 (a Minkowski sum of two complex-scaled convex
polygons, so convex), one separating-axis test: :func:`exact_member`, written in numpy
apart from the compiled kernels, so that it can check them.

Each movement is one fresh map's first movement, drawn as the envs draw theirs (the
Khepera layout or a random one, a random start, a move of the default length range,
uniform noise within +-epsilon, epsilon in region-search's range); one landmark's
region after it, as the map update computes it, is measured against E. E's area is
counted on a grid of cell centres over a box that holds E (the box of a dense inner
reference, grown until no border point is in E); the reference is the hull of the
images of 100 samples per edge of A_L1 and A_L2.

    bearing-env transfer-tightness
    bearing-env transfer-tightness --movements 100 --resolution 300 --json tightness.json

Prints the median and 95th percentile of region area / exact area, and how many regions
hold every grid point of E and every vertex of the reference (within the map's relative
containment tolerance); exits with status 1 if any does not.

``--containment-only`` checks containment alone, at scale (about 10 ms a region on one
free core): every region against every image of the dense reference (so every vertex of
its hull) and every point of E on a 24 x 24 grid over the images' box (grown until E is
inside), no areas. It prints the counts (movements drawn, regions, reference images and
grid points of E checked, misses), lists the first misses in full (with the seed and the
draw to replay them), and exits with status 1 on a miss; Ctrl-C stops early and keeps the
counts so far (the --json is written, marked interrupted). ``--merge`` sums the --json
files of runs with different seeds:

    bearing-env transfer-tightness --containment-only --movements 50000 --seed 0 --json c0.json
    bearing-env transfer-tightness --containment-only --merge c0.json c1.json --json all.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from numpy.typing import NDArray

from bearing_env.slam import PolygonSLAM
from bearing_env.slam.audit import SearchSettings, contains
from bearing_env.slam.batch import CONTAINMENT_TOLERANCE
from bearing_env.slam.geometry import FR_BOUNDED, cone_region
from bearing_env.slam.transfer import TRANSFERS
from bearing_env.train.common.cli_parser import (
    add_json_output,
    add_no_progress,
    command_parser,
    doc_summary,
)
from bearing_env.train.common.cli_values import COUNT, SEED, at_least
from bearing_env.train.common.errors import exit_on_output_errors
from bearing_env.train.common.files import write_json_atomically
from bearing_env.train.common.progress import progress_bar
from bearing_env.train.common.provenance import measured_here
from bearing_env.world import SCENARIOS, Arena, NoiseModel, World, random_layout, random_start

ComplexArray = NDArray[np.complex128]
FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: The layouts drawn, with equal odds.
LAYOUTS = ("khepera", "random")
#: Landmark counts of a random layout (L1, L2 and 1 to 6 others).
RANDOM_LANDMARKS = (3, 8)
#: Samples per edge of A_L1 and A_L2 for the dense inner reference.
REFERENCE_SAMPLES = 100
#: The grid box's first margin around the reference's box, relative to its size; it
#: doubles while E reaches the border (E lies within the transfer's sagitta bound of the
#: reference's hull, which at 100 samples per edge is far inside 2%).
BOX_MARGIN = 0.02
BOX_GROWTHS = 8
#: Regions whose area is also counted at twice the resolution, to show the grid's error.
RESOLUTION_CHECKS = 16
#: Grid points tested per numpy call (bounds the temporaries to tens of MB).
CHUNK = 20_000
#: :func:`region_holds_all`: patches of BLOCK x BLOCK images (of neighbouring samples of
#: L1 and L2) go in one test, when their box lies INNER_MARGIN (relative to the region's
#: size, far above rounding) inside every edge of the region.
BLOCK = 10
INNER_MARGIN = 1e-12
#: Grid points per side of E's box in the containment-only check (--containment-only).
CONTAINMENT_RESOLUTION = 24
#: Misses listed in full (printed and in the JSON).
MISSES_LISTED = 10


# ----------------------------------------------------------------------------------------
# The exact transferred set
# ----------------------------------------------------------------------------------------


def edges(polygon: ComplexArray) -> ComplexArray:
    """The edge vectors of a polygon (a point's single edge is 0)."""
    return np.roll(polygon, -1) - polygon


def exact_member(
    w: ComplexArray, target: ComplexArray, a1: ComplexArray, a2: ComplexArray
) -> BoolArray:
    """Whether each FL point ``w`` is in the exact transferred set of the convex FR region
    ``target`` given the convex FR regions ``a1`` and ``a2`` of L1 and L2.

    ``w`` is in it when ``target`` meets M(w) = (1 - w) a1 + w a2, which is convex. Two
    convex polygons are disjoint exactly when their projections on some edge normal of
    one of them are disjoint, and M(w)'s edges are those of (1 - w) a1 and of w a2: so
    the normals of ``target``, (1 - w) a1 and w a2 are the only axes to try, and M(w)'s
    projection is the sum of its two parts' (no hull is needed). Touching counts as
    meeting.
    """
    w = np.asarray(w, dtype=np.complex128)[..., None]
    normals = np.concatenate(
        [
            np.broadcast_to(1j * edges(target), (*w.shape[:-1], target.size)),
            1j * (1.0 - w) * edges(a1),
            1j * w * edges(a2),
        ],
        axis=-1,
    )
    axis = np.conj(normals)[..., None]
    along_target = (axis * target).real
    along_first = (axis * (1.0 - w[..., None]) * a1).real
    along_second = (axis * w[..., None] * a2).real
    low = along_first.min(axis=-1) + along_second.min(axis=-1)
    high = along_first.max(axis=-1) + along_second.max(axis=-1)
    separated = (along_target.max(axis=-1) < low) | (high < along_target.min(axis=-1))
    return ~separated.any(axis=-1)


def minkowski_sum(p: ComplexArray, q: ComplexArray) -> ComplexArray:
    """The Minkowski sum of two convex polygons: the hull (CCW, shapely's) of every sum
    of a vertex of ``p`` and one of ``q``."""
    sums = (p[:, None] + q[None, :]).ravel()
    hull = shapely.convex_hull(shapely.multipoints(np.stack([sums.real, sums.imag], -1)))
    return polygon_vertices(hull)


def polygon_vertices(geometry: shapely.Geometry) -> ComplexArray:
    """The CCW vertices of a shapely polygon (the points of a point or a segment)."""
    if isinstance(geometry, shapely.Polygon):
        geometry = shapely.geometry.polygon.orient(geometry)
        xy = np.asarray(geometry.exterior.coords)[:-1]
    else:
        xy = shapely.get_coordinates(geometry)
    return np.ascontiguousarray(xy[:, 0] + 1j * xy[:, 1])


def boundary_points(polygon: ComplexArray, per_edge: int) -> ComplexArray:
    """``per_edge`` evenly spaced points on each edge of a polygon, from its first vertex."""
    steps = np.arange(per_edge) / per_edge
    return (polygon[:, None] + steps[None, :] * edges(polygon)[:, None]).ravel()


def reference_images(
    target: ComplexArray, a1: ComplexArray, a2: ComplexArray, per_edge: int = REFERENCE_SAMPLES
) -> ComplexArray:
    """The images of ``target``'s vertices under the hypotheses at ``per_edge`` samples
    per edge of ``a1`` and ``a2``, the points whose hull is :func:`reference_hull`: an
    array (target vertex, sample of L1, sample of L2)."""
    h1 = boundary_points(a1, per_edge)
    h2 = boundary_points(a2, per_edge)
    return (target[:, None, None] - h1[None, :, None]) / (h2 - h1[:, None])


def reference_hull(
    target: ComplexArray, a1: ComplexArray, a2: ComplexArray, per_edge: int = REFERENCE_SAMPLES
) -> ComplexArray:
    """An inner reference for the exact set's hull: the hull (CCW) of the images of
    ``target``'s vertices under the hypotheses at ``per_edge`` samples per edge of ``a1``
    and ``a2`` (the hull of the exact set is attained on the boundaries, and an image is
    affine in the target point)."""
    images = reference_images(target, a1, a2, per_edge).ravel()
    # One linestring through the images: shapely builds it from the array in one go,
    # where a multipoint makes a geometry per point (ten times slower); the hull is the same.
    path = shapely.linestrings(np.stack([images.real, images.imag], axis=-1))
    return polygon_vertices(shapely.convex_hull(path))


# ----------------------------------------------------------------------------------------
# Movements
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Movement:
    """One landmark's single-movement region and what made it: the FR regions (CCW
    complex vertices, R1 = 0, R2 = 1) of the landmark and of L1 and L2, its true FL
    position, and the map's FL region after the movement."""

    layout: str
    epsilon: float
    landmark: int  #: the landmark's index (>= 2: L1 and L2 are 0 and 1)
    target_fr: ComplexArray
    l1_fr: ComplexArray
    l2_fr: ComplexArray
    truth_fl: complex
    region: ComplexArray


@dataclass(frozen=True)
class Mapping:
    """How the measured map transfers its regions (:class:`PolygonSLAM`'s arguments)."""

    transfer: str = "conservative"
    edge_samples: int = 3


def draw_movement(rng: np.random.Generator, mapping: Mapping | None = None) -> Movement | str:
    """A fresh map's first movement, drawn from ``rng`` with the world's own generators;
    one of the landmarks it updated, drawn uniformly. When it gives no region, why not:
    ``"no_move"`` (the robot faced a wall), the map's frame status (``"l1_l2_too_close"``,
    ...) or ``"no_landmark_updated"``."""
    layout = str(rng.choice(LAYOUTS))
    scenario = SCENARIOS[layout]
    arena = Arena(*scenario.arena_size)
    if scenario.landmarks is not None:
        landmarks = np.array(scenario.landmarks)
    else:
        low, high = RANDOM_LANDMARKS
        landmarks = random_layout(rng, arena, int(rng.integers(low, high + 1)))
    position, heading = random_start(rng, arena, landmarks)
    epsilon = math.radians(rng.uniform(*SearchSettings().epsilon_deg))
    world = World(arena, landmarks, position, heading, NoiseModel(), epsilon)
    bearings_start = world.read_bearings(rng)
    moved = world.move(float(rng.uniform(*arena.default_move_length)))
    if moved.travelled < arena.min_baseline:
        return "no_move"
    bearings_end = world.read_bearings(rng)
    mapping = mapping or Mapping()
    slam = PolygonSLAM(
        len(landmarks), epsilon, transfer=mapping.transfer, edge_samples=mapping.edge_samples
    )
    result = slam.update(bearings_start, bearings_end)
    updated = np.flatnonzero(result.landmark_status == "updated")
    if not result.frame_changed:
        return result.frame_status
    if updated.size == 0:
        return "no_landmark_updated"
    landmark = int(rng.choice(updated)) + 2
    cones = []
    for index in (landmark, 0, 1):
        vertices, status = cone_region(bearings_start[index], bearings_end[index], epsilon)
        if status != FR_BOUNDED:  # the map updated it, so its cones were bounded
            raise AssertionError(f"landmark {index}'s FR region is not bounded ({status})")
        cones.append(vertices)
    world_points = landmarks[:, 0] + 1j * landmarks[:, 1]
    region = slam.polygons[landmark - 2]
    assert region is not None  # updated, so initialised
    return Movement(
        layout=layout,
        epsilon=epsilon,
        landmark=landmark,
        target_fr=cones[0],
        l1_fr=cones[1],
        l2_fr=cones[2],
        truth_fl=complex(
            (world_points[landmark] - world_points[0]) / (world_points[1] - world_points[0])
        ),
        region=np.ascontiguousarray(region[:, 0] + 1j * region[:, 1]),
    )


# ----------------------------------------------------------------------------------------
# Measuring one region
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Measurement:
    """One region against its exact set (areas in FL units squared)."""

    layout: str
    epsilon_deg: float
    region_area: float
    exact_area: float  #: grid points in E times the cell area
    reference_area: float  #: the dense inner reference's hull
    #: The grid's error bound, relative to ``exact_area``: only cells with a neighbour
    #: on the other side of E's boundary can be miscounted, each by at most one cell.
    grid_error_bound: float
    grid_points_in_e: int
    box_growths: int
    holds_grid: bool  #: every grid point of E is in the region
    holds_reference: bool  #: every vertex of the reference is in the region
    truth_in_e: bool  #: a check of the test: noise within +-epsilon puts the truth in E
    #: The region as K support values in fixed FL directions (its circumscribed K-gon,
    #: the other representation a transfer could keep): the K-gon's area, by K.
    fixed_direction_areas: dict[str, float] = field(default_factory=dict)

    @property
    def ratio(self) -> float:
        return self.region_area / self.exact_area

    @property
    def contained(self) -> bool:
        return self.holds_grid and self.holds_reference


@dataclass(frozen=True)
class Grid:
    """Cell centres over a box: ``points`` (rows, columns) complex and the cell area."""

    points: ComplexArray
    cell_area: float


def grid_over(low: complex, high: complex, resolution: int) -> Grid:
    """A ``resolution`` x ``resolution`` grid of cell centres over the box [low, high]."""
    steps = (np.arange(resolution) + 0.5) / resolution
    x = low.real + steps * (high.real - low.real)
    y = low.imag + steps * (high.imag - low.imag)
    cell = (high.real - low.real) * (high.imag - low.imag) / resolution**2
    return Grid(x[None, :] + 1j * y[:, None], cell)


def members_on(grid: Grid, movement: Movement) -> BoolArray:
    """:func:`exact_member` of every grid point, a chunk of points at a time."""
    flat = grid.points.ravel()
    inside = np.empty(flat.size, dtype=bool)
    for start in range(0, flat.size, CHUNK):
        inside[start : start + CHUNK] = exact_member(
            flat[start : start + CHUNK], movement.target_fr, movement.l1_fr, movement.l2_fr
        )
    return inside.reshape(grid.points.shape)


def exact_grid(
    movement: Movement, reference: ComplexArray, resolution: int
) -> tuple[Grid, BoolArray, int]:
    """The grid over a box that holds E, E's points on it, and how often the box grew
    (the first box is ``reference``'s, grown by :data:`BOX_MARGIN`)."""
    low = complex(reference.real.min(), reference.imag.min())
    high = complex(reference.real.max(), reference.imag.max())
    size = max(high.real - low.real, high.imag - low.imag)
    margin = BOX_MARGIN * size
    for growths in range(BOX_GROWTHS + 1):
        grid = grid_over(low - margin * (1 + 1j), high + margin * (1 + 1j), resolution)
        inside = members_on(grid, movement)
        border = inside[0].any() or inside[-1].any() or inside[:, 0].any() or inside[:, -1].any()
        if not border:
            return grid, inside, growths
        margin *= 2.0
    raise RuntimeError(f"E still reaches the grid's border after {BOX_GROWTHS} growths")


def boundary_cells(inside: BoolArray) -> int:
    """Points of E with a 4-neighbour outside it (the box's border holds none of E)."""
    padded = np.pad(inside, 1)
    neighbours_in = padded[:-2, 1:-1] & padded[2:, 1:-1] & padded[1:-1, :-2] & padded[1:-1, 2:]
    return int((inside & ~neighbours_in).sum())


def region_holds(region: ComplexArray, points: ComplexArray) -> bool:
    """Whether the convex CCW ``region`` holds every point, within the map's relative
    containment tolerance (the audit's numpy test, not the kernels')."""
    if points.size == 0:
        return True
    counts = np.array([region.size])
    return bool(contains(region[None], counts, points, CONTAINMENT_TOLERANCE).all())


def region_holds_all(region: ComplexArray, images: ComplexArray, block: int = BLOCK) -> bool:
    """:func:`region_holds` of every one of :func:`reference_images` (an array whose last
    two axes are samples of L1 and of L2), fast: the images of ``block`` x ``block``
    neighbouring pairs of samples (a small patch) hold together when their bounding box
    lies strictly inside the convex region, and so does an image strictly inside it;
    :func:`region_holds` decides the others (usually none). The same answer, for 640,000
    images in a few ms."""
    rows, columns = images.shape[-2:]
    if region.size < 3 or rows % block or columns % block or not images.flags.c_contiguous:
        return region_holds(region, images.ravel())
    # Real and imaginary parts side by side (a view): the rows of a patch reduce first,
    # along the contiguous last axis, many times faster than over a short last axis.
    parts = images.view(np.float64).reshape(-1, block, 2 * columns)
    boxes = []
    for extreme in (np.minimum, np.maximum):
        strips = extreme.reduce(parts, axis=1).reshape(-1, columns // block, block, 2)
        box = strips[:, :, 0].copy()  # then over the patch's columns, one at a time
        for step in range(1, block):
            extreme(box, strips[:, :, step], out=box)
        boxes.append(box.reshape(-1, 2))
    (low_x, low_y), (high_x, high_y) = (box.T[:, :, None] for box in boxes)
    inside = _strictly_inside(region, low_x, high_x, low_y, high_y)
    if inside.all():
        return True
    # The images of the other patches: those strictly inside hold too.
    patches = images.reshape(-1, block, columns // block, block)
    first, column = np.divmod(np.flatnonzero(~inside), columns // block)
    rest = patches[first, :, column, :].ravel()
    x, y = rest.real[:, None], rest.imag[:, None]
    return region_holds(region, rest[~_strictly_inside(region, x, x, y, y)])


def _strictly_inside(
    region: ComplexArray,
    low_x: FloatArray,
    high_x: FloatArray,
    low_y: FloatArray,
    high_y: FloatArray,
) -> BoolArray:
    """Whether each box (columns of corners, shaped (n, 1)) lies at least INNER_MARGIN of
    the size inside every edge of the convex CCW ``region``."""
    steps = np.roll(region, -1) - region
    # cross(step, z - vertex) = a x + b y - c = |step| x (z's distance inside the edge's
    # line); a box's least a x + b y is at the corner that a's and b's signs pick.
    a, b = -steps.imag, steps.real
    size = max(np.ptp(region.real), np.ptp(region.imag))
    c = steps.real * region.imag - steps.imag * region.real + INNER_MARGIN * size * np.abs(steps)
    if low_x is high_x and low_y is high_y:  # points
        least = a * low_x + b * low_y
    else:
        least = np.where(a > 0, a * low_x, a * high_x) + np.where(b > 0, b * low_y, b * high_y)
    return (least > c).all(axis=1)


def worst_excess(region: ComplexArray, points: ComplexArray) -> tuple[int, float]:
    """How many points lie outside the convex CCW ``region`` beyond the containment
    tolerance, and the farthest one's distance outside, relative to the region's size."""
    points = points.ravel()
    size = max(np.ptp(region.real), np.ptp(region.imag))
    steps = np.roll(region, -1) - region
    outside = np.zeros(points.size)
    for start in range(0, points.size, CHUNK):
        offsets = points[start : start + CHUNK, None] - region
        distance = (steps.real * offsets.imag - steps.imag * offsets.real) / np.abs(steps)
        outside[start : start + CHUNK] = -distance.min(axis=1) / size
    return int((outside > CONTAINMENT_TOLERANCE).sum()), float(outside.max(initial=0.0))


def measure(movement: Movement, reference: ComplexArray, resolution: int) -> Measurement:
    """One region against its exact set, on a ``resolution`` x ``resolution`` grid, and
    against the inner ``reference`` (:func:`reference_hull`)."""
    grid, inside, growths = exact_grid(movement, reference, resolution)
    count = int(inside.sum())
    exact_area = count * grid.cell_area
    truth = np.array([movement.truth_fl])
    return Measurement(
        layout=movement.layout,
        epsilon_deg=math.degrees(movement.epsilon),
        region_area=float(shapely.Polygon(_xy(movement.region)).area),
        exact_area=exact_area,
        reference_area=float(shapely.Polygon(_xy(reference)).area),
        grid_error_bound=boundary_cells(inside) / max(count, 1),
        grid_points_in_e=count,
        box_growths=growths,
        holds_grid=region_holds(movement.region, grid.points[inside]),
        holds_reference=region_holds(movement.region, reference),
        truth_in_e=bool(exact_member(truth, movement.target_fr, movement.l1_fr, movement.l2_fr)[0]),
        fixed_direction_areas={
            str(k): circumscribed_area(movement.region, k) for k in FIXED_DIRECTIONS
        },
    )


#: The direction counts of the fixed-direction representation measured beside the hull.
FIXED_DIRECTIONS = (12, 16, 24)


def circumscribed_area(region: ComplexArray, directions: int) -> float:
    """Area of the convex region's circumscribed polygon whose edge normals are
    ``directions`` fixed directions, evenly spaced: the intersection of the half-planes
    ``<u_k, w> <= max over the region of <u_k, w>``. Each of them touches the region, so
    the vertices are the crossings of consecutive lines."""
    normals = np.exp(2j * np.pi * np.arange(directions) / directions)
    support = (region[None, :] * np.conj(normals[:, None])).real.max(axis=1)
    following = np.roll(normals, -1)
    support_next = np.roll(support, -1)
    # w = x n_k + y i n_k with x = h_k; <n_{k+1}, w> = h_{k+1} gives y.
    cos_turn = (following * np.conj(normals)).real
    sin_turn = (following * np.conj(normals)).imag
    along = (support_next - support * cos_turn) / sin_turn
    vertices = normals * (support + 1j * along)
    x, y = vertices.real, vertices.imag
    return float(0.5 * np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _xy(points: ComplexArray) -> FloatArray:
    return np.stack([points.real, points.imag], axis=-1)


# ----------------------------------------------------------------------------------------
# The run
# ----------------------------------------------------------------------------------------


@dataclass
class TightnessRun:
    """The measurements of a run, and why the movements that gave no region did not."""

    measurements: list[Measurement]
    #: |area at the resolution / area at twice it - 1| for the first regions.
    resolution_checks: list[float]
    movements_drawn: int
    no_region: dict[str, int]
    seconds: float


def run(
    movements: int,
    seed: int,
    resolution: int,
    progress: bool = False,
    mapping: Mapping | None = None,
) -> TightnessRun:
    """Measure ``movements`` single-movement regions drawn from ``seed``, transferred
    with ``mapping`` (the map's defaults if None)."""
    rng = np.random.default_rng(seed)
    measurements: list[Measurement] = []
    checks: list[float] = []
    drawn = 0
    no_region: dict[str, int] = {}
    began = time.perf_counter()
    with progress_bar(movements, desc="regions", unit="region", enabled=progress) as bar:
        while len(measurements) < movements:
            drawn += 1
            movement = draw_movement(rng, mapping)
            if isinstance(movement, str):
                no_region[movement] = no_region.get(movement, 0) + 1
                continue
            reference = reference_hull(movement.target_fr, movement.l1_fr, movement.l2_fr)
            measurement = measure(movement, reference, resolution)
            measurements.append(measurement)
            if len(checks) < RESOLUTION_CHECKS:
                grid, inside, _ = exact_grid(movement, reference, 2 * resolution)
                finer = int(inside.sum()) * grid.cell_area
                checks.append(abs(measurement.exact_area / finer - 1.0))
            bar.update(1)
    return TightnessRun(measurements, checks, drawn, no_region, time.perf_counter() - began)


def summary(result: TightnessRun) -> dict[str, Any]:
    """The figures of a run: ratios' quantiles, containment fractions, the grid's error."""
    found = result.measurements
    ratios = np.array([m.ratio for m in found])
    to_reference = np.array([m.region_area / m.reference_area for m in found])
    bounds = np.array([m.grid_error_bound for m in found])
    exact = np.array([m.exact_area for m in found])
    fixed = {
        str(k): np.array([m.fixed_direction_areas[str(k)] for m in found]) for k in FIXED_DIRECTIONS
    }
    return {
        "regions": len(found),
        "movements_drawn": result.movements_drawn,
        "no_region": dict(sorted(result.no_region.items())),
        "ratio_median": float(np.median(ratios)),
        "ratio_p95": float(np.percentile(ratios, 95)),
        "ratio_min": float(ratios.min()),
        "ratio_max": float(ratios.max()),
        "ratio_to_reference_median": float(np.median(to_reference)),
        "ratio_to_reference_p95": float(np.percentile(to_reference, 95)),
        "exact_over_reference_median": float(np.median(to_reference / ratios)),
        "contains_grid": float(np.mean([m.holds_grid for m in found])),
        "contains_reference": float(np.mean([m.holds_reference for m in found])),
        "contains_both": float(np.mean([m.contained for m in found])),
        "truth_in_exact_set": float(np.mean([m.truth_in_e for m in found])),
        "grid_error_bound_median": float(np.median(bounds)),
        "grid_error_bound_p95": float(np.percentile(bounds, 95)),
        "resolution_check_max": max(result.resolution_checks, default=0.0),
        "fixed_directions": {
            str(k): {
                "ratio_median": float(np.median(fixed[str(k)] / exact)),
                "ratio_p95": float(np.percentile(fixed[str(k)] / exact, 95)),
            }
            for k in FIXED_DIRECTIONS
        },
        "seconds": result.seconds,
    }


def format_summary(figures: dict[str, Any], resolution: int) -> list[str]:
    return [
        f"{figures['regions']} regions from {figures['movements_drawn']} movements "
        f"(no region: {figures['no_region']}), E on a {resolution}x{resolution} grid "
        f"({figures['seconds']:.0f} s)",
        f"region area / exact area: median {figures['ratio_median']:.3g}, "
        f"95th percentile {figures['ratio_p95']:.3g} "
        f"(min {figures['ratio_min']:.3g}, max {figures['ratio_max']:.3g})",
        "as support values in fixed directions: "
        + ", ".join(
            f"K = {k}: median {entry['ratio_median']:.3g}, 95th percentile {entry['ratio_p95']:.3g}"
            for k, entry in figures["fixed_directions"].items()
        ),
        f"region area / reference hull area: median "
        f"{figures['ratio_to_reference_median']:.3g}, "
        f"95th percentile {figures['ratio_to_reference_p95']:.3g}",
        f"regions holding every grid point of E: {100 * figures['contains_grid']:.1f}%; "
        f"every reference vertex: {100 * figures['contains_reference']:.1f}%",
        f"grid error of E's area: bound median {100 * figures['grid_error_bound_median']:.2g}%, "
        f"95th percentile {100 * figures['grid_error_bound_p95']:.2g}%; against twice the "
        f"resolution at most {100 * figures['resolution_check_max']:.2g}%",
    ]


# ----------------------------------------------------------------------------------------
# Containment only, at scale
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ContainmentCheck:
    """One region against every image of the dense reference and every point of E on a
    coarse grid (no areas)."""

    reference_images: int  #: images checked: every vertex of the reference is one
    grid_points_in_e: int
    box_growths: int
    holds_reference: bool
    holds_grid: bool

    @property
    def contained(self) -> bool:
        return self.holds_reference and self.holds_grid


def check_containment(
    movement: Movement, resolution: int = CONTAINMENT_RESOLUTION
) -> ContainmentCheck:
    """Whether the region holds every image of :func:`reference_images` (so the whole
    dense reference, :func:`reference_hull`: the region is convex) and every point of E on
    a ``resolution`` x ``resolution`` grid over the images' box, grown until E is inside."""
    images = reference_images(movement.target_fr, movement.l1_fr, movement.l2_fr)
    grid, inside, growths = exact_grid(movement, _box(images), resolution)
    points = grid.points[inside]
    return ContainmentCheck(
        reference_images=images.size,
        grid_points_in_e=points.size,
        box_growths=growths,
        holds_reference=region_holds_all(movement.region, images),
        holds_grid=region_holds(movement.region, points),
    )


def _box(points: ComplexArray) -> ComplexArray:
    """The two corners of the points' bounding box."""
    x, y = points.real, points.imag
    return np.array([complex(x.min(), y.min()), complex(x.max(), y.max())])


def describe_miss(
    movement: Movement, check: ContainmentCheck, seed: int, draw: int, resolution: int
) -> dict[str, Any]:
    """A miss in full: where it was drawn (the ``draw``-th movement from ``seed``), what
    failed and by how much, and the regions to replay it."""
    images = reference_images(movement.target_fr, movement.l1_fr, movement.l2_fr)
    grid, inside, _ = exact_grid(movement, _box(images), resolution)
    reference_out, reference_worst = worst_excess(movement.region, images)
    grid_out, grid_worst = worst_excess(movement.region, grid.points[inside])
    return {
        "seed": seed,
        "draw": draw,
        "layout": movement.layout,
        "epsilon_deg": math.degrees(movement.epsilon),
        "landmark": movement.landmark,
        **asdict(check),
        "reference_images_outside": reference_out,
        "reference_worst_outside": reference_worst,  #: relative to the region's size
        "grid_points_outside": grid_out,
        "grid_worst_outside": grid_worst,
        "truth_fl": [movement.truth_fl.real, movement.truth_fl.imag],
        "target_fr": _xy(movement.target_fr).tolist(),
        "l1_fr": _xy(movement.l1_fr).tolist(),
        "l2_fr": _xy(movement.l2_fr).tolist(),
        "region": _xy(movement.region).tolist(),
    }


@dataclass
class ContainmentRun:
    """The counts of a containment-only run (Ctrl-C ends it early, counts kept)."""

    movements_drawn: int = 0
    regions: int = 0
    reference_images_checked: int = 0
    grid_points_in_e_checked: int = 0
    box_growths_max: int = 0
    misses: int = 0
    reference_misses: int = 0
    grid_misses: int = 0
    no_region: dict[str, int] = field(default_factory=dict)
    first_misses: list[dict[str, Any]] = field(default_factory=list)
    interrupted: bool = False
    seconds: float = 0.0


def run_containment(
    movements: int,
    seed: int,
    resolution: int = CONTAINMENT_RESOLUTION,
    progress: bool = False,
    mapping: Mapping | None = None,
) -> ContainmentRun:
    """Check ``movements`` single-movement regions drawn from ``seed`` (transferred with
    ``mapping``) for containment only; Ctrl-C stops early with the counts so far."""
    rng = np.random.default_rng(seed)
    found = ContainmentRun()
    began = time.perf_counter()
    with progress_bar(movements, desc="containment", unit="region", enabled=progress) as bar:
        try:
            while found.regions < movements:
                movement = draw_movement(rng, mapping)
                found.movements_drawn += 1
                if isinstance(movement, str):
                    found.no_region[movement] = found.no_region.get(movement, 0) + 1
                    continue
                check = check_containment(movement, resolution)
                found.regions += 1
                found.reference_images_checked += check.reference_images
                found.grid_points_in_e_checked += check.grid_points_in_e
                found.box_growths_max = max(found.box_growths_max, check.box_growths)
                if not check.contained:
                    found.misses += 1
                    found.reference_misses += not check.holds_reference
                    found.grid_misses += not check.holds_grid
                    if len(found.first_misses) < MISSES_LISTED:
                        found.first_misses.append(
                            describe_miss(movement, check, seed, found.movements_drawn, resolution)
                        )
                bar.update(1)
        except KeyboardInterrupt:
            found.interrupted = True
            print("interrupted: the counts cover what was checked so far", file=sys.stderr)
    found.seconds = time.perf_counter() - began
    return found


def containment_summary(found: ContainmentRun) -> dict[str, Any]:
    """A containment run's counts (no list of misses)."""
    figures = {k: v for k, v in asdict(found).items() if k != "first_misses"}
    figures["no_region"] = dict(sorted(found.no_region.items()))
    figures["ms_per_region"] = 1e3 * found.seconds / max(found.regions, 1)
    return figures


def merge_containment(payloads: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """One summary of containment runs with different seeds (their JSON payloads): counts
    summed, the largest box growth, the misses listed up to :data:`MISSES_LISTED`."""
    keys = ("transfer", "edge_samples", "resolution", "reference_samples_per_edge")
    first = payloads[0]["settings"]
    for payload in payloads[1:]:
        if any(payload["settings"][key] != first[key] for key in keys):
            raise ValueError(f"runs with different settings: {first} and {payload['settings']}")
    seeds = [payload["settings"]["seed"] for payload in payloads]
    if len(set(seeds)) != len(seeds):
        raise ValueError(f"runs with the same seed: {seeds}")
    merged = ContainmentRun()
    for payload in payloads:
        figures = payload["summary"]
        for name in (
            "movements_drawn", "regions", "reference_images_checked",
            "grid_points_in_e_checked", "misses", "reference_misses", "grid_misses", "seconds",
        ):  # fmt: skip
            setattr(merged, name, getattr(merged, name) + figures[name])
        merged.box_growths_max = max(merged.box_growths_max, figures["box_growths_max"])
        merged.interrupted |= figures["interrupted"]
        for reason, count in figures["no_region"].items():
            merged.no_region[reason] = merged.no_region.get(reason, 0) + count
        merged.first_misses += payload["misses"]
    merged.first_misses = merged.first_misses[:MISSES_LISTED]
    return {
        "settings": {key: first[key] for key in keys} | {"seeds": seeds},
        "summary": containment_summary(merged) | {"seconds_summed_over_runs": True},
        "misses": merged.first_misses,
    }


def format_containment(figures: dict[str, Any], transfer: str, resolution: int) -> list[str]:
    lines = [
        f"{figures['regions']:,} regions from {figures['movements_drawn']:,} movements "
        f"(no region: {figures['no_region']}), transfer {transfer}"
        + (" (interrupted)" if figures["interrupted"] else ""),
        f"checked: {figures['reference_images_checked']:,} reference images "
        f"({REFERENCE_SAMPLES} samples per edge; every reference vertex is one) and "
        f"{figures['grid_points_in_e_checked']:,} grid points of E ({resolution}x{resolution} "
        f"grid, box grown at most {figures['box_growths_max']} times)",
        f"misses: {figures['misses']:,} regions ({figures['reference_misses']:,} not holding "
        f"the reference, {figures['grid_misses']:,} not holding E's grid points), within "
        f"{CONTAINMENT_TOLERANCE:g} of the region's size "
        f"({figures['seconds']:.0f} s, {figures['ms_per_region']:.1f} ms per region)",
    ]
    return lines


def run_settings(args: argparse.Namespace, resolution: int, mapping: Mapping) -> dict[str, Any]:
    """What a run was drawn and measured with, for its JSON."""
    return {
        "movements": args.movements,
        "seed": args.seed,
        "resolution": resolution,
        "transfer": mapping.transfer,
        "edge_samples": mapping.edge_samples,
        "reference_samples_per_edge": REFERENCE_SAMPLES,
        "containment_tolerance": CONTAINMENT_TOLERANCE,
        "layouts": list(LAYOUTS),
        "epsilon_deg": list(SearchSettings().epsilon_deg),
    }


def main_containment(
    parser: argparse.ArgumentParser, args: argparse.Namespace, arguments: list[str]
) -> None:
    """``--containment-only`` (and ``--merge``): print the counts, write the JSON, exit 1
    on a miss."""
    measured = measured_here(parser.prog, arguments)
    if args.merge:
        payloads = []
        for path in args.merge:
            with exit_on_output_errors(parser, path, "--merge", refusals=()):
                payloads.append(json.loads(path.read_text(encoding="utf-8")))
        try:
            merged = merge_containment(payloads)
        except (KeyError, ValueError) as error:
            parser.error(f"--merge: {error}")
        figures, misses = merged["summary"], merged["misses"]
        transfer, resolution = merged["settings"]["transfer"], merged["settings"]["resolution"]
        payload = {"measured": measured, **merged, "runs": payloads}
    else:
        resolution = args.resolution or CONTAINMENT_RESOLUTION
        mapping = Mapping(args.transfer, args.edge_samples)
        found = run_containment(
            args.movements, args.seed, resolution, not args.no_progress, mapping
        )
        figures, misses = containment_summary(found), found.first_misses
        transfer = mapping.transfer
        payload = {
            "measured": measured,
            "settings": run_settings(args, resolution, mapping),
            "summary": figures,
            "misses": misses,
        }
    print("\n".join(format_containment(figures, transfer, resolution)))
    for miss in misses:
        print(f"not contained: {json.dumps(miss)}")
    if args.json:
        with exit_on_output_errors(parser, Path(args.json), "--json", refusals=()):
            write_json_atomically(Path(args.json), payload)
        print(f"wrote {args.json}")
    if figures["misses"]:
        sys.exit(1)


def make_parser() -> argparse.ArgumentParser:
    parser = command_parser("bearing-env transfer-tightness", doc_summary(__doc__))
    parser.add_argument(
        "--movements",
        type=COUNT,
        default=628,
        help="single-movement regions to measure, one per movement (default %(default)s)",
    )
    parser.add_argument(
        "--resolution",
        type=at_least(8),
        default=None,
        help=f"grid points per side of E's box (default 200; {CONTAINMENT_RESOLUTION} with "
        "--containment-only)",
    )
    parser.add_argument("--seed", type=SEED, default=0, help="movement seed (default %(default)s)")
    parser.add_argument(
        "--transfer",
        choices=TRANSFERS,
        default="conservative",
        help="the map's transfer (default %(default)s)",
    )
    parser.add_argument(
        "--edge-samples",
        type=at_least(1),
        default=3,
        help="the map's samples per edge (default %(default)s)",
    )
    parser.add_argument(
        "--containment-only",
        action="store_true",
        help="check containment only, at scale: every region against every image of the "
        f"dense reference and E's points on a {CONTAINMENT_RESOLUTION}x"
        f"{CONTAINMENT_RESOLUTION} grid, no areas; prints the counts and the misses",
    )
    parser.add_argument(
        "--merge",
        type=Path,
        nargs="+",
        metavar="PATH",
        default=None,
        help="with --containment-only: sum the --json files of runs with different seeds "
        "into one summary instead of running (default: none)",
    )
    add_json_output(parser, "the figures and every region's measurement")
    add_no_progress(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    parser = make_parser()
    arguments = list(sys.argv[1:] if argv is None else argv)
    args = parser.parse_args(arguments)
    if args.merge and not args.containment_only:
        parser.error("--merge goes with --containment-only")
    if args.json:  # an unwritable --json fails before the measurement, in one line
        with exit_on_output_errors(parser, Path(args.json), "--json", refusals=()):
            Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    if args.containment_only:
        main_containment(parser, args, arguments)
        return
    args.resolution = args.resolution or 200
    mapping = Mapping(args.transfer, args.edge_samples)
    result = run(
        args.movements, args.seed, args.resolution, progress=not args.no_progress, mapping=mapping
    )
    figures = summary(result)
    print("\n".join(format_summary(figures, args.resolution)))
    misses = [asdict(m) for m in result.measurements if not m.contained]
    for miss in misses[:10]:
        print(f"not contained: {miss!r}")
    if args.json:
        payload = {
            "measured": measured_here(parser.prog, arguments),
            "settings": run_settings(args, args.resolution, mapping),
            "summary": figures,
            "resolution_checks": result.resolution_checks,
            "regions": [asdict(m) for m in result.measurements],
        }
        with exit_on_output_errors(parser, Path(args.json), "--json", refusals=()):
            write_json_atomically(Path(args.json), payload)
        print(f"wrote {args.json}")
    if misses:
        sys.exit(1)


if __name__ == "__main__":
    main()
