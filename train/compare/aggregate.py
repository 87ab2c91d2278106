"""Statistics over training seeds, as Agarwal et al. (NeurIPS 2021) recommend and their
``rliable`` package computes them: the interquartile mean (IQM) with stratified bootstrap
95% confidence intervals, the probability of improvement, and performance profiles.

The score is the total area after a number of moves (lower is better), one per
(run, evaluation episode): a policy's scores are a ``(runs, episodes)`` matrix. A trained
model has one run per training seed; a planner or heuristic has one run. The evaluation
episodes are the strata (rliable's "tasks": each is a fixed start, the same for every
policy), and the bootstrap resamples both the episodes and, within each episode, the runs
(``task_bootstrap=True``), so a CI reflects the spread over episodes and over seeds.

Every function here is deterministic given its ``seed``: rliable draws its run indices from
NumPy's global generator, which :func:`_global_numpy_seed` seeds and then restores.
"""

from __future__ import annotations

import contextlib
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: Bootstrap resamples of the intervals (rliable's own default is 50,000; 2,000 keeps an
#: evaluation's statistics to seconds, with CI bounds stable to about 1%).
DEFAULT_RESAMPLES = 2000
DEFAULT_BOOTSTRAP_SEED = 20211206
CONFIDENCE = 0.95


@dataclass(frozen=True)
class Interval:
    """A point estimate with its 95% confidence interval."""

    value: float
    low: float
    high: float

    def to_json(self) -> dict[str, float]:
        return {"value": self.value, "ci_low": self.low, "ci_high": self.high}


@contextlib.contextmanager
def _global_numpy_seed(seed: int) -> Iterator[np.random.RandomState]:
    """Seed NumPy's global generator (rliable's ``StratifiedBootstrap`` draws its run
    indices from it) and give a ``RandomState`` for arch's own draws; restore the global
    state afterwards, so callers' randomness is untouched."""
    saved = np.random.get_state()  # noqa: NPY002  (rliable draws from the global generator)
    np.random.seed(seed)  # noqa: NPY002  (rliable draws from the global generator)
    try:
        with warnings.catch_warnings():
            # arch asks for a Generator in place of the RandomState rliable passes it.
            warnings.filterwarnings("ignore", "random_state is deprecated", FutureWarning)
            yield np.random.RandomState(seed)
    finally:
        np.random.set_state(saved)  # noqa: NPY002  (rliable draws from the global generator)


def _checked(scores: NDArray[np.float64], name: str, ndim: int = 2) -> NDArray[np.float64]:
    matrix = np.asarray(scores, dtype=np.float64)
    if matrix.ndim != ndim or 0 in matrix.shape:
        shape = "(runs, episodes)" if ndim == 2 else "(runs, episodes, moves)"
        raise ValueError(f"{name}: scores must be a non-empty {shape} array, got {matrix.shape}")
    if not np.all(np.isfinite(matrix)):
        raise ValueError(f"{name}: scores must be finite")
    return matrix


def iqm(scores: NDArray[np.float64]) -> float:
    """The interquartile mean of every (run, episode) score (rliable's ``aggregate_iqm``)."""
    from rliable import metrics

    return float(metrics.aggregate_iqm(_checked(scores, "iqm")))


def iqm_intervals(
    score_dict: Mapping[str, NDArray[np.float64]],
    resamples: int = DEFAULT_RESAMPLES,
    seed: int = DEFAULT_BOOTSTRAP_SEED,
) -> dict[str, list[Interval]]:
    """Each policy's IQM with its stratified-bootstrap 95% CI (rliable's
    ``get_interval_estimates``: percentile intervals, runs and episodes resampled), for
    scores of shape ``(runs, episodes, moves)``: one :class:`Interval` per move, from one
    bootstrap that resamples the same (run, episode) pairs at every move."""
    import scipy.stats  # with rliable, in the train extra
    from rliable import library

    def iqm_per_move(x: NDArray[np.float64]) -> NDArray[np.float64]:
        # rliable's aggregate_iqm (a 25% trimmed mean of all scores) of each move at once.
        flat = x.reshape(x.shape[0] * x.shape[1], x.shape[2])
        return np.asarray(scipy.stats.trim_mean(flat, proportiontocut=0.25, axis=0))

    intervals = {}
    for name, scores in score_dict.items():
        checked = _checked(scores, name, ndim=3)
        # The same seed for every policy: adding a policy leaves the others' intervals
        # unchanged.
        with _global_numpy_seed(seed) as random_state:
            points, cis = library.get_interval_estimates(
                {name: checked},
                iqm_per_move,
                method="percentile",
                task_bootstrap=True,
                reps=resamples,
                confidence_interval_size=CONFIDENCE,
                random_state=random_state,
            )
        intervals[name] = [
            Interval(float(value), float(low), float(high))
            for value, low, high in zip(points[name], cis[name][0], cis[name][1], strict=True)
        ]
    return intervals


def probability_of_improvement(areas_x: NDArray[np.float64], areas_y: NDArray[np.float64]) -> float:
    """P(X's area < Y's area) on the same episode, ties counting one half, averaged over
    the episodes: rliable's ``probability_of_improvement`` on the negated areas (lower
    is better), computed for all episodes at once."""
    x = _checked(areas_x, "areas_x")
    y = _checked(areas_y, "areas_y")
    if x.shape[1] != y.shape[1]:
        raise ValueError(f"X and Y must share their episodes, got {x.shape} and {y.shape}")
    return float(_improvement_per_episode(x[None], y[None]).mean())


def _improvement_per_episode(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
    """(reps, episodes) Mann-Whitney probabilities for x (reps, runs_x, episodes) and
    y (reps, runs_y, episodes)."""
    better = (x[:, :, None, :] < y[:, None, :, :]).mean(axis=(1, 2))
    tied = (x[:, :, None, :] == y[:, None, :, :]).mean(axis=(1, 2))
    return better + 0.5 * tied


def improvement_interval(
    areas_x: NDArray[np.float64],
    areas_y: NDArray[np.float64],
    resamples: int = DEFAULT_RESAMPLES,
    seed: int = DEFAULT_BOOTSTRAP_SEED,
) -> Interval:
    """:func:`probability_of_improvement` with a stratified-bootstrap 95% CI: the episodes
    are resampled (the same ones for X and Y, which played them), and within each episode
    each policy's runs independently."""
    x = _checked(areas_x, "areas_x")
    y = _checked(areas_y, "areas_y")
    value = probability_of_improvement(x, y)
    rng = np.random.default_rng(seed)
    episodes = x.shape[1]
    picked = rng.integers(0, episodes, size=(resamples, episodes))
    blocks = []
    # In blocks of 250 resamples: the pairwise comparisons of a block stay a few MB.
    for block in np.array_split(np.arange(resamples), max(1, resamples // 250)):
        columns = picked[block][:, None, :]
        x_runs = rng.integers(0, x.shape[0], size=(len(block), x.shape[0], episodes))
        y_runs = rng.integers(0, y.shape[0], size=(len(block), y.shape[0], episodes))
        blocks.append(_improvement_per_episode(x[x_runs, columns], y[y_runs, columns]).mean(axis=1))
    estimates = np.concatenate(blocks)
    tail = 100.0 * (1.0 - CONFIDENCE) / 2.0
    low, high = np.percentile(estimates, [tail, 100.0 - tail])
    return Interval(value, float(low), float(high))


@dataclass(frozen=True)
class Profile:
    """A performance profile: at each threshold, the fraction of (run, episode) scores
    with total area below the threshold, with its 95% CI band."""

    thresholds: NDArray[np.float64]
    fraction: NDArray[np.float64]
    low: NDArray[np.float64]
    high: NDArray[np.float64]


def performance_profiles(
    score_dict: Mapping[str, NDArray[np.float64]],
    thresholds: Sequence[float] | NDArray[np.float64],
    resamples: int = DEFAULT_RESAMPLES,
    seed: int = DEFAULT_BOOTSTRAP_SEED,
) -> dict[str, Profile]:
    """rliable's ``create_performance_profile`` (score distributions, runs and episodes
    resampled) on the negated areas, so that a profile reads "fraction of episodes with
    total area < tau"."""
    from rliable import library

    taus = np.asarray(thresholds, dtype=np.float64)
    profiles = {}
    for name, scores in score_dict.items():
        negated = -_checked(scores, name)
        with _global_numpy_seed(seed):
            fractions, cis = library.create_performance_profile(
                {name: negated}, -taus, task_bootstrap=True, reps=resamples
            )
        profiles[name] = Profile(taus, fractions[name], cis[name][0], cis[name][1])
    return profiles
