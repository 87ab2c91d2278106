"""The training loop of ``bearing-env train``: :func:`train` trains (or resumes) PPO, SAC or
DQN with stable-baselines3 as :class:`TrainSettings` say. Its command line is
:mod:`bearing_env.train.sb3.train_cli`, ``run.json`` and resuming
:mod:`bearing_env.train.sb3.run_record`.

    bearing-env train --algo ppo                                   # PPO, Khepera scenario
    bearing-env train --algo sac --env BearingSLAM-Khepera-v1 --timesteps 200000
    bearing-env train --algo dqn --env BearingSLAMDiscrete-v1 --env-kwargs scenario=random
    bearing-env train --algo ppo --output runs/ppo_khepera --resume --timesteps 2000000
    bearing-env train --algo ppo --output runs/ppo_khepera --export-only \
        --export agents/pretrained/ppo_khepera

**Hyperparameters** come from the shipped ``hyperparams/<algo>.yml`` (``bearing-env
hyperparams <algo>`` prints its path) in rl-zoo3's format: one
entry per env id holding ``n_envs``, ``n_timesteps``, ``policy``, ``normalize``,
``policy_kwargs`` (a Python expression string) and the algorithm's constructor arguments
(``lin_<x>`` is a schedule decaying linearly from ``x`` to 0); an entry may hold
``env_kwargs`` too, but the shipped ones are keyed by the id whose registered kwargs
carry the settings (``BearingSLAM-Khepera-v1``), so that the same files run under
rl-zoo3, which makes its evaluation env from the id alone::

    python -m rl_zoo3.train --gym-packages bearing_env --algo ppo --env BearingSLAM-Khepera-v1 \\
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

from bearing_env.agents.sb3 import (
    find_vecnormalize,
    load_model,
    load_vecnormalize,
    resolve_model_path,
)
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
    Hyperparameters,
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
    #: A model (a ``.zip``, or a run folder's best model) whose weights the new run
    #: starts from: a fine-tune. Its VecNormalize statistics beside it are loaded too.
    init_from: Path | None = None
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
def stop_on_signals(
    request: StopRequest, notice: str = "stopping at the next step and saving a checkpoint"
) -> Iterator[None]:
    """While active, Ctrl-C and SIGTERM set ``request`` and print ``notice`` (the trainer
    stops at the next step); a second Ctrl-C raises ``KeyboardInterrupt`` at once."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handle(signum: int, frame: Any) -> None:
        if request:
            raise KeyboardInterrupt
        request.set(signal.Signals(signum).name)
        print(
            f"\n{signal.Signals(signum).name}: {notice} (Ctrl-C again to stop at once)",
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
    """Train (or resume) a run; see the module docstring for the files it writes.

    The phases, in order (each a function below): :func:`plan_run` reads the settings,
    the hyperparameters and, on ``--resume``, the run folder; :func:`apply_process_settings`
    sets torch's threads; :func:`build_envs` makes the validation and training envs and
    :func:`normalize_envs` wraps them in VecNormalize; :func:`build_model` makes or loads
    the model; :func:`start_run_record` writes ``run.json`` with the running segment;
    :func:`build_callbacks` makes the checkpoint, stop and evaluation callbacks;
    :func:`learn` trains until the budget or a stop request; :func:`save_run` saves the
    checkpoint, the final model and the finished record. The envs are closed at the end."""
    check_device(settings.device)
    plan = plan_run(settings)
    apply_process_settings(settings, plan)
    envs = build_envs(settings, plan)
    try:
        normalize_envs(envs, plan, settings)
        model = build_model(settings, plan, envs)
        run_log = start_run_record(settings, plan, envs, model)
        callbacks = build_callbacks(settings, plan, envs, run_log)
        interrupted = learn(settings, plan, model, callbacks, run_log.remaining)
        saved = save_run(plan, model, callbacks, run_log, interrupted)
    finally:
        envs.close()
    return TrainResult(
        model=model,
        run_dir=settings.output,
        num_timesteps=int(model.num_timesteps),
        target_timesteps=plan.target,
        interrupted=interrupted,
        checkpoint=saved.checkpoint,
        steps_per_second=saved.steps_per_second,
        wall_seconds=saved.wall_seconds,
    )


@dataclass(frozen=True)
class RunPlan:
    """What a run will do, settled before anything is built: the algorithm, the entry of
    the hyperparameter file, the checkpoint it resumes from (if any) and its budget."""

    algorithm_class: type[BaseAlgorithm]
    #: The raw entry of the hyperparameter file (overrides merged), as ``run.json`` keeps it.
    raw: dict[str, Any]
    hyperparams: Hyperparameters
    checkpoint: Checkpoint | None
    #: ``run.json`` of the run being resumed (empty for a new run).
    previous_record: dict[str, Any]
    n_envs: int
    #: The total timesteps the run trains to.
    target: int
    files: RunFiles
    #: A note that the run stops at a whole rollout past ``target`` (on-policy algorithms).
    notice: str | None

    @property
    def start_timesteps(self) -> int:
        return self.checkpoint.timesteps if self.checkpoint is not None else 0


def plan_run(settings: TrainSettings) -> RunPlan:
    """Phase 1: the algorithm, the hyperparameters and (on ``--resume``) the checkpoint and
    record to resume from, all checked before any env or model is built."""
    algorithm_class = algorithm_class_for(settings.algo)
    raw, checkpoint = resolve_run(settings)
    if settings.init_from is not None:
        if checkpoint is not None:
            raise ValueError(
                f"--init-from starts a new run, but {settings.output} holds a checkpoint to "
                "resume: drop --resume, or choose another --output"
            )
        settings.init_from = resolve_model_path(settings.init_from)
    hyperparams = parse_hyperparameters(raw, settings.algo)
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
    return RunPlan(
        algorithm_class=algorithm_class,
        raw=raw,
        hyperparams=hyperparams,
        checkpoint=checkpoint,
        previous_record=previous_record,
        n_envs=n_envs,
        target=target,
        files=files,
        notice=notice,
    )


def apply_process_settings(settings: TrainSettings, plan: RunPlan) -> None:
    """Phase 2: torch's thread count for this process, then the plan's rollout notice."""
    if settings.torch_threads is not None:
        if settings.torch_threads < 1:
            raise ValueError(f"torch_threads must be >= 1 (or None), got {settings.torch_threads}")
        torch.set_num_threads(settings.torch_threads)
    if plan.notice is not None:
        print(plan.notice, file=sys.stderr)


@dataclass
class TrainingEnvs:
    """The training and validation envs; :func:`normalize_envs` replaces both with their
    VecNormalize wrappers, and :meth:`close` closes whichever they are then."""

    train: VecEnv
    validation: VecEnv
    #: The ``--vec-env`` kind the training env was built with.
    kind: str
    #: The area cap of the env, for the evaluation's scores.
    area_cap: float
    #: Training env ``i`` first resets with seed ``seed_start + i``.
    seed_start: int

    def close(self) -> None:
        _close_quietly(self.train)
        _close_quietly(self.validation)


def build_envs(settings: TrainSettings, plan: RunPlan) -> TrainingEnvs:
    """Phase 3: the validation env, then the run folder and the training envs."""
    vec_env_kind = resolve_vec_env_kind(settings.vec_env, settings.env_id)
    # The validation env is built first, in this process: bad env kwargs fail here, fast.
    eval_venv: VecEnv = make_validation_env(
        settings.env_id,
        plan.hyperparams.env_kwargs,
        settings.eval_episodes,
        vec_monitor=vec_env_kind == "batched",
    )
    area_cap = float(eval_venv.get_attr("area_cap")[0])
    settings.output.mkdir(parents=True, exist_ok=True)
    seed_start = training_seed_start(settings.seed, plan.start_timesteps, plan.n_envs)
    venv: VecEnv = make_training_env(
        settings.env_id, plan.hyperparams.env_kwargs, plan.n_envs, vec_env_kind, plan.files.monitor
    )
    return TrainingEnvs(venv, eval_venv, vec_env_kind, area_cap, seed_start)


def init_statistics(init_from: Path | None) -> Path | None:
    """The VecNormalize statistics beside an ``--init-from`` model (None without one)."""
    return None if init_from is None else find_vecnormalize(init_from)


def normalize_envs(envs: TrainingEnvs, plan: RunPlan, settings: TrainSettings) -> None:
    """Phase 4: when the entry normalises, VecNormalize around both envs (the training
    one resumes the checkpoint's statistics, or starts from those of the ``--init-from``
    model; the validation one never updates its own)."""
    normalize = plan.hyperparams.normalize
    if normalize is None:
        return
    checkpoint = plan.checkpoint
    statistics = init_statistics(settings.init_from)
    if checkpoint is not None and checkpoint.vecnormalize_path.is_file():
        statistics = checkpoint.vecnormalize_path
    if statistics is not None and statistics.is_file():
        resumed = load_vecnormalize(statistics, envs.train)
        resumed.training = True
        envs.train = resumed
    else:
        envs.train = VecNormalize(envs.train, **normalize)
    eval_normalize = {**normalize, "training": False, "norm_reward": False}
    envs.validation = VecNormalize(envs.validation, **eval_normalize)


def build_model(settings: TrainSettings, plan: RunPlan, envs: TrainingEnvs) -> BaseAlgorithm:
    """Phase 5: the model, loaded from the checkpoint (with its replay buffer) or new, and
    seeded for this segment."""
    tensorboard_log = str(plan.files.tensorboard) if settings.tensorboard else None
    checkpoint = plan.checkpoint
    model: BaseAlgorithm
    if checkpoint is not None:
        model = load_model(
            checkpoint.model_path,
            settings.algo,
            env=envs.train,
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
        model = plan.algorithm_class(
            env=envs.train,
            seed=settings.seed,
            device=settings.device,
            tensorboard_log=tensorboard_log,
            verbose=settings.verbose,
            **plan.hyperparams.algorithm_kwargs,
        )
        if settings.init_from is not None:
            start_from(model, settings.init_from, settings.device)
    model.set_random_seed(envs.seed_start)  # torch/numpy/action space, env i: seed_start + i
    return model


@dataclass
class RunLog:
    """``run.json`` while the run trains: the record, this invocation's segment (None
    when there is nothing left to train) and when learning started."""

    path: Path
    record: dict[str, Any]
    segment: dict[str, Any] | None
    learn_start: float
    #: Timesteps left to train in this invocation (<= 0: the run is already done).
    remaining: int

    def write(self) -> None:
        write_json_atomically(self.path, self.record)

    def checkpoint_saved(self, saved_checkpoint: Checkpoint) -> None:
        """The record after each periodic checkpoint: a killed process leaves its segment
        ending at the timesteps of its last checkpoint."""
        assert self.segment is not None
        self.segment["end_timesteps"] = saved_checkpoint.timesteps
        self.segment["wall_seconds"] = round(time.perf_counter() - self.learn_start, 3)
        self.record["num_timesteps"] = saved_checkpoint.timesteps
        self.write()


def start_run_record(
    settings: TrainSettings, plan: RunPlan, envs: TrainingEnvs, model: BaseAlgorithm
) -> RunLog:
    """Phase 6: ``run.json`` with the settings, the entry actually used, the segments of
    earlier invocations and, when there is training left, this one's running segment."""
    raw = {**plan.raw, "n_envs": plan.n_envs, "n_timesteps": plan.target}  # the entry used
    record = new_run_record(
        settings,
        hyperparams=raw,
        env_kwargs=plan.hyperparams.env_kwargs,
        n_envs=plan.n_envs,
        vec_env_kind=envs.kind,
        target_timesteps=plan.target,
        num_timesteps=int(model.num_timesteps),
        segments=segments_after_a_kill(plan.previous_record, plan.checkpoint),
    )
    learn_start = time.perf_counter()
    remaining = plan.target - int(model.num_timesteps)
    segment: dict[str, Any] | None = None
    if remaining > 0:
        # Written now and at every checkpoint, so a killed process leaves its segment
        # (marked "killed" on --resume) with the timesteps of its last checkpoint.
        segment = running_segment(plan.start_timesteps, plan.n_envs, envs.kind)
        record["segments"].append(segment)
    run_log = RunLog(plan.files.record, record, segment, learn_start, remaining)
    run_log.write()
    return run_log


def start_from(model: BaseAlgorithm, path: Path, device: str) -> None:
    """Give a new model the weights of the model saved at ``path`` (``--init-from``), or
    a clear error when its networks do not fit (another observation kind, algorithm or
    network size)."""
    try:
        model.set_parameters(str(path), exact_match=True, device=device)
    except (RuntimeError, KeyError, ValueError) as error:
        first_line = str(error).strip().splitlines()[0] if str(error).strip() else repr(error)
        raise ValueError(
            f"--init-from: the weights of {path} do not fit this run's "
            f"{model.__class__.__name__} policy ({first_line})"
        ) from error


@dataclass(frozen=True)
class TrainingCallbacks:
    """The callbacks of ``learn()`` and the objects the phases after it read."""

    store: CheckpointStore
    stop_request: StopRequest
    stop: StopOnRequestCallback
    checkpoint: PeriodicCheckpointCallback
    #: In the order ``learn()`` calls them.
    in_order: list[BaseCallback]


def build_callbacks(
    settings: TrainSettings, plan: RunPlan, envs: TrainingEnvs, run_log: RunLog
) -> TrainingCallbacks:
    """Phase 7: stop on request, periodic checkpoints (each recorded in ``run.json``) and
    the fixed-seed evaluation that keeps the best model (its history restored on resume)."""
    store = CheckpointStore(plan.files.checkpoints, keep=settings.keep_checkpoints)
    stop_request = StopRequest()
    eval_callback = FixedSeedEvalCallback(
        envs.validation,
        best_folder=plan.files.best,
        area_cap=envs.area_cap,
        n_eval_episodes=settings.eval_episodes,
        eval_freq=callback_calls(settings.eval_freq, plan.n_envs) if settings.eval_freq > 0 else 0,
        deterministic=True,
        verbose=1 if settings.verbose >= 0 else 0,
    )
    if plan.checkpoint is not None:
        eval_callback.restore_history()
    stop_callback = StopOnRequestCallback(stop_request)
    checkpoint_callback = PeriodicCheckpointCallback(
        store, settings.checkpoint_freq, verbose=settings.verbose, on_save=run_log.checkpoint_saved
    )
    return TrainingCallbacks(
        store=store,
        stop_request=stop_request,
        stop=stop_callback,
        checkpoint=checkpoint_callback,
        in_order=[stop_callback, checkpoint_callback, eval_callback],
    )


def learn(
    settings: TrainSettings,
    plan: RunPlan,
    model: BaseAlgorithm,
    callbacks: TrainingCallbacks,
    remaining: int,
) -> bool:
    """Phase 8: ``model.learn()`` for the ``remaining`` timesteps, stopping on Ctrl-C or
    SIGTERM; whether it was interrupted. A stop inside a rollout rewinds the model to the
    last update boundary, so that it counts only the steps it was trained on."""
    interrupted = False
    stopped_at_once = False
    if remaining <= 0:
        print(f"{settings.output}: already at {model.num_timesteps} >= {plan.target} timesteps")
    else:
        with stop_on_signals(callbacks.stop_request):
            try:
                model.learn(
                    total_timesteps=remaining,
                    callback=callbacks.in_order,
                    reset_num_timesteps=plan.checkpoint is None,
                    progress_bar=settings.progress_bar,
                    tb_log_name=settings.algo.upper(),
                )
            except KeyboardInterrupt:
                interrupted = stopped_at_once = True
    interrupted = interrupted or bool(callbacks.stop_request)
    boundary = callbacks.checkpoint.boundary
    if (callbacks.stop.stopped_mid_rollout or stopped_at_once) and boundary is not None:
        # learn() left without training on the partial rollout: save the model of the
        # last update boundary, which counts only the steps it was trained on.
        dropped = rewind_to_boundary(model, boundary)
        if dropped > 0 and settings.verbose >= 0:
            print(
                f"stopped in a rollout: its {dropped} steps were not trained on and are "
                f"not counted; the checkpoint is at {model.num_timesteps} timesteps",
                file=sys.stderr,
            )
    return interrupted


@dataclass(frozen=True)
class SavedRun:
    """What :func:`save_run` saved, and the speed of this invocation's ``learn()``."""

    #: The checkpoint written now, or the one resumed from when there was nothing to train.
    checkpoint: Checkpoint | None
    steps_per_second: float
    wall_seconds: float


def save_run(
    plan: RunPlan,
    model: BaseAlgorithm,
    callbacks: TrainingCallbacks,
    run_log: RunLog,
    interrupted: bool,
) -> SavedRun:
    """Phase 9: a checkpoint (when this invocation trained), the final model and its
    statistics (unless interrupted), and ``run.json`` with the segment's end and status."""
    wall_seconds = time.perf_counter() - run_log.learn_start
    steps_done = int(model.num_timesteps) - plan.start_timesteps
    saved = callbacks.store.save(model) if run_log.remaining > 0 else plan.checkpoint
    if not interrupted:
        save_model_atomically(model, plan.files.final_model)
        normalizer = model.get_vec_normalize_env()
        if normalizer is not None:
            save_vecnormalize_atomically(normalizer, plan.files.final_vecnormalize)
    steps_per_second = steps_done / wall_seconds if wall_seconds > 0 else math.nan
    status = "interrupted" if interrupted else "finished"
    if run_log.segment is not None:
        run_log.segment.update(
            end_timesteps=int(model.num_timesteps),
            status=status,
            wall_seconds=round(wall_seconds, 3),
            steps_per_second=round(steps_per_second, 1),
        )
    run_log.record["num_timesteps"] = int(model.num_timesteps)
    run_log.record["status"] = status
    run_log.write()
    return SavedRun(saved, steps_per_second, wall_seconds)
