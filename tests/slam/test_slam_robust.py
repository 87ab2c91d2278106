"""The robust fusion (``fusion="robust"``): its nested levels against a brute force, its
binomial rule against the exact tail, the strict intersection bit for bit on clean data,
containment under outliers, the noise-bound estimate (its probe, growth and rebuild from
the bearing history), and its settings' errors."""

from __future__ import annotations

import itertools
import math
import pickle

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from bearing_env.slam import MapSettings, PolygonSLAM, kernels
from bearing_env.slam.geometry import robust_levels
from tests.slam.test_slam_relaxed import (
    EPS,
    assert_same_result,
    convex_polygon,
    polygon_angles,
    run_with_outlier,
    shapely_polygon,
)
from tests.slam_sim import random_episode


def exact_relaxed_set(polygons: list[np.ndarray], left_out: int) -> shapely.Geometry | None:
    """The points in all of ``polygons`` but at most ``left_out``, by shapely: the
    pieces with area (the kernels call an intersection with no area empty); None when
    GEOS cannot union them (pieces within rounding of each other's edges)."""
    shapes = [shapely_polygon(p) for p in polygons]
    pieces = []
    for kept in itertools.combinations(range(len(shapes)), len(shapes) - left_out):
        piece = shapes[kept[0]]
        for i in kept[1:]:
            piece = piece.intersection(shapes[i])
        if piece.area > 1e-9:
            pieces.append(piece)
    try:
        return shapely.union_all(pieces) if pieces else shapely.Polygon()
    except shapely.errors.GEOSException:
        return None


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    centers=st.lists(st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)), min_size=1, max_size=7),
    radii=st.lists(st.floats(0.3, 1.5), min_size=7, max_size=7),
    angles=st.lists(polygon_angles, min_size=7, max_size=7),
)
def test_levels_are_nested_supersets_of_the_relaxed_sets(
    centers: list[tuple[float, float]], radii: list[float], angles: list[list[float]]
) -> None:
    polygons = [
        convex_polygon(complex(x, y), radii[i], angles[i]) for i, (x, y) in enumerate(centers)
    ]
    levels = robust_levels(polygons)
    assert len(levels) == min(len(polygons), kernels.ROBUST_LEVELS)
    previous = None
    for k, level in enumerate(levels):
        exact = exact_relaxed_set(polygons, k)
        assume(exact is not None)
        assert exact is not None
        if level.size == 0:
            assert exact.area < 1e-9
            continue
        hull = shapely_polygon(level).buffer(1e-8)
        assert exact.is_empty or hull.contains(exact)  # shapely: nothing contains empty
        if k == 0:  # the strict intersection itself
            area = shapely_polygon(level).area
            assert area == pytest.approx(exact.area, rel=1e-6, abs=1e-8)
        if previous is not None:
            assert hull.contains(previous)
        previous = shapely_polygon(level)


@settings(max_examples=200, deadline=None, derandomize=True)
@given(
    n=st.integers(0, 40),
    p=st.floats(0.0, 0.9),
    risk=st.floats(1e-4, 0.5),
    q_cap=st.integers(0, 10),
)
def test_binomial_rule_is_the_smallest_q_under_the_risk(
    n: int, p: float, risk: float, q_cap: int
) -> None:
    def tail(q: int) -> float:  # P(Bin(n, p) > q), exactly
        return sum(math.comb(n, x) * p**x * (1 - p) ** (n - x) for x in range(q + 1, n + 1))

    q = kernels.binomial_q(n, p, risk, q_cap)
    assert 0 <= q <= q_cap
    if q < q_cap:
        assert tail(q) < risk + 1e-9
    if q > 0:
        assert tail(q - 1) >= risk - 1e-9


@pytest.mark.parametrize("noise_bound", ["nominal", "estimate"])
def test_clean_data_gives_the_strict_intersection_exactly(noise_bound: str) -> None:
    """With the nominal bound always; with the estimate, in every episode whose probe
    never fires (19 of 20 here: the probe rarely contradicts clean data)."""
    rng = np.random.default_rng(5)
    unchanged = 0
    for _ in range(20):
        episode = random_episode(rng, 6, 14)
        strict = PolygonSLAM(6, EPS)
        robust = PolygonSLAM(6, EPS, fusion="robust", noise_bound=noise_bound)
        results = []
        for b1, b2 in episode.readings(EPS):
            results.append((strict.update(b1, b2), robust.update(b1, b2)))
        if robust.bound > EPS:
            assert noise_bound == "estimate"
            continue
        unchanged += 1
        for expected, result in results:
            assert_same_result(result, expected)
        np.testing.assert_array_equal(robust.areas, strict.areas)
        for mine, theirs in zip(robust.polygons, strict.polygons, strict=True):
            np.testing.assert_array_equal(mine, theirs)  # type: ignore[arg-type]
        assert robust.outliers.tolist() == [0, 0, 0, 0]
    assert unchanged >= 19 if noise_bound == "estimate" else unchanged == 20


def contained_with_bound(noise_bound: str, factor: float) -> tuple[int, int, int]:
    """Regions holding the truth, regions, and maps whose bound grew, over 20 seeded
    episodes of 24 moves whose bearing errors reach ``factor`` times the map's bound."""
    rng = np.random.default_rng(21)
    held = total = grown = 0
    for _ in range(20):
        episode = random_episode(rng, 6, 24)
        slam = PolygonSLAM(6, EPS, fusion="robust", noise_bound=noise_bound)
        for b1, b2 in episode.readings(factor * EPS):
            slam.update(b1, b2)
        inside = slam.contains(episode.truth_fl())
        held += int(inside[slam.initialised].sum())
        total += int(slam.initialised.sum())
        grown += slam.bound > EPS
    return held, total, grown


def test_a_bound_too_small_is_found_and_the_truth_kept() -> None:
    held, total, grown = contained_with_bound("estimate", 1.5)
    nominal_held, nominal_total, nominal_grown = contained_with_bound("nominal", 1.5)
    assert total == nominal_total > 0 and nominal_grown == 0
    assert grown >= 18  # the probe saw it in nearly every episode
    assert held >= 0.95 * total
    assert held - nominal_held >= 0.1 * total  # the nominal bound loses 15% here
    assert contained_with_bound("estimate", 1.0)[2] == 0  # and clean maps keep epsilon


def test_a_grown_bound_rebuilds_the_map_from_the_kept_bearings() -> None:
    """After each growth the levels are those of a map at the new bound (estimate off)
    fed the last ``HISTORY`` movements, including growths after the history is full."""
    rng = np.random.default_rng(21)
    growths = late = 0
    for _ in range(6):
        episode = random_episode(rng, 6, 30)
        readings = episode.readings(1.6 * EPS)
        slam = PolygonSLAM(6, EPS, fusion="robust")
        for m, (b1, b2) in enumerate(readings):
            bound = slam.bound
            slam.update(b1, b2)
            if slam.bound == bound:
                continue
            assert slam.bound == pytest.approx(bound * kernels.BOUND_GROWTH)
            growths += 1
            late += m >= kernels.HISTORY
            again = PolygonSLAM(6, slam.bound, fusion="robust", noise_bound="nominal")
            for start, end in readings[max(0, m + 1 - kernels.HISTORY) : m + 1]:
                again.update(start, end)
            mine, theirs = slam.batch, again.batch
            np.testing.assert_array_equal(mine.level_counts, theirs.level_counts)
            for (j, k), count in np.ndenumerate(mine.level_counts[0]):
                np.testing.assert_array_equal(
                    mine.level_vertices[0, j, k, :count], theirs.level_vertices[0, j, k, :count]
                )
            np.testing.assert_array_equal(mine.robot_polygon(0), theirs.robot_polygon(0))
            assert slam.n_updates == m + 1
    assert growths >= 6 and late >= 1


def test_noise_within_epsilon_is_always_contained() -> None:
    rng = np.random.default_rng(6)
    for _ in range(15):
        episode = random_episode(rng, 5, 12, noise="extreme")
        slam = PolygonSLAM(5, EPS, fusion="robust", robust_set="guaranteed")
        for b1, b2 in episode.readings(EPS):
            slam.update(b1, b2)
        inside = slam.contains(episode.truth_fl())
        assert inside[slam.initialised].all()


def outlier_episode_contains(robust_set: str, seed: int) -> tuple[int, int]:
    """Regions holding the truth and regions, over a few seeded episodes with 10% of the
    readings replaced by random bearings."""
    rng = np.random.default_rng(seed)
    held = total = 0
    for _ in range(12):
        episode = random_episode(rng, 6, 16)
        slam = PolygonSLAM(6, EPS, fusion="robust", robust_set=robust_set)
        for b1, b2 in episode.readings(EPS):
            for bearings in (b1, b2):
                misread = rng.random(bearings.shape) < 0.1
                bearings[misread] = rng.uniform(-np.pi, np.pi, misread.sum())
            slam.update(b1, b2)
        inside = slam.contains(episode.truth_fl())
        total += int(slam.initialised.sum())
        held += int(inside[slam.initialised].sum())
    return held, total


def test_the_guaranteed_set_holds_the_truth_more_often_than_the_likely_set() -> None:
    guaranteed, total = outlier_episode_contains("guaranteed", 7)
    likely, total_likely = outlier_episode_contains("likely", 7)
    assert total == total_likely > 0
    assert guaranteed > likely
    assert guaranteed >= 0.9 * total


def test_a_misread_frame_landmark_is_caught_by_the_robot_region() -> None:
    robust, statuses, truth = run_with_outlier("robust", 1, 0.6)
    assert statuses[6] == "rejected"  # its start misses where the last move ended
    assert statuses.count("rejected") == 1
    assert robust.contains(truth).all()
    assert robust.outliers.tolist() == [0, 0, 0, 0]  # nothing of it was fused


def test_a_misread_landmark_is_left_out_for_that_landmark_only() -> None:
    robust, statuses, truth = run_with_outlier("robust", 3, 0.3)
    assert "rejected" not in statuses
    assert robust.contains(truth).all()
    assert robust.outliers.tolist() == [0, 1, 0, 0]


@pytest.mark.parametrize("factor", [1.0, 1.6])
def test_the_robust_state_survives_copies_and_pickles(factor: float) -> None:
    """With one outlier (the levels differ), and with a bound too small (the bound, the
    probe and the bearing history carry over)."""
    episode = random_episode(np.random.default_rng(2), 5, 24)
    readings = episode.readings(factor * EPS)
    readings[3][0][2] += 1.0
    slam = PolygonSLAM(5, EPS, fusion="robust")
    for b1, b2 in readings[:12]:
        slam.update(b1, b2)
    copies = [slam.copy(), pickle.loads(pickle.dumps(slam))]
    for b1, b2 in readings[12:]:
        expected = slam.update(b1, b2)
        for other in copies:
            assert_same_result(other.update(b1, b2), expected)
            np.testing.assert_array_equal(other.areas, slam.areas)
            assert other.bound == slam.bound
    assert (slam.bound > EPS) == (factor > 1.0)


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"fusion": "robust", "risk": 0.0}, ValueError, r"risk must be in \(0, 0.5\], got 0.0"),
        ({"fusion": "robust", "risk": 0.7}, ValueError, r"risk must be in \(0, 0.5\], got 0.7"),
        ({"fusion": "robust", "risk": "low"}, TypeError, "risk must be a number, got 'low'"),
        ({"robust_set": "best"}, ValueError, "robust_set must be one of .* got 'best'"),
        ({"noise_bound": "guess"}, ValueError, "noise_bound must be one of .* got 'guess'"),
    ],
)
def test_bad_robust_settings_are_named(kwargs: dict[str, object], error: type, match: str) -> None:
    with pytest.raises(error, match=match):
        PolygonSLAM(4, EPS, **kwargs)  # type: ignore[arg-type]
    with pytest.raises(error, match=match):
        MapSettings(EPS, **kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"fusion": "robust", "risk": 1.0}, r"risk must be in \(0, 0.5\], got 1.0"),
        ({"fusion": "robust", "robust_set": "all"}, "unknown robust_set 'all'"),
        ({"fusion": "robust", "noise_bound": "auto"}, "unknown noise_bound 'auto'"),
    ],
)
def test_env_rejects_bad_robust_settings(kwargs: dict[str, object], match: str) -> None:
    from bearing_env.envs import BearingSLAMEnv

    with pytest.raises(ValueError, match=match):
        BearingSLAMEnv(**kwargs)  # type: ignore[arg-type]


def test_env_robust_reports_its_levels_and_decodes_them() -> None:
    from bearing_env.envs import BearingSLAMEnv
    from bearing_env.envs.robot_map import decode

    env = BearingSLAMEnv(
        scenario="khepera", fusion="robust", noise={"kind": "uniform", "outlier_rate": 0.2}
    )
    env.reset(seed=4)
    env.action_space.seed(4)
    for _ in range(12):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:
            break
    data = info["robot_map"]
    assert "level_vertices" in data and "window_vertices" not in data
    slam = env.slam
    assert slam is not None
    copy = decode(data, slam.n_landmarks, env.config.map_settings)
    np.testing.assert_array_equal(copy.areas, slam.areas)
    np.testing.assert_array_equal(copy.outliers, slam.outliers)
    assert copy.bound == slam.bound
    np.testing.assert_array_equal(copy.batch.history_bearings, slam.batch.history_bearings)
    np.testing.assert_array_equal(copy.batch.probe_counts, slam.batch.probe_counts)
    for j, count in enumerate(slam.batch.probe_counts[0]):
        np.testing.assert_array_equal(
            copy.batch.probe_vertices[0, j, :count], slam.batch.probe_vertices[0, j, :count]
        )
    env.close()


@pytest.mark.parametrize("vector", [False, True])
def test_a_reset_forgets_the_grown_bound_and_the_history(vector: bool) -> None:
    """The bound is a property of an episode's data: a new episode starts at epsilon."""
    import gymnasium as gym

    kwargs = {
        "scenario": "random",
        "n_landmarks": 8,
        "fusion": "robust",
        "noise": {"kind": "uniform", "bound_deg": 4.0},
        "max_moves": 30,
        "target_area": 1e-12,
    }
    env = (
        gym.make_vec("BearingSLAM-v1", num_envs=2, **kwargs)
        if vector
        else gym.make("BearingSLAM-v1", **kwargs)
    )

    def maps() -> list[PolygonSLAM]:
        if vector:
            return list(env.unwrapped.get_attr("slam"))  # type: ignore[attr-defined]
        return [env.unwrapped.slam]  # type: ignore[attr-defined]

    env.reset(seed=3)
    env.action_space.seed(3)
    for _ in range(29):
        env.step(env.action_space.sample())
    assert any(slam.bound > slam.epsilon for slam in maps())
    env.reset(seed=4)
    for slam in maps():
        batch, row = slam.batch, slam.index
        assert slam.bound == slam.epsilon and batch.history_length[row] == 0
        assert batch.bound_events[row] == 0 and not batch.probe_counts[row].any()
    env.close()


@pytest.mark.parametrize("n", [10, 2**62])
def test_binomial_q_returns_q_cap_at_once_when_the_risk_is_never_met(n: int) -> None:
    # risk <= 0 is never met: the answer is q_cap, however large (the loop once ran up to
    # q_cap, endless for a huge one).
    assert kernels.binomial_q(n, 0.5, 0.0, 2**63 - 1) == 2**63 - 1
    assert kernels.binomial_q(n, 0.5, -1.0, 7) == 7
    # A huge q_cap with a risk that is met: the smallest q, as with a small cap.
    assert kernels.binomial_q(10, 0.5, 0.05, 2**63 - 1) == kernels.binomial_q(10, 0.5, 0.05, 10)
