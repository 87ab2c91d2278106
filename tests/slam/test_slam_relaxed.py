"""The relaxed fusion (``fusion="relaxed"``): the q-relaxed intersection of a landmark's
regions over a window of movements, and missed readings (NaN bearings).

Checked against shapely (an independent brute force over every subset of regions), by
properties (outliers that contradict the consistent regions are left out, so the
region contains the truth), and against the strict intersection on clean data.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from bearing_env.slam import PolygonSLAM, UpdateResult
from bearing_env.slam.geometry import relaxed_intersection
from tests.extras import needs
from tests.slam_sim import random_episode

EPS = np.deg2rad(2.0)


def assert_same_result(result: UpdateResult, expected: UpdateResult) -> None:
    assert (result.frame_status, result.n_inconsistent) == (
        expected.frame_status,
        expected.n_inconsistent,
    )
    assert result.landmark_status.tolist() == expected.landmark_status.tolist()


def convex_polygon(center: complex, radius: float, angles: list[float]) -> np.ndarray:
    """A convex polygon (CCW) with vertices on a circle."""
    return center + radius * np.exp(1j * np.sort(np.asarray(angles)))


polygon_angles = st.lists(
    st.floats(0.0, 2 * np.pi, exclude_max=True), min_size=3, max_size=8, unique=True
).filter(lambda a: np.ptp(np.sort(a)) > np.pi and np.max(np.diff(np.sort(a))) < np.pi)


def shapely_polygon(vertices: np.ndarray) -> shapely.Polygon:
    return shapely.Polygon(np.stack([vertices.real, vertices.imag], 1))


def brute_force(polygons: list[np.ndarray], max_outliers: int) -> tuple[float, int] | None:
    """(area of the hull, q) of the q-relaxed intersection, by shapely over all subsets;
    None when an intersection is too close to empty to call."""
    shapes = [shapely_polygon(p) for p in polygons]
    k = len(shapes)
    for q in range(min(max_outliers, k - 1) + 1):
        pieces = []
        for kept in itertools.combinations(range(k), k - q):
            piece = shapes[kept[0]]
            for i in kept[1:]:
                piece = piece.intersection(shapes[i])
            if 0.0 < piece.area < 1e-9:
                return None
            if piece.area > 0.0:
                pieces.append(piece)
        if pieces:
            return shapely.union_all(pieces).convex_hull.area, q
    return 0.0, min(max_outliers, k - 1)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    centers=st.lists(
        st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)), min_size=1, max_size=6
    ),
    radii=st.lists(st.floats(0.3, 1.5), min_size=6, max_size=6),
    angles=st.lists(polygon_angles, min_size=6, max_size=6),
    max_outliers=st.integers(0, 3),
)
def test_matches_a_brute_force_over_every_subset(
    centers: list[tuple[float, float]],
    radii: list[float],
    angles: list[list[float]],
    max_outliers: int,
) -> None:
    polygons = [
        convex_polygon(complex(x, y), radii[i], angles[i]) for i, (x, y) in enumerate(centers)
    ]
    expected = brute_force(polygons, max_outliers)
    assume(expected is not None)  # an intersection within rounding of empty
    assert expected is not None
    area, q = expected
    vertices, q_found, _ = relaxed_intersection(polygons, max_outliers)
    if area == 0.0:
        assert vertices.size == 0
        return
    assert q_found == q
    assert shapely_polygon(vertices).area == pytest.approx(area, rel=1e-7)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(
    truth=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
    n_consistent=st.integers(2, 5),
    n_outliers=st.integers(0, 3),
    shifts=st.lists(st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)), min_size=5, max_size=5),
    angles=st.lists(polygon_angles, min_size=8, max_size=8),
    directions=st.lists(st.floats(0.0, 2 * np.pi), min_size=3, max_size=3),
    order=st.randoms(use_true_random=False),
)
def test_contradicting_outliers_are_left_out_and_the_truth_kept(
    truth: tuple[float, float],
    n_consistent: int,
    n_outliers: int,
    shifts: list[tuple[float, float]],
    angles: list[list[float]],
    directions: list[float],
    order: object,
) -> None:
    """Consistent regions all contain the truth; each of up to ``max_outliers`` outliers
    lies away from all of them (as a misread bearing's region does once the map is
    good). The relaxed region then leaves out exactly the outliers."""
    t = complex(*truth)
    consistent = [
        # A radius above the shift keeps the truth inside.
        convex_polygon(t + complex(*shifts[i]), 1.0, angles[i]) for i in range(n_consistent)
    ]
    consistent = [p for p in consistent if shapely_polygon(p).contains(shapely.Point(*truth))]
    assume(len(consistent) >= 2)
    outliers = [
        convex_polygon(t + 6.0 * (m + 1) * np.exp(1j * directions[m]), 1.0, angles[5 + m])
        for m in range(n_outliers)
    ]
    labelled = [(p, False) for p in consistent] + [(p, True) for p in outliers]
    import random

    assert isinstance(order, random.Random)
    order.shuffle(labelled)
    polygons = [p for p, _ in labelled]
    vertices, q, inliers = relaxed_intersection(polygons, max_outliers=3)
    assert q == n_outliers
    assert inliers.tolist() == [not is_outlier for _, is_outlier in labelled]
    assert shapely_polygon(vertices).buffer(1e-9).contains(shapely.Point(*truth))


def test_clean_data_gives_the_strict_intersection_exactly() -> None:
    rng = np.random.default_rng(3)
    for _ in range(20):
        episode = random_episode(rng, 6, 14)
        strict = PolygonSLAM(6, EPS)
        relaxed = PolygonSLAM(6, EPS, fusion="relaxed")
        for b1, b2 in episode.readings(EPS):
            expected = strict.update(b1, b2)
            assert_same_result(relaxed.update(b1, b2), expected)
            np.testing.assert_array_equal(relaxed.areas, strict.areas)
        assert relaxed.outliers.tolist() == [0, 0, 0, 0]


def run_with_outlier(
    fusion: str, landmark: int, offset: float, move: int = 6
) -> tuple[PolygonSLAM, list[str], np.ndarray]:
    """A seeded clean episode in which one bearing (landmark ``landmark``, at the start
    of move ``move``) is misread by ``offset`` radians; also returns the truth."""
    episode = random_episode(np.random.default_rng(12), 6, 16)
    slam = PolygonSLAM(6, EPS, fusion=fusion)
    statuses = []
    for m, (b1, b2) in enumerate(episode.readings(EPS)):
        if m == move:
            b1 = b1.copy()
            b1[landmark] += offset
        statuses.append(slam.update(b1, b2).frame_status)
    return slam, statuses, episode.truth_fl()


def test_a_misread_frame_landmark_rejects_the_movement() -> None:
    relaxed, statuses, truth = run_with_outlier("relaxed", 1, 0.6)
    assert relaxed.contains(truth).all()
    assert statuses[6] == "rejected"
    assert statuses.count("rejected") == 1
    # Every landmark's region from that movement is left out.
    assert relaxed.outliers.tolist() == [1, 1, 1, 1]
    strict, strict_statuses, _ = run_with_outlier("intersect", 1, 0.6)
    assert strict_statuses[6] == "ok"  # the strict map fused it
    assert strict.n_inconsistent > 0


def test_a_misread_landmark_is_left_out_for_that_landmark_only() -> None:
    relaxed, statuses, truth = run_with_outlier("relaxed", 3, 0.3)
    assert relaxed.contains(truth).all()
    assert "rejected" not in statuses
    assert relaxed.outliers.tolist() == [0, 1, 0, 0]


def test_nan_is_a_missed_reading() -> None:
    episode = random_episode(np.random.default_rng(5), 5, 6)
    readings = episode.readings(EPS)
    slam = PolygonSLAM(5, EPS)
    for b1, b2 in readings[:3]:
        slam.update(b1, b2)
    areas = slam.areas.copy()
    b1, b2 = (r.copy() for r in readings[3])
    b1[3] = np.nan
    result = slam.update(b1, b2)
    assert result.landmark_status[1] == "missing"
    assert slam.areas[1] == areas[1]
    b1, b2 = (r.copy() for r in readings[4])
    b2[0] = np.nan
    before = slam.areas.copy()
    result = slam.update(b1, b2)
    assert (result.frame_status, result.frame_changed) == ("l1_missing", False)
    np.testing.assert_array_equal(slam.areas, before)
    b2[0], b2[1] = b1[0], np.nan
    assert slam.update(b1, b2).frame_status == "l2_missing"
    with pytest.raises(ValueError, match="finite or NaN"):
        slam.update(np.full(5, np.inf), b2)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"fusion": "vote"}, ValueError, "fusion must be one of"),
        ({"fusion": "relaxed", "max_outliers": -1}, ValueError, "max_outliers must be >= 0"),
        ({"fusion": "relaxed", "max_outliers": 1.5}, TypeError, "max_outliers must be an int"),
        ({"fusion": "relaxed", "window": 0}, ValueError, "window must be >= 1"),
        ({"fusion": "relaxed", "window": 33}, ValueError, "window must be <= 32"),
        ({"fusion": "relaxed", "window": 4, "max_outliers": 4}, ValueError, "< window"),
    ],
)
def test_bad_settings_are_named(kwargs: dict[str, object], error: type, match: str) -> None:
    with pytest.raises(error, match=match):
        PolygonSLAM(4, EPS, **kwargs)  # type: ignore[arg-type]


def test_the_relaxed_state_survives_copies_and_pickles() -> None:
    import pickle

    episode = random_episode(np.random.default_rng(2), 5, 12)
    readings = episode.readings(EPS)
    slam = PolygonSLAM(5, EPS, fusion="relaxed", max_outliers=1, window=4)
    for b1, b2 in readings[:9]:
        slam.update(b1, b2)
    copies = [slam.copy(), pickle.loads(pickle.dumps(slam))]
    for b1, b2 in readings[9:]:
        expected = slam.update(b1, b2)
        for other in copies:
            assert_same_result(other.update(b1, b2), expected)
            np.testing.assert_array_equal(other.areas, slam.areas)


# --------------------------------------------------------------------------------------
# The env's fusion setting
# --------------------------------------------------------------------------------------


@needs("render")
def test_env_relaxed_passes_the_checkers_and_reports_outliers() -> None:
    import warnings

    import gymnasium as gym
    from gymnasium.utils.env_checker import check_env

    kwargs = {
        "scenario": "khepera",
        "fusion": "relaxed",
        "noise": {"kind": "uniform", "outlier_rate": 0.2},
    }
    env = gym.make("BearingSLAM-v1", **kwargs)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    env.reset(seed=4)
    env.action_space.seed(4)
    total = 0
    for _ in range(20):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        assert info["outliers"].shape == (2,) and info["outliers"].dtype == np.int64
        assert "window_vertices" in info["robot_map"]  # the map's whole state, as data
        total = int(info["outliers"].sum())
        if terminated or truncated:
            break
    assert total > 0  # a 20% outlier rate leaves regions out
    env.close()


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"fusion": "union"}, "unknown fusion 'union'"),
        ({"fusion": "relaxed", "max_outliers": 8}, "max_outliers must be <= 7"),
        ({"on_inconsistency": "drop"}, "unknown on_inconsistency 'drop'"),
    ],
)
def test_env_rejects_bad_fusion_settings(kwargs: dict[str, object], match: str) -> None:
    from bearing_env.envs import BearingSLAMEnv

    with pytest.raises(ValueError, match=match):
        BearingSLAMEnv(**kwargs)  # type: ignore[arg-type]


def test_env_fusion_change_gives_a_new_map() -> None:
    from bearing_env.envs import BearingSLAMEnv

    env = BearingSLAMEnv(scenario="khepera")
    env.action_space.seed(0)
    env.reset(seed=0)
    env.step(env.action_space.sample())
    env.fusion = "relaxed"
    assert env.config.fusion == "relaxed"
    env.reset(seed=0)
    _, _, _, _, info = env.step(np.zeros(2, dtype=np.float32))
    assert info["outliers"].tolist() == [0, 0]


def test_missed_detections_are_nan_readings_that_the_map_skips() -> None:
    from bearing_env.envs import BearingSLAMEnv
    from bearing_env.envs.observations import observation_slices

    noise = {"kind": "uniform", "detection_rate": 0.7}
    env = BearingSLAMEnv(scenario="khepera", noise=noise, fusion="relaxed")
    observation, _ = env.reset(seed=3)
    env.action_space.seed(3)
    missed = 0
    for _ in range(20):
        observation, _, terminated, truncated, info = env.step(env.action_space.sample())
        assert np.all(np.isfinite(observation)) and env.observation_space.contains(observation)
        table = observation[observation_slices(env.max_landmarks)["bearings"]].reshape(-1, 3)
        present = table[:, 0] == 1.0
        missed += int(np.sum(present & (table[:, 1] == 0.0) & (table[:, 2] == 0.0)))
        if terminated or truncated:
            break
    assert missed > 0
    # Every region still holds its landmark: a missed reading only skips it.
    assert np.all(info["landmark_contains_truth"][np.isfinite(info["landmark_area"])])
    with pytest.raises(ValueError, match="detection_rate must be in"):
        BearingSLAMEnv(noise={"detection_rate": 0.0})
