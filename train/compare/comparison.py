"""One comparison from start to finish: check that ``--resume`` continues the same
comparison, run the episodes the log lacks through an executor, log each one, then
summarise and write every report.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bearing_env.train.common.files import atomic_write_text
from bearing_env.train.common.progress import progress_bar
from bearing_env.train.compare.config import CompareConfig
from bearing_env.train.compare.log import LOG_NAME, EpisodeLog
from bearing_env.train.compare.report import write_outputs
from bearing_env.train.compare.runner import EpisodeExecutor, episode_tasks, run_locally
from bearing_env.train.compare.stats import policy_ms_per_move, summarise

CONFIG_NAME = "config.json"


class RunMismatchError(ValueError):
    """``--resume`` on an output folder that holds a different comparison."""


def _check_resumable(existing: Mapping[str, Any], config: CompareConfig) -> None:
    wanted = config.to_json()
    for key in ("env_id", "env_kwargs"):
        if existing.get(key) != wanted[key]:
            raise RunMismatchError(
                f"cannot resume: the output folder ran {key}={existing.get(key)!r}, "
                f"this run asks for {wanted[key]!r}; use another --out"
            )
    for label, spec in wanted["policies"].items():
        old = existing.get("policies", {}).get(label)
        if old is not None and old != spec:
            raise RunMismatchError(
                f"cannot resume: policy {label!r} was {old!r} and is now {spec!r}; "
                "give it another label (spec option label=...) or use another --out"
            )


@dataclass
class CompareResult:
    summary: dict[str, Any]
    records: list[dict[str, Any]]
    complete: bool
    out: Path
    timing: dict[str, float]


def run_comparison(
    config: CompareConfig,
    out: Path,
    workers: int = 1,
    resume: bool = False,
    overwrite: bool = False,
    stop_after: int | None = None,
    progress: bool = True,
    plots: bool = True,
    command: str | None = None,
    executor: EpisodeExecutor = run_locally,
    desc: str = "compare",
) -> CompareResult:
    """Run (or finish) a comparison and write every output file.

    Args:
        config: what to run.
        out: the output folder.
        workers: processes for the episodes (1: in this process).
        resume: keep the finished episodes of a previous run in ``out`` and run the rest.
        overwrite: discard a previous run in ``out``.
        stop_after: run at most this many new episodes, then write the outputs of what is
            done (``complete`` is False if episodes remain; ``resume`` finishes them).
        progress: show a progress bar.
        plots: write the PNG plots.
        command: the command line to quote in the report.
        executor: what runs the episodes (``runner.EpisodeExecutor``): the local
            worker pool by default, given ``workers``; ``runner.executor_named``
            gives the Ray one.
        desc: the progress bar's label (``bearing-env suite``: the task id).
    """
    out = Path(out)
    log = _open_run(config, out, resume, overwrite)

    records = log.load()
    done = {(r["policy"], int(r["seed"])) for r in records}
    pending = episode_tasks(config, done)
    tasks = pending if stop_after is None else pending[: max(0, stop_after)]
    n_total = len(config.seeds) * len(config.policies)
    done_before = n_total - len(pending)
    with progress_bar(
        n_total, initial=done_before, desc=desc, unit="episode", enabled=progress
    ) as bar:
        for record in executor(tasks, workers):
            log.append(record)  # fsynced before the next one: a kill loses no logged episode
            records.append(record)
            bar.update()
    # Task order (seed-major), whatever order the executor finished them in.
    position = {(task.label, task.seed): i for i, task in enumerate(episode_tasks(config, set()))}
    records.sort(key=lambda r: position.get((r["policy"], int(r["seed"])), len(position)))

    summary = summarise(records, config)
    wanted = {(label, seed) for label in config.policies for seed in config.seeds}
    finished = {(r["policy"], int(r["seed"])) for r in records} & wanted
    timing = policy_ms_per_move(records, config)
    write_outputs(summary, records, config, out, timing, plots, command)
    return CompareResult(summary, records, finished == wanted, out, timing)


def _open_run(config: CompareConfig, out: Path, resume: bool, overwrite: bool) -> EpisodeLog:
    """The episode log of a comparison in ``out``, after checking that ``resume`` /
    ``overwrite`` fit what ``out`` holds, with ``config`` written there."""
    log = EpisodeLog(out / LOG_NAME)
    config_path = out / CONFIG_NAME
    if resume and overwrite:
        raise ValueError("resume and overwrite contradict each other: choose one")
    if resume and not (log.path.exists() or config_path.exists()):
        raise RunMismatchError(
            f"cannot resume: {out} holds no comparison (no {LOG_NAME}, no {CONFIG_NAME}); "
            "run without --resume to start one"
        )
    if log.path.exists() and not (resume or overwrite):
        raise FileExistsError(
            f"{out} already holds a comparison ({LOG_NAME}); pass --resume to finish it "
            "or --overwrite to start again"
        )
    if overwrite and not resume:
        log.clear()
    if resume and config_path.exists():
        try:
            existing = json.loads(config_path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as error:
            raise RunMismatchError(
                f"cannot resume: {config_path} is not valid JSON ({error}); rerun with "
                "--overwrite instead of --resume to start the comparison again"
            ) from None
        _check_resumable(existing, config)
    atomic_write_text(config_path, json.dumps(config.to_json(), indent=2) + "\n")
    return log
