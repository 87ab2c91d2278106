"""The ``"shapes"`` observation: the entity table with each region's shape (elongation
and long axis), checked against an independent computation of the second moments
(shapely's area and centroid, and the moments of a fan of triangles)."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import MultiPoint, Polygon

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.envs.kernels import _write_shape
from bearing_env.envs.observations import (
    ELONGATION_LIMIT,
    ENTITY_FEATURES,
    SHAPE_ENTITY_FEATURES,
    SHAPE_FEATURES,
)
from tests.envs.test_env_vector import assert_same

SLOTS = 7


def reference_shape(points: np.ndarray) -> np.ndarray:
    """(elongation, cos 2 theta, sin 2 theta) of the polygon ``points`` (n, 2), from a fan
    of triangles: a triangle's second moment per unit area about the origin is
    (sum_i v_i v_i^T + s s^T) / 12, s the sum of its vertices."""
    polygon = Polygon(points)
    centroid = np.array(polygon.centroid.coords[0])
    moments, total = np.zeros((2, 2)), 0.0
    for k in range(1, len(points) - 1):
        triangle = np.array([points[0], points[k], points[k + 1]]) - centroid
        area = abs(Polygon(triangle).area)
        summed = triangle.sum(axis=0)
        moments += area * (triangle.T @ triangle + np.outer(summed, summed)) / 12.0
        total += area
    assert math.isclose(total, polygon.area, rel_tol=1e-9)
    covariance = moments / total
    shortest, longest = np.linalg.eigvalsh(covariance)
    a, b, d = covariance[0, 0], covariance[0, 1], covariance[1, 1]
    radius = math.hypot(0.5 * (a - d), b)
    return np.array(
        [
            min(0.5 * math.log(longest / shortest), ELONGATION_LIMIT),
            0.5 * (a - d) / radius,
            b / radius,
        ]
    )


def kernel_shape(points: np.ndarray) -> np.ndarray:
    vertices = np.zeros(16, np.complex128)
    vertices[: len(points)] = points[:, 0] + 1j * points[:, 1]
    out = np.zeros(2 * len(SHAPE_FEATURES), np.float32)
    _write_shape(vertices, len(points), out, 1)
    assert not out[: len(SHAPE_FEATURES)].any()  # only the block of slot 1 is written
    return out[len(SHAPE_FEATURES) :].astype(np.float64)


coordinate = st.floats(-3.0, 3.0, allow_nan=False)


@settings(max_examples=150, deadline=None, derandomize=True)
@given(
    st.lists(st.tuples(coordinate, coordinate), min_size=3, max_size=12),
    st.floats(0.05, 20.0),
    st.booleans(),
)
def test_the_shape_block_matches_the_moments_of_a_fan_of_triangles(
    points: list[tuple[float, float]], stretch: float, clockwise: bool
) -> None:
    hull = MultiPoint([(x * stretch, y) for x, y in points]).convex_hull
    if not isinstance(hull, Polygon) or hull.area < 1e-3 * hull.length**2:
        return  # degenerate (a point, a segment or a sliver): covered below
    ring = np.array(hull.exterior.coords[:-1])
    if clockwise == hull.exterior.is_ccw:
        ring = ring[::-1]
    expected, got = reference_shape(ring), kernel_shape(ring)
    np.testing.assert_allclose(got[0], expected[0], rtol=1e-4, atol=1e-5)
    if expected[0] > 1e-3:  # a round region has no axis to compare
        np.testing.assert_allclose(got[1:], expected[1:], atol=1e-4)
        assert math.isclose(math.hypot(got[1], got[2]), 1.0, rel_tol=1e-5)


def test_the_axis_and_elongation_of_known_shapes() -> None:
    # A 4 x 1 rectangle along x: moments 16/12 and 1/12, elongation log(4), axis 0.
    rectangle = np.array([[0, 0], [4, 0], [4, 1], [0, 1]], float)
    np.testing.assert_allclose(kernel_shape(rectangle), [math.log(4.0), 1.0, 0.0], atol=1e-6)
    # The same along y (theta = 90 degrees: cos 2 theta = -1) and along the diagonal.
    upright = rectangle[:, ::-1][::-1]
    np.testing.assert_allclose(kernel_shape(upright), [math.log(4), -1, 0], atol=1e-6)
    turn = np.array([[1, -1], [1, 1]]) / math.sqrt(2.0)  # 45 degrees
    np.testing.assert_allclose(kernel_shape(rectangle @ turn.T), [math.log(4), 0, 1], atol=1e-6)
    # A square is round: no elongation, no axis.
    np.testing.assert_allclose(kernel_shape(rectangle * [0.25, 1]), [0, 0, 0], atol=1e-6)
    # A region with no area leaves its block at zeros; a needle is clipped to the limit.
    np.testing.assert_array_equal(kernel_shape(np.array([[0, 0], [1, 1], [2, 2]], float)), 0)
    needle = np.array([[0, 0], [1, 0], [1, 1e-12], [0, 1e-12]], float)
    assert kernel_shape(needle)[0] == ELONGATION_LIMIT


@pytest.mark.parametrize("env_id", ["BearingSLAM-v1", "BearingSLAMDiscrete-v1"])
def test_the_shape_table_is_the_entity_table_with_the_regions_shapes(env_id: str) -> None:
    kwargs = {"n_landmarks": (3, 6), "max_landmarks": SLOTS}
    entity_env = gym.make(env_id, observation="entities", **kwargs)
    shape_env = gym.make(env_id, observation="shapes", **kwargs)
    width, column = len(SHAPE_ENTITY_FEATURES), SHAPE_ENTITY_FEATURES.index
    checked = 0
    for seed in (0, 1):
        entities, _ = entity_env.reset(seed=seed)
        shapes, info = shape_env.reset(seed=seed)
        entity_env.action_space.seed(seed)
        for _ in range(8):
            assert shape_env.observation_space.contains(shapes)
            np.testing.assert_array_equal(shapes["robot"], entities["robot"])
            table = shapes["landmarks"].reshape(SLOTS, width)
            entity_table = entities["landmarks"].reshape(SLOTS, len(ENTITY_FEATURES))
            np.testing.assert_array_equal(table[:, : len(ENTITY_FEATURES)], entity_table)
            np.testing.assert_array_equal(table[:2, column("elongation") :], 0.0)  # the frame
            robot_map = info["robot_map"]
            for j, count in enumerate(robot_map["counts"]):
                block = table[j + 2, column("elongation") :]
                if count < 3:
                    np.testing.assert_array_equal(block, 0.0)  # no region yet, or absent
                    continue
                expected = reference_shape(robot_map["vertices"][j, :count])
                np.testing.assert_allclose(block[0], expected[0], rtol=1e-4, atol=1e-4)
                if expected[0] > 1e-2:
                    np.testing.assert_allclose(block[1:], expected[1:], atol=1e-3)
                checked += 1
            action = entity_env.action_space.sample()
            entities, *entity_rest = entity_env.step(action)
            shapes, *shape_rest = shape_env.step(action)
            # The kind changes the observation's layout, not the episode.
            assert_same(tuple(shape_rest), tuple(entity_rest))
            _, terminated, truncated, info = shape_rest
            if terminated or truncated:
                break
    assert checked > 10


def test_the_shape_observation_on_the_vector_env_is_the_single_envs() -> None:
    # One landmark count: SyncVectorEnv cannot batch infos of varying sizes.
    kwargs = {"scenario": "random", "n_landmarks": 5, "observation": "shapes"}
    batched = gym.make_vec("BearingSLAM-v1", num_envs=3, **kwargs)
    reference = gym.make_vec("BearingSLAM-v1", num_envs=3, vectorization_mode="sync", **kwargs)
    assert batched.observation_space == reference.observation_space
    batched.action_space.seed(3)
    first, _ = batched.reset(seed=3)
    second, _ = reference.reset(seed=3)
    elongated = 0
    for _ in range(25):  # through an autoreset
        assert batched.observation_space.contains(first)
        for key in ("robot", "landmarks"):
            np.testing.assert_array_equal(first[key], second[key])
        table = first["landmarks"].reshape(3, -1, len(SHAPE_ENTITY_FEATURES))
        elongated += int((table[..., SHAPE_ENTITY_FEATURES.index("elongation")] > 0.1).sum())
        actions = batched.action_space.sample()
        first, *_ = batched.step(actions)
        second, *_ = reference.step(actions)
    assert elongated > 0
