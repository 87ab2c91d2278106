"""Checks that the world model's regions are what it promises, and a seeded search for
counter-examples.

Every region the core keeps (a landmark's or the robot's) must be a simple, strictly
convex, counter-clockwise polygon whose area is its shapely area, and, whenever the
bearing noise is within +-epsilon, must hold the truth (the conservative transfer's
guarantee). The checks here are written apart from the compiled kernels, in numpy and
shapely, so that they can catch the kernels out:

* :func:`simple_convex` : every turn strictly left and one full turn in all, which
  together make a polygon simple and convex;
* :func:`shapely_areas` : the areas shapely computes for the same vertex arrays;
* :func:`contains` : point-in-convex-polygon with the map's relative tolerance.

:func:`search` runs fresh maps through random movements (random layouts, moves and
epsilon, uniform noise within +-epsilon) and counts what fails each check; it is the
engine of ``python -m bearing_env.benchmarks.region_search``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely
from numpy.typing import NDArray

from bearing_env.slam.batch import CONTAINMENT_TOLERANCE, BatchedPolygonSLAM

ComplexArray = NDArray[np.complex128]

#: How far the summed turning of a convex polygon may stray from one full turn.
TURNING_TOLERANCE = 1e-6
#: How far the map's area may stray from shapely's, relative to the area.
AREA_TOLERANCE = 1e-9


def _padded_next(vertices: ComplexArray, counts: NDArray[np.int64], step: int) -> ComplexArray:
    """``vertices[..., (i + step) % count]`` for every slot ``i`` of each polygon."""
    slots = np.arange(vertices.shape[-1])
    safe = np.maximum(counts, 1)[..., None]
    return np.take_along_axis(vertices, (slots + step) % safe, axis=-1)


def simple_convex(vertices: ComplexArray, counts: NDArray[np.int64]) -> NDArray[np.bool_]:
    """Whether each polygon ``vertices[..., :count]`` is simple, strictly convex and CCW.

    Every vertex must turn strictly left (by an angle in (0, pi)), and the turns must add
    up to one full turn: a polygon that turns left everywhere but winds twice (a
    pentagram) or doubles back (a spike, a turn of pi) fails. Polygons with fewer than
    three vertices fail too.
    """
    edges = _padded_next(vertices, counts, 1) - vertices
    turns = np.angle(_padded_next(edges, counts, 1) * np.conj(edges))
    used = np.arange(vertices.shape[-1]) < counts[..., None]
    left = np.where(used, (turns > 0.0) & (turns < math.pi), True).all(axis=-1)
    total = np.where(used, turns, 0.0).sum(axis=-1)
    return (counts >= 3) & left & (np.abs(total - 2.0 * math.pi) <= TURNING_TOLERANCE)


def shapely_areas(
    vertices: ComplexArray, counts: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """(area, is_valid) that shapely gives each polygon ``vertices[..., :count]``, built as
    one ragged array; polygons of fewer than three vertices get (0, False)."""
    area = np.zeros(counts.shape)
    valid = np.zeros(counts.shape, dtype=bool)
    rings = counts >= 3
    ring_vertices, ring_counts = vertices[rings], counts[rings]
    if ring_counts.size == 0:
        return area, valid
    closed = np.concatenate([ring_vertices, ring_vertices[:, :1]], axis=1)
    # Each ring's used vertices, then its first again in the slot after them.
    closed[np.arange(ring_counts.size), ring_counts] = ring_vertices[:, 0]
    points = closed[np.arange(closed.shape[1]) <= ring_counts[:, None]]
    offsets = np.concatenate([[0], np.cumsum(ring_counts + 1)])
    polygons = shapely.from_ragged_array(
        shapely.GeometryType.POLYGON,
        np.stack([points.real, points.imag], axis=-1),
        (offsets, np.arange(ring_counts.size + 1)),
    )
    area[rings] = shapely.area(polygons)
    valid[rings] = shapely.is_valid(polygons)
    return area, valid


def contains(
    vertices: ComplexArray,
    counts: NDArray[np.int64],
    points: ComplexArray,
    relative: float = CONTAINMENT_TOLERANCE,
) -> NDArray[np.bool_]:
    """Whether each convex CCW polygon holds its point, within ``relative`` times the
    polygon's size (the map's own containment rule)."""
    used = np.arange(vertices.shape[-1]) < counts[..., None]
    first = vertices[..., :1]
    filled = np.where(used, vertices, first)
    size = np.maximum(np.ptp(filled.real, axis=-1), np.ptp(filled.imag, axis=-1))
    edges = _padded_next(vertices, counts, 1) - vertices
    lengths = np.where(used, np.abs(edges), 1.0)
    offsets = points[..., None] - vertices
    distance = (edges.real * offsets.imag - edges.imag * offsets.real) / lengths
    tolerance = (relative * size)[..., None]
    return np.where(used, distance >= -tolerance, True).all(axis=-1) & (counts >= 3)


@dataclass(frozen=True)
class SearchSettings:
    """What :func:`search` draws.

    Landmarks and the robot's start lie in the unit square; each move has a uniform
    heading and a log-uniform length in ``move_length``; epsilon is drawn per batch of
    maps, uniformly in degrees; the noise on every bearing is uniform within
    ``noise_fraction * epsilon`` (1.0: within the bound, where the guarantee holds).
    """

    transfer: str = "conservative"
    fusion: str = "intersect"
    landmark_counts: tuple[int, ...] = (3, 4, 6)
    moves: int = 1
    epsilon_deg: tuple[float, float] = (0.5, 10.0)
    move_length: tuple[float, float] = (0.01, 1.0)
    noise_fraction: float = 1.0


@dataclass
class SearchReport:
    """Counts over every region checked, and the first counter-examples."""

    movements: int = 0
    regions: int = 0
    not_simple_convex: int = 0
    shapely_invalid: int = 0
    area_mismatches: int = 0
    containment_checks: int = 0
    misses: int = 0
    nonfinite: int = 0
    #: Single-movement counter-examples as (epsilon, bearings_start, bearings_end).
    examples: list[tuple[float, list[float], list[float]]] = field(default_factory=list)

    @property
    def defects(self) -> int:
        return (
            self.not_simple_convex
            + self.shapely_invalid
            + self.area_mismatches
            + self.misses
            + self.nonfinite
        )

    def add(self, other: SearchReport, max_examples: int = 10) -> None:
        for name in (
            "movements",
            "regions",
            "not_simple_convex",
            "shapely_invalid",
            "area_mismatches",
            "containment_checks",
            "misses",
            "nonfinite",
        ):
            setattr(self, name, getattr(self, name) + getattr(other, name))
        self.examples.extend(other.examples[: max_examples - len(self.examples)])


def check_batch(
    batch: BatchedPolygonSLAM,
    truth_fl: ComplexArray,
    robot_fl: ComplexArray,
    robot_current: NDArray[np.bool_],
    expect_containment: bool,
) -> tuple[SearchReport, NDArray[np.bool_]]:
    """Check every initialised region of ``batch`` (landmarks and robot) against the
    true FL positions; returns the counts and which maps had a defect.

    The robot's region is checked for containment only in the maps where
    ``robot_current`` (its last movement changed frames, so the region is of the robot's
    present position)."""
    vertices = np.concatenate([batch.vertices, batch.robot_vertices[:, None]], axis=1)
    counts = np.concatenate([batch.counts, batch.robot_counts[:, None]], axis=1)
    areas = np.concatenate([batch.areas, batch.robot_area[:, None]], axis=1)
    truth = np.concatenate([truth_fl, robot_fl[:, None]], axis=1)
    held = counts > 0
    report = SearchReport(regions=int(held.sum()))
    convex = simple_convex(vertices, counts) | ~held
    shapely_area, valid = shapely_areas(vertices, counts)
    valid |= ~held
    finite = np.isfinite(vertices).all(axis=-1) & np.isfinite(areas) | ~held
    area_ok = np.abs(areas - shapely_area) <= AREA_TOLERANCE * np.maximum(shapely_area, 1e-300)
    area_ok |= ~held
    inside = contains(vertices, counts, truth) | ~held
    inside[:, -1] |= ~robot_current
    report.not_simple_convex = int((~convex).sum())
    report.shapely_invalid = int((~valid).sum())
    report.area_mismatches = int((~area_ok).sum())
    report.nonfinite = int((~finite).sum())
    bad = ~(convex & valid & area_ok & finite)
    if expect_containment:
        report.containment_checks = int(held[:, :-1].sum() + (held[:, -1] & robot_current).sum())
        report.misses = int((~inside).sum())
        bad |= ~inside
    return report, bad.any(axis=1)


def search(
    settings: SearchSettings, num_maps: int, rng: np.random.Generator, max_examples: int = 10
) -> SearchReport:
    """Run ``num_maps`` fresh maps through ``settings.moves`` random movements each, with
    one epsilon and landmark count drawn from ``rng``, and check every region after every
    movement."""
    n_landmarks = int(rng.choice(settings.landmark_counts))
    epsilon = math.radians(rng.uniform(*settings.epsilon_deg))
    batch = BatchedPolygonSLAM(
        num_maps, n_landmarks, epsilon, transfer=settings.transfer, fusion=settings.fusion
    )
    landmarks = rng.uniform(size=(num_maps, n_landmarks)) + 1j * rng.uniform(
        size=(num_maps, n_landmarks)
    )
    frame = landmarks[:, 1] - landmarks[:, 0]
    truth_fl = (landmarks[:, 2:] - landmarks[:, :1]) / frame[:, None]
    position = rng.uniform(size=num_maps) + 1j * rng.uniform(size=num_maps)
    low, high = np.log(settings.move_length)
    expect_containment = settings.transfer == "conservative" and settings.noise_fraction <= 1.0
    report = SearchReport()
    for _ in range(settings.moves):
        heading = np.exp(1j * rng.uniform(-math.pi, math.pi, num_maps))
        end = position + np.exp(rng.uniform(low, high, num_maps)) * heading
        bound = settings.noise_fraction * epsilon
        noise = rng.uniform(-bound, bound, size=(2, num_maps, n_landmarks))
        start_bearings = np.angle((landmarks - position[:, None]) / heading[:, None]) + noise[0]
        end_bearings = np.angle((landmarks - end[:, None]) / heading[:, None]) + noise[1]
        moved = batch.update(start_bearings, end_bearings).frame_changed
        robot_fl = (end - landmarks[:, 0]) / frame
        found, bad_maps = check_batch(batch, truth_fl, robot_fl, moved, expect_containment)
        found.movements = num_maps
        if settings.moves == 1:
            found.examples = [
                (epsilon, start_bearings[i].tolist(), end_bearings[i].tolist())
                for i in np.flatnonzero(bad_maps)[:max_examples]
            ]
        report.add(found, max_examples)
        position = end
    return report
