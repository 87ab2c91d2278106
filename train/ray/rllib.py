"""``bearing-env rllib``: train PPO with RLlib, on this machine or a Ray cluster.

    bearing-env rllib --env BearingSLAM-v1 --iterations 50
    bearing-env rllib --env BearingSLAMDiscrete-v1 --env-kwargs scenario=random \\
        --num-env-runners 4 --ray-address HEAD_IP:6379
    bearing-env rllib --output runs/rllib_ppo --resume --iterations 100

RLlib's PPO (its new API stack: an RLModule trained by a Learner, episodes collected by
``--num-env-runners`` remote env runners, each stepping ``--envs-per-runner`` sub-envs
of the id's batched vector env, ``gym.make_vec(..., vectorization_mode=
"vector_entry_point")``). ``--env-kwargs`` go to the env; the hyperparameters not
exposed as options keep RLlib's defaults.

**Seeds.** ``--seed s`` seeds RLlib (``config.debugging(seed=...)``): env runner ``w``
(1, 2, ...; 0 samples in the driver) first resets its sub-env ``i`` with seed
``s' + w + i`` and runs on from there, where ``s' = s`` for a new run and
``s' = segment_seed(s, k)`` for a run resumed at iteration ``k`` (so a resumed run does
not replay the episodes it started with). Every training seed stays below
``bearing_env.train.common.seeds.TRAINING_SEED_LIMIT`` (the evaluation episodes of
``bearing-env compare`` start there); ``run.json`` lists each segment's seed.

**Run folder** (``--output``, default ``runs/rllib_ppo_<env>_seed<seed>``)::

    run.json          settings, status, the iteration and env steps of the checkpoint
    progress.jsonl    one line per finished iteration: env steps, episodes, mean return
    checkpoint/       the newest checkpoint (``Algorithm.save_to_path``); load it with
                      ``ray.rllib.algorithms.algorithm.Algorithm.from_checkpoint(path)``

**Interruptions.** A checkpoint is written every ``--checkpoint-every`` iterations and at
the end, into a temporary folder that then replaces the old one, so there is always one
whole checkpoint. Ctrl-C stops the run (the iteration in progress is dropped), writes the
outputs and exits with status 130; ``--resume`` restores the checkpoint and trains up to
``--iterations`` in total, dropping the lines of ``progress.jsonl`` past the checkpoint.

``bearing-env sweep`` (``bearing_env.train.ray.sweep``) runs this configuration under Ray
Tune over a grid of hyperparameters or env kwargs.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from bearing_env.registration import ENV_IDS
from bearing_env.train.common.cli_parser import add_no_progress, command_parser
from bearing_env.train.common.cli_values import COUNT, NON_NEGATIVE, SEED, parse_key_values
from bearing_env.train.common.errors import exit_on_output_errors, fail, require
from bearing_env.train.common.files import atomic_write_text
from bearing_env.train.common.progress import progress_bar
from bearing_env.train.common.seeds import TRAINING_SEED_LIMIT
from bearing_env.train.compare.config import DEFAULT_ENV_KWARGS
from bearing_env.train.ray.ray_executor import RAY_CONNECT_TIMEOUT, check_ray_address, ray_session

RUN_NAME = "run.json"
PROGRESS_NAME = "progress.jsonl"
CHECKPOINT_NAME = "checkpoint"
#: The result metrics kept per iteration (``progress.jsonl``), from ``Algorithm.train()``.
METRICS = ("episode_return_mean", "episode_len_mean", "num_episodes")


@dataclass(frozen=True)
class RLlibSettings:
    """One PPO run. ``env_id`` is a registered id (``BearingSLAM-v1``, with or without the
    ``bearing_env:`` prefix)."""

    env_id: str = "BearingSLAM-v1"
    env_kwargs: dict[str, Any] = field(default_factory=lambda: dict(DEFAULT_ENV_KWARGS))
    iterations: int = 20
    seed: int = 0
    num_env_runners: int = 1
    envs_per_runner: int = 4
    train_batch_size: int = 4000
    minibatch_size: int = 128
    epochs: int = 10
    lr: float = 3e-4
    gamma: float = 0.99
    checkpoint_every: int = 1

    def __post_init__(self) -> None:
        name = self.env_id.split(":")[-1]
        if name not in ENV_IDS:
            raise ValueError(f"env id must be one of {sorted(ENV_IDS)}, got {self.env_id!r}")
        for key in ("iterations", "envs_per_runner", "train_batch_size", "minibatch_size"):
            if int(getattr(self, key)) < 1:
                raise ValueError(f"{key} must be >= 1, got {getattr(self, key)!r}")
        for key in ("epochs", "checkpoint_every"):
            if int(getattr(self, key)) < 1:
                raise ValueError(f"{key} must be >= 1, got {getattr(self, key)!r}")
        if self.num_env_runners < 0:
            raise ValueError(f"num_env_runners must be >= 0, got {self.num_env_runners!r}")
        if self.minibatch_size > self.train_batch_size:
            raise ValueError(
                f"minibatch_size ({self.minibatch_size}) must not exceed train_batch_size "
                f"({self.train_batch_size})"
            )
        limit = TRAINING_SEED_LIMIT - self.num_env_runners - self.envs_per_runner
        if not 0 <= self.seed < limit:
            raise ValueError(
                f"seed must be in [0, {limit}) so that training seeds stay below "
                f"{TRAINING_SEED_LIMIT}, got {self.seed}"
            )
        if not (0.0 < self.gamma <= 1.0) or not self.lr > 0.0:
            raise ValueError(
                f"need 0 < gamma <= 1 and lr > 0, got gamma={self.gamma}, lr={self.lr}"
            )

    @property
    def seed_span(self) -> int:
        """How many consecutive env seeds one seeding of the env runners uses."""
        return self.num_env_runners + self.envs_per_runner + 1

    def segment_seed(self, iteration: int) -> int:
        """RLlib's seed for the segment that starts after ``iteration`` iterations."""
        limit = TRAINING_SEED_LIMIT - self.seed_span
        return (self.seed + iteration * self.seed_span) % limit

    @property
    def gym_id(self) -> str:
        """The id as env runners make it: ``bearing_env:<id>`` imports the package there."""
        return f"bearing_env:{self.env_id.split(':')[-1]}"

    def to_json(self) -> dict[str, Any]:
        plain: dict[str, Any] = json.loads(json.dumps(asdict(self)))  # as it reads back
        return {**plain, "env_id": self.gym_id}


def ppo_config(settings: RLlibSettings, seed: int | None = None) -> Any:
    """The RLlib ``PPOConfig`` of a run, seeded with ``seed`` (default the settings')
    (MissingExtraError without the ``ray`` extra)."""
    ppo = require("ray.rllib.algorithms.ppo", "RLlib training", extra="ray")
    return (
        ppo.PPOConfig()
        .environment(env=settings.gym_id, env_config=dict(settings.env_kwargs))
        .env_runners(
            num_env_runners=settings.num_env_runners,
            num_envs_per_env_runner=settings.envs_per_runner,
            gym_env_vectorize_mode="vector_entry_point",  # the id's batched vector env
            rollout_fragment_length="auto",
        )
        .training(
            train_batch_size_per_learner=settings.train_batch_size,
            minibatch_size=settings.minibatch_size,
            num_epochs=settings.epochs,
            lr=settings.lr,
            gamma=settings.gamma,
        )
        .debugging(seed=settings.seed if seed is None else seed)
    )


def iteration_metrics(result: Mapping[str, Any]) -> dict[str, Any]:
    """What ``progress.jsonl`` keeps of one ``Algorithm.train()`` result."""
    runners = result.get("env_runners", {})
    row: dict[str, Any] = {
        "iteration": int(result["training_iteration"]),
        "env_steps": int(result.get("num_env_steps_sampled_lifetime", 0)),
    }
    for key in METRICS:
        value = runners.get(key)
        row[key] = None if value is None else float(value)
    return row


@dataclass
class RLlibResult:
    output: Path
    iterations: int
    env_steps: int
    progress: list[dict[str, Any]]
    checkpoint: Path
    complete: bool


def _read_progress(path: Path, up_to: int) -> list[dict[str, Any]]:
    if not path.exists():
        return []
    rows = []
    for line in path.read_text(encoding="utf-8").splitlines():
        with contextlib.suppress(json.JSONDecodeError):  # a torn last line
            row = json.loads(line)
            if isinstance(row, dict) and int(row.get("iteration", 0)) <= up_to:
                rows.append(row)
    return rows


def _save_checkpoint(algo: Any, output: Path) -> Path:
    """Write a checkpoint beside the old one, then swap: one whole checkpoint always."""
    final = output / CHECKPOINT_NAME
    temporary = output / f".{CHECKPOINT_NAME}.{os.getpid()}.tmp"
    old = output / f".{CHECKPOINT_NAME}.old"
    shutil.rmtree(temporary, ignore_errors=True)
    algo.save_to_path(str(temporary.resolve()))
    shutil.rmtree(old, ignore_errors=True)
    if final.exists():
        os.replace(final, old)
    os.replace(temporary, final)
    shutil.rmtree(old, ignore_errors=True)
    return final


def _checkpoint_of(output: Path) -> Path | None:
    """The whole checkpoint of a run folder (the old one if a swap was cut short)."""
    for candidate in (output / CHECKPOINT_NAME, output / f".{CHECKPOINT_NAME}.old"):
        if candidate.is_dir():
            return candidate
    return None


@dataclass
class _RunFolder:
    """A run folder while it trains: ``run.json``'s record and ``progress.jsonl``'s rows."""

    output: Path
    record: dict[str, Any]
    rows: list[dict[str, Any]]
    checkpoint: Path | None

    @property
    def checkpoint_iteration(self) -> int:
        return int(self.record.get("checkpoint_iteration", 0))

    def write_record(self, status: str) -> None:
        self.record["status"] = status
        atomic_write_text(self.output / RUN_NAME, json.dumps(self.record, indent=1) + "\n")

    def append_row(self, row: dict[str, Any]) -> None:
        """Keep one iteration's metrics, on disk at once (appended and fsynced)."""
        self.rows.append(row)
        with open(self.output / PROGRESS_NAME, "a", encoding="utf-8") as handle:
            handle.write(json.dumps(row) + "\n")
            handle.flush()
            os.fsync(handle.fileno())


def _open_run_folder(settings: RLlibSettings, output: Path, resume: bool) -> _RunFolder:
    """The run folder ready for a new segment: the old record checked (``resume``) or no
    run there (a new one), ``progress.jsonl`` cut back to the checkpoint, the segment's
    seed recorded and ``run.json`` marked running."""
    run_path = output / RUN_NAME
    record: dict[str, Any] = {"settings": settings.to_json()}
    checkpoint = _checkpoint_of(output)
    if resume:
        if checkpoint is None or not run_path.exists():
            raise ValueError(f"cannot resume: {output} holds no checkpoint; drop --resume")
        old = json.loads(run_path.read_text(encoding="utf-8"))
        mismatched = {
            key: (old["settings"].get(key), value)
            for key, value in settings.to_json().items()
            if key not in ("iterations", "checkpoint_every") and old["settings"].get(key) != value
        }
        if mismatched:
            raise ValueError(f"cannot resume: the run in {output} has other settings {mismatched}")
        record = {**old, "settings": settings.to_json()}
    elif run_path.exists() or checkpoint is not None:
        raise FileExistsError(f"{output} already holds a run; pass --resume to continue it")
    done = int(record.get("checkpoint_iteration", 0))
    rows = _read_progress(output / PROGRESS_NAME, done)
    output.mkdir(parents=True, exist_ok=True)
    atomic_write_text(output / PROGRESS_NAME, "".join(json.dumps(row) + "\n" for row in rows))
    folder = _RunFolder(output=output, record=record, rows=rows, checkpoint=checkpoint)
    segment = {"start_iteration": done, "seed": settings.segment_seed(done)}
    record.setdefault("segments", []).append(segment)
    folder.write_record("running")
    return folder


def _train_iterations(
    algo: Any, settings: RLlibSettings, folder: _RunFolder, target: int, progress: bool
) -> None:
    """Train up to iteration ``target``, logging each and checkpointing every
    ``checkpoint_every`` iterations and at the last."""
    iteration = done = folder.checkpoint_iteration
    with progress_bar(
        settings.iterations, initial=done, desc="rllib ppo", unit="iter", enabled=progress
    ) as bar:
        while iteration < target:
            row = iteration_metrics(algo.train())
            iteration = row["iteration"]
            folder.append_row(row)
            if iteration % settings.checkpoint_every == 0 or iteration >= target:
                folder.checkpoint = _save_checkpoint(algo, folder.output)
                folder.record.update(checkpoint_iteration=iteration, env_steps=row["env_steps"])
                folder.write_record("running")
            bar.update()
            bar.set_postfix(ret=row["episode_return_mean"])


def train_rllib(
    settings: RLlibSettings,
    output: Path,
    resume: bool = False,
    address: str | None = None,
    progress: bool = True,
    stop_after: int | None = None,
) -> RLlibResult:
    """Train (or continue) a PPO run in ``output``.

    Args:
        settings: the run.
        output: the run folder (see the module doc).
        resume: continue from the checkpoint in ``output`` (settings must match).
        address: a Ray cluster to join (default: this process's Ray instance, or a new
            local one).
        progress: show a progress bar.
        stop_after: train at most this many new iterations (``complete`` is False if
            iterations remain; ``resume`` finishes them).

    Raises:
        FileExistsError: ``output`` holds a run and ``resume`` is False.
        ValueError: ``resume`` with other settings, or without a checkpoint.
    """
    folder = _open_run_folder(settings, Path(output), resume)
    done = folder.checkpoint_iteration
    target = settings.iterations
    if stop_after is not None:
        target = min(target, done + max(0, stop_after))
    with ray_session(address) as _ray:
        algo = ppo_config(settings, settings.segment_seed(done)).build_algo()
        try:
            if resume and folder.checkpoint is not None:
                algo.restore_from_path(str(folder.checkpoint.resolve()))
            _train_iterations(algo, settings, folder, target, progress)
        except KeyboardInterrupt:
            folder.write_record("interrupted")
            raise
        finally:
            algo.stop()
    complete = folder.checkpoint_iteration >= settings.iterations
    folder.write_record("finished" if complete else "stopped")
    assert folder.checkpoint is not None
    return RLlibResult(
        output=folder.output,
        iterations=folder.checkpoint_iteration,
        env_steps=int(folder.record.get("env_steps", 0)),
        progress=folder.rows,
        checkpoint=folder.checkpoint,
        complete=complete,
    )


# --------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------


def add_settings_arguments(parser: argparse.ArgumentParser) -> None:
    """The options of :class:`RLlibSettings` (shared with ``bearing-env sweep``)."""
    defaults = RLlibSettings()
    add = parser.add_argument
    add(
        "--env",
        default=defaults.env_id,
        choices=sorted(ENV_IDS),
        help="env id (default %(default)s)",
    )
    add(
        "--env-kwargs",
        nargs="*",
        default=None,
        metavar="KEY=VALUE",
        help="env kwargs (default: scenario=khepera)",
    )
    add(
        "--iterations",
        type=COUNT,
        default=defaults.iterations,
        help="training iterations in total (default %(default)s)",
    )
    add("--seed", type=SEED, default=defaults.seed, help="RLlib's seed (default %(default)s)")
    add(
        "--num-env-runners",
        type=NON_NEGATIVE,
        default=defaults.num_env_runners,
        help="remote env runners, one CPU each (0: sample in the driver; default %(default)s)",
    )
    add(
        "--envs-per-runner",
        type=COUNT,
        default=defaults.envs_per_runner,
        help="sub-envs of each runner's batched vector env (default %(default)s)",
    )
    add(
        "--train-batch-size",
        type=COUNT,
        default=defaults.train_batch_size,
        help="env steps per iteration (default %(default)s)",
    )
    add(
        "--minibatch-size",
        type=COUNT,
        default=defaults.minibatch_size,
        help="SGD minibatch (default %(default)s)",
    )
    add(
        "--epochs",
        type=COUNT,
        default=defaults.epochs,
        help="SGD passes over each batch (default %(default)s)",
    )
    add("--lr", type=float, default=defaults.lr, help="learning rate (default %(default)s)")
    add("--gamma", type=float, default=defaults.gamma, help="discount (default %(default)s)")
    add(
        "--ray-address",
        default=None,
        metavar="ADDRESS",
        help="a running Ray cluster to join (HOST:PORT, or auto); default a local instance. "
        f"A HOST:PORT that does not answer within {RAY_CONNECT_TIMEOUT:g} s is refused",
    )
    add_no_progress(parser)


def settings_from_args(args: argparse.Namespace, **overrides: Any) -> RLlibSettings:
    env_kwargs = dict(DEFAULT_ENV_KWARGS)
    if args.env_kwargs is not None:
        env_kwargs = parse_key_values(args.env_kwargs, "--env-kwargs")
    values: dict[str, Any] = {
        "env_id": args.env,
        "env_kwargs": env_kwargs,
        "iterations": args.iterations,
        "seed": args.seed,
        "num_env_runners": args.num_env_runners,
        "envs_per_runner": args.envs_per_runner,
        "train_batch_size": args.train_batch_size,
        "minibatch_size": args.minibatch_size,
        "epochs": args.epochs,
        "lr": args.lr,
        "gamma": args.gamma,
    }
    values.update(overrides)
    return RLlibSettings(**values)


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env rllib",
        "Train PPO with RLlib on this machine or a Ray cluster (the ray extra).",
    )
    add_settings_arguments(parser)
    add = parser.add_argument
    add(
        "--output",
        type=Path,
        default=None,
        help="run folder (default runs/rllib_ppo_<env>_seed<seed>)",
    )
    add("--resume", action="store_true", help="continue the run in --output")
    add(
        "--checkpoint-every",
        type=COUNT,
        default=1,
        metavar="N",
        help="write a checkpoint every N iterations (default %(default)s; and at the end)",
    )
    add(
        "--stop-after",
        type=NON_NEGATIVE,
        default=None,
        metavar="N",
        help="train at most N new iterations, then stop (resume later; default: train "
        "them all)",
    )
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        require("ray.rllib", "RLlib training", extra="ray")
        settings = settings_from_args(args, checkpoint_every=args.checkpoint_every)
        if args.ray_address is not None:
            check_ray_address(args.ray_address)
    except (ValueError, TypeError) as error:
        parser.error(str(error))
    except ImportError as error:
        fail(parser.prog, str(error))
    output = args.output or Path(
        f"runs/rllib_ppo_{settings.env_id.split(':')[-1]}_seed{settings.seed}"
    )
    started = time.perf_counter()
    try:
        with exit_on_output_errors(parser, output, "--output"):
            result = train_rllib(
                settings,
                output,
                resume=args.resume,
                address=args.ray_address,
                progress=not args.no_progress,
                stop_after=args.stop_after,
            )
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: the newest checkpoint is in {output / CHECKPOINT_NAME}; rerun "
            "the same command with --resume to continue",
            file=sys.stderr,
        )
        raise SystemExit(130) from None
    last = result.progress[-1] if result.progress else {}
    status = "complete" if result.complete else "INCOMPLETE (rerun with --resume)"
    print(
        f"{status}: {result.iterations} iterations, {result.env_steps} env steps, mean "
        f"episode return {last.get('episode_return_mean')} "
        f"({time.perf_counter() - started:.0f} s); checkpoint: {result.checkpoint}"
    )


if __name__ == "__main__":
    main()
