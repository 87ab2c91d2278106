"""``bearing-env evaluate``: a model you trained, as one run or as several training seeds,
against the task's baselines on the task's evaluation episodes, with statistics over the
seeds.

    bearing-env evaluate runs/ppo_khepera --env BearingSLAM-Khepera-v1 --out outputs/eval
    bearing-env evaluate 'runs/ppo_khepera/seed*' model.zip ...   # run folders, globs, .zip

A MODEL is a run folder of ``bearing-env train`` (its best model, ``best/best_model.zip``),
a folder of several run folders (one per training seed, as ``bearing-env train --seeds``
writes them), a model ``.zip`` (with ``<stem>_vecnormalize.pkl`` and ``<stem>.json``
beside it when it has them, as ``--export`` writes them), or a glob of any of these. Every
model is one run of the same model, told apart by its training seed.

The baselines (random polygonal, Parallax, GreedyOneStep, Lookahead by default) and every
run play the same evaluation episodes, ``--episodes`` of them from seed 1,000,000, which
training never uses. The episodes run through ``bearing-env compare`` into
``OUT/episodes/`` (its log, so an interrupted evaluation resumes with ``--resume``); then
:mod:`~bearing_env.train.compare.evaluation_report` writes into ``OUT``:

- ``evaluation.json``: the command, commit, machine and date; per run and aggregated over
  the runs, the IQM of the total area after 1, 3, 5, 10 and 20 moves with its stratified
  bootstrap 95% CI, the median, the worst-5% mean; the probability that the model beats
  each baseline on an episode, with its CI; how many runs and episodes each figure rests
  on;
- ``evaluation.md``: the same as tables;
- ``area_vs_moves.png``: IQM total area against moves, with 95% CI bands;
- ``performance_profile.png``: the fraction of episodes whose total area after 10 moves is
  below each threshold, with 95% CI bands.

The model's recorded task (``run.json``, or the ``.json`` beside an exported model) must be
the task evaluated on (``--env``, by default the models' own); a mismatch is refused in one
line naming the settings that differ. Nothing is ever written into ``docs/``.
"""

from __future__ import annotations

import argparse
import glob
import json
import sys
import time
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from bearing_env.tasks import current_id
from bearing_env.train.common.cli_parser import add_no_progress, command_parser
from bearing_env.train.common.cli_values import COUNT, registered_env_id
from bearing_env.train.common.errors import exit_on_missing_extra, exit_on_output_errors, fail
from bearing_env.train.common.seeds import EVAL_SEED_START
from bearing_env.train.compare.aggregate import DEFAULT_BOOTSTRAP_SEED, DEFAULT_RESAMPLES
from bearing_env.train.compare.cli import reproducing_command, result_arguments, task_of
from bearing_env.train.compare.comparison import RunMismatchError, run_comparison
from bearing_env.train.compare.config import DEFAULT_EPISODES, CompareConfig, policies_from_specs
from bearing_env.train.compare.log import LOG_NAME, CorruptLogError

PROG = "bearing-env evaluate"
#: The task's baselines, as policy specs.
DEFAULT_BASELINES: tuple[str, ...] = ("random", "parallax", "greedy", "lookahead")
#: Where the comparison's own files go inside the output folder.
EPISODES_FOLDER = "episodes"
RUN_RECORD = "run.json"
#: Arguments that change how the evaluation runs, not its results: left out of the
#: command its files quote.
PROCESS_FLAGS = ("--resume", "--overwrite", "--no-progress")
PROCESS_OPTIONS = ("--workers",)
BEST_MODEL = Path("best") / "best_model.zip"


class ModelError(ValueError):
    """A MODEL argument that names no usable model, or models of different tasks."""


@dataclass(frozen=True)
class ModelRun:
    """One run of the evaluated model: its ``.zip``, the training seed and the task it
    recorded (None when it recorded none)."""

    path: Path
    training_seed: int | None
    env_id: str | None
    env_kwargs: dict[str, Any] = field(default_factory=dict)


def _record(path: Path) -> dict[str, Any]:
    try:
        record = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as error:
        raise ModelError(f"cannot read {path}: {error}") from None
    if not isinstance(record, dict):
        raise ModelError(f"{path} is not a record of a training run (not a JSON object)")
    return record


def _run_of_folder(folder: Path) -> ModelRun:
    """A ``bearing-env train`` run folder's best model and its record."""
    record = _record(folder / RUN_RECORD)
    model = folder / BEST_MODEL
    if not model.is_file():
        raise ModelError(
            f"run folder {folder} has no best model yet ({BEST_MODEL}): it is written at the "
            "run's first evaluation (bearing-env train --eval-freq > 0)"
        )
    seed = record.get("seed")
    return ModelRun(
        model,
        int(seed) if isinstance(seed, int) else None,
        str(record["env_id"]) if "env_id" in record else None,
        dict(record.get("env_kwargs") or {}),
    )


def _runs_of_path(path: Path) -> list[ModelRun]:
    """The runs one existing path holds (see the module doc)."""
    from bearing_env.agents.sb3 import resolve_model_path

    if path.is_dir() and (path / RUN_RECORD).is_file():
        return [_run_of_folder(path)]
    if path.is_dir():
        children = sorted(child for child in path.iterdir() if (child / RUN_RECORD).is_file())
        if children:
            return [_run_of_folder(child) for child in children]
    try:
        model = resolve_model_path(path)
    except FileNotFoundError as error:
        raise ModelError(str(error)) from None
    if not zipfile.is_zipfile(model):
        raise ModelError(f"{model} is not a stable-baselines3 model (not a .zip archive)")
    beside = model.with_suffix(".json")
    record = _record(beside) if beside.is_file() else {}
    seed = record.get("seed")
    return [
        ModelRun(
            model,
            int(seed) if isinstance(seed, int) else None,
            str(record["env_id"]) if "env_id" in record else None,
            dict(record.get("env_kwargs") or {}),
        )
    ]


def resolve_models(arguments: Sequence[str]) -> list[ModelRun]:
    """Every run the MODEL arguments name, in order; a glob is expanded (sorted) when no
    file has its literal name.

    Raises:
        ModelError: an argument names nothing usable, or two name the same model.
    """
    runs: list[ModelRun] = []
    for argument in arguments:
        path = Path(argument).expanduser()
        if path.exists():
            matches = [path]
        else:
            # A glob keeps what can hold a model (seed*/ also matches the seeds' logs).
            matches = [
                Path(match)
                for match in sorted(glob.glob(str(path)))
                if Path(match).is_dir() or match.endswith(".zip")
            ]
            if not matches:
                raise ModelError(f"no model at {argument!r} (no such file or folder, no match)")
        for match in matches:
            runs.extend(_runs_of_path(match))
    seen: set[Path] = set()
    for run in runs:
        if run.path.resolve() in seen:
            raise ModelError(f"model {run.path} is given twice")
        seen.add(run.path.resolve())
    return runs


def run_labels(name: str, runs: Sequence[ModelRun]) -> list[str]:
    """``NAME/seedS`` for each run, by its training seed when every run has a distinct
    one, else ``NAME/runK`` in order."""
    seeds = [run.training_seed for run in runs]
    if None not in seeds and len(set(seeds)) == len(seeds):
        return [f"{name}/seed{seed}" for seed in seeds]
    return [f"{name}/run{index}" for index in range(len(runs))]


def default_name(arguments: Sequence[str], runs: Sequence[ModelRun]) -> str:
    """The model's name in reports: the folder holding the run folders, or the model's
    file name for a single ``.zip``."""
    first = Path(arguments[0].split("*")[0].rstrip("/")).expanduser()
    if first.is_dir() and not (first / RUN_RECORD).is_file():
        return first.name
    parents = {run.path.parent.parent.parent for run in runs if run.path.parent.name == "best"}
    if len(parents) == 1 and len(runs) > 1:
        return parents.pop().name
    if len(runs) == 1 and runs[0].path.parent.name == "best":
        return runs[0].path.parent.parent.name
    return runs[0].path.stem


def task_for(runs: Sequence[ModelRun], env: str | None) -> tuple[str, dict[str, Any]]:
    """The task evaluated on: ``env`` (a registered id), or the runs' recorded one; every
    run that recorded a task must have recorded this one.

    Raises:
        ModelError: no task is given or recorded, or a run's task differs.
    """
    recorded = [run for run in runs if run.env_id is not None]
    if env is not None:
        env_id, env_kwargs = registered_env_id(env).rpartition(":")[2], {}
    elif recorded:
        env_id = current_id(str(recorded[0].env_id).rpartition(":")[2])
        env_kwargs = dict(recorded[0].env_kwargs)
    else:
        raise ModelError("the models record no task (no run.json or .json beside them): pass --env")
    wanted = task_of(env_id, env_kwargs)
    for run in recorded:
        if task_of(str(run.env_id), run.env_kwargs) != wanted:
            kwargs = ", ".join(f"{k}={v!r}" for k, v in run.env_kwargs.items())
            raise ModelError(
                f"model {run.path} was trained on {run.env_id}"
                f"{f' with {kwargs}' if kwargs else ''}, not on {env_id}; evaluate it on its "
                "own task (leave --env out) or pass the models of one task"
            )
    return env_id, env_kwargs


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        PROG,
        "Evaluate a trained model (one run, or several training seeds) against the task's "
        "baselines on its evaluation episodes: IQM with stratified bootstrap CIs, "
        "probability of improvement and performance profiles (rliable), as JSON, a "
        "markdown table and plots.",
        epilog=(
            "MODEL: a bearing-env train run folder, a folder of run folders (bearing-env "
            "train --seeds), a model .zip, or a glob of these (quote it). Interrupted? "
            "Rerun the same command with --resume."
        ),
    )
    add = parser.add_argument
    add("models", nargs="+", metavar="MODEL", help="the model's runs (see below)")
    add("--env", help="task id (default: the task the models were trained on)")
    add("--out", type=Path, help="output folder (default outputs/evaluate/<name>)")
    add("--name", help="the model's name in reports (default: its folder or file name)")
    add(
        "--baselines",
        nargs="*",
        default=list(DEFAULT_BASELINES),
        metavar="SPEC",
        help="baseline policy specs, as for bearing-env compare",
    )
    add("--episodes", type=COUNT, default=DEFAULT_EPISODES, help="evaluation episodes")
    add("--workers", type=COUNT, default=1, help="processes to run the episodes in")
    again = parser.add_mutually_exclusive_group()
    again.add_argument("--resume", action="store_true", help="finish the evaluation in --out")
    again.add_argument("--overwrite", action="store_true", help="discard the one in --out")
    add("--bootstrap", type=COUNT, default=DEFAULT_RESAMPLES, help="bootstrap resamples")
    add_no_progress(parser)
    return parser


def comparison_config(
    env_id: str,
    env_kwargs: dict[str, Any],
    baselines: Sequence[str],
    labels: Sequence[str],
    runs: Sequence[ModelRun],
    episodes: int,
) -> CompareConfig:
    """The comparison behind an evaluation: the baselines, then one policy per run."""
    models = {
        label: f"sb3:path={str(run.path)!r},label={label!r}"
        for label, run in zip(labels, runs, strict=True)
    }
    policies = policies_from_specs([*baselines, *models.values()])
    clash = sorted(set(policies_from_specs(baselines)) & set(labels))
    if clash:
        raise ModelError(f"a baseline and a run share the label {clash[0]!r}: pass --name")
    return CompareConfig(
        policies=policies,
        env_id=f"bearing_env:{env_id}",
        env_kwargs=env_kwargs,
        episodes=episodes,
        seed_start=EVAL_SEED_START,
    )


def _check_policies(config: CompareConfig) -> None:
    """Build every policy once on the task's env, so a bad model or spec fails in one
    line before any episode runs."""
    import contextlib

    from bearing_env.agents.registry import make_policy
    from bearing_env.train.compare.runner import make_env

    with contextlib.closing(make_env(config.env_id, config.env_kwargs)) as env:
        for spec in config.policies.values():
            make_policy(spec, env)


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    arguments = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(arguments)
    with exit_on_missing_extra(PROG):
        import rliable  # noqa: F401  (the statistics; the train extra)
        import stable_baselines3  # noqa: F401

        try:
            runs = resolve_models(args.models)
            env_id, env_kwargs = task_for(runs, args.env)
            name = args.name or default_name(args.models, runs)
            labels = run_labels(name, runs)
            config = comparison_config(
                env_id, env_kwargs, args.baselines, labels, runs, args.episodes
            )
            _check_policies(config)
        except (ModelError, ValueError, FileNotFoundError) as error:
            fail(PROG, str(error))
        out = args.out if args.out is not None else Path("outputs") / "evaluate" / name
        from bearing_env.train.compare.evaluation_report import write_evaluation

        kept = result_arguments(arguments, PROCESS_FLAGS, PROCESS_OPTIONS)
        command = reproducing_command(arguments, PROG, PROCESS_FLAGS, PROCESS_OPTIONS)
        started = time.perf_counter()
        try:
            with exit_on_output_errors(parser, out, "--out", (RunMismatchError, CorruptLogError)):
                result = run_comparison(
                    config,
                    out / EPISODES_FOLDER,
                    workers=args.workers,
                    resume=args.resume,
                    overwrite=args.overwrite,
                    progress=not args.no_progress,
                    command=command,
                )
                if not result.complete:
                    fail(
                        PROG,
                        f"episodes are missing in {out / EPISODES_FOLDER}; rerun with --resume",
                    )
                written = write_evaluation(
                    result.records,
                    config,
                    model=name,
                    labels=labels,
                    paths=[run.path for run in runs],
                    out=out,
                    argv=kept,
                    resamples=args.bootstrap,
                    seed=DEFAULT_BOOTSTRAP_SEED,
                )
        except KeyboardInterrupt:
            print(
                "\ninterrupted: finished episodes are saved in "
                f"{out / EPISODES_FOLDER / LOG_NAME}; "
                "rerun the same command with --resume to finish",
                file=sys.stderr,
            )
            raise SystemExit(130) from None
    print((out / "evaluation.md").read_text(encoding="utf-8"))
    files = ", ".join(str(path) for path in written)
    print(f"{len(result.records)} episodes in {time.perf_counter() - started:.0f} s; wrote {files}")


if __name__ == "__main__":
    main()
