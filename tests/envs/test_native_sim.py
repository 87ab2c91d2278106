"""The native simulator kernels (``bearing_env._core``, csrc/sim/) against the numba ones of
:mod:`bearing_env.world` and :mod:`bearing_env.sensing`, bit for bit: random and degenerate
inputs (obstacles, walls, field of view, range, line of sight), then bad arguments."""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bearing_env import _core, sensing, world
from bearing_env.obstacles import box
from bearing_env.sensing import pack_polygons
from bearing_env.world import SCENARIOS

FloatArray = np.ndarray


def bits(value: Any) -> Any:
    """A value's bits: floats as their uint64 pattern (NaN payloads and signed zeros count),
    tuples element by element, the rest as itself."""
    if isinstance(value, tuple):
        return tuple(bits(item) for item in value)
    if isinstance(value, (float, np.floating)):
        return int(np.float64(value).view(np.uint64))
    return value


def same_arrays(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def assert_same_call(reference: Callable[..., Any], native: Callable[..., Any], *args: Any) -> None:
    expected, got = reference(*args), native(*args)
    assert type(got) is type(expected) or isinstance(expected, (bool, np.bool_)), (expected, got)
    assert bits(got) == bits(expected), (args, expected, got)


# ----------------------------------------------------------------------------------------
# Inputs
# ----------------------------------------------------------------------------------------

#: Any double, the special ones included.
any_float = st.floats(allow_nan=True, allow_infinity=True)
#: Coordinates of a small world: grid values (exact collinearity and touching) and others.
coordinate = st.one_of(
    st.integers(-4, 4).map(lambda k: 0.25 * k),
    st.floats(-2.0, 2.0, allow_nan=False),
    st.sampled_from([0.0, -0.0, 1e-300, -1e-300, 1e-12, 0.1 + 0.2, 1e300]),
)
angle = st.one_of(
    st.floats(-10.0, 10.0, allow_nan=False),
    st.sampled_from([0.0, -0.0, math.pi, -math.pi, 0.5 * math.pi, -0.5 * math.pi, 2 * math.pi]),
)


def scenario_obstacles() -> list[tuple[FloatArray, np.ndarray]]:
    """Packed obstacles: none, the scenarios', and degenerate polygons (repeated vertices,
    a zero-length edge, a collinear ring, a lone vertex, an empty polygon)."""
    packed = [pack_polygons(())]
    for scenario in SCENARIOS.values():
        if scenario.obstacles:
            packed.append(pack_polygons(scenario.obstacles))
    packed.append(
        pack_polygons(
            (
                box(0.5, 0.5, 1.0, 1.0),
                ((0.0, 0.0), (0.0, 0.0), (0.5, 0.0), (0.5, 0.5)),
                ((1.0, 0.0), (1.5, 0.0), (2.0, 0.0)),
                ((1.25, 1.25),),
                ((-1.0, -1.0), (-0.5, -1.5), (0.0, -1.0), (-0.5, -0.25), (-0.75, -1.25)),
            )
        )
    )
    vertices, starts = pack_polygons((box(0.0, 0.0, 1.0, 1.0), box(1.0, 1.0, 2.0, 2.0)))
    packed.append((vertices, np.concatenate([starts, starts[-1:]])))  # an empty polygon
    return packed


OBSTACLES = scenario_obstacles()


def random_obstacles(rng: np.random.Generator) -> tuple[FloatArray, np.ndarray]:
    """A few random polygons (star-shaped rings of 1 to 7 vertices, some on a grid)."""
    polygons = []
    for _ in range(int(rng.integers(0, 4))):
        k = int(rng.integers(1, 8))
        centre = rng.uniform(-1.5, 1.5, 2)
        angles = np.sort(rng.uniform(0.0, 2 * math.pi, k))
        radii = rng.uniform(0.05, 0.8, k)
        ring = centre + np.stack([radii * np.cos(angles), radii * np.sin(angles)], axis=1)
        if rng.random() < 0.3:
            ring = np.round(ring * 4.0) / 4.0
        polygons.append(tuple(map(tuple, ring)))
    return pack_polygons(tuple(polygons))


# ----------------------------------------------------------------------------------------
# Scalar kernels (hypothesis)
# ----------------------------------------------------------------------------------------


@settings(max_examples=400, deadline=None, derandomize=True)
@given(st.lists(any_float, min_size=9, max_size=9), st.lists(coordinate, min_size=9, max_size=9))
def test_edge_and_disc_entries(wild: list[float], tame: list[float]) -> None:
    for values in (wild, tame):
        assert_same_call(sensing._edge_entry, _core._edge_entry, *values)
        assert_same_call(sensing._disc_entry, _core._disc_entry, *values[:7])


@settings(max_examples=400, deadline=None, derandomize=True)
@given(st.lists(any_float, min_size=8, max_size=8), st.lists(coordinate, min_size=8, max_size=8))
def test_crossings(wild: list[float], tame: list[float]) -> None:
    for values in (wild, tame):
        assert_same_call(sensing._cross, _core._cross, *values[:6])
        assert_same_call(sensing._on_segment, _core._on_segment, *values[:6])
        assert_same_call(sensing.segments_cross, _core.segments_cross, *values)
        assert_same_call(sensing._segment_distance, _core._segment_distance, *values[:6])


@settings(max_examples=400, deadline=None, derandomize=True)
@given(st.lists(any_float, min_size=8, max_size=8), st.lists(coordinate, min_size=4, max_size=4))
def test_bearing_and_straight_move(wild: list[float], tame: list[float]) -> None:
    assert_same_call(world.bearing, _core.bearing, *wild[:5])
    assert_same_call(world.straight_move, _core.straight_move, *wild)
    x, y, heading, length = tame
    for arena in ((1.05, 0.68, 0.025, 1e-4), (2.0, 2.0, 0.0, 0.0), (1.0, 1.0, 0.6, 1e-4)):
        width, height, margin, baseline = arena
        assert_same_call(
            world.straight_move,
            _core.straight_move,
            abs(x),
            abs(y),
            heading,
            abs(length),
            width,
            height,
            margin,
            baseline,
        )


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    st.lists(coordinate, min_size=4, max_size=4),
    angle,
    st.floats(0.0, 2.5),
    st.sampled_from([0.0, 0.025, 0.1, 0.3]),
    st.integers(0, len(OBSTACLES) - 1),
)
def test_obstacle_kernels(
    point: list[float], heading: float, length: float, margin: float, which: int
) -> None:
    vertices, starts = OBSTACLES[which]
    x, y, tx, ty = point
    assert_same_call(
        sensing.free_length, _core.free_length, x, y, heading, vertices, starts, margin
    )
    assert_same_call(sensing.line_of_sight, _core.line_of_sight, x, y, tx, ty, vertices, starts)
    assert_same_call(sensing.clearance, _core.clearance, x, y, vertices, starts)
    for first, last in itertools.pairwise(starts):
        assert_same_call(
            sensing.inside_polygon, _core.inside_polygon, x, y, vertices, int(first), int(last)
        )
    for half_fov in (math.pi, 4.0, 0.5 * math.pi, 0.3, 0.0):
        for max_range in (math.inf, 0.5, 0.0):
            assert_same_call(
                sensing.visible,
                _core.visible,
                x,
                y,
                heading,
                tx,
                ty,
                half_fov,
                max_range,
                vertices,
                starts,
            )
    settings_ = (2.0, 2.0, margin, 1e-4)
    assert_same_call(
        world.obstructed_move,
        _core.obstructed_move,
        abs(x),
        abs(y),
        heading,
        length,
        settings_,
        vertices,
        starts,
    )


# ----------------------------------------------------------------------------------------
# Seeded random batches
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("seed", range(6))
def test_moves_and_sight_among_random_obstacles(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for _ in range(20):
        vertices, starts = (
            random_obstacles(rng)
            if rng.random() < 0.7
            else OBSTACLES[int(rng.integers(len(OBSTACLES)))]
        )
        width, height = rng.uniform(0.5, 3.0, 2)
        margin = float(rng.choice([0.0, 0.025, 0.1]))
        settings_ = (float(width), float(height), margin, 1e-4)
        for _ in range(30):
            x, y = rng.uniform(-0.2, 3.0, 2)
            heading = float(rng.uniform(-4.0, 4.0))
            length = float(rng.choice([0.0, 1e-5, rng.uniform(0.0, 3.0), math.inf]))
            args = (float(x), float(y), heading, length, settings_, vertices, starts)
            assert_same_call(world.obstructed_move, _core.obstructed_move, *args)
            tx, ty = rng.uniform(-0.2, 3.0, 2)
            half_fov = float(rng.choice([math.pi, rng.uniform(0.0, math.pi)]))
            max_range = float(rng.choice([math.inf, rng.uniform(0.0, 2.0)]))
            vis = (float(x), float(y), heading, float(tx), float(ty), half_fov, max_range)
            assert_same_call(sensing.visible, _core.visible, *vis, vertices, starts)
            assert_same_call(
                sensing.clearance, _core.clearance, float(x), float(y), vertices, starts
            )


@pytest.mark.parametrize("seed", range(4))
def test_row_kernels(seed: int) -> None:
    rng = np.random.default_rng(100 + seed)
    rows, n = int(rng.integers(0, 12)), int(rng.integers(0, 9))
    true = rng.uniform(-4.0, 4.0, (rows, n))
    offsets = rng.normal(0.0, 0.1, (rows, n))
    if true.size:
        true.flat[rng.integers(true.size)] = np.nan
        offsets.flat[rng.integers(true.size)] = np.inf
        true.flat[rng.integers(true.size)] = 1e17
        true.flat[rng.integers(true.size)] = -math.pi
    is_outlier = rng.random((rows, n)) < 0.3
    replacement = np.where(rng.random((rows, n)) < 0.2, np.nan, rng.uniform(-4, 4, (rows, n)))
    for args in ((true, offsets), (true, offsets, is_outlier, replacement)):
        expected, got = np.empty((rows, n)), np.empty((rows, n))
        reference = world._add_wrapped if len(args) == 2 else world._add_wrapped_with_outliers
        native = _core._add_wrapped if len(args) == 2 else _core._add_wrapped_with_outliers
        reference(*args, expected)
        native(*args, got)
        assert same_arrays(expected, got)

    landmarks = rng.uniform(-0.5, 2.5, (rows, n, 2))
    positions = rng.uniform(0.0, 2.0, (rows, 2))
    headings = rng.uniform(-4.0, 4.0, rows)
    if rows and n:
        landmarks[0, 0] = positions[0]  # a landmark under the robot
    expected, got = np.empty((rows, n)), np.empty((rows, n))
    world._true_bearings_into(landmarks, positions, headings, expected)
    _core._true_bearings_into(landmarks, positions, headings, got)
    assert same_arrays(expected, got)

    for vertices, starts in (*OBSTACLES, random_obstacles(rng)):
        for half_fov, max_range in ((math.pi, math.inf), (0.7, 1.2), (2.0, math.inf)):
            seen, native_seen = np.empty((rows, n), bool), np.empty((rows, n), bool)
            args = (landmarks, positions, headings, half_fov, max_range, vertices, starts)
            sensing.visible_rows(*args, seen)
            _core.visible_rows(*args, native_seen)
            assert same_arrays(seen, native_seen)


# ----------------------------------------------------------------------------------------
# Bad arguments
# ----------------------------------------------------------------------------------------


def test_bad_arguments_are_refused_naming_them() -> None:
    vertices, starts = OBSTACLES[1]
    with pytest.raises(TypeError, match="vertices must have dtype float64"):
        _core.free_length(0.0, 0.0, 0.0, vertices.astype(np.float32), starts, 0.1)
    with pytest.raises(ValueError, match="vertices has axis 1"):
        _core.clearance(0.0, 0.0, np.zeros((4, 3)), starts)
    with pytest.raises(TypeError, match="starts must have dtype int64"):
        _core.line_of_sight(0.0, 0.0, 1.0, 1.0, vertices, starts.astype(np.int32))
    with pytest.raises(ValueError, match="starts indexes past"):
        _core.visible(0.0, 0.0, 0.0, 1.0, 1.0, math.pi, math.inf, vertices, starts + 1)
    with pytest.raises(TypeError, match="starts must be a numpy array"):
        _core.clearance(0.0, 0.0, vertices, [0, 4])
    with pytest.raises(ValueError, match="first and last"):
        _core.inside_polygon(0.0, 0.0, vertices, 0, len(vertices) + 1)
    with pytest.raises(ValueError, match="out has shape"):
        _core._add_wrapped(np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((3, 2)))
    with pytest.raises(ValueError, match="offsets has shape"):
        _core._add_wrapped(np.zeros((2, 3)), np.zeros((2, 2)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="out must be writeable"):
        out = np.zeros((2, 3))
        out.flags.writeable = False
        _core._add_wrapped(np.zeros((2, 3)), np.zeros((2, 3)), out)
    with pytest.raises(TypeError, match="is_outlier must have dtype bool"):
        _core._add_wrapped_with_outliers(
            np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3)), np.zeros((2, 3))
        )
    with pytest.raises(ValueError, match="positions has axis 0"):
        _core._true_bearings_into(
            np.zeros((2, 3, 2)), np.zeros((3, 2)), np.zeros(2), np.zeros((2, 3))
        )
    with pytest.raises(ValueError, match="landmarks must be C-contiguous"):
        landmarks = np.zeros((2, 3, 4))[:, :, ::2]
        _core.visible_rows(
            landmarks,
            np.zeros((2, 2)),
            np.zeros(2),
            1.0,
            1.0,
            vertices,
            starts,
            np.zeros((2, 3), bool),
        )
    with pytest.raises(TypeError):
        _core.obstructed_move(0.0, 0.0, 0.0, 1.0, (1.0, 1.0, 0.0), vertices, starts)


def test_read_only_inputs_are_taken() -> None:
    landmarks = np.array([[[1.0, 2.0], [0.5, -0.5]]])
    landmarks.flags.writeable = False  # as the envs' WorldView hands them out
    positions, headings = np.zeros((1, 2)), np.array([0.3])
    expected, got = np.empty((1, 2)), np.empty((1, 2))
    world._true_bearings_into(landmarks, positions, headings, expected)
    _core._true_bearings_into(landmarks, positions, headings, got)
    assert same_arrays(expected, got)
