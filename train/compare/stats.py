"""The statistics of a comparison: per policy, the total area after each reported move
count (median, mean with a seeded percentile-bootstrap 95% CI, and the worst case: the
90th percentile and the mean of the worst 5%), success, landmark error,
containment, path length, and the policies' time per move.

Deterministic given the records: each interval's resampling stream is keyed by the
policy's label, the metric and the move count, never by the order of the policies.
"""

from __future__ import annotations

import math
import zlib
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env.train.compare.config import CompareConfig

#: Move counts at which the total area is reported.
REPORTED_MOVES: tuple[int, ...] = (1, 3, 5, 10, 20)


def bootstrap_mean_ci(
    values: NDArray[np.float64], rng: np.random.Generator, resamples: int, level: float = 0.95
) -> tuple[float, float]:
    """Percentile bootstrap CI of the mean."""
    n = values.size
    if n == 0:
        return (math.nan, math.nan)
    if n == 1:
        return (float(values[0]), float(values[0]))
    means = values[rng.integers(0, n, size=(resamples, n))].mean(axis=1)
    tail = 100.0 * (1.0 - level) / 2.0
    low, high = np.percentile(means, [tail, 100.0 - tail])
    return (float(low), float(high))


def _stat_rng(bootstrap_seed: int, label: str, metric: str, move: int) -> np.random.Generator:
    # Keyed by the label (not the policy's position), so adding a policy to a comparison
    # does not change the others' intervals.
    key = zlib.crc32(f"{label}|{metric}".encode())
    return np.random.default_rng([bootstrap_seed, key, move])


def series_matrix(
    records: Sequence[Mapping[str, Any]], key: str, length: int
) -> NDArray[np.float64]:
    """(episodes, length) values per move; None -> NaN; carried forward after the end."""
    matrix = np.full((len(records), length), np.nan)
    for row, record in enumerate(records):
        values = [np.nan if v is None else float(v) for v in record[key]]
        values = values[:length] + [values[-1]] * max(0, length - len(values))
        matrix[row] = values
    return matrix


def _nan_to_none(value: float) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


#: The share of the episodes whose mean is the "worst 5%" figure.
WORST_SHARE = 0.05


def worst_share_mean(values: NDArray[np.float64], share: float = WORST_SHARE) -> float:
    """The mean of the largest ``ceil(share * n)`` values (at least one): the tail a
    median hides, as in a conditional value at risk."""
    if values.size == 0:
        return math.nan
    count = max(1, math.ceil(share * values.size - 1e-9))
    return float(np.sort(values)[-count:].mean())


def _distribution(
    values: NDArray[np.float64], rng: np.random.Generator, resamples: int
) -> dict[str, Any]:
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return {
            "n": 0,
            "median": None,
            "mean": None,
            "ci_low": None,
            "ci_high": None,
            "p90": None,
            "worst5_mean": None,
        }
    low, high = bootstrap_mean_ci(finite, rng, resamples)
    return {
        "n": int(finite.size),
        "median": float(np.median(finite)),
        "mean": float(np.mean(finite)),
        "ci_low": _nan_to_none(low),
        "ci_high": _nan_to_none(high),
        "p90": float(np.percentile(finite, 90.0)),
        "worst5_mean": worst_share_mean(finite),
    }


def summarise_policy(
    label: str, records: Sequence[Mapping[str, Any]], config: CompareConfig
) -> dict[str, Any]:
    """Every reported number for one policy (deterministic given the records)."""
    records = sorted(records, key=lambda r: r["seed"])
    max_moves = max(int(r["max_moves"]) for r in records)
    length = max_moves + 1
    areas = series_matrix(records, "area", length)
    errors = series_matrix(records, "error", length)
    resamples = config.bootstrap

    area_after = {
        str(k): _distribution(
            areas[:, k], _stat_rng(config.bootstrap_seed, label, "area", k), resamples
        )
        for k in REPORTED_MOVES
        if k <= max_moves
    }
    curves: dict[str, list[float | None]] = {
        key: []
        for key in (
            "area_median",
            "area_mean",
            "area_ci_low",
            "area_ci_high",
            "error_median",
            "error_mean",
            "error_ci_low",
            "error_ci_high",
        )
    }
    for k in range(length):
        for metric, matrix in (("area", areas), ("error", errors)):
            stats = _distribution(
                matrix[:, k],
                _stat_rng(config.bootstrap_seed, label, f"{metric}_curve", k),
                resamples,
            )
            for name in ("median", "mean", "ci_low", "ci_high"):
                curves[f"{metric}_{name}"].append(stats[name])

    success = np.array([bool(r["success"]) for r in records])
    moves_to_success = np.array(
        [r["moves_to_success"] for r in records if r["moves_to_success"] is not None], float
    )
    final_errors = errors[:, -1]
    n_mapped = np.array([int(r["n_mapped"]) for r in records])
    final_initialised = n_mapped - np.array([int(r["uninitialised"][-1]) for r in records])
    contained = np.array([int(r["contained"][-1]) for r in records])
    path_lengths = np.array([float(r["path_length"]) for r in records])
    moves = np.array([int(r["moves"]) for r in records])
    return {
        "label": label,
        "spec": config.policies[label],
        "episodes": len(records),
        "max_moves": max_moves,
        "area_after": area_after,
        "success_rate": float(success.mean()),
        "moves_to_success_median": _nan_to_none(
            float(np.median(moves_to_success)) if moves_to_success.size else math.nan
        ),
        "moves_to_success_mean": _nan_to_none(
            float(np.mean(moves_to_success)) if moves_to_success.size else math.nan
        ),
        "final_error": _distribution(
            final_errors, _stat_rng(config.bootstrap_seed, label, "final_error", 0), resamples
        ),
        "containment_rate": (
            float(contained.sum() / final_initialised.sum()) if final_initialised.sum() else None
        ),
        "uninitialised_rate": float(1.0 - final_initialised.sum() / n_mapped.sum()),
        "path_length_mean": float(path_lengths.mean()),
        "frame_change_rate": float(sum(int(r["frame_changes"]) for r in records) / moves.sum()),
        "inconsistent_per_episode": float(np.mean([int(r["inconsistent"]) for r in records])),
        "curves": curves,
    }


def summarise(records: Sequence[Mapping[str, Any]], config: CompareConfig) -> dict[str, Any]:
    """The summary of a comparison: the config and one entry per policy, in config order."""
    wanted = set(config.seeds)
    by_label: dict[str, list[Mapping[str, Any]]] = {label: [] for label in config.policies}
    for record in records:
        if record["policy"] in by_label and record["seed"] in wanted:
            by_label[record["policy"]].append(record)
    return {
        "config": config.to_json(),
        "policies": {
            label: summarise_policy(label, rows, config) for label, rows in by_label.items() if rows
        },
    }


def policy_ms_per_move(
    records: Sequence[Mapping[str, Any]], config: CompareConfig
) -> dict[str, float]:
    """Milliseconds of policy time per move, per policy (machine-dependent)."""
    timing = {}
    for label in config.policies:
        rows = [r for r in records if r["policy"] == label]
        moves = sum(int(r["moves"]) for r in rows)
        if moves:
            timing[label] = 1000.0 * sum(float(r["policy_seconds"]) for r in rows) / moves
    return timing
