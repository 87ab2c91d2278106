"""How a policy trained on random layouts generalises across landmark counts.

Runs ``bearing-env compare`` on random layouts (evaluation seeds, unseen in training) for
each landmark count, including counts the policy never saw, prints one table of the
median total area after 10 moves per policy and count, and writes it to
``generalisation.json`` with a plot, ``generalisation.png`` (the medians against the count,
and each policy's median over GreedyOneStep's but random polygonal's, with the model's
training range shaded).

    bearing-env generalisation --model ppo_random --counts 3 4 6 8 10 --episodes 50
    python -m bearing_env.train.studies.generalisation ...     # the same

The total area is summed over the mapped landmarks (L3, L4, ...), so it grows with the
count; compare policies within a column. Every count runs with the env kwargs the model
was trained with (its observation kind and ``max_landmarks`` slots), the landmark count
and the random scenario aside. It needs the ``train`` extra (the shipped model runs on
stable-baselines3); without it, it says so in one line and exits with status 2.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from bearing_env.agents.sb3 import pretrained_names, pretrained_record
from bearing_env.envs.config import EnvConfig
from bearing_env.extras import available
from bearing_env.train.common.cli_parser import command_parser, doc_summary
from bearing_env.train.common.cli_values import COUNT, format_key_values
from bearing_env.train.common.errors import MissingExtraError, fail
from bearing_env.train.common.files import write_json_atomically
from bearing_env.train.common.tables import print_table

DEFAULT_BASELINES = ("random", "parallax", "greedy")
#: The label the ratio panel divides by (GreedyOneStep's report label).
REFERENCE_LABEL = "greedy_one_step"


def env_kwargs_for_count(trained: dict[str, Any], count: int) -> dict[str, Any]:
    """The model's training env kwargs on a random layout of ``count`` landmarks."""
    return {**trained, "scenario": "random", "n_landmarks": count}


def run_counts(
    model: str,
    counts: list[int],
    episodes: int,
    workers: int,
    out: Path,
    resume: bool,
) -> dict[int, dict[str, float]]:
    """Median total area after 10 moves, per landmark count and policy label."""
    trained = dict(pretrained_record(model).get("env_kwargs", {}))
    medians: dict[int, dict[str, float]] = {}
    for count in counts:
        folder = out / f"n{count}"
        env_kwargs = env_kwargs_for_count(trained, count)
        command = [
            sys.executable,
            "-m",
            "bearing_env.train.compare.cli",
            "--env-kwargs",
            *format_key_values(env_kwargs),
            "--policies",
            *DEFAULT_BASELINES,
            f"pretrained:{model}",
            "--episodes",
            str(episodes),
            "--workers",
            str(workers),
            "--out",
            str(folder),
            "--no-progress",
        ]
        if resume and (folder / "config.json").exists():
            command.append("--resume")
        subprocess.run(command, check=True)
        summary = json.loads((folder / "summary.json").read_text())
        medians[count] = {
            label: float(stats["area_after"]["10"]["median"])
            for label, stats in summary["policies"].items()
        }
    return medians


def plot_medians(
    medians: dict[int, dict[str, float]], model: str, trained_counts: tuple[int, int], path: Path
) -> Path:
    """The medians against the landmark count (log scale) and over GreedyOneStep's."""
    from bearing_env.train.studies.figures import _plt, save_and_close

    plt = _plt()
    counts = sorted(medians)
    labels = list(medians[counts[0]])
    figure, (areas, ratios) = plt.subplots(1, 2, figsize=(10, 4))
    for axes in (areas, ratios):
        axes.axvspan(*trained_counts, color="0.9", label=f"{model}'s training range")
    colours = plt.get_cmap("tab10").colors
    for index, label in enumerate(labels):
        values = [medians[count][label] for count in counts]
        style = {"linewidth": 2.5 if label == model else 1.2, "color": colours[index % 10]}
        areas.plot(counts, values, marker="o", label=label, **style)
        # Random polygonal is several times above the rest: it would flatten that panel.
        if REFERENCE_LABEL in medians[counts[0]] and label != "random_polygonal":
            reference = [medians[count][REFERENCE_LABEL] for count in counts]
            ratio = [value / ref for value, ref in zip(values, reference, strict=True)]
            ratios.plot(counts, ratio, marker="o", label=label, **style)
    areas.set_yscale("log")
    areas.set_xlabel("landmarks")
    areas.set_ylabel("median total area after 10 moves (FL units², log)")
    areas.legend(fontsize=8)
    ratios.axhline(1.0, color="0.4", linewidth=0.8, linestyle="--")
    ratios.set_xlabel("landmarks")
    ratios.set_ylabel(f"median ÷ {REFERENCE_LABEL}'s")
    ratios.legend(fontsize=8)
    figure.suptitle(f"{model} across landmark counts: random layouts, evaluation seeds")
    return save_and_close(figure, path, rect=(0, 0, 1, 0.94))


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser("bearing-env generalisation", doc_summary(__doc__))
    parser.add_argument(
        "--model",
        default="ppo_random",
        help=f"shipped model name: {', '.join(pretrained_names())} (default %(default)s)",
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
    parser.add_argument(
        "--workers", type=COUNT, default=2, help="processes per comparison, >= 1"
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=Path("outputs/generalisation"),
        help="output folder: one comparison per count, the table and the plot",
    )
    parser.add_argument("--resume", action="store_true", help="continue interrupted counts")
    return parser


def print_medians(medians: dict[int, dict[str, float]]) -> None:
    """The medians as one table: a row per landmark count, a column per policy."""
    labels = list(next(iter(medians.values())))
    rows = [
        [str(count), *(f"{row[label]:.3g}" for label in labels)]
        for count, row in medians.items()
    ]
    print_table(
        "median total area after 10 moves, random layouts (evaluation seeds)",
        ["landmarks", *labels],
        rows,
    )


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if args.model not in pretrained_names():
        parser.error(f"unknown model {args.model!r}; shipped: {', '.join(pretrained_names())}")
    # The env's own resolution of the training settings: their counts and observation slots.
    trained = EnvConfig.create(**pretrained_record(args.model).get("env_kwargs", {}))
    max_landmarks = trained.observations.max_landmarks
    if min(args.counts) < 3 or max(args.counts) > max_landmarks:
        parser.error(
            f"--counts must lie in [3, {max_landmarks}]: {args.model} has "
            f"max_landmarks={max_landmarks} observation slots"
        )
    for module in ("stable_baselines3", "torch", "rich", "matplotlib"):
        if not available(module):
            fail(parser.prog, str(MissingExtraError(module, "this command")))
    medians = run_counts(
        args.model, args.counts, args.episodes, args.workers, args.out, args.resume
    )
    print_medians(medians)
    write_json_atomically(args.out / "generalisation.json", {str(k): v for k, v in medians.items()})
    figure = plot_medians(
        medians, args.model, trained.layout.landmark_counts, args.out / "generalisation.png"
    )
    print(f"wrote {args.out / 'generalisation.json'} and {figure}")


if __name__ == "__main__":
    main()
