"""``bearing-env train``: train PPO, SAC or DQN agents with stable-baselines3.

    bearing-env train --algo ppo                                   # PPO, Khepera scenario
    bearing-env train --algo sac --env BearingSLAM-v0 --timesteps 200000
    bearing-env train --algo dqn --env BearingSLAMDiscrete-v0 --env-kwargs scenario=random
    bearing-env train --algo ppo --output runs/ppo_khepera --resume --timesteps 2000000
    bearing-env train --algo ppo --output runs/ppo_khepera --export-only \
        --export agents/pretrained/ppo_khepera

**Hyperparameters** come from the shipped ``hyperparams/<algo>.yml`` (``bearing-env
hyperparams <algo>`` prints its path) in rl-zoo3's format: one
entry per env id holding ``n_envs``, ``n_timesteps``, ``policy``, ``normalize``,
``env_kwargs``, ``policy_kwargs`` (a Python expression string) and the algorithm's
constructor arguments (``lin_<x>`` is a schedule decaying linearly from ``x`` to 0). The
same files run under rl-zoo3::

    python -m rl_zoo3.train --gym-packages bearing_env --algo ppo --env BearingSLAM-v0 \\
        --conf-file "$(bearing-env hyperparams ppo)"

``--env-kwargs k=v ...`` is merged over the entry's ``env_kwargs`` (rl-zoo3 replaces them
instead), and ``--hyperparams k=v ...`` over the entry itself. Values are Python literals
when they parse as one, strings otherwise.

**Vectorisation** (``--vec-env``). ``batched`` runs the ``n_envs`` training envs as one
Gymnasium vector env in this process, through ``bearing_env.train.vec_env``'s SB3 adapter: the id's
natively batched ``vector_entry_point`` when it registers one (one batched
computation steps every env), else a ``SyncVectorEnv`` of single envs. ``subproc`` runs
one single env per worker process (spawn), ``dummy`` all of them in this process.
``auto``, the default, is ``batched`` when the id registers a batched vector env and
``subproc`` otherwise. Every
kind seeds env ``i`` alike, so the kinds train on the same data when the batched env
reproduces the single env; ``run.json`` records the kind used by each segment, and a run
may be resumed with another kind.

**Seeds.** Training env ``i`` first resets with seed ``s + i`` and then runs on from its
own random stream, where ``s = --seed`` for a new run and ``(seed + t) mod (900000 -
n_envs)`` for a segment resumed at timestep ``t``: every training seed is below
``VALIDATION_SEED_START = 900000``. The periodic evaluation that picks the best model
plays validation episode ``k`` with seed ``900000 + k`` (``k < --eval-episodes``), the
same episodes at every evaluation. Both ranges lie below ``compare``'s test seeds
(1000000 and up), so neither training nor model selection ever sees a test episode;
``bearing_env.train.seeds`` defines every range.

**Run folder** (``--output``, default ``runs/<algo>_<env>_seed<seed>``)::

    run.json                 settings, seeds, status, timesteps, per-segment status/timing
    model.zip                final model (written when the run reaches its budget)
    vecnormalize.pkl         its VecNormalize statistics (when the config normalises)
    best/best_model.zip      best model on the validation episodes
    best/vecnormalize.pkl    the statistics that evaluation used
    best/best.json           its score: mean reward, median total area after 10 moves, ...
    best/evaluations.npz     every evaluation (SB3's format)
    checkpoints/             rl_model_<N>_steps.zip (+ _vecnormalize_, _replay_buffer_)
    monitor/                 episode logs (SB3 Monitor CSV): <i>.monitor.csv per env, or
                             batched.monitor.csv for all envs of --vec-env batched
    tensorboard/             TensorBoard logs (``tensorboard --logdir runs``)

**Interruptions.** A checkpoint counts only steps its model was trained on: periodic
checkpoints are written at the first update boundary (the start of a rollout, after
``train()`` consumed the previous one) at or past each multiple of ``--checkpoint-freq``.
Ctrl-C (or SIGTERM) stops at the next env step and saves the state of the last update
boundary: the steps of the partial rollout are dropped (counts, VecNormalize statistics,
replay-buffer position) and collected again on resume. A second Ctrl-C stops at once and
saves the same way (if it lands inside ``train()``, the weights may already hold part of
that update). The command then exits with status 130. ``--resume`` continues from the
newest checkpoint with the replay buffer (SAC, DQN) and the VecNormalize statistics,
keeping the timestep count (``--timesteps`` is the total), so a run killed at any moment
(SIGKILL included) and resumed ends with the ``num_timesteps`` and number of updates of
an uninterrupted run. ``run.json`` lists the running segment from its start and updates
its ``end_timesteps`` at each checkpoint; a segment whose process died (the record still
says ``running``) is marked ``killed`` on ``--resume``, ending at the checkpoint the run
resumes from. Each segment's ``status`` is ``finished``, ``interrupted`` or ``killed``.

**Export.** ``--export DIR/NAME`` copies the best model (else the final one) of the run to
``DIR/NAME.zip``, its statistics to ``DIR/NAME_vecnormalize.pkl`` and a description to
``DIR/NAME.json``, the layout ``agents/pretrained/`` uses.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import signal
import sys
import threading
import time
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch
from bearing_env.agents.sb3 import load_model, load_vecnormalize
from bearing_env.train.callbacks import (
    Checkpoint,
    CheckpointStore,
    FixedSeedEvalCallback,
    PeriodicCheckpointCallback,
    StopOnRequestCallback,
    StopRequest,
    callback_calls,
    rewind_to_boundary,
    save_model_atomically,
    save_vecnormalize_atomically,
)
from bearing_env.train.cli_values import json_safe, parse_key_values
from bearing_env.train.errors import fail, write_error_message
from bearing_env.train.export import ExportedModel, export_run
from bearing_env.train.files import write_json_atomically
from bearing_env.train.run_folder import (
    RunFiles,
    read_run_record,
)
from bearing_env.train.seeds import (
    TRAINING_SEED_LIMIT,
    VALIDATION_SEED_START,
    training_seed_start,
)
from bearing_env.train.training_envs import (
    VEC_ENV_CHOICES,
    make_training_env,
    make_validation_env,
    resolve_vec_env_kind,
)
from bearing_env.train.zoo import (
    DEFAULT_ENV_IDS,
    algorithm_class_for,
    hyperparams_key,
    parse_hyperparameters,
    read_hyperparameters,
)
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
from stable_baselines3.common.vec_env import (
    VecEnv,
    VecNormalize,
)

import bearing_env

DEFAULT_EVAL_FREQ = 25_000
DEFAULT_EVAL_EPISODES = 50
DEFAULT_CHECKPOINT_FREQ = 50_000
DEFAULT_KEEP_CHECKPOINTS = 3
DEFAULT_RUNS_DIR = Path("runs")

RUN_FORMAT_VERSION = 1
EXIT_INTERRUPTED = 130


# --------------------------------------------------------------------------------------
# Training
# --------------------------------------------------------------------------------------


@dataclass
class TrainSettings:
    """Everything one ``bearing-env train`` invocation needs."""

    algo: str
    env_id: str
    output: Path
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    hyperparam_overrides: dict[str, Any] = field(default_factory=dict)
    conf_file: Path | None = None
    timesteps: int | None = None
    seed: int = 0
    n_envs: int | None = None
    vec_env: str = "auto"
    resume: bool = False
    eval_freq: int = DEFAULT_EVAL_FREQ
    eval_episodes: int = DEFAULT_EVAL_EPISODES
    checkpoint_freq: int = DEFAULT_CHECKPOINT_FREQ
    keep_checkpoints: int = DEFAULT_KEEP_CHECKPOINTS
    progress_bar: bool = True
    tensorboard: bool = True
    device: str = "cpu"
    torch_threads: int | None = 1
    verbose: int = 0


@dataclass(frozen=True)
class TrainResult:
    """What one invocation did; ``model`` is the trained model (its envs are closed)."""

    model: BaseAlgorithm
    run_dir: Path
    num_timesteps: int
    target_timesteps: int
    interrupted: bool
    checkpoint: Checkpoint | None
    #: Env steps per second of wall time in this invocation (``learn()`` only).
    steps_per_second: float
    wall_seconds: float


def _versions() -> dict[str, str]:
    import stable_baselines3

    return {
        "bearing_env": bearing_env.__version__,
        "stable_baselines3": stable_baselines3.__version__,
        "torch": torch.__version__,
        "gymnasium": gym.__version__,
        "numpy": np.__version__,
        "python": sys.version.split()[0],
    }


@contextlib.contextmanager
def stop_on_signals(request: StopRequest) -> Iterator[None]:
    """While active, Ctrl-C and SIGTERM set ``request`` (the trainer stops at the next step);
    a second Ctrl-C raises ``KeyboardInterrupt`` at once."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handle(signum: int, frame: Any) -> None:
        if request:
            raise KeyboardInterrupt
        request.set(signal.Signals(signum).name)
        print(
            f"\n{signal.Signals(signum).name}: stopping at the next step and saving a checkpoint "
            "(Ctrl-C again to stop at once)",
            file=sys.stderr,
            flush=True,
        )

    previous = {sig: signal.signal(sig, handle) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


def _close_quietly(venv: VecEnv) -> None:
    with contextlib.suppress(EOFError, BrokenPipeError, ConnectionError, OSError):
        venv.close()


def _changed_settings(given: Mapping[str, Any], saved: Mapping[str, Any]) -> dict[str, Any]:
    """The entries of ``given`` that differ from ``saved`` once both are JSON (a tuple
    given on the command line equals the list run.json read back)."""
    return {
        key: value for key, value in given.items() if json_safe(saved.get(key)) != json_safe(value)
    }


def _resolve_run(settings: TrainSettings) -> tuple[dict[str, Any], Checkpoint | None]:
    """The raw hyperparameter entry and, when resuming, the checkpoint to start from."""
    files = RunFiles(settings.output)
    if not settings.resume:
        if files.record.exists():
            record = read_run_record(settings.output)
            raise FileExistsError(
                f"{settings.output} already holds a run ({record.get('num_timesteps', 0)} "
                "timesteps): pass --resume to continue it, or choose another --output"
            )
        raw = read_hyperparameters(settings.algo, settings.env_id, settings.conf_file)
        raw.update(settings.hyperparam_overrides)
        raw["env_kwargs"] = {**(raw.get("env_kwargs") or {}), **settings.env_kwargs}
        return raw, None

    record = read_run_record(settings.output)
    for key, given in (("algo", settings.algo), ("env_id", settings.env_id)):
        if record.get(key) != given:
            raise ValueError(
                f"cannot resume {settings.output}: it was trained with {key}={record.get(key)!r}, "
                f"not {given!r}"
            )
    raw = dict(record["hyperparams"])
    saved_env_kwargs = raw.get("env_kwargs") or {}
    changed = _changed_settings(settings.env_kwargs, saved_env_kwargs)
    if changed:
        raise ValueError(
            f"cannot resume {settings.output} with different env kwargs {changed}; "
            f"it was trained with {saved_env_kwargs}"
        )
    different = _changed_settings(settings.hyperparam_overrides, raw)
    if different:
        raise ValueError(
            f"cannot resume {settings.output} with different hyperparameters {different}; "
            "a resumed run keeps its own"
        )
    checkpoint = CheckpointStore(files.checkpoints).latest()
    if checkpoint is None:
        print(f"{settings.output}: no checkpoint yet, starting the run from scratch")
    return raw, checkpoint


def _segments_after_a_kill(
    previous_record: dict[str, Any], checkpoint: Checkpoint | None
) -> list[dict[str, Any]]:
    """The segments of the run being resumed, the one a killed process left "running"
    marked "killed" at the timesteps of the checkpoint the run resumes from.

    A record that still says "running" was left by a process that died without finishing
    (SIGKILL, power loss, out of memory). Older records did not list the running segment;
    it is added.
    """
    segments = [dict(item) for item in previous_record.get("segments", [])]
    if previous_record.get("status") != "running":
        return segments
    resumed_at = checkpoint.timesteps if checkpoint is not None else 0
    if segments and segments[-1].get("status") == "running":
        killed = segments[-1]
    else:
        start = int(segments[-1]["end_timesteps"]) if segments else 0
        killed = {
            "start_timesteps": start,
            "n_envs": previous_record.get("n_envs"),
            "vec_env": previous_record.get("vec_env"),
        }
        segments.append(killed)
    killed["status"] = "killed"
    # The steps after its last checkpoint are lost; none of them is counted.
    killed["end_timesteps"] = max(resumed_at, int(killed["start_timesteps"]))
    return segments


def train(settings: TrainSettings) -> TrainResult:
    """Train (or resume) a run; see the module docstring for the files it writes."""
    algorithm_class = algorithm_class_for(settings.algo)
    raw, checkpoint = _resolve_run(settings)
    hyperparams = parse_hyperparameters(raw, settings.algo)
    env_kwargs = hyperparams.env_kwargs
    n_envs = settings.n_envs if settings.n_envs is not None else hyperparams.n_envs
    target = settings.timesteps if settings.timesteps is not None else hyperparams.n_timesteps
    if n_envs < 1 or target < 1:
        raise ValueError(f"n_envs and timesteps must be >= 1, got {n_envs} and {target}")
    files = RunFiles(settings.output)
    previous_record = read_run_record(settings.output) if settings.resume else {}
    if (
        checkpoint is not None
        and issubclass(algorithm_class, OffPolicyAlgorithm)
        and previous_record.get("n_envs") not in (None, n_envs)
    ):
        raise ValueError(
            f"cannot resume {settings.algo.upper()} with n_envs={n_envs}: its replay buffer was "
            f"collected with n_envs={previous_record['n_envs']}"
        )
    if settings.torch_threads is not None:
        torch.set_num_threads(settings.torch_threads)

    vec_env_kind = resolve_vec_env_kind(settings.vec_env, settings.env_id)
    # The validation env is built first, in this process: bad env kwargs fail here, fast.
    eval_venv: VecEnv = make_validation_env(
        settings.env_id,
        env_kwargs,
        settings.eval_episodes,
        vec_monitor=vec_env_kind == "batched",
    )
    area_cap = float(eval_venv.get_attr("area_cap")[0])
    settings.output.mkdir(parents=True, exist_ok=True)
    start_timesteps = checkpoint.timesteps if checkpoint is not None else 0
    seed_start = training_seed_start(settings.seed, start_timesteps, n_envs)
    venv: VecEnv = make_training_env(
        settings.env_id, env_kwargs, n_envs, vec_env_kind, files.monitor
    )
    try:
        if hyperparams.normalize is not None:
            if checkpoint is not None and checkpoint.vecnormalize_path.is_file():
                venv = load_vecnormalize(checkpoint.vecnormalize_path, venv)
                venv.training = True
            else:
                venv = VecNormalize(venv, **hyperparams.normalize)
            eval_normalize = {**hyperparams.normalize, "training": False, "norm_reward": False}
            eval_venv = VecNormalize(eval_venv, **eval_normalize)
        tensorboard_log = str(files.tensorboard) if settings.tensorboard else None
        if checkpoint is not None:
            model = load_model(
                checkpoint.model_path,
                settings.algo,
                env=venv,
                device=settings.device,
                tensorboard_log=tensorboard_log,
                verbose=settings.verbose,
            )
            if isinstance(model, OffPolicyAlgorithm):
                if checkpoint.replay_buffer_path.is_file():
                    model.load_replay_buffer(checkpoint.replay_buffer_path)
                else:
                    print(f"warning: {checkpoint.replay_buffer_path} missing; empty replay buffer")
        else:
            model = algorithm_class(
                env=venv,
                seed=settings.seed,
                device=settings.device,
                tensorboard_log=tensorboard_log,
                verbose=settings.verbose,
                **hyperparams.algorithm_kwargs,
            )
        model.set_random_seed(seed_start)  # torch/numpy/action space, and env i: seed_start + i

        raw = {**raw, "n_envs": n_envs, "n_timesteps": target}  # the entry actually used
        record = {
            "format": RUN_FORMAT_VERSION,
            "algo": settings.algo,
            "env_id": settings.env_id,
            "env_kwargs": json_safe(env_kwargs),
            "hyperparams": json_safe(raw),
            "n_envs": n_envs,
            "seed": settings.seed,
            "vec_env": vec_env_kind,
            "target_timesteps": target,
            "num_timesteps": int(model.num_timesteps),
            "status": "running",
            "seeds": {
                "training_first_reset": "env i of a segment starting at timestep t: "
                f"(seed + t) mod {TRAINING_SEED_LIMIT - n_envs} + i",
                "validation": [
                    VALIDATION_SEED_START,
                    VALIDATION_SEED_START + settings.eval_episodes,
                ],
            },
            "segments": _segments_after_a_kill(previous_record, checkpoint),
            "versions": _versions(),
        }
        learn_start = time.perf_counter()
        remaining = target - int(model.num_timesteps)
        segment: dict[str, Any] | None = None
        if remaining > 0:
            # Written now and at every checkpoint, so a killed process leaves its segment
            # (marked "killed" on --resume) with the timesteps of its last checkpoint.
            segment = {
                "start_timesteps": start_timesteps,
                "end_timesteps": start_timesteps,
                "n_envs": n_envs,
                "vec_env": vec_env_kind,
                "status": "running",
                "wall_seconds": 0.0,
            }
            record["segments"].append(segment)
        write_json_atomically(files.record, record)

        def record_checkpoint(saved_checkpoint: Checkpoint) -> None:
            assert segment is not None
            segment["end_timesteps"] = saved_checkpoint.timesteps
            segment["wall_seconds"] = round(time.perf_counter() - learn_start, 3)
            record["num_timesteps"] = saved_checkpoint.timesteps
            write_json_atomically(files.record, record)

        store = CheckpointStore(files.checkpoints, keep=settings.keep_checkpoints)
        stop_request = StopRequest()
        eval_callback = FixedSeedEvalCallback(
            eval_venv,
            best_folder=files.best,
            area_cap=area_cap,
            n_eval_episodes=settings.eval_episodes,
            eval_freq=callback_calls(settings.eval_freq, n_envs) if settings.eval_freq > 0 else 0,
            deterministic=True,
            verbose=1 if settings.verbose >= 0 else 0,
        )
        if checkpoint is not None:
            eval_callback.restore_history()
        stop_callback = StopOnRequestCallback(stop_request)
        checkpoint_callback = PeriodicCheckpointCallback(
            store, settings.checkpoint_freq, verbose=settings.verbose, on_save=record_checkpoint
        )
        callbacks: list[BaseCallback] = [stop_callback, checkpoint_callback, eval_callback]

        interrupted = False
        stopped_at_once = False
        if remaining <= 0:
            print(f"{settings.output}: already at {model.num_timesteps} >= {target} timesteps")
        else:
            with stop_on_signals(stop_request):
                try:
                    model.learn(
                        total_timesteps=remaining,
                        callback=callbacks,
                        reset_num_timesteps=checkpoint is None,
                        progress_bar=settings.progress_bar,
                        tb_log_name=settings.algo.upper(),
                    )
                except KeyboardInterrupt:
                    interrupted = stopped_at_once = True
        interrupted = interrupted or bool(stop_request)
        boundary = checkpoint_callback.boundary
        if (stop_callback.stopped_mid_rollout or stopped_at_once) and boundary is not None:
            # learn() left without training on the partial rollout: save the model of the
            # last update boundary, which counts only the steps it was trained on.
            dropped = rewind_to_boundary(model, boundary)
            if dropped > 0 and settings.verbose >= 0:
                print(
                    f"stopped in a rollout: its {dropped} steps were not trained on and are "
                    f"not counted; the checkpoint is at {model.num_timesteps} timesteps",
                    file=sys.stderr,
                )
        wall_seconds = time.perf_counter() - learn_start
        steps_done = int(model.num_timesteps) - start_timesteps
        saved = store.save(model) if remaining > 0 else checkpoint
        if not interrupted:
            save_model_atomically(model, files.final_model)
            normalizer = model.get_vec_normalize_env()
            if normalizer is not None:
                save_vecnormalize_atomically(normalizer, files.final_vecnormalize)
        steps_per_second = steps_done / wall_seconds if wall_seconds > 0 else math.nan
        if segment is not None:
            segment.update(
                end_timesteps=int(model.num_timesteps),
                status="interrupted" if interrupted else "finished",
                wall_seconds=round(wall_seconds, 3),
                steps_per_second=round(steps_per_second, 1),
            )
        record["num_timesteps"] = int(model.num_timesteps)
        record["status"] = "interrupted" if interrupted else "finished"
        write_json_atomically(files.record, record)
    finally:
        _close_quietly(venv)
        _close_quietly(eval_venv)
    return TrainResult(
        model=model,
        run_dir=settings.output,
        num_timesteps=int(model.num_timesteps),
        target_timesteps=target,
        interrupted=interrupted,
        checkpoint=saved,
        steps_per_second=steps_per_second,
        wall_seconds=wall_seconds,
    )


# --------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="bearing-env train",
        description="Train PPO/SAC (BearingSLAM-v0) or DQN (BearingSLAMDiscrete-v0) with "
        "stable-baselines3; hyperparameters from the shipped <algo>.yml (rl-zoo3 format; "
        "bearing-env hyperparams ALGO prints its path). "
        "Ctrl-C saves a checkpoint; --resume continues from it.",
    )
    add = parser.add_argument
    add("--algo", required=True, choices=sorted(DEFAULT_ENV_IDS))
    add("--env", help="env id (default BearingSLAM-v0; for dqn BearingSLAMDiscrete-v0)")
    add("--env-kwargs", nargs="*", default=[], metavar="K=V", help="merged over the YAML's")
    add("--hyperparams", nargs="*", default=[], metavar="K=V", help="override YAML entries")
    add("--conf-file", type=Path, help="hyperparameter file (default: the shipped <algo>.yml)")
    add("--timesteps", type=int, help="total env steps of the run (default the YAML's n_timesteps)")
    add("--seed", type=int, default=0, help="default %(default)s")
    add("--n-envs", type=int, help="parallel envs (default the YAML's n_envs)")
    add(
        "--vec-env",
        choices=VEC_ENV_CHOICES,
        default="auto",
        help="batched: one Gymnasium vector env in this process (the id's batched "
        "vector_entry_point, else a SyncVectorEnv); subproc: a process per env (spawn); "
        "dummy: all in this process; auto (default): batched when the id registers a "
        "batched vector env, else subproc",
    )
    add("--output", type=Path, help="run folder (default runs/<algo>_<env>_seed<seed>)")
    add("--resume", action="store_true", help="continue the run in --output from its checkpoint")
    add(
        "--eval-freq", type=int, default=DEFAULT_EVAL_FREQ, help="env steps (0: never; %(default)s)"
    )
    add("--eval-episodes", type=int, default=DEFAULT_EVAL_EPISODES, help="default %(default)s")
    add(
        "--checkpoint-freq",
        type=int,
        default=DEFAULT_CHECKPOINT_FREQ,
        help="env steps (%(default)s)",
    )
    add(
        "--keep-checkpoints", type=int, default=DEFAULT_KEEP_CHECKPOINTS, help="default %(default)s"
    )
    add("--no-progress", action="store_true", help="no progress bar")
    add("--no-tensorboard", action="store_true", help="no TensorBoard logs")
    add("--device", default="cpu", help="torch device (default %(default)s)")
    add("--torch-threads", type=int, default=1, help="0: torch's default (default %(default)s)")
    add("--verbose", type=int, default=0, help="1: SB3 training tables; -1: no evaluation lines")
    add(
        "--export",
        type=Path,
        metavar="DIR/NAME",
        help="after training, copy the best model to DIR/NAME.zip (+ _vecnormalize.pkl, .json)",
    )
    add("--export-only", action="store_true", help="export the run in --output without training")
    return parser


def default_output(algo: str, env_id: str, seed: int) -> Path:
    return DEFAULT_RUNS_DIR / f"{algo}_{hyperparams_key(env_id)}_seed{seed}"


def settings_from_args(args: argparse.Namespace) -> TrainSettings:
    env_id = args.env or DEFAULT_ENV_IDS[args.algo]
    return TrainSettings(
        algo=args.algo,
        env_id=env_id,
        output=args.output or default_output(args.algo, env_id, args.seed),
        env_kwargs=parse_key_values(args.env_kwargs, "--env-kwargs"),
        hyperparam_overrides=parse_key_values(args.hyperparams, "--hyperparams"),
        conf_file=args.conf_file,
        timesteps=args.timesteps,
        seed=args.seed,
        n_envs=args.n_envs,
        vec_env=args.vec_env,
        resume=args.resume,
        eval_freq=args.eval_freq,
        eval_episodes=args.eval_episodes,
        checkpoint_freq=args.checkpoint_freq,
        keep_checkpoints=args.keep_checkpoints,
        progress_bar=not args.no_progress,
        tensorboard=not args.no_tensorboard,
        device=args.device,
        torch_threads=args.torch_threads or None,
        verbose=args.verbose,
    )


def _output_of(args: argparse.Namespace) -> Path:
    """The run folder the arguments name (``--output`` or its default)."""
    env_id = args.env or DEFAULT_ENV_IDS[args.algo]
    return Path(args.output or default_output(args.algo, env_id, args.seed))


def _print_export(exported: ExportedModel) -> None:
    print(f"exported the {exported.source} model to {exported.model_path}")
    if exported.vecnormalize_path is not None:
        print(f"  VecNormalize statistics: {exported.vecnormalize_path}")
    print(f"  description: {exported.metadata_path}")


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else list(argv))
    if args.export_only and args.export is None:
        parser.error("--export-only needs --export DIR/NAME")
    with _clear_errors(args):
        settings = settings_from_args(args)
        if args.export_only:
            _print_export(export_run(settings.output, args.export))
            return
        result = train(settings)
    speed = (
        f", {result.steps_per_second:.0f} env steps/s over {result.wall_seconds:.1f} s"
        if math.isfinite(result.steps_per_second) and result.wall_seconds > 0.01
        else ""
    )
    print(f"{result.run_dir}: {result.num_timesteps}/{result.target_timesteps} timesteps{speed}")
    if result.interrupted:
        where = result.checkpoint.model_path if result.checkpoint is not None else "?"
        print(f"interrupted: checkpoint {where}; continue with --resume", file=sys.stderr)
        raise SystemExit(EXIT_INTERRUPTED)
    if args.export is not None:
        with _clear_errors(args):
            _print_export(export_run(settings.output, args.export))


@contextlib.contextmanager
def _clear_errors(args: argparse.Namespace) -> Iterator[None]:
    """Bad settings and files, and OSErrors while writing (disk full, no permission, a
    parent that is a file), end the command with one line and exit status 2."""
    try:
        yield
    except (FileNotFoundError, FileExistsError, ValueError, TypeError) as error:
        print(f"bearing-env train: error: {error}", file=sys.stderr)
        raise SystemExit(2) from error
    except OSError as error:
        output = _output_of(args)
        in_run = str(error.filename or output).startswith(str(output))
        option = "--export" if args.export is not None and not in_run else "--output"
        fail("bearing-env train", write_error_message(error, output, option))


if __name__ == "__main__":
    main()
