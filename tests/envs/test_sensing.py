"""The compiled sensor and obstacle geometry (bearing_env.sensing) against shapely."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point, Polygon

from bearing_env.obstacles import random_obstacles
from bearing_env.sensing import clearance, free_length, line_of_sight, pack_polygons, visible
from bearing_env.world import obstructed_move, straight_move

coordinate = st.floats(-2.0, 3.0, allow_nan=False)
heading = st.floats(-math.pi, math.pi, allow_nan=False)
#: Random boxes (rotated rectangles) in a 1 x 1 m square; the tests' obstacles.
seed = st.integers(0, 2**31 - 1)


def _obstacles(rng_seed: int) -> tuple[tuple[tuple[float, float], ...], ...]:
    return random_obstacles(np.random.default_rng(rng_seed), 1.0, 1.0, 3)


def _union(polygons: tuple[tuple[tuple[float, float], ...], ...]) -> Polygon:
    shape = Polygon(polygons[0])
    for polygon in polygons[1:]:
        shape = shape.union(Polygon(polygon))
    return shape


@settings(max_examples=150, deadline=None)
@given(seed, coordinate, coordinate, coordinate, coordinate)
def test_line_of_sight_is_shapely_s_intersection(
    rng_seed: int, x: float, y: float, tx: float, ty: float
) -> None:
    polygons = _obstacles(rng_seed)
    shape = _union(polygons)
    if shape.contains(Point(x, y)) or shape.contains(Point(tx, ty)):
        return  # the simulator never asks from or about a point inside an obstacle
    expected = not LineString([(x, y), (tx, ty)]).intersects(shape)
    assert line_of_sight(x, y, tx, ty, *pack_polygons(polygons)) == expected


@settings(max_examples=150, deadline=None)
@given(seed, st.floats(0.0, 1.0), st.floats(0.0, 1.0), heading, st.floats(0.0, 1.5))
def test_a_move_stops_at_the_obstacles_margin(
    rng_seed: int, x: float, y: float, direction: float, length: float
) -> None:
    """The path keeps ``margin`` from every obstacle (shapely's distance), and a move
    stopped short ends at the margin."""
    polygons = _obstacles(rng_seed)
    shape = _union(polygons)
    margin = 0.02
    if shape.distance(Point(x, y)) < margin:
        return  # starts are at least the margin away
    vertices, starts = pack_polygons(polygons)
    room = free_length(x, y, direction, vertices, starts, margin)
    travelled = min(length, room)
    end = (x + travelled * math.cos(direction), y + travelled * math.sin(direction))
    path = LineString([(x, y), end]) if travelled > 0.0 else Point(x, y)
    assert path.distance(shape) >= margin - 1e-9
    if room < length:
        assert shape.distance(Point(end)) == pytest.approx(margin, abs=1e-9)


@settings(max_examples=100, deadline=None)
@given(seed, st.floats(0.0, 1.0), st.floats(0.0, 1.0))
def test_clearance_is_shapely_s_distance(rng_seed: int, x: float, y: float) -> None:
    polygons = _obstacles(rng_seed)
    expected = _union(polygons).distance(Point(x, y))
    assert clearance(x, y, *pack_polygons(polygons)) == pytest.approx(expected, abs=1e-12)


@settings(max_examples=100, deadline=None)
@given(st.floats(0.05, 1.0), st.floats(0.05, 0.63), heading, st.floats(0.0, 1.2))
def test_without_obstacles_a_move_is_the_wall_move_bit_for_bit(
    x: float, y: float, direction: float, length: float
) -> None:
    walls = (1.05, 0.68, 0.025, 1e-4)
    x, y = min(x, 1.025), min(y, 0.655)
    empty = pack_polygons(())
    assert obstructed_move(x, y, direction, length, walls, *empty) == straight_move(
        x, y, direction, length, *walls
    )


def test_a_move_into_a_box_is_blocked_at_the_margin() -> None:
    box = ((0.5, 0.2), (0.7, 0.2), (0.7, 0.4), (0.5, 0.4))
    vertices, starts = pack_polygons((box,))
    x, y, travelled, blocked = obstructed_move(
        0.1, 0.3, 0.0, 0.8, (1.05, 0.68, 0.025, 1e-4), vertices, starts
    )
    assert blocked and travelled == pytest.approx(0.375) and (x, y) == pytest.approx((0.475, 0.3))
    # Against it, facing it: it cannot move; facing away it can.
    assert obstructed_move(x, y, 0.0, 0.1, (1.05, 0.68, 0.025, 1e-4), vertices, starts)[2] == 0.0
    assert obstructed_move(x, y, math.pi, 0.1, (1.05, 0.68, 0.025, 1e-4), vertices, starts)[2] == (
        pytest.approx(0.1)
    )


def test_visibility_field_of_view_range_and_occlusion() -> None:
    box = ((0.5, -0.1), (0.6, -0.1), (0.6, 0.1), (0.5, 0.1))
    empty, boxed = pack_polygons(()), pack_polygons((box,))
    half_fov = math.radians(45.0)
    # Ahead and in range: seen; behind the box: not.
    assert visible(0.0, 0.0, 0.0, 1.0, 0.0, half_fov, math.inf, *empty)
    assert not visible(0.0, 0.0, 0.0, 1.0, 0.0, half_fov, math.inf, *boxed)
    # 50 degrees off the heading is outside a 90 degree view, 40 inside.
    for degrees, seen in ((50.0, False), (40.0, True), (-40.0, True), (-50.0, False)):
        angle = math.radians(degrees)
        target = (math.cos(angle), math.sin(angle))
        assert visible(0.0, 0.0, 0.0, *target, half_fov, math.inf, *empty) == seen
    # Panoramic sees behind; the range cuts at its value.
    assert visible(0.0, 0.0, 0.0, -1.0, 0.0, math.pi, math.inf, *empty)
    assert visible(0.0, 0.0, 0.0, 0.9, 0.0, math.pi, 0.9, *empty)
    assert not visible(0.0, 0.0, 0.0, 0.91, 0.0, math.pi, 0.9, *empty)


@settings(max_examples=30, deadline=None)
@given(seed)
def test_landmarks_seen_is_visible_for_every_pose_and_landmark(rng_seed: int) -> None:
    from bearing_env.sensing import landmarks_seen

    rng = np.random.default_rng(rng_seed)
    obstacles = pack_polygons(_obstacles(rng_seed))
    landmarks = rng.uniform(0.0, 1.0, (5, 2))
    positions = rng.uniform(0.0, 1.0, (7, 2))
    headings = rng.uniform(-math.pi, math.pi, 7)
    half_fov, max_range = float(rng.uniform(0.3, math.pi)), float(rng.uniform(0.3, 1.5))
    seen = landmarks_seen(landmarks, positions, headings, half_fov, max_range, obstacles)
    expected = [
        [visible(*p, h, *q, half_fov, max_range, *obstacles) for q in landmarks]
        for p, h in zip(positions, headings, strict=True)
    ]
    np.testing.assert_array_equal(seen, expected)
