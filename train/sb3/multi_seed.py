"""``bearing-env train --seeds S1 S2 ...``: one run per training seed, each in its own run
folder ``OUTPUT/seed<S>``, one after another or in ``--workers`` processes at once.

Each seed is a separate ``bearing-env train --seed S --output OUTPUT/seed<S>`` process, so
a seed that crashes leaves the others running and their runs intact. Rerunning the same
command with ``--resume`` skips the finished seeds, resumes the unfinished ones from their
checkpoints and starts the missing ones. Ctrl-C stops every seed at its next update
boundary with a checkpoint (as for one seed), and the command exits with status 130.

With one worker the seeds run in the foreground, with their progress bars. With more,
each seed writes its output to ``OUTPUT/seed<S>.log`` and the command prints a line as each
one ends; each process then steps its envs on one thread (``BEARING_ENV_NUM_THREADS=1``,
unless set), so that ``--workers`` processes share the cores instead of oversubscribing
them.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from bearing_env.train.sb3.run_folder import RunFiles

#: The options of the parent command that its seeds do not take (they get their own).
PARENT_FLAGS = ("--resume", "--no-progress")
PARENT_OPTIONS = ("--seeds", "--workers", "--output", "--seed")
EXIT_INTERRUPTED = 130
POLL_SECONDS = 0.5


def seed_folder(output: Path, seed: int) -> Path:
    return output / f"seed{seed}"


def seed_state(folder: Path) -> str:
    """``"new"`` (no run yet), ``"finished"`` (trained to its target) or ``"unfinished"``."""
    record_path = RunFiles(folder).record
    if not record_path.is_file():
        return "new"
    try:
        record = json.loads(record_path.read_text(encoding="utf-8"))
        done = record.get("status") == "finished" and int(record["num_timesteps"]) >= int(
            record["target_timesteps"]
        )
    except (OSError, ValueError, KeyError, TypeError):
        return "unfinished"  # a damaged record: --resume says what is wrong with it
    return "finished" if done else "unfinished"


def seed_arguments(argv: Sequence[str]) -> list[str]:
    """The parent's arguments less the ones each seed gets its own value of
    (:data:`PARENT_OPTIONS`, with all their values) and :data:`PARENT_FLAGS`."""
    kept: list[str] = []
    skipping = False
    for argument in argv:
        name = argument.split("=", 1)[0]
        if name in PARENT_OPTIONS:
            skipping = "=" not in argument
        elif name in PARENT_FLAGS:
            skipping = False
        elif skipping and not argument.startswith("-"):
            continue  # a value of a skipped option (--seeds takes several)
        else:
            skipping = False
            kept.append(argument)
    return kept


@dataclass
class SeedRun:
    seed: int
    folder: Path
    resume: bool
    process: subprocess.Popen[bytes] | None = None
    status: int | None = None

    def command(self, arguments: Sequence[str], progress: bool) -> list[str]:
        command = [sys.executable, "-m", "bearing_env.train.sb3.train_cli", *arguments]
        command += ["--seed", str(self.seed), "--output", str(self.folder)]
        if self.resume:
            command.append("--resume")
        if not progress:
            command.append("--no-progress")
        return command


def plan_seeds(output: Path, seeds: Sequence[int], resume: bool) -> list[SeedRun]:
    """The seeds to run: all of them, or with ``resume`` the unfinished and missing ones.

    Raises:
        FileExistsError: without ``resume``, a seed's folder already holds a run.
        ValueError: a seed is given twice.
    """
    if len(set(seeds)) != len(seeds):
        raise ValueError(f"--seeds: a seed is given twice: {list(seeds)}")
    states = {seed: seed_state(seed_folder(output, seed)) for seed in seeds}
    started = [seed for seed, state in states.items() if state != "new"]
    if started and not resume:
        raise FileExistsError(
            f"{output} already holds runs of seeds {started}; pass --resume to finish them "
            "(finished seeds are skipped) or choose another --output"
        )
    return [
        SeedRun(seed, seed_folder(output, seed), resume=state == "unfinished")
        for seed, state in states.items()
        if state != "finished"
    ]


def _log_path(run: SeedRun) -> Path:
    return run.folder.with_name(f"{run.folder.name}.log")


def _start(run: SeedRun, arguments: Sequence[str], workers: int, progress: bool) -> None:
    environment = dict(os.environ)
    if workers == 1:
        run.process = subprocess.Popen(run.command(arguments, progress))
        return
    environment.setdefault("BEARING_ENV_NUM_THREADS", "1")
    run.folder.parent.mkdir(parents=True, exist_ok=True)
    with open(_log_path(run), "ab") as log:
        run.process = subprocess.Popen(
            run.command(arguments, progress=False),
            stdout=log,
            stderr=subprocess.STDOUT,
            env=environment,
        )
    print(f"seed {run.seed}: {'resumed' if run.resume else 'started'} (log {_log_path(run)})")


def _describe(run: SeedRun) -> str:
    if run.status == 0:
        return f"seed {run.seed}: finished ({run.folder})"
    if run.status == EXIT_INTERRUPTED:
        return f"seed {run.seed}: interrupted, checkpoint saved ({run.folder})"
    return f"seed {run.seed}: FAILED with exit status {run.status} (see {_log_path(run)})"


def train_seeds(
    argv: Sequence[str],
    output: Path,
    seeds: Sequence[int],
    workers: int,
    resume: bool,
    progress: bool,
) -> int:
    """Train every planned seed (:func:`plan_seeds`); the command's exit status: 0 when
    every seed finished, 130 after an interruption, else 1."""
    runs = plan_seeds(output, seeds, resume)
    skipped = sorted(set(seeds) - {run.seed for run in runs})
    if skipped:
        print(f"seeds {skipped}: already finished in {output}")
    arguments = seed_arguments(argv)
    pending, running = list(runs), list[SeedRun]()
    try:
        while pending or running:
            while pending and len(running) < workers:
                run = pending.pop(0)
                _start(run, arguments, workers, progress)
                running.append(run)
            time.sleep(POLL_SECONDS if workers > 1 else 0)
            for run in list(running):
                assert run.process is not None
                status = run.process.wait() if workers == 1 else run.process.poll()
                if status is not None:
                    run.status = status
                    running.remove(run)
                    print(_describe(run))
    except KeyboardInterrupt:
        for run in running:
            assert run.process is not None
            run.process.send_signal(signal.SIGINT)  # each saves its checkpoint
        for run in running:
            assert run.process is not None
            run.status = run.process.wait()
            print(_describe(run))
        print(
            f"interrupted: rerun the same command with --resume to finish {output}", file=sys.stderr
        )
        return EXIT_INTERRUPTED
    failed = [run for run in runs if run.status != 0]
    if failed:
        print(
            f"{len(failed)} of {len(runs)} seeds did not finish; rerun the same command with "
            "--resume to retry them (the finished ones are kept)",
            file=sys.stderr,
        )
        return 1
    print(f"all {len(seeds)} seeds finished in {output}")
    return 0
