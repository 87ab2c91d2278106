"""The ``throughput`` section of ``bearing-env bench``: EnvPool's and gymnax's table, env
steps/s with random actions for 1, 64, 256 and 1024 sub-envs, each next to CartPole-v1
stepped with as many sub-envs in the same run, and PPO training steps/s on the batched env
next to SB3 PPO on CartPole-v1 with the same hyperparameters and number of envs.

- Env steps: ``gym.make_vec("BearingSLAM-v1", num_envs=N, vectorization_mode=
  "vector_entry_point")`` (the batched ``BearingSLAMVectorEnv``) against
  ``gym.make_vec("CartPole-v1", num_envs=N, ...)`` with Gymnasium's own batched
  ``CartPoleVectorEnv`` (``vector_entry_point``; a ``SyncVectorEnv`` if the installed
  Gymnasium had none, named in the JSON). The actions are sampled up front from the seeded
  action space (:data:`ACTION_BATCHES` batches, cycled), so sampling is not timed; each
  env is warmed up for :data:`WARMUP_FRACTION` of ``--seconds`` first. Rates count env
  transitions summed over the sub-envs: in NEXT_STEP autoreset mode (both envs' default)
  the reset-only sub-step after an episode's end is timed but not counted.
- PPO: SB3 ``PPO`` with ``ppo.yml``'s BearingSLAM-v1 settings (VecNormalize included) on
  ``--ppo-envs`` batched envs (``make_training_env``'s ``batched`` kind) and, with the
  same settings (n_steps, batch_size, n_epochs, policy and net_arch, learning rate, ...),
  on CartPole-v1 in a ``DummyVecEnv`` of as many envs, timed in interleaved rounds
  (:func:`~bearing_env.benchmarks.bench_timing.timed_ppo_rounds`); the ratio is the median
  of the per-round ratios. The issue's target: >= 0.5.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode

from bearing_env.benchmarks.bench_timing import (
    Bench,
    PPORun,
    autoreset_mode,
    build_ppo_run,
    log,
    make_vector_env,
    median_round_ratio,
    timed_figure,
    timed_ppo_rounds,
    torch_threads,
)
from bearing_env.extras import available

CARTPOLE_ID = "CartPole-v1"
DEFAULT_THROUGHPUT_COUNTS: tuple[int, ...] = (1, 64, 256, 1024)
QUICK_THROUGHPUT_COUNTS: tuple[int, ...] = (1, 4)
#: Action batches sampled before the timed loop, which cycles through them.
ACTION_BATCHES = 64
#: Untimed stepping before each timed loop, as a fraction of --seconds.
WARMUP_FRACTION = 0.25
#: SB3's vec env of the CartPole-v1 PPO run (``make_training_env``'s kind).
CARTPOLE_PPO_KIND = "dummy"


def cartpole_vectorization_mode() -> str:
    """``vector_entry_point`` when the installed Gymnasium has a batched CartPole-v1, else
    ``sync``."""
    return "vector_entry_point" if gym.spec(CARTPOLE_ID).vector_entry_point else "sync"


def presampled_actions(venv: gym.vector.VectorEnv, seed: int) -> list[Any]:
    """:data:`ACTION_BATCHES` batches of random actions from the seeded action space."""
    venv.action_space.seed(seed)
    return [venv.action_space.sample() for _ in range(ACTION_BATCHES)]


def step_presampled(
    venv: gym.vector.VectorEnv, actions: Sequence[Any], seconds: float, min_calls: int = 2
) -> tuple[int, float, int]:
    """Step ``venv`` through ``actions`` (cycled) for ``seconds``: (env transitions,
    seconds, step() calls). A NEXT_STEP sub-env whose episode ended resets on the next
    call and ignores its action: that sub-step is not a transition."""
    mode = autoreset_mode(venv)
    if mode == AutoresetMode.DISABLED:
        raise ValueError(f"the throughput section needs an autoresetting vector env, not {mode}")
    num_envs = venv.num_envs
    pending = np.zeros(num_envs, dtype=bool)
    transitions = calls = 0
    start = time.perf_counter()
    while calls < min_calls or time.perf_counter() - start < seconds:
        _, _, terminated, truncated, _ = venv.step(actions[calls % len(actions)])
        calls += 1
        if mode == AutoresetMode.NEXT_STEP:
            transitions += num_envs - int(np.count_nonzero(pending))
            pending = np.logical_or(terminated, truncated)
        else:
            transitions += num_envs
    return transitions, time.perf_counter() - start, calls


def random_action_figure(bench: Bench, venv: gym.vector.VectorEnv, seed: int = 0) -> dict[str, Any]:
    """``venv``'s env steps/s with presampled random actions, after an untimed warm-up."""
    actions = presampled_actions(venv, seed)
    venv.reset(seed=seed)
    step_presampled(venv, actions, WARMUP_FRACTION * bench.seconds)
    venv.reset(seed=seed)
    calls = 0

    def run() -> tuple[int, float]:
        nonlocal calls
        transitions, elapsed, calls = step_presampled(venv, actions, bench.seconds)
        return transitions, elapsed

    figure = timed_figure(bench, run)
    return {**figure, "step_calls": calls, "autoreset_mode": autoreset_mode(venv).value}


def bench_env_steps(
    bench: Bench, counts: Sequence[int], env_kwargs: dict[str, Any]
) -> list[dict[str, Any]]:
    """For each N in ``counts``: CartPole-v1 with N sub-envs, then the batched
    BearingSLAM-v1 env with N sub-envs, and the ratio of their rates."""
    cartpole_mode = cartpole_vectorization_mode()
    rows: list[dict[str, Any]] = []
    for num_envs in counts:
        cartpole = gym.make_vec(CARTPOLE_ID, num_envs=num_envs, vectorization_mode=cartpole_mode)
        try:
            cartpole_figure = random_action_figure(bench, cartpole)
        finally:
            cartpole.close()
        bearing = make_vector_env(num_envs, "vector_entry_point", env_kwargs)
        try:
            bearing_figure = random_action_figure(bench, bearing)
        finally:
            bearing.close()
        ratio = bearing_figure["steps_per_s"] / cartpole_figure["steps_per_s"]
        rows.append(
            {
                "num_envs": num_envs,
                "cartpole": {**cartpole_figure, "vectorization_mode": cartpole_mode},
                "bearing_slam": {**bearing_figure, "vectorization_mode": "vector_entry_point"},
                "ratio_to_cartpole_vector": ratio,
            }
        )
        log(
            f"  throughput {num_envs:5d} envs: CartPole-v1 {cartpole_figure['steps_per_s']:12,.0f}"
            f"  BearingSLAM-v1 {bearing_figure['steps_per_s']:12,.0f} steps/s ({ratio:.3f})"
        )
    return rows


def bench_ppo_against_cartpole(
    bench: Bench,
    n_envs: int,
    total_steps: int,
    env_kwargs: dict[str, Any],
    overrides: dict[str, Any],
    rounds: int,
) -> dict[str, Any]:
    """PPO on ``n_envs`` batched BearingSLAM-v1 envs and on CartPole-v1 (DummyVecEnv, the
    same hyperparameters), in interleaved rounds; their rows and the median round ratio."""
    runs: list[PPORun] = []
    try:
        with torch_threads(1):  # as bearing-env train (--torch-threads 1)
            log(f"  throughput PPO: building {n_envs} batched envs and warming up ...")
            runs.append(build_ppo_run(bench, "batched", n_envs, total_steps, env_kwargs, overrides))
            log(f"  throughput PPO: building {n_envs} CartPole-v1 envs and warming up ...")
            runs.append(
                build_ppo_run(
                    bench, CARTPOLE_PPO_KIND, n_envs, total_steps, {}, overrides, CARTPOLE_ID
                )
            )
            bearing_row, cartpole_row = timed_ppo_rounds(bench, runs, rounds, "throughput")
    finally:
        for run in runs:
            run.close()
    ratio = median_round_ratio(runs[0], runs[1])
    log(f"  throughput PPO: BearingSLAM-v1 / CartPole-v1 = {ratio:.3f} (median round)")
    return {
        "n_envs": n_envs,
        "bearing_slam": bearing_row,
        "cartpole": cartpole_row,
        "ratio_to_cartpole_ppo": ratio,
    }


def bench_throughput(
    bench: Bench,
    counts: Sequence[int],
    env_kwargs: dict[str, Any],
    ppo_envs: int,
    ppo_steps: int,
    ppo_overrides: dict[str, Any],
    ppo_rounds: int,
) -> dict[str, Any]:
    """The section's results: env-step rows per N, and the PPO pair (None, with a note,
    without stable-baselines3)."""
    bench.measure_reference("throughput")
    section: dict[str, Any] = {
        "counts": list(counts),
        "cartpole_vectorization_mode": cartpole_vectorization_mode(),
        "env_steps": bench_env_steps(bench, counts, env_kwargs),
        "ppo": None,
        "ppo_note": None,
    }
    if available("stable_baselines3", "torch"):
        section["ppo"] = bench_ppo_against_cartpole(
            bench, ppo_envs, ppo_steps, env_kwargs, ppo_overrides, ppo_rounds
        )
    else:
        section["ppo_note"] = "PPO not measured: needs the train extra (stable-baselines3)"
        log(f"  {section['ppo_note']}")
    return section
