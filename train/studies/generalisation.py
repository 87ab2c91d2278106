"""How a policy trained on random layouts generalises across landmark counts.

Runs ``bearing-env compare`` on random layouts (evaluation seeds, unseen in training) for
each model and landmark count, including counts a model never saw, beside the baselines
(random polygonal, Parallax, GreedyOneStep and Lookahead by default). It prints one table
per model of the total area after 10 moves per policy and count (median and 90th
percentile), and writes ``generalisation.json`` (model -> count -> policy -> median, 90th
percentile and worst-5% mean) with a plot, ``generalisation.png``: the medians against the
count, and each policy's median over GreedyOneStep's and over Lookahead's, with each
model's training range shaded.

    bearing-env generalisation --model ppo_random --counts 3 4 6 8 10 --episodes 50
    bearing-env generalisation --model ppo_generalist ppo_random --counts 3 8 10
    bearing-env generalisation --model ppo_generalist models/candidate.zip --counts 3 8
    python -m bearing_env.train.studies.generalisation ...     # the same

A model is a shipped one by name, or a ``.zip`` that ``bearing-env train --export`` wrote
(its ``.json`` record beside it gives its task), labelled by its file name. When a model
runs on the same envs as the first (its training env kwargs give the same env at every
count, whatever its observation kind), the baselines are not run again: its tables and
plot reuse the first model's.

The total area is summed over the mapped landmarks (L3, L4, ...), so it grows with the
count; compare policies within a column. Every count runs with the env kwargs the model
was trained with (its observation kind and ``max_landmarks`` slots), the landmark count
and the random scenario aside; a model of a set policy (the entity observation's deep set
or attention extractor) also runs on counts beyond its slots, with as many slots as the
count needs. It needs the ``train`` extra (the shipped model runs on
stable-baselines3); without it, it says so in one line and exits with status 2.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from bearing_env.agents.model_task import ModelTask, task_record_of
from bearing_env.agents.sb3 import pretrained_names, pretrained_task
from bearing_env.envs.config import EnvConfig
from bearing_env.extras import available
from bearing_env.train.common.cli_parser import command_parser, doc_summary
from bearing_env.train.common.cli_values import COUNT, format_key_values
from bearing_env.train.common.errors import MissingExtraError, fail
from bearing_env.train.common.files import write_json_atomically
from bearing_env.train.common.progress import progress_bar
from bearing_env.train.common.tables import print_table

DEFAULT_BASELINES = ("random", "parallax", "greedy", "lookahead")
#: The labels the ratio panels divide by (GreedyOneStep's and Lookahead's report labels).
REFERENCE_LABELS = ("greedy_one_step", "lookahead")
#: The total-area figures kept per policy and count (see ``bearing-env compare``).
FIGURES = ("median", "p90", "worst5_mean")
#: The move count the study reports.
MOVES = "10"

#: model -> landmark count -> policy label -> figure -> total area after 10 moves.
Results = dict[str, dict[int, dict[str, dict[str, float]]]]


def env_kwargs_for_count(
    trained: dict[str, Any], count: int, max_landmarks: int | None = None
) -> dict[str, Any]:
    """The model's training env kwargs on a random layout of ``count`` landmarks; with
    ``max_landmarks`` (the model's slots), more slots when ``count`` needs them (only a
    set policy's model runs with more slots than it was trained with)."""
    kwargs = {**trained, "scenario": "random", "n_landmarks": count}
    if max_landmarks is not None and count > max_landmarks:
        kwargs["max_landmarks"] = count
    return kwargs


class StudyModel(NamedTuple):
    """A model of the study: its label, its policy spec and what it was trained on."""

    label: str
    spec: str
    task: ModelTask


def study_model(value: str) -> StudyModel:
    """A shipped model by name, or an exported ``.zip`` with its ``.json`` record.

    Raises:
        ValueError: neither a shipped name nor an exported model with a record.
    """
    if value in pretrained_names():
        return StudyModel(value, f"pretrained:{value}", pretrained_task(value))
    path = Path(value)
    task = task_record_of(path) if path.suffix == ".zip" and path.is_file() else None
    if task is None:
        raise ValueError(
            f"unknown model {value!r}: neither a shipped model ({', '.join(pretrained_names())}) "
            "nor an exported .zip with its .json record beside it (bearing-env train --export)"
        )
    spec = f"sb3:path={path},label={path.stem}"
    return StudyModel(path.stem, spec, task)


def study_envs(model: StudyModel, counts: Sequence[int]) -> list[dict[str, Any]]:
    """The env kwargs a model's comparisons run with, one per count."""
    trained = model.task.env_kwargs
    slots = EnvConfig.create(**trained).observations.max_landmarks
    return [env_kwargs_for_count(trained, count, slots) for count in counts]


def baseline_envs(model: StudyModel, counts: Sequence[int]) -> list[dict[str, Any]]:
    """:func:`study_envs` as the baselines see them: without the observation kind, which
    changes how an observation is laid out, not the episodes (the planners act on the
    robot's map and the bearings, the same numbers in every kind)."""
    return [
        {key: value for key, value in kwargs.items() if key != "observation"}
        for kwargs in study_envs(model, counts)
    ]


class StudySettings(NamedTuple):
    """What every comparison of the study shares."""

    counts: list[int]
    baselines: list[str]
    episodes: int
    workers: int
    out: Path
    resume: bool


def compare_command(
    model: StudyModel,
    env_kwargs: dict[str, Any],
    study: StudySettings,
    folder: Path,
    baselines: bool = True,
) -> list[str]:
    """The ``bearing-env compare`` run of one model and count (with the baselines)."""
    command = [
        sys.executable,
        "-m",
        "bearing_env.train.compare.cli",
        "--env-kwargs",
        *format_key_values(env_kwargs),
        "--policies",
        *(study.baselines if baselines else []),
        model.spec,
        "--episodes",
        str(study.episodes),
        "--workers",
        str(study.workers),
        "--out",
        str(folder),
        "--no-progress",
    ]
    if study.resume and (folder / "config.json").exists():
        command.append("--resume")
    return command


def run_model(
    model: StudyModel,
    study: StudySettings,
    baselines_from: dict[int, dict[str, dict[str, float]]] | None = None,
) -> dict[int, dict[str, dict[str, float]]]:
    """The total area after 10 moves (median, 90th percentile, worst 5% mean) per
    landmark count and policy label, for one model and the baselines beside it (run, or
    taken from ``baselines_from``: the baselines' results on the same envs). Each count
    is its own comparison folder, so an interrupted study resumes count by count."""
    results: dict[int, dict[str, dict[str, float]]] = {}
    envs = study_envs(model, study.counts)
    with progress_bar(len(study.counts), desc=model.label, unit="count", enabled=True) as bar:
        for count, kwargs in zip(study.counts, envs, strict=True):
            folder = study.out / model.label / f"n{count}"
            command = compare_command(model, kwargs, study, folder, baselines_from is None)
            subprocess.run(command, check=True)
            summary = json.loads((folder / "summary.json").read_text())
            results[count] = {
                label: {name: float(stats["area_after"][MOVES][name]) for name in FIGURES}
                for label, stats in summary["policies"].items()
            }
            if baselines_from is not None:
                results[count] = {**baselines_from[count], **results[count]}
            bar.update()
    return results


def plot_medians(results: Results, training_counts: dict[str, tuple[int, int]], path: Path) -> Path:
    """The medians against the landmark count (log scale), and each policy's median over
    GreedyOneStep's and over Lookahead's, with each model's training range shaded."""
    from bearing_env.train.studies.figures import _plt, save_and_close

    plt = _plt()
    first = next(iter(results.values()))
    references = [label for label in REFERENCE_LABELS if label in next(iter(first.values()))]
    figure, panels = plt.subplots(1, 1 + len(references), figsize=(5 * (1 + len(references)), 4))
    panels = np.atleast_1d(panels)
    colours = plt.get_cmap("tab10").colors
    # The baselines once (from the first model's runs), then each model.
    lines = [(label, first) for label in next(iter(first.values())) if label not in results]
    lines += [(model, results[model]) for model in results]
    for index, (label, by_count) in enumerate(lines):
        counts = sorted(by_count)
        colour = colours[index % 10]
        values = np.array([by_count[count][label]["median"] for count in counts])
        style = {"linewidth": 2.5 if label in results else 1.2, "color": colour, "marker": "o"}
        if label in training_counts:
            for axes in panels:
                axes.axvspan(*training_counts[label], color=colour, alpha=0.12)
        panels[0].plot(counts, values, label=label, **style)
        for axes, reference in zip(panels[1:], references, strict=True):
            # Random polygonal is several times above the rest: it would flatten the panel.
            if label not in ("random_polygonal", reference):
                ratio = values / np.array([by_count[c][reference]["median"] for c in counts])
                axes.plot(counts, ratio, label=label, **style)
    panels[0].set_yscale("log")
    panels[0].set_ylabel(f"median total area after {MOVES} moves (FL units², log)")
    for axes, reference in zip(panels[1:], references, strict=True):
        axes.axhline(1.0, color="0.4", linewidth=0.8, linestyle="--")
        axes.set_ylabel(f"median ÷ {reference}'s")
    for axes in panels:
        axes.set_xlabel("landmarks")
        axes.legend(fontsize=8)
    figure.suptitle(
        "across landmark counts: random layouts, evaluation seeds "
        "(shaded: each model's training range)"
    )
    return save_and_close(figure, path, rect=(0, 0, 1, 0.94))


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser("bearing-env generalisation", doc_summary(__doc__))
    parser.add_argument(
        "--model",
        nargs="+",
        default=["ppo_random"],
        metavar="NAME",
        help=f"models, one or more: shipped ({', '.join(pretrained_names())}) or an exported "
        ".zip with its .json record (default ppo_random)",
    )
    parser.add_argument(
        "--baselines",
        nargs="+",
        default=list(DEFAULT_BASELINES),
        metavar="SPEC",
        help="the policies run beside each model (greedy and lookahead give the ratio panels)",
    )
    parser.add_argument(
        "--counts",
        type=COUNT,
        nargs="+",
        default=[3, 4, 6, 8, 10],
        metavar="N",
        help="landmark counts, each in [3, the model's max_landmarks] (default 3 4 6 8 10)",
    )
    parser.add_argument(
        "--episodes", type=COUNT, default=50, help="evaluation episodes per count and policy"
    )
    parser.add_argument("--workers", type=COUNT, default=2, help="processes per comparison, >= 1")
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("outputs/generalisation"),
        help="output folder: one comparison per count, the table and the plot",
    )
    parser.add_argument("--resume", action="store_true", help="continue interrupted counts")
    return parser


def print_results(model: str, results: dict[int, dict[str, dict[str, float]]]) -> None:
    """One model's tables, median then 90th percentile: a row per landmark count, a
    column per policy."""
    labels = list(next(iter(results.values())))
    for figure, title in (("median", "median"), ("p90", "90th percentile")):
        rows = [
            [str(count), *(f"{row[label][figure]:.3g}" for label in labels)]
            for count, row in results.items()
        ]
        print_table(
            f"{model}: {title} total area after {MOVES} moves, random layouts (evaluation seeds)",
            ["landmarks", *labels],
            rows,
        )


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    training_counts: dict[str, tuple[int, int]] = {}
    models: list[StudyModel] = []
    for value in args.model:
        try:
            model = study_model(value)
        except ValueError as error:
            parser.error(str(error))
        if model.label in training_counts:
            parser.error(f"two models are labelled {model.label!r}: rename one")
        # The env's own resolution of the training settings: counts and observation slots.
        trained = EnvConfig.create(**model.task.env_kwargs)
        max_landmarks = trained.observations.max_landmarks
        if model.task.slot_free:
            max_landmarks = max(args.counts)  # a set policy: any count, with more slots
        if min(args.counts) < 3 or max(args.counts) > max_landmarks:
            parser.error(
                f"--counts must lie in [3, {max_landmarks}]: {model.label} has "
                f"max_landmarks={max_landmarks} observation slots"
            )
        training_counts[model.label] = trained.layout.landmark_counts
        models.append(model)
    for module in ("stable_baselines3", "torch", "rich", "matplotlib"):
        if not available(module):
            fail(parser.prog, str(MissingExtraError(module, "this command")))
    study = StudySettings(
        args.counts, args.baselines, args.episodes, args.workers, args.out, args.resume
    )
    results: Results = {}
    for index, model in enumerate(models):
        # The baselines run once per set of envs: a model on the first model's envs
        # reuses its baselines.
        first = models[0]
        baselines = None
        if index > 0 and baseline_envs(model, study.counts) == baseline_envs(first, study.counts):
            baselines = {
                count: {label: row[label] for label in row if label != first.label}
                for count, row in results[first.label].items()
            }
        results[model.label] = run_model(model, study, baselines)
        print_results(model.label, results[model.label])
    write_json_atomically(
        args.out / "generalisation.json",
        {model: {str(k): v for k, v in by_count.items()} for model, by_count in results.items()},
    )
    figure = plot_medians(results, training_counts, args.out / "generalisation.png")
    print(f"wrote {args.out / 'generalisation.json'} and {figure}")


if __name__ == "__main__":
    main()
