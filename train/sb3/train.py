"""The training loop of ``bearing-env train``: :func:`train` trains (or resumes) PPO, SAC or
DQN with stable-baselines3 as :class:`TrainSettings` say. Its command line is
:mod:`bearing_env.train.sb3.train_cli`, ``run.json`` and resuming
:mod:`bearing_env.train.sb3.run_record`.

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
Gymnasium vector env in this process, through ``bearing_env.train.sb3.vec_env``'s SB3 adapter:
the id's natively batched ``vector_entry_point`` when it registers one (one batched
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
``bearing_env.train.common.seeds`` defines every range.

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

import contextlib
import math
import signal
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import torch
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
from stable_baselines3.common.vec_env import (
    VecEnv,
    VecNormalize,
)

from bearing_env.agents.sb3 import load_model, load_vecnormalize
from bearing_env.train.common.files import write_json_atomically
from bearing_env.train.common.seeds import (
    training_seed_start,
)
from bearing_env.train.sb3.callbacks import (
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
from bearing_env.train.sb3.run_folder import (
    RunFiles,
    read_run_record,
)
from bearing_env.train.sb3.run_record import (
    new_run_record,
    resolve_run,
    running_segment,
    segments_after_a_kill,
)
from bearing_env.train.sb3.training_envs import (
    make_training_env,
    make_validation_env,
    resolve_vec_env_kind,
)
from bearing_env.train.sb3.zoo import (
    algorithm_class_for,
    parse_hyperparameters,
)

DEFAULT_EVAL_FREQ = 25_000
DEFAULT_EVAL_EPISODES = 50
DEFAULT_CHECKPOINT_FREQ = 50_000
DEFAULT_KEEP_CHECKPOINTS = 3
DEFAULT_RUNS_DIR = Path("runs")


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


def check_device(device: str) -> None:
    """ValueError naming ``device`` unless torch can use it here: ``auto``, ``cpu``, or
    ``cuda``/``cuda:N``/``mps`` when that hardware is present (SB3 would quietly train on
    the CPU instead, or fail at the first tensor)."""
    if device == "auto":
        return
    try:
        parsed = torch.device(device)
    except (RuntimeError, TypeError) as error:
        raise ValueError(f"device {device!r} is not a torch device ({error})") from None
    if parsed.type == "cuda":
        if not torch.cuda.is_available():
            raise ValueError(
                f"device {device!r}: CUDA is not available on this machine (torch "
                f"{torch.__version__}); use --device cpu"
            )
        if parsed.index is not None and parsed.index >= torch.cuda.device_count():
            raise ValueError(
                f"device {device!r}: this machine has {torch.cuda.device_count()} CUDA devices"
            )
    elif parsed.type == "mps" and not torch.backends.mps.is_available():
        raise ValueError(
            f"device {device!r}: MPS is not available on this machine; use --device cpu"
        )
    elif parsed.type not in ("cpu", "cuda", "mps"):
        raise ValueError(f"device {device!r}: expected auto, cpu, cuda, cuda:N or mps")


def rollout_notice(
    algorithm_kwargs: dict[str, Any], n_envs: int, done: int, target: int
) -> str | None:
    """For an on-policy algorithm (``n_steps`` in its settings), which trains in whole
    rollouts of ``n_steps * n_envs`` env steps: a one-line note when ``target`` is not
    reached in whole rollouts from ``done``, saying where the run will stop instead.
    ValueError when a rollout is a single step (SB3 refuses it)."""
    if "n_steps" not in algorithm_kwargs:
        return None
    n_steps = int(algorithm_kwargs["n_steps"])
    rollout = n_steps * n_envs
    if rollout < 2:
        raise ValueError(
            f"n_steps * n_envs must be >= 2 (one rollout), got n_steps={n_steps}, n_envs={n_envs}"
        )
    remaining = target - done
    if remaining <= 0 or remaining % rollout == 0:
        return None
    end = done + -(-remaining // rollout) * rollout
    return (
        f"note: training runs in whole rollouts of {rollout} env steps (n_steps {n_steps} x "
        f"n_envs {n_envs}), so this run trains to {end} timesteps, not {target}"
    )


def train(settings: TrainSettings) -> TrainResult:
    """Train (or resume) a run; see the module docstring for the files it writes."""
    check_device(settings.device)
    algorithm_class = algorithm_class_for(settings.algo)
    raw, checkpoint = resolve_run(settings)
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
    notice = rollout_notice(
        hyperparams.algorithm_kwargs,
        n_envs,
        checkpoint.timesteps if checkpoint is not None else 0,
        target,
    )
    if settings.torch_threads is not None:
        if settings.torch_threads < 1:
            raise ValueError(f"torch_threads must be >= 1 (or None), got {settings.torch_threads}")
        torch.set_num_threads(settings.torch_threads)
    if notice is not None:
        print(notice, file=sys.stderr)

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
                resumed = load_vecnormalize(checkpoint.vecnormalize_path, venv)
                resumed.training = True
                venv = resumed
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
        record = new_run_record(
            settings,
            hyperparams=raw,
            env_kwargs=env_kwargs,
            n_envs=n_envs,
            vec_env_kind=vec_env_kind,
            target_timesteps=target,
            num_timesteps=int(model.num_timesteps),
            segments=segments_after_a_kill(previous_record, checkpoint),
        )
        learn_start = time.perf_counter()
        remaining = target - int(model.num_timesteps)
        segment: dict[str, Any] | None = None
        if remaining > 0:
            # Written now and at every checkpoint, so a killed process leaves its segment
            # (marked "killed" on --resume) with the timesteps of its last checkpoint.
            segment = running_segment(start_timesteps, n_envs, vec_env_kind)
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
