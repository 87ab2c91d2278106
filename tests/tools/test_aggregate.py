"""Statistics over training seeds (``bearing_env.train.compare.aggregate``), checked
against rliable's own functions and against direct computations."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.stats
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.extras import skip_module_without

skip_module_without("train", "rliable")

from rliable import metrics  # noqa: E402

from bearing_env.train.compare import aggregate  # noqa: E402


def scores(seed: int, runs: int, episodes: int, moves: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    values = rng.lognormal(size=(runs, episodes, moves))
    return np.round(values, 1)  # rounding makes ties, as capped areas do


def test_iqm_per_move_is_rliables_aggregate_iqm() -> None:
    data = scores(0, 3, 50, moves=4)
    intervals = aggregate.iqm_intervals({"p": data}, resamples=50)["p"]
    for move, interval in enumerate(intervals):
        assert interval.value == pytest.approx(metrics.aggregate_iqm(data[:, :, move]), rel=1e-12)
        assert interval.low <= interval.value <= interval.high
    assert aggregate.iqm(data[:, :, 0]) == pytest.approx(metrics.aggregate_iqm(data[:, :, 0]))


def test_intervals_are_deterministic_and_leave_numpys_global_state_alone() -> None:
    data = {"a": scores(1, 3, 40), "b": scores(2, 1, 40)}
    np.random.seed(123)  # noqa: NPY002  (rliable draws from the global generator)
    before = np.random.random()  # noqa: NPY002  (rliable draws from the global generator)
    np.random.seed(123)  # noqa: NPY002  (rliable draws from the global generator)
    first = aggregate.iqm_intervals(data, resamples=100, seed=7)
    assert np.random.random() == before, "the global generator moved"  # noqa: NPY002
    assert aggregate.iqm_intervals(data, resamples=100, seed=7) == first
    alone = aggregate.iqm_intervals({"a": data["a"]}, resamples=100, seed=7)
    assert alone["a"] == first["a"], "adding a policy changed another's interval"
    assert aggregate.iqm_intervals(data, resamples=100, seed=8) != first


def test_episodes_are_resampled_so_one_run_still_has_a_spread() -> None:
    single_run = scores(3, 1, 60)
    interval = aggregate.iqm_intervals({"planner": single_run}, resamples=200)["planner"][0]
    assert interval.low < interval.value < interval.high


@settings(max_examples=40, deadline=None)
@given(
    runs_x=st.integers(1, 4),
    runs_y=st.integers(1, 4),
    episodes=st.integers(1, 12),
    seed=st.integers(0, 10_000),
)
def test_probability_of_improvement_is_rliables_on_negated_areas(
    runs_x: int, runs_y: int, episodes: int, seed: int
) -> None:
    x = scores(seed, runs_x, episodes)[:, :, 0]
    y = scores(seed + 1, runs_y, episodes)[:, :, 0]
    expected = metrics.probability_of_improvement(-x, -y)
    assert aggregate.probability_of_improvement(x, y) == pytest.approx(expected, abs=1e-12)


def test_improvement_interval_brackets_its_value_and_is_reproducible() -> None:
    x, y = scores(4, 3, 80)[:, :, 0], scores(5, 1, 80)[:, :, 0] * 1.5
    interval = aggregate.improvement_interval(x, y, resamples=300, seed=3)
    assert interval.low <= interval.value <= interval.high
    assert 0.5 < interval.value <= 1.0, "y is worse (larger areas) on most episodes"
    assert aggregate.improvement_interval(x, y, resamples=300, seed=3) == interval
    same = aggregate.improvement_interval(x, x, resamples=100)
    assert same.value == pytest.approx(0.5)


def test_performance_profile_is_the_fraction_below_each_threshold() -> None:
    data = scores(6, 2, 100)[:, :, 0]
    thresholds = np.geomspace(0.1, 10.0, 25)
    profile = aggregate.performance_profiles({"p": data}, thresholds, resamples=100)["p"]
    direct = np.array([np.mean(data < tau) for tau in thresholds])
    np.testing.assert_allclose(profile.fraction, direct)
    assert np.all(np.diff(profile.fraction) >= 0)
    assert np.all(profile.low <= profile.fraction + 1e-12)
    assert np.all(profile.fraction <= profile.high + 1e-12)


@pytest.mark.parametrize(
    "bad",
    [np.zeros((0, 3)), np.zeros(5), np.array([[1.0, np.inf]]), np.array([[np.nan]])],
)
def test_bad_score_arrays_are_refused(bad: np.ndarray) -> None:
    with pytest.raises(ValueError, match="scores"):
        aggregate.probability_of_improvement(bad, bad)


def test_trimmed_mean_matches_scipy_on_pooled_runs() -> None:
    data = scores(9, 4, 30)
    pooled = data[:, :, 0].ravel()
    assert aggregate.iqm(data[:, :, 0]) == pytest.approx(scipy.stats.trim_mean(pooled, 0.25))
