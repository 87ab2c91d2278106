"""The files of ``bearing-env evaluate``: from the episodes of the baselines and of every run
of the model, the statistics over runs (:mod:`~bearing_env.train.compare.aggregate`) as
``evaluation.json``, ``evaluation.md``, ``area_vs_moves.png`` and
``performance_profile.png``.

The score is the total area after n moves (FL units², each landmark capped at the task's
``area_cap``; lower is better), an episode that ended early counting with its final map.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env.train.common.files import (
    atomic_save_figure,
    atomic_write_text,
    write_json_atomically,
)
from bearing_env.train.common.provenance import measured_here, measured_sentence
from bearing_env.train.compare.aggregate import (
    Interval,
    improvement_interval,
    iqm_intervals,
    performance_profiles,
)
from bearing_env.train.compare.config import CompareConfig
from bearing_env.train.compare.stats import REPORTED_MOVES, series_matrix, worst_share_mean

#: The move count of the performance profile and of the tables' first columns.
HEADLINE_MOVES = 10
PROFILE_THRESHOLDS = 120


def score_arrays(
    records: Sequence[Mapping[str, Any]], groups: Mapping[str, Sequence[str]]
) -> dict[str, NDArray[np.float64]]:
    """``(runs, episodes, moves + 1)`` total areas of each group of policy labels (one
    run per label), episodes in seed order."""
    by_label: dict[str, list[Mapping[str, Any]]] = {}
    for record in records:
        by_label.setdefault(str(record["policy"]), []).append(record)
    length = 1 + max(int(record["max_moves"]) for record in records)
    arrays = {}
    for group, labels in groups.items():
        runs = [
            series_matrix(sorted(by_label[label], key=lambda r: int(r["seed"])), "area", length)
            for label in labels
        ]
        arrays[group] = np.stack(runs)
    return arrays


def _interval_json(interval: Interval) -> dict[str, float]:
    return interval.to_json()


def _figures(
    scores: NDArray[np.float64], curve: Sequence[Interval], moves: Sequence[int]
) -> dict[str, Any]:
    """The figures of one policy (all its runs) after each reported move count."""
    return {
        "runs": int(scores.shape[0]),
        "episodes": int(scores.shape[1]),
        "area_after": {
            str(k): {
                "iqm": _interval_json(curve[k]),
                "median": float(np.median(scores[:, :, k])),
                "mean": float(np.mean(scores[:, :, k])),
                "worst5_mean": worst_share_mean(scores[:, :, k].ravel()),
            }
            for k in moves
        },
        "iqm_curve": [_interval_json(interval) for interval in curve],
    }


def evaluation_results(
    records: Sequence[Mapping[str, Any]],
    config: CompareConfig,
    model: str,
    labels: Sequence[str],
    resamples: int,
    seed: int,
) -> dict[str, Any]:
    """Every figure of an evaluation (without its provenance), JSON-safe."""
    baselines = [label for label in config.policies if label not in labels]
    groups: dict[str, Sequence[str]] = {label: [label] for label in baselines}
    groups[model] = labels
    groups.update({label: [label] for label in labels})
    scores = score_arrays(records, groups)
    curves = iqm_intervals(scores, resamples, seed)
    max_moves = next(iter(scores.values())).shape[2] - 1
    moves = [k for k in REPORTED_MOVES if k <= max_moves]
    headline = min(HEADLINE_MOVES, max_moves)
    improvement = {
        baseline: {
            str(k): improvement_interval(
                scores[model][:, :, k], scores[baseline][:, :, k], resamples, seed
            ).to_json()
            for k in moves
        }
        for baseline in baselines
    }
    aggregate_iqm = curves[model][headline].value
    representative = min(
        labels, key=lambda label: abs(curves[label][headline].value - aggregate_iqm)
    )
    return {
        "task": config.env_id.rpartition(":")[2],
        "env_kwargs": config.env_kwargs,
        "episodes": config.episodes,
        "episode_seeds": [config.seeds[0], config.seeds[-1]],
        "score": "total area after n moves (FL units^2, each landmark capped at area_cap; "
        "lower is better)",
        "statistics": {
            "iqm": "interquartile mean of every (run, episode) score (rliable aggregate_iqm)",
            "ci": "95% stratified bootstrap, percentile: episodes resampled, and runs within "
            "each episode (rliable get_interval_estimates, task_bootstrap=True)",
            "probability_of_improvement": "P(model's area < baseline's on the same "
            "episode), ties counting 1/2, averaged over episodes (rliable's definition)",
            "resamples": resamples,
            "seed": seed,
        },
        # The run to ship as "the" model: its IQM is the closest to the IQM over the runs.
        "model": {"name": model, "runs": list(labels), "representative_run": representative},
        "baselines": baselines,
        "moves": moves,
        "headline_moves": headline,
        "policies": {group: _figures(scores[group], curves[group], moves) for group in groups},
        "probability_of_improvement": improvement,
        "profile": _profile_json(scores, [*baselines, model], headline, resamples, seed),
    }


def _profile_json(
    scores: Mapping[str, NDArray[np.float64]],
    groups: Sequence[str],
    move: int,
    resamples: int,
    seed: int,
) -> dict[str, Any]:
    at_move = {group: scores[group][:, :, move] for group in groups}
    positive = np.concatenate([values[values > 0].ravel() for values in at_move.values()])
    low = float(positive.min()) if positive.size else 1e-3
    high = float(max(values.max() for values in at_move.values()))
    thresholds = np.geomspace(low * 0.9, max(high, low) * 1.1, PROFILE_THRESHOLDS)
    profiles = performance_profiles(at_move, thresholds, resamples, seed)
    return {
        "moves": move,
        "thresholds": thresholds.tolist(),
        "policies": {
            group: {
                "fraction": profile.fraction.tolist(),
                "ci_low": profile.low.tolist(),
                "ci_high": profile.high.tolist(),
            }
            for group, profile in profiles.items()
        },
    }


def _cell(entry: Mapping[str, Any], digits: int = 3) -> str:
    return (
        f"{entry['value']:.{digits}g} [{entry['ci_low']:.{digits}g}, {entry['ci_high']:.{digits}g}]"
    )


def seeds_markdown(results: Mapping[str, Any]) -> str:
    """A task card's summary of a shipped model's training seeds: the IQM over the seeds,
    the representative (shipped) seed alone, and the baselines, with the probability
    that the model beats each."""
    model = results["model"]["name"]
    runs = results["model"]["runs"]
    shipped = results["model"]["representative_run"]
    policies = results["policies"]
    head, final = str(results["headline_moves"]), str(results["moves"][-1])
    header = (
        f"| policy | runs x episodes | IQM after {head} [95% CI] | IQM after {final} "
        f"[95% CI] | P({model} better) after {head} [95% CI] |"
    )
    lines = [header, "|---|---|---|---|---|"]
    rows = [(f"{model}, {len(runs)} seeds", model), (f"{shipped} (shipped)", shipped)]
    rows += [(baseline, baseline) for baseline in results["baselines"]]
    for name, group in rows:
        figures = policies[group]
        improvement = results["probability_of_improvement"].get(group)
        lines.append(
            f"| {name} | {figures['runs']} x {figures['episodes']} | "
            f"{_cell(figures['area_after'][head]['iqm'])} | "
            f"{_cell(figures['area_after'][final]['iqm'])} | "
            f"{_cell(improvement[head], 2) if improvement else '-'} |"
        )
    return "\n".join(lines)


def evaluation_markdown(
    results: Mapping[str, Any], source: str = "evaluation.json", heading: bool = True
) -> str:
    """``evaluation.md`` from ``evaluation.json``'s content: the aggregate table, the
    per-run table, and what they rest on, citing the results file as ``source``; without
    the page heading for a docs block (``bearing-env docs-tables``)."""
    measured = results["measured"]
    model = results["model"]["name"]
    runs = results["model"]["runs"]
    policies = results["policies"]
    head = str(results["headline_moves"])
    final = str(results["moves"][-1])
    lines = [f"# {model} on {results['task']}", ""] if heading else []
    lines += [
        f"{len(runs)} run(s) of `{model}` (training seeds) and each baseline (one run) on the "
        f"same {results['episodes']} evaluation episodes (seeds {results['episode_seeds'][0]}"
        f"..{results['episode_seeds'][1]}). Score: {results['score']}. IQM: "
        f"{results['statistics']['iqm']}; [95% CI]: {results['statistics']['ci']}, "
        f"{results['statistics']['resamples']} resamples. P(better): "
        f"{results['statistics']['probability_of_improvement']}.",
        "",
        f"| policy | runs x episodes | IQM after {head} | median after {head} | worst-5% mean "
        f"after {head} | IQM after {final} | P({model} better) after {head} |",
        "|---|---|---|---|---|---|---|",
    ]
    for group in [*results["baselines"], model]:
        figures = policies[group]
        at_head, at_final = figures["area_after"][head], figures["area_after"][final]
        improvement = results["probability_of_improvement"].get(group)
        lines.append(
            f"| {group} | {figures['runs']} x {figures['episodes']} | {_cell(at_head['iqm'])} | "
            f"{at_head['median']:.3g} | {at_head['worst5_mean']:.3g} | "
            f"{_cell(at_final['iqm'])} | "
            f"{_cell(improvement[head], 2) if improvement else '-'} |"
        )
    lines += [
        "",
        "Each run alone (one run x the episodes):",
        "",
        f"| run | IQM after {head} | median after {head} | worst-5% mean after {head} | "
        f"IQM after {final} |",
        "|---|---|---|---|---|",
    ]
    for run in runs:
        at_head, at_final = policies[run]["area_after"][head], policies[run]["area_after"][final]
        lines.append(
            f"| {run} | {_cell(at_head['iqm'])} | {at_head['median']:.3g} | "
            f"{at_head['worst5_mean']:.3g} | {_cell(at_final['iqm'])} |"
        )
    lines += [
        "",
        f"The run closest to the IQM over the runs after {head} moves: "
        f"`{results['model']['representative_run']}`.",
        "",
        measured_sentence(measured, source),
    ]
    return "\n".join(lines)


def plot_evaluation(results: Mapping[str, Any], out: Path) -> list[Path]:
    """The IQM area curves with CI bands, and the performance profile."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    model = results["model"]["name"]
    groups = [*results["baselines"], model]
    colours = plt.get_cmap("tab10").colors  # type: ignore[attr-defined]  # a ListedColormap
    title = (
        f"{results['task']}: {len(results['model']['runs'])} run(s) of {model}, "
        f"{results['episodes']} evaluation episodes"
    )
    figure, axes = plt.subplots(figsize=(7.0, 4.3), dpi=110)
    for index, group in enumerate(groups):
        curve = results["policies"][group]["iqm_curve"]
        x = np.arange(len(curve))
        colour = colours[index % len(colours)]
        axes.plot(x, [c["value"] for c in curve], color=colour, lw=2, label=group)
        low, high = [c["ci_low"] for c in curve], [c["ci_high"] for c in curve]
        axes.fill_between(x, low, high, color=colour, alpha=0.2, lw=0)
    for run in results["model"]["runs"]:
        curve = results["policies"][run]["iqm_curve"]
        axes.plot([c["value"] for c in curve], color="0.4", lw=0.8, ls=":")
    axes.set_yscale("log")
    axes.xaxis.set_major_locator(MaxNLocator(integer=True))
    axes.set_xlabel("moves")
    axes.set_ylabel("total area (FL units², log)")
    axes.set_title(f"{title}\nIQM with 95% stratified bootstrap CI; dotted: each run", fontsize=9)
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    written = [out / "area_vs_moves.png"]
    atomic_save_figure(figure, written[0])
    plt.close(figure)

    profile = results["profile"]
    figure, axes = plt.subplots(figsize=(7.0, 4.3), dpi=110)
    for index, group in enumerate(groups):
        entry = profile["policies"][group]
        colour = colours[index % len(colours)]
        axes.plot(profile["thresholds"], entry["fraction"], color=colour, lw=2, label=group)
        axes.fill_between(
            profile["thresholds"], entry["ci_low"], entry["ci_high"], color=colour, alpha=0.2, lw=0
        )
    axes.set_xscale("log")
    axes.set_ylim(0.0, 1.0)
    axes.set_xlabel(f"threshold τ on the total area after {profile['moves']} moves (FL units²)")
    axes.set_ylabel("fraction of episodes with area < τ")
    axes.set_title(f"{title}\nperformance profile, 95% stratified bootstrap CI", fontsize=9)
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8)
    figure.tight_layout()
    written.append(out / "performance_profile.png")
    atomic_save_figure(figure, written[1])
    plt.close(figure)
    return written


def write_evaluation(
    records: Sequence[Mapping[str, Any]],
    config: CompareConfig,
    model: str,
    labels: Sequence[str],
    paths: Sequence[Path],
    out: Path,
    argv: Sequence[str],
    resamples: int,
    seed: int,
) -> list[Path]:
    """Write every file of an evaluation into ``out``; the paths written."""
    results = evaluation_results(records, config, model, labels, resamples, seed)
    results["model"]["paths"] = [str(path) for path in paths]
    results["measured"] = measured_here("bearing-env evaluate", argv)
    out.mkdir(parents=True, exist_ok=True)
    json_path, markdown_path = out / "evaluation.json", out / "evaluation.md"
    write_json_atomically(json_path, results)
    atomic_write_text(markdown_path, evaluation_markdown(results) + "\n")
    return [json_path, markdown_path, *plot_evaluation(results, out)]
