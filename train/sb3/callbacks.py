"""The stable-baselines3 callbacks of ``bearing-env train``: checkpoints at update
boundaries, stopping on request, and the fixed-seed evaluation.

- :class:`CheckpointStore`: the run's ``checkpoints/`` folder. A checkpoint is the model
  (``rl_model_<N>_steps.zip``), its VecNormalize statistics
  (``rl_model_vecnormalize_<N>_steps.pkl``) and, for off-policy algorithms, the replay
  buffer (``rl_model_replay_buffer_<N>_steps.pkl``), the names SB3's own
  ``CheckpointCallback`` uses. Every file is written to a temporary name and renamed, and
  the model ``.zip`` is written last, so a checkpoint whose ``.zip`` exists is complete.
- :class:`PeriodicCheckpointCallback`: a checkpoint every ``save_freq`` env steps, taken
  at the first *update boundary* at or past each multiple: the start of a rollout, which
  SB3 reaches only after ``train()`` has consumed the previous rollout. A checkpoint
  therefore never counts a step its model has not been trained on, and a run killed at
  any moment (SIGKILL included) resumes with as many updates per counted step as a run
  that was never stopped. The callback also remembers the state at the last boundary
  (:class:`UpdateBoundary`), so that a run stopped in the middle of a rollout can
  :func:`rewind_to_boundary` and save that instead of the partial rollout.
- :class:`StopOnRequestCallback`: ends ``learn()`` cleanly at the next env step once a
  :class:`StopRequest` is set (by the Ctrl-C handler).

:class:`PeriodicCheckpointCallback` subclasses SB3's ``CheckpointCallback`` and keeps its
file names (``_checkpoint_path``), but not its saving: SB3 saves from ``_on_step`` on a
call count, in the middle of a rollout (the steps of the partial rollout are counted but
were never trained on), writes in place and does not prune.
- :class:`FixedSeedEvalCallback`: SB3's ``EvalCallback`` that plays the same validation
  episodes (fixed reset seeds) at every evaluation, logs the total uncertainty area, saves
  the VecNormalize statistics beside the best model, and carries its history over a
  resume.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from stable_baselines3.common.base_class import BaseAlgorithm
from stable_baselines3.common.callbacks import BaseCallback, CheckpointCallback, EvalCallback
from stable_baselines3.common.off_policy_algorithm import OffPolicyAlgorithm
from stable_baselines3.common.vec_env import VecEnv, VecNormalize

from bearing_env.train.common.files import atomic_path, write_json_atomically

CHECKPOINT_PREFIX = "rl_model"
_CHECKPOINT_MODEL_PATTERN = re.compile(rf"^{CHECKPOINT_PREFIX}_(\d+)_steps\.zip$")
#: Files beside the best model (``best/``).
BEST_MODEL_NAME = "best_model.zip"
BEST_VECNORMALIZE_NAME = "vecnormalize.pkl"
BEST_SUMMARY_NAME = "best.json"
#: Validation metrics are reported at this move count (and at the end of the episode).
AREA_REPORT_MOVE = 10


def save_model_atomically(model: BaseAlgorithm, path: Path) -> None:
    with atomic_path(path) as temporary, open(temporary, "wb") as handle:
        model.save(handle)


def save_vecnormalize_atomically(normalizer: VecNormalize, path: Path) -> None:
    with atomic_path(path) as temporary:
        normalizer.save(str(temporary))


@dataclass(frozen=True)
class Checkpoint:
    """The files of one checkpoint (the optional ones may not exist)."""

    timesteps: int
    model_path: Path
    vecnormalize_path: Path
    replay_buffer_path: Path


class CheckpointStore:
    """Writes, lists and prunes the checkpoints of one run folder.

    Args:
        folder: the ``checkpoints/`` folder.
        keep: model checkpoints to keep (older ones are deleted); at least 1. Replay
            buffers are large, so only the newest one is kept.
    """

    def __init__(self, folder: Path, keep: int = 3) -> None:
        if keep < 1:
            raise ValueError(f"keep must be >= 1, got {keep}")
        self.folder = folder
        self.keep = keep

    def checkpoint_at(self, timesteps: int) -> Checkpoint:
        """The files of the checkpoint at ``timesteps``, named by SB3's own
        ``CheckpointCallback._checkpoint_path``."""
        namer = CheckpointCallback(1, str(self.folder), name_prefix=CHECKPOINT_PREFIX)
        namer.num_timesteps = timesteps
        return Checkpoint(
            timesteps=timesteps,
            model_path=Path(namer._checkpoint_path(extension="zip")),
            vecnormalize_path=Path(namer._checkpoint_path("vecnormalize_", extension="pkl")),
            replay_buffer_path=Path(namer._checkpoint_path("replay_buffer_", extension="pkl")),
        )

    def list(self) -> list[Checkpoint]:
        """The complete checkpoints, oldest first."""
        if not self.folder.is_dir():
            return []
        found = []
        for path in self.folder.iterdir():
            match = _CHECKPOINT_MODEL_PATTERN.match(path.name)
            if match:
                found.append(self.checkpoint_at(int(match.group(1))))
        return sorted(found, key=lambda checkpoint: checkpoint.timesteps)

    def latest(self) -> Checkpoint | None:
        checkpoints = self.list()
        return checkpoints[-1] if checkpoints else None

    def save(self, model: BaseAlgorithm) -> Checkpoint:
        """Save the model's current state (model, VecNormalize, replay buffer) and prune."""
        checkpoint = self.checkpoint_at(int(model.num_timesteps))
        normalizer = model.get_vec_normalize_env()
        if normalizer is not None:
            save_vecnormalize_atomically(normalizer, checkpoint.vecnormalize_path)
        if isinstance(model, OffPolicyAlgorithm) and model.replay_buffer is not None:
            with atomic_path(checkpoint.replay_buffer_path) as temporary:
                with open(temporary, "wb") as handle:
                    model.save_replay_buffer(handle)
        save_model_atomically(model, checkpoint.model_path)  # last: marks it complete
        self._prune(newest=checkpoint)
        return checkpoint

    def _prune(self, newest: Checkpoint) -> None:
        checkpoints = self.list()
        for old in checkpoints[: max(len(checkpoints) - self.keep, 0)]:
            for path in (old.model_path, old.vecnormalize_path, old.replay_buffer_path):
                path.unlink(missing_ok=True)
        for old in checkpoints:
            if old.timesteps != newest.timesteps:
                old.replay_buffer_path.unlink(missing_ok=True)


@dataclass
class UpdateBoundary:
    """What a model counts at an update boundary (the start of a rollout, after ``train()``).

    Between two boundaries SB3 changes no weights, only these counters, the VecNormalize
    statistics and, off-policy, the replay buffer's write position: restoring them
    (:func:`rewind_to_boundary`) turns a model stopped mid-rollout back into the model of
    the boundary, with the partial rollout's steps no longer counted.
    """

    num_timesteps: int
    counters: dict[str, int] = field(default_factory=dict)
    normalizer_stats: dict[str, Any] = field(default_factory=dict)
    buffer_position: tuple[int, bool] | None = None


#: Per-step counters of SB3 algorithms besides ``num_timesteps`` (DQN's target-network
#: period counts ``_n_calls``).
_BOUNDARY_COUNTERS = ("_n_calls", "_episode_num")


def update_boundary(model: BaseAlgorithm) -> UpdateBoundary:
    counters = {
        name: int(getattr(model, name)) for name in _BOUNDARY_COUNTERS if hasattr(model, name)
    }
    normalizer = model.get_vec_normalize_env()
    stats: dict[str, Any] = {}
    if normalizer is not None:
        stats = {
            name: getattr(normalizer, name).copy()
            for name in ("obs_rms", "ret_rms")
            if getattr(normalizer, name, None) is not None
        }
    position = None
    if isinstance(model, OffPolicyAlgorithm) and model.replay_buffer is not None:
        position = (int(model.replay_buffer.pos), bool(model.replay_buffer.full))
    return UpdateBoundary(int(model.num_timesteps), counters, stats, position)


def rewind_to_boundary(model: BaseAlgorithm, boundary: UpdateBoundary) -> int:
    """Forget the steps collected since ``boundary``; returns how many were dropped.

    The dropped transitions of an off-policy replay buffer are left beyond its write
    position (unsampled, overwritten next); when the buffer had already wrapped, the
    slots they overwrote keep them instead of the oldest transitions.
    """
    dropped = int(model.num_timesteps) - boundary.num_timesteps
    model.num_timesteps = boundary.num_timesteps
    for name, value in boundary.counters.items():
        setattr(model, name, value)
    normalizer = model.get_vec_normalize_env()
    if normalizer is not None:
        for name, stats in boundary.normalizer_stats.items():
            setattr(normalizer, name, stats.copy())
    if boundary.buffer_position is not None and isinstance(model, OffPolicyAlgorithm):
        buffer = model.replay_buffer
        if buffer is not None:
            buffer.pos, buffer.full = boundary.buffer_position
    return dropped


class PeriodicCheckpointCallback(CheckpointCallback):
    """SB3's ``CheckpointCallback`` (its folder, prefix and file names) that saves at the
    first update boundary at or past each multiple of ``save_freq`` env steps instead of
    from ``_on_step`` in the middle of a rollout, writes through :class:`CheckpointStore`
    (atomic files, pruning), and remembers the last boundary (:attr:`boundary`).

    ``on_save`` is called with each checkpoint written (the trainer updates ``run.json``).
    """

    def __init__(
        self,
        store: CheckpointStore,
        save_freq: int,
        verbose: int = 0,
        on_save: Callable[[Checkpoint], None] | None = None,
    ) -> None:
        if save_freq < 1:
            raise ValueError(f"save_freq must be >= 1 env steps, got {save_freq}")
        super().__init__(
            save_freq,
            str(store.folder),
            name_prefix=CHECKPOINT_PREFIX,
            save_replay_buffer=True,
            save_vecnormalize=True,
            verbose=verbose,
        )
        self.store = store
        self.save_freq = save_freq
        self.on_save = on_save
        self._next_save = save_freq
        #: The state after the last ``train()``: at the start of the current rollout.
        self.boundary: UpdateBoundary | None = None

    def _on_training_start(self) -> None:
        done = int(self.model.num_timesteps)
        self._next_save = (done // self.save_freq + 1) * self.save_freq

    def _on_rollout_start(self) -> None:
        # SB3 calls this before each rollout, after train() consumed the previous one.
        self.boundary = update_boundary(self.model)
        done = self.boundary.num_timesteps
        if done >= self._next_save:
            checkpoint = self.store.save(self.model)
            self._next_save = (done // self.save_freq + 1) * self.save_freq
            if self.verbose >= 1:
                print(f"checkpoint: {checkpoint.model_path}")
            if self.on_save is not None:
                self.on_save(checkpoint)

    def _on_step(self) -> bool:
        # Never SB3's save here: mid-rollout, it would count steps not yet trained on.
        return True


class StopRequest:
    """A flag the signal handler sets and :class:`StopOnRequestCallback` reads."""

    def __init__(self) -> None:
        self.reason: str | None = None

    def set(self, reason: str) -> None:
        self.reason = reason

    def __bool__(self) -> bool:
        return self.reason is not None


class StopOnRequestCallback(BaseCallback):
    """Stops ``learn()`` at the next env step once ``request`` is set.

    :attr:`stopped_mid_rollout` tells that it did: SB3 then leaves ``learn()`` without
    training on the partial rollout (see :func:`rewind_to_boundary`).
    """

    def __init__(self, request: StopRequest) -> None:
        super().__init__(verbose=0)
        self.request = request
        self.stopped_mid_rollout = False

    def _on_step(self) -> bool:
        if self.request:
            self.stopped_mid_rollout = True
            return False
        return True


class FixedSeedEvalCallback(EvalCallback):
    """``EvalCallback`` on fixed validation episodes, with area metrics and resumable history.

    The eval env's sub-envs must expose ``rewind_episode_seeds()`` (see
    ``bearing_env.train.sb3.training_envs.EpisodeSeedCycle``): it is called before every
    evaluation, so every evaluation plays the same episodes and the best model is chosen
    on a fixed set.

    Besides SB3's ``eval/mean_reward``, it logs ``eval/median_total_area_10`` (total area
    of landmarks L3, L4, ..., each capped at ``area_cap``, after 10 moves; an episode that
    ended earlier counts with its final map) and ``eval/median_total_area_final``, and
    records them in ``best/best.json`` when the model is the best so far. The VecNormalize
    statistics the evaluation used are saved as ``best/vecnormalize.pkl`` beside
    ``best/best_model.zip``.
    """

    def __init__(self, eval_env: VecEnv, best_folder: Path, area_cap: float, **kwargs: Any) -> None:
        super().__init__(
            eval_env, best_model_save_path=str(best_folder), log_path=str(best_folder), **kwargs
        )
        self.best_folder = best_folder
        self.area_cap = float(area_cap)
        self._areas_at_report_move: list[float] = []
        self._final_areas: list[float] = []
        self._moves: dict[int, int] = {}
        self.last_metrics: dict[str, float] = {}

    def restore_history(self) -> None:
        """Continue the best score and ``evaluations.npz`` of an earlier segment of the run."""
        summary_path = self.best_folder / BEST_SUMMARY_NAME
        if summary_path.is_file():
            summary = json.loads(summary_path.read_text())
            self.best_mean_reward = float(summary["mean_reward"])
        history_path = self.best_folder / "evaluations.npz"
        if history_path.is_file():
            with np.load(history_path) as history:
                self.evaluations_timesteps = [int(t) for t in history["timesteps"]]
                self.evaluations_results = [list(map(float, r)) for r in history["results"]]
                self.evaluations_length = [list(map(int, n)) for n in history["ep_lengths"]]

    def _capped_total_area(self, info: dict[str, Any]) -> float:
        areas = np.minimum(np.asarray(info["landmark_area"], dtype=np.float64), self.area_cap)
        return float(areas.sum())

    def _log_success_callback(self, locals_: dict[str, Any], globals_: dict[str, Any]) -> None:
        """Called by ``evaluate_policy`` after every step of every eval sub-env."""
        super()._log_success_callback(locals_, globals_)
        info = locals_["info"]
        env_index = int(locals_.get("i", 0))
        moves = self._moves.get(env_index, 0) + 1
        done = bool(locals_["done"])
        if moves == AREA_REPORT_MOVE or (done and moves < AREA_REPORT_MOVE):
            self._areas_at_report_move.append(self._capped_total_area(info))
        if done:
            self._final_areas.append(self._capped_total_area(info))
        self._moves[env_index] = 0 if done else moves

    def _on_step(self) -> bool:
        evaluating = self.eval_freq > 0 and self.n_calls % self.eval_freq == 0
        if not evaluating:
            return super()._on_step()
        self.eval_env.env_method("rewind_episode_seeds")
        self._areas_at_report_move = []
        self._final_areas = []
        self._moves = {}
        previous_best = self.best_mean_reward
        continue_training = super()._on_step()
        self.last_metrics = {
            "mean_reward": float(self.last_mean_reward),
            f"median_total_area_{AREA_REPORT_MOVE}": _median(self._areas_at_report_move),
            "median_total_area_final": _median(self._final_areas),
        }
        for key, value in self.last_metrics.items():
            if key != "mean_reward":
                self.logger.record(f"eval/{key}", value)
        if self.best_mean_reward > previous_best:
            self._save_best_extras()
        return continue_training

    def _save_best_extras(self) -> None:
        normalizer = self.model.get_vec_normalize_env()
        if normalizer is not None:
            save_vecnormalize_atomically(normalizer, self.best_folder / BEST_VECNORMALIZE_NAME)
        write_json_atomically(
            self.best_folder / BEST_SUMMARY_NAME,
            {
                "timesteps": int(self.num_timesteps),
                "n_eval_episodes": int(self.n_eval_episodes),
                "deterministic": bool(self.deterministic),
                **self.last_metrics,
            },
        )


def _median(values: list[float]) -> float:
    return float(np.median(values)) if values else float("nan")


def callback_calls(every_timesteps: int, n_envs: int) -> int:
    """SB3 callbacks count vec-env steps (``n_envs`` env steps each): the call period."""
    return max(every_timesteps // n_envs, 1)
