"""The envs of a training run: the training ``VecEnv`` of each ``--vec-env`` kind, with
env ``i`` first reset with seed ``seed_start + i``, and the validation env that replays
the same validation episodes (``bearing_env.train.common.seeds``) at every evaluation.
"""

from __future__ import annotations

import signal
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, SupportsFloat

import gymnasium as gym
from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.vec_env import DummyVecEnv, SubprocVecEnv, VecEnv, VecMonitor

import bearing_env
from bearing_env.train.common.seeds import validation_seeds
from bearing_env.train.sb3.vec_env import (
    MONITOR_INFO_KEYWORDS,
    has_vector_entry_point,
    make_batched_vec_env,
    monitor_csv_path,
)

#: How the training envs run: ``batched`` is one Gymnasium vector env (the id's natively
#: batched ``vector_entry_point``, else a ``SyncVectorEnv``) behind
#: ``bearing_env.train.sb3.vec_env``'s adapter; ``subproc`` one process per env (spawn);
#: ``dummy`` all envs in this process.
VEC_ENV_KINDS: tuple[str, ...] = ("batched", "subproc", "dummy")

#: ``--vec-env`` also takes ``auto``: ``batched`` when the env id registers a batched
#: vector env (``vector_entry_point``), else ``subproc``.
VEC_ENV_CHOICES: tuple[str, ...] = ("auto", *VEC_ENV_KINDS)

class EpisodeSeedCycle(gym.Wrapper[Any, Any, Any, Any]):
    """Resets with the next seed of a fixed list whenever no seed is given.

    ``rewind_episode_seeds()`` starts the list again, so every evaluation plays the same
    episodes. An explicit ``reset(seed=...)`` is honoured and does not advance the list.
    """

    def __init__(self, env: gym.Env[Any, Any], seeds: Sequence[int]) -> None:
        super().__init__(env)
        if not seeds:
            raise ValueError("EpisodeSeedCycle needs at least one seed")
        self.episode_seeds = [int(seed) for seed in seeds]
        self._next_index = 0

    def rewind_episode_seeds(self) -> None:
        self._next_index = 0

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        if seed is None:
            seed = self.episode_seeds[self._next_index % len(self.episode_seeds)]
            self._next_index += 1
        return self.env.reset(seed=seed, options=options)

class SuccessInfo(gym.Wrapper[Any, Any, Any, Any]):
    """Adds ``info["is_success"]`` at the end of an episode (the env's termination is success),
    so SB3 logs ``rollout/success_rate`` and ``eval/success_rate``."""

    def step(self, action: Any) -> tuple[Any, SupportsFloat, bool, bool, dict[str, Any]]:
        observation, reward, terminated, truncated, info = self.env.step(action)
        if terminated or truncated:
            info["is_success"] = bool(terminated)
        return observation, reward, terminated, truncated, info

@dataclass(frozen=True, eq=False)
class EnvFactory:
    """Builds one wrapped env; picklable, so ``SubprocVecEnv`` (spawn) can call it in a worker."""

    env_id: str
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    monitor_path: str | None = None
    episode_seeds: tuple[int, ...] | None = None
    #: Log episodes with SB3's ``Monitor``; False when a ``VecMonitor`` does it instead.
    monitor: bool = True
    #: In worker processes: leave Ctrl-C to the trainer, which stops and checkpoints.
    ignore_interrupts: bool = False

    def __call__(self) -> gym.Env[Any, Any]:
        if self.ignore_interrupts:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        bearing_env.registration.register_envs()
        env: gym.Env[Any, Any] = gym.make(self.env_id, **self.env_kwargs)
        env = SuccessInfo(env)
        if self.monitor:
            env = Monitor(
                env,
                filename=self.monitor_path,
                info_keywords=("is_success",),
                # A resumed run appends; a new log starts with SB3's header (load_results
                # needs it).
                override_existing=self.monitor_path is None
                or not Path(monitor_csv_path(self.monitor_path)).is_file(),
            )
        if self.episode_seeds is not None:
            env = EpisodeSeedCycle(env, self.episode_seeds)
        return env

def resolve_vec_env_kind(vec_env_kind: str, env_id: str) -> str:
    """The kind of :data:`VEC_ENV_KINDS` that ``vec_env_kind`` means for ``env_id``.

    ``auto`` is ``batched`` when the id registers a natively batched vector env, which
    steps all envs in one batched computation, and ``subproc`` otherwise: a ``SyncVectorEnv``
    fallback would step the envs one by one in this process, and processes are faster.
    """
    if vec_env_kind == "auto":
        return "batched" if has_vector_entry_point(env_id) else "subproc"
    if vec_env_kind not in VEC_ENV_KINDS:
        raise ValueError(f"unknown vec env {vec_env_kind!r}; expected one of {VEC_ENV_CHOICES}")
    return vec_env_kind

def make_training_env(
    env_id: str,
    env_kwargs: dict[str, Any],
    n_envs: int,
    vec_env_kind: str,
    monitor_dir: Path | None,
) -> VecEnv:
    """``n_envs`` training envs: one batched Gymnasium vector env (``batched``, logged to
    ``monitor_dir/batched.monitor.csv``), a ``SubprocVecEnv`` (spawn) or a ``DummyVecEnv``
    (logged to ``monitor_dir/<i>.monitor.csv``). ``auto``: see :func:`resolve_vec_env_kind`.

    Every kind seeds env ``i`` with ``seed + i`` at ``venv.seed(seed)``, so the kinds train
    on the same data when the batched env reproduces the single env.
    """
    vec_env_kind = resolve_vec_env_kind(vec_env_kind, env_id)
    if monitor_dir is not None:
        monitor_dir.mkdir(parents=True, exist_ok=True)
    if vec_env_kind == "batched":
        monitor_path = None if monitor_dir is None else str(monitor_dir / "batched")
        return make_batched_vec_env(env_id, env_kwargs, n_envs, monitor_path)
    factories: list[Callable[[], gym.Env[Any, Any]]] = [
        EnvFactory(
            env_id=env_id,
            env_kwargs=dict(env_kwargs),
            monitor_path=None if monitor_dir is None else str(monitor_dir / str(rank)),
            ignore_interrupts=vec_env_kind == "subproc",
        )
        for rank in range(n_envs)
    ]
    if vec_env_kind == "subproc":
        return SubprocVecEnv(factories, start_method="spawn")
    return DummyVecEnv(factories)

def make_validation_env(
    env_id: str, env_kwargs: dict[str, Any], n_episodes: int, vec_monitor: bool = False
) -> VecEnv:
    """One in-process env cycling through the validation seeds.

    ``vec_monitor``: log episodes with a ``VecMonitor`` instead of a ``Monitor``, so that the
    wrappers stack up as in a ``batched`` training env. SB3's evaluation copies the
    ``VecNormalize`` statistics by walking both stacks in step, and fails on a
    ``VecMonitor`` that only the training env has.
    """
    factory = EnvFactory(
        env_id,
        dict(env_kwargs),
        episode_seeds=validation_seeds(n_episodes),
        monitor=not vec_monitor,
    )
    venv: VecEnv = DummyVecEnv([factory])
    return VecMonitor(venv, info_keywords=MONITOR_INFO_KEYWORDS) if vec_monitor else venv
