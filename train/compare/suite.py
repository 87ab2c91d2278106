"""``bearing-env suite``: the baselines on every registered task (:mod:`bearing_env.tasks`),
with their task cards.

The suite is ``bearing-env compare`` once per task: for each task a
:class:`~bearing_env.train.compare.config.CompareConfig` on the task's id, run by the
comparison harness (:func:`~bearing_env.train.compare.comparison.run_comparison`) into
its own folder ``--out/<task id>/``, with every output compare writes there. Every task
plays the same evaluation seeds (episode ``i``: seed ``EVAL_SEED_START + i``).

Resuming: a task folder that already holds a comparison is continued, never started
again, so an interrupted suite (Ctrl-C, a kill) rerun with the same command runs only
the episodes its logs lack and ends with the results an uninterrupted run gives.
``--overwrite`` discards them instead.

Policies: ``random`` (the paper's random polygonal trajectories), ``parallax``,
``greedy`` and ``lookahead``, and every model shipped in ``agents/pretrained/`` whose
training settings are the task's (its env id's action kind and its resolved env settings,
less ``max_moves``; a model trained on an older version of an id runs on its current one).

Docs (``--docs``, default ``docs/tasks``): one card per finished task,
``<task id>.md`` (observation, action, reward, episode end, settings, the baseline tables
with bootstrap CIs, a rendered frame and the area plot, next to it as PNGs) and the
task table ``index.md`` (:mod:`~bearing_env.train.compare.task_cards`).

    bearing-env suite --episodes 50
    bearing-env suite --quick --tasks BearingSLAM-Khepera-v1 BearingSLAM-Random8-v1
"""

from __future__ import annotations

import argparse
import json
import shutil
import sys
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bearing_env.tasks import (
    REGISTERED_TASKS_BY_ID,
    TASKS,
    TASKS_BY_ID,
    Task,
    current_id,
    task_named,
)
from bearing_env.train.common.cli_parser import add_no_progress, command_parser
from bearing_env.train.common.cli_values import COUNT, NON_NEGATIVE
from bearing_env.train.common.errors import exit_on_output_errors, fail, missing_extra
from bearing_env.train.compare.cli import (
    QUICK_MAX_MOVES,
    QUICK_POLICIES,
    installed_models,
    reproducing_command,
)
from bearing_env.train.compare.comparison import (
    CONFIG_NAME,
    CompareResult,
    RunMismatchError,
    run_comparison,
)
from bearing_env.train.compare.config import (
    DEFAULT_BOOTSTRAP,
    CompareConfig,
    policies_from_specs,
)
from bearing_env.train.compare.log import LOG_NAME, CorruptLogError
from bearing_env.train.compare.runner import EpisodeExecutor, make_env, run_locally

#: The baselines every task runs (the shipped models whose task matches come on top).
DEFAULT_POLICIES: tuple[str, ...] = ("random", "parallax", "greedy", "lookahead")
#: Evaluation episodes per policy and task.
DEFAULT_EPISODES = 50
#: ``--quick``: episodes per policy and task (and QUICK_POLICIES, QUICK_MAX_MOVES moves).
QUICK_EPISODES = 5
DEFAULT_OUT = Path("outputs/suite")
QUICK_OUT = Path("outputs/suite_quick")
DEFAULT_DOCS = Path("docs/tasks")

#: Options that change how a run proceeds but not its results (left out of the command
#: the cards quote).
_PROCESS_ONLY_FLAGS = ("--overwrite", "--no-progress")
_PROCESS_ONLY_OPTIONS = ("--workers", "--stop-after")


def task_models(task: Task) -> list[str]:
    """``pretrained:NAME`` specs of the shipped models trained on this task's settings:
    the same action kind and the same resolved :class:`EnvConfig` (``max_moves`` aside:
    it only sets how long an episode runs), an id of an older version taken as its
    current one (:func:`~bearing_env.tasks.current_id`: a model trained on
    ``BearingSLAM-v0`` with ``scenario="khepera"`` runs on ``BearingSLAM-Khepera-v1``)."""
    from bearing_env.agents import pretrained_names, pretrained_record
    from bearing_env.envs.config import EnvConfig

    def resolved(settings: dict[str, Any]) -> EnvConfig:
        return EnvConfig.create(**{k: v for k, v in settings.items() if k != "max_moves"})

    wanted = resolved(task.kwargs())
    specs = []
    for name in pretrained_names():
        record = pretrained_record(name)
        trained_on = current_id(str(record.get("env_id", "")).rpartition(":")[2])
        settings = dict(record.get("env_kwargs", {}))
        if trained_on in REGISTERED_TASKS_BY_ID:  # trained on a task's id: its settings first
            settings = {**REGISTERED_TASKS_BY_ID[trained_on].kwargs(), **settings}
            trained_on = REGISTERED_TASKS_BY_ID[trained_on].base_id
        if trained_on == task.base_id and resolved(settings) == wanted:
            specs.append(f"pretrained:{name}")
    return specs


def task_config(
    task: Task,
    policies: Sequence[str],
    episodes: int,
    max_moves: int | None = None,
    bootstrap: int = DEFAULT_BOOTSTRAP,
) -> CompareConfig:
    """The comparison of ``policies`` on ``task`` (its registered id, its settings;
    ``max_moves`` overrides the task's episode length, for quick runs)."""
    return CompareConfig(
        policies=policies_from_specs(policies),
        env_id=f"bearing_env:{task.id}",
        env_kwargs={} if max_moves is None else {"max_moves": max_moves},
        episodes=episodes,
        bootstrap=bootstrap,
    )


@dataclass
class TaskRun:
    """One task's comparison: what ran and what came of it."""

    task: Task
    config: CompareConfig
    result: CompareResult


def holds_comparison(folder: Path) -> bool:
    """Whether ``folder`` holds a (possibly unfinished) comparison to resume."""
    return (folder / LOG_NAME).exists() or (folder / CONFIG_NAME).exists()


def run_suite(
    configs: Sequence[tuple[Task, CompareConfig]],
    out: Path,
    docs: Path | None = None,
    workers: int = 1,
    overwrite: bool = False,
    stop_after: int | None = None,
    progress: bool = True,
    command: str | None = None,
    executor: EpisodeExecutor = run_locally,
) -> list[TaskRun]:
    """Run (or finish) each task's comparison in ``out/<task id>/``, then write the cards
    of the finished tasks and the task table into ``docs`` (if given).

    Args:
        configs: the tasks and their comparisons, in run order.
        out: the suite's output folder.
        docs: where the cards and ``index.md`` go (None: no docs).
        workers: processes for the episodes (1: in this process).
        overwrite: discard the comparisons already in ``out``; otherwise they resume.
        stop_after: run at most this many new episodes over the whole suite, then stop
            (a rerun continues).
        progress: show a progress bar per task.
        command: the command line the cards quote.
        executor: what runs the episodes (``runner.EpisodeExecutor``).
    """
    from bearing_env.train.compare.task_cards import write_index, write_task_card

    runs: list[TaskRun] = []
    budget = stop_after
    for task, config in configs:
        if budget == 0:
            break  # the rest waits for the next run
        folder = out / task.id
        before = 0 if overwrite or not holds_comparison(folder) else _logged(folder)
        result = run_comparison(
            config,
            folder,
            workers=workers,
            resume=holds_comparison(folder) and not overwrite,
            overwrite=overwrite,
            stop_after=budget,
            progress=progress,
            plots=True,
            command=command,
            executor=executor,
            desc=task.id,
        )
        runs.append(TaskRun(task, config, result))
        if budget is not None:
            budget = max(0, budget - (len(result.records) - before))
        if docs is not None and result.complete:
            write_task_card(task, config, result, folder, docs, command)
    if docs is not None:
        write_index(TASKS, docs)
    return runs


def _logged(folder: Path) -> int:
    from bearing_env.train.compare.log import EpisodeLog

    return len(EpisodeLog(folder / LOG_NAME).load())


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env suite",
        "Run the baselines on every registered task (bearing-env compare once per "
        "task, each in OUT/<task id>/, resuming what a previous run left) and write "
        "the task cards and the task table.",
        f"Tasks: {', '.join(TASKS_BY_ID)}. Policy specs as for bearing-env compare "
        "(random, parallax, greedy, lookahead, pretrained:NAME, ...). Rerun the same "
        "command after an interruption to finish.",
    )
    _add_selection_arguments(parser)
    _add_run_arguments(parser)
    return parser


def _add_selection_arguments(parser: argparse.ArgumentParser) -> None:
    """What runs: the tasks, the policies, the episodes, and where the results go."""
    parser.add_argument(
        "--tasks",
        nargs="+",
        default=None,
        metavar="ID",
        help="task ids to run (default: all; the index lists all of them either way)",
    )
    parser.add_argument(
        "--policies",
        nargs="+",
        default=None,
        metavar="SPEC",
        help=f"policy specs for every task (default: {' '.join(DEFAULT_POLICIES)}, and the "
        "shipped models trained on each task's settings; --quick: "
        f"{' '.join(QUICK_POLICIES)})",
    )
    parser.add_argument(
        "--episodes",
        type=COUNT,
        default=None,
        help=f"evaluation episodes per policy and task (default {DEFAULT_EPISODES}; "
        f"--quick {QUICK_EPISODES})",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help=f"output folder, one subfolder per task (default {DEFAULT_OUT}; with --quick "
        f"{QUICK_OUT})",
    )
    parser.add_argument(
        "--docs",
        type=Path,
        default=None,
        help=f"folder of the task cards and index.md (default {DEFAULT_DOCS}; with --quick "
        "OUT/docs, so a quick run leaves the published cards alone)",
    )


def _add_run_arguments(parser: argparse.ArgumentParser) -> None:
    """How it runs: quick or full, workers, resuming, the CIs, the progress bars."""
    parser.add_argument(
        "--quick",
        action="store_true",
        help=f"a short run: {QUICK_EPISODES} episodes of {QUICK_MAX_MOVES} moves per task, "
        f"policies {' '.join(QUICK_POLICIES)}",
    )
    parser.add_argument(
        "--workers",
        type=COUNT,
        default=1,
        help="processes to run episodes in, >= 1 (default %(default)s)",
    )
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="discard the results already in --out instead of resuming them",
    )
    parser.add_argument(
        "--stop-after",
        type=NON_NEGATIVE,
        default=None,
        metavar="N",
        help="run at most N new episodes in all, then write what is done (rerun to finish; "
        "default: no limit)",
    )
    parser.add_argument(
        "--bootstrap",
        type=COUNT,
        default=DEFAULT_BOOTSTRAP,
        help="bootstrap resamples for the CIs, >= 1 (default %(default)s)",
    )
    add_no_progress(parser)


def suite_configs(args: argparse.Namespace) -> list[tuple[Task, CompareConfig]]:
    """The task comparisons the arguments ask for (ValueError on an unknown task or a
    bad policy spec)."""
    tasks = list(TASKS) if args.tasks is None else _unique(task_named(t) for t in args.tasks)
    episodes = args.episodes or (QUICK_EPISODES if args.quick else DEFAULT_EPISODES)
    configs = []
    for task in tasks:
        policies = args.policies or (
            list(QUICK_POLICIES)
            if args.quick
            else [*DEFAULT_POLICIES, *installed_models(task_models(task))]
        )
        max_moves = QUICK_MAX_MOVES if args.quick else None
        configs.append((task, task_config(task, policies, episodes, max_moves, args.bootstrap)))
    return configs


def _unique(tasks: Iterable[Task]) -> list[Task]:
    return list(dict.fromkeys(tasks))


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    arguments = list(sys.argv[1:] if argv is None else argv)
    args = parser.parse_args(arguments)
    out = args.out if args.out is not None else (QUICK_OUT if args.quick else DEFAULT_OUT)
    docs = args.docs if args.docs is not None else (out / "docs" if args.quick else DEFAULT_DOCS)
    try:
        configs = suite_configs(args)
        # Fail fast on a bad policy spec, before any episode runs.
        from bearing_env.agents.registry import make_policy

        for _, config in configs:
            env = make_env(config.env_id, config.env_kwargs)
            try:
                for spec in config.policies.values():
                    make_policy(spec, env)
            finally:
                env.close()
    except (ValueError, TypeError, FileNotFoundError) as error:
        parser.error(str(error))
    except ImportError as error:  # a pretrained: policy without stable-baselines3, ...
        clear = missing_extra(error, "this suite")
        if clear is None:
            raise
        fail(parser.prog, str(clear))
    command = reproducing_command(
        arguments, "bearing-env suite", _PROCESS_ONLY_FLAGS, _PROCESS_ONLY_OPTIONS
    )
    started = time.perf_counter()
    try:
        with exit_on_output_errors(parser, out, "--out", (RunMismatchError, CorruptLogError)):
            runs = run_suite(
                configs,
                out,
                docs,
                workers=args.workers,
                overwrite=args.overwrite,
                stop_after=args.stop_after,
                progress=not args.no_progress,
                command=command,
            )
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: finished episodes are saved under {out}; rerun the same command "
            "to finish",
            file=sys.stderr,
        )
        raise SystemExit(130) from None
    from bearing_env.train.compare.task_cards import overview_table

    print(overview_table([(run.task, run.result.summary) for run in runs]))
    unfinished = [run.task.id for run in runs if not run.result.complete]
    status = (
        "complete" if not unfinished else f"INCOMPLETE ({', '.join(unfinished)}; rerun to finish)"
    )
    print(
        f"{status}: {len(runs)} tasks in {out} ({time.perf_counter() - started:.0f} s); "
        f"task cards: {docs / 'index.md'}"
    )


def copy_file(source: Path, target: Path) -> None:
    """Copy ``source`` to ``target`` atomically (a reader sees the old or the new file)."""
    from bearing_env.train.common.files import atomic_path

    with atomic_path(target, suffix=target.suffix) as temporary:
        shutil.copyfile(source, temporary)


def read_summary(folder: Path) -> dict[str, Any] | None:
    """The ``summary.json`` of a task folder, or None if it has none."""
    path = folder / "summary.json"
    if not path.is_file():
        return None
    summary: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return summary


if __name__ == "__main__":
    main()
