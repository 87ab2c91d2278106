"""Env, vector env and PPO throughput of BearingSLAM-v0 against CartPole-v1, in one run.

    python benchmarks/bench_env.py [--seconds 2] [--sections single,vector,ppo] [--quick]
    bearing-env bench [...]                      # the same
    bearing-env bench --profile single           # cProfile of the single-env loop
    bearing-env bench --slam [--seconds 2]       # the world-model benchmark (bench_slam.py)

Absolute rates drift on shared machines, so every figure is also given as a ratio to
Gymnasium's CartPole-v1 ``env.step`` rate (``gym.make("CartPole-v1")`` with its default
wrappers, :func:`bearing_env.benchmarks.bench_slam.cartpole_steps_per_second`). The reference is
measured at the start, again before each section (before each PPO variant), and at the
end; each figure is divided by the reference measured closest to it in time, and also by
the start reference.

Sections:

- ``single``: one env, ``gym.make("BearingSLAM-v0", ...).unwrapped``, actions from a
  seeded generator, ``reset()`` at the end of each episode (resets count in the time, not
  as steps). The Khepera scenario, and the random scenario with 4, 16 and 64 landmarks
  (``max_landmarks = n``). One more row steps the Khepera env through ``gym.make``'s
  wrappers, as a user (or SB3's DummyVecEnv) does.
- ``vector``: ``gym.make_vec`` with ``vectorization_mode="vector_entry_point"`` (the
  batched ``BearingSLAMVectorEnv``) and with ``"sync"`` (a SyncVectorEnv of single envs,
  the baseline) for each ``--num-envs``. Rates are env transitions per second summed over
  the sub-envs; in NEXT_STEP autoreset mode the reset-only sub-steps that follow an
  episode's end count in the time but not as transitions.
- ``slam``: ``PolygonSLAM.update`` alone (:mod:`bearing_env.benchmarks.bench_slam`'s readings), both
  transfers, 4 and 64 landmarks.
- ``startup``: the compiled core's start-up, in fresh processes: compiling from an empty
  numba cache (a new ``NUMBA_CACHE_DIR``), then, with that cache warm, the time from the
  interpreter's start to the end of the first ``env.step`` (imports included), the
  median of three processes. These are seconds, not ratios.
- ``planning``: ``agents.GreedyOneStep``'s planning time per move (its ``act()``, which
  scores 16 candidate moves on copies of the map), Khepera scenario, the median over the
  moves of several episodes. Seconds, not a ratio.
- ``ppo``: SB3 ``PPO`` with the shipped ``ppo.yml``'s settings for BearingSLAM-v0
  (VecNormalize included) on ``--ppo-envs`` envs built by
  ``bearing_env.train.training_envs.make_training_env``
  for each vec env kind (batched, subproc with spawn, dummy). The rate is env steps per
  second of wall time of ``model.learn()``, measured after a warm-up ``learn()`` of one
  rollout, so process start-up and torch initialisation are excluded. PPO always finishes
  the rollout it starts, so ``--ppo-steps`` is rounded up to whole rollouts. All kinds
  are built first, then timed in ``--ppo-rounds`` interleaved rounds (each round times
  every kind once, in turn): a kind's rate is its median round and its ratio to
  SubprocVecEnv the median of the per-round ratios, so that a machine whose speed drifts
  during the run favours no kind.

When the batched pieces are missing (no ``vector_entry_point`` on the spec, or no
``"batched"`` in ``bearing_env.train.training_envs.VEC_ENV_KINDS``), the rows fall back
to ``sync`` and ``dummy`` and are labelled as fallbacks; the targets that depend on them say so.

Targets (printed as met / not met and stored in the JSON):

a. single env, Khepera scenario: >= 10% of CartPole-v1's step rate;
b. batched env, 64 sub-envs (Khepera, 4 landmarks): total env steps/s >= 30% of
   CartPole-v1's single-env step rate (the long-term goal is 100%);
c. 64 landmarks at >= 1/16 of the 4-landmark single-env rate;
d. PPO on the batched env >= 2x the env steps/s of PPO on SubprocVecEnv, same n_envs;
e. ``PolygonSLAM.update``, 4 landmarks, conservative: >= 20% of CartPole-v1's step rate;
f. first env step in a fresh process with a warm numba cache: <= 1.5 s;
g. ``GreedyOneStep`` plans a move in <= 0.2 ms (median).
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import datetime as _dt
import json
import math
import os
import platform
import pstats
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from bearing_env.benchmarks.bench_slam import cartpole_steps_per_second
from bearing_env.train.cli_values import json_safe, parse_key_values
from gymnasium.vector import AutoresetMode

import bearing_env

ENV_ID = "BearingSLAM-v0"
SECTIONS: tuple[str, ...] = ("single", "vector", "slam", "startup", "planning", "ppo")
PPO_KINDS: tuple[str, ...] = ("batched", "subproc", "dummy")
DEFAULT_NUM_ENVS: tuple[int, ...] = (1, 4, 16, 64, 256)
DEFAULT_SINGLE_LANDMARKS: tuple[int, ...] = (4, 16, 64)
#: Relative to the working directory, so an installed package never writes into itself.
DEFAULT_JSON = Path("outputs") / "bench_env.json"
DEFAULT_SECONDS = 2.0
DEFAULT_PPO_ENVS = 16
DEFAULT_PPO_STEPS = 4096
#: Interleaved timed rounds per PPO kind (see :func:`bench_ppo`).
DEFAULT_PPO_ROUNDS = 3
JSON_FORMAT = 1

#: Hyperparameter overrides of the ``--quick`` PPO runs: tiny rollouts, one epoch, and
#: (set where the number of envs is known) one minibatch of the whole rollout.
QUICK_PPO_OVERRIDES: dict[str, Any] = {"n_steps": 8, "n_epochs": 1}

TARGETS: dict[str, str] = {
    "a": "single env, Khepera: env.step >= 10% of CartPole-v1",
    "b": "batched env, 64 envs x 4 landmarks: total steps/s >= 30% of CartPole-v1",
    "c": "single env, 64 landmarks >= 1/16 of the 4-landmark rate",
    "d": "PPO on the batched env >= 2x PPO on SubprocVecEnv (same n_envs)",
    "e": "PolygonSLAM.update, 4 landmarks: >= 20% of CartPole-v1",
    "f": "first env step, fresh process, warm cache: <= 1.5 s",
    "g": "GreedyOneStep planning per move (median): <= 0.2 ms",
}
TARGET_THRESHOLDS: dict[str, float] = {
    "a": 0.10,
    "b": 0.30,
    "c": 1.0 / 16.0,
    "d": 2.0,
    "e": 0.20,
    "f": 1.5,
    "g": 0.2e-3,
}
#: Targets that are upper bounds (seconds); the others are lower bounds (ratios).
UPPER_BOUND_TARGETS = frozenset({"f", "g"})
#: Episodes of the planning section (Khepera, 20 moves each; --quick: 2).
PLANNING_EPISODES = 20
#: Fresh processes timed with a warm cache (the median counts).
STARTUP_WARM_RUNS = 3


def log(message: str) -> None:
    """Progress lines go to stderr, so stdout holds only the table."""
    print(message, file=sys.stderr, flush=True)


# --------------------------------------------------------------------------------------
# The CartPole reference
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Reference:
    label: str
    steps_per_s: float
    #: Middle of the measurement, seconds since the bench started.
    time_s: float


@dataclass
class Bench:
    """The run's clock, its CartPole references and the reference measurement time."""

    seconds: float
    start: float = field(default_factory=time.perf_counter)
    references: list[Reference] = field(default_factory=list)

    def now(self) -> float:
        return time.perf_counter() - self.start

    def measure_reference(self, label: str) -> Reference:
        begin = self.now()
        rate = cartpole_steps_per_second(self.seconds)
        reference = Reference(label, rate, 0.5 * (begin + self.now()))
        self.references.append(reference)
        log(f"  CartPole-v1 reference ({label}): {rate:,.0f} steps/s")
        return reference

    def nearest(self, time_s: float) -> Reference:
        return min(self.references, key=lambda ref: abs(ref.time_s - time_s))

    def ratios(self, rate: float, time_s: float) -> dict[str, Any]:
        """The ratio fields of a figure measured around ``time_s``."""
        nearest = self.nearest(time_s)
        start = self.references[0]
        return {
            "cartpole_reference": nearest.label,
            "cartpole_steps_per_s": nearest.steps_per_s,
            "ratio_to_cartpole": rate / nearest.steps_per_s,
            "ratio_to_cartpole_start": rate / start.steps_per_s,
        }


def timed_figure(bench: Bench, run: Callable[[], tuple[int, float]]) -> dict[str, Any]:
    """Run ``run() -> (steps, seconds)`` and return its rate with the CartPole ratios."""
    begin = bench.now()
    steps, elapsed = run()
    rate = steps / elapsed
    figure = {"steps": int(steps), "seconds": elapsed, "steps_per_s": rate}
    figure.update(bench.ratios(rate, 0.5 * (begin + bench.now())))
    return figure


# --------------------------------------------------------------------------------------
# Single env
# --------------------------------------------------------------------------------------


def single_env_cases(landmarks: Sequence[int]) -> list[tuple[str, dict[str, Any], bool]]:
    """(name, env kwargs, unwrapped) of the single-env rows."""
    cases = [("khepera", {"scenario": "khepera"}, True)]
    for n in landmarks:
        cases.append(
            (f"random_{n}", {"scenario": "random", "n_landmarks": n, "max_landmarks": n}, True)
        )
    cases.append(("khepera_wrapped", {"scenario": "khepera"}, False))
    return cases


def make_single_env(env_kwargs: dict[str, Any], unwrapped: bool = True) -> gym.Env[Any, Any]:
    env = gym.make(ENV_ID, **env_kwargs)
    return env.unwrapped if unwrapped else env


def run_single_env(
    env: gym.Env[Any, Any], seconds: float, seed: int = 0, min_steps: int = 2
) -> tuple[int, float, int]:
    """Step ``env`` with seeded random actions for ``seconds``: (steps, seconds, resets)."""
    rng = np.random.default_rng(seed)
    low = env.action_space.low
    high = env.action_space.high
    env.reset(seed=seed)
    env.step(rng.uniform(low, high).astype(np.float32))  # warm-up, not timed
    env.reset(seed=seed)
    steps = resets = 0
    block = rng.uniform(low, high, size=(256, *low.shape)).astype(np.float32)
    start = time.perf_counter()
    while True:
        action = block[steps % len(block)]
        _, _, terminated, truncated, _ = env.step(action)
        steps += 1
        if terminated or truncated:
            env.reset()
            resets += 1
        if steps % len(block) == 0:
            block = rng.uniform(low, high, size=block.shape).astype(np.float32)
        if steps >= min_steps and time.perf_counter() - start >= seconds:
            break
    return steps, time.perf_counter() - start, resets


def bench_single(bench: Bench, landmarks: Sequence[int]) -> list[dict[str, Any]]:
    bench.measure_reference("single")
    rows: list[dict[str, Any]] = []
    for name, env_kwargs, unwrapped in single_env_cases(landmarks):
        env = make_single_env(env_kwargs, unwrapped)
        resets = 0

        def run(env: gym.Env[Any, Any] = env) -> tuple[int, float]:
            nonlocal resets
            steps, elapsed, resets = run_single_env(env, bench.seconds)
            return steps, elapsed

        figure = timed_figure(bench, run)
        n_landmarks = int(env.unwrapped.n_landmarks)  # type: ignore[attr-defined]
        env.close()
        row = {
            "name": name,
            "env_kwargs": env_kwargs,
            "unwrapped": unwrapped,
            "n_landmarks": n_landmarks,
            "resets": resets,
            **figure,
        }
        rows.append(row)
        log(f"  single {name:<16} {row['steps_per_s']:10,.0f} steps/s")
    base = next((row for row in rows if row["name"] == "random_4"), None)
    for row in rows:
        row["ratio_to_4_landmarks"] = (
            row["steps_per_s"] / base["steps_per_s"]
            if base is not None and row["name"].startswith("random_")
            else None
        )
    return rows


# --------------------------------------------------------------------------------------
# The world model alone, and the compiled core's start-up
# --------------------------------------------------------------------------------------


def bench_slam_updates(bench: Bench) -> list[dict[str, Any]]:
    from bearing_env.benchmarks.bench_slam import updates_per_second

    bench.measure_reference("slam")
    rows: list[dict[str, Any]] = []
    for transfer in ("conservative", "paper"):
        for n_landmarks in (4, 64):
            begin = bench.now()
            rate = updates_per_second(n_landmarks, transfer, bench.seconds)
            row = {"transfer": transfer, "n_landmarks": n_landmarks, "steps_per_s": rate}
            row.update(bench.ratios(rate, 0.5 * (begin + bench.now())))
            rows.append(row)
            log(f"  update() {transfer:>12} {n_landmarks:3d} landmarks {rate:10,.0f} /s")
    return rows


#: Run in a fresh interpreter: seconds from its start to the end of the first env step.
FIRST_STEP_SCRIPT = """
import time
start = time.perf_counter()
import gymnasium as gym
import bearing_env  # noqa: F401
env = gym.make("BearingSLAM-v0", scenario="khepera")
env.reset(seed=0)
env.step(env.action_space.sample())
print(time.perf_counter() - start)
"""


def first_step_seconds(cache_dir: str) -> float:
    environment = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    done = subprocess.run(
        [sys.executable, "-c", FIRST_STEP_SCRIPT],
        capture_output=True,
        text=True,
        env=environment,
        check=True,
        timeout=900,
    )
    return float(done.stdout.strip().splitlines()[-1])


def bench_startup() -> dict[str, Any]:
    """Compile from an empty cache once, then time fresh processes with it warm."""
    with tempfile.TemporaryDirectory(prefix="bearing-env-numba-") as cache_dir:
        log("  compiling from an empty numba cache (a fresh process) ...")
        cold = first_step_seconds(cache_dir)
        warm = [first_step_seconds(cache_dir) for _ in range(STARTUP_WARM_RUNS)]
    log(f"  first step: {cold:.2f} s with an empty cache, {np.median(warm):.2f} s warm")
    return {
        "cold_first_step_s": cold,
        "warm_first_step_s": float(np.median(warm)),
        "warm_runs_s": warm,
    }


def bench_planning(episodes: int) -> dict[str, Any]:
    """GreedyOneStep's act() time per move, Khepera, seeded episodes."""
    from bearing_env.agents import GreedyOneStep

    env = gym.make(ENV_ID, scenario="khepera")
    policy = GreedyOneStep(env)
    times: list[float] = []
    for episode in range(episodes + 1):  # the first episode warms up, untimed
        observation, info = env.reset(seed=episode)
        policy.reset(seed=episode)
        done = False
        while not done:
            start = time.perf_counter()
            action = policy.act(observation, info)
            if episode:
                times.append(time.perf_counter() - start)
            observation, _, terminated, truncated, info = env.step(action)
            done = terminated or truncated
    env.close()
    median = float(np.median(times))
    log(f"  GreedyOneStep: {median * 1e3:.3f} ms per move (median of {len(times)})")
    return {
        "moves": len(times),
        "median_s": median,
        "mean_s": float(np.mean(times)),
        "p90_s": float(np.percentile(times, 90)),
    }


# --------------------------------------------------------------------------------------
# Vector env
# --------------------------------------------------------------------------------------


def has_vector_entry_point(env_id: str = ENV_ID) -> bool:
    return gym.spec(env_id).vector_entry_point is not None


def make_vector_env(num_envs: int, mode: str, env_kwargs: dict[str, Any]) -> gym.vector.VectorEnv:
    return gym.make_vec(ENV_ID, num_envs=num_envs, vectorization_mode=mode, **env_kwargs)


def autoreset_mode(venv: gym.vector.VectorEnv) -> AutoresetMode:
    """The vector env's autoreset mode (Gymnasium's default, NEXT_STEP, if it declares none)."""
    mode = venv.metadata.get("autoreset_mode", AutoresetMode.NEXT_STEP)
    return mode if isinstance(mode, AutoresetMode) else AutoresetMode(mode)


def run_vector_env(
    venv: gym.vector.VectorEnv, seconds: float, seed: int = 0, min_calls: int = 2
) -> tuple[int, float, int]:
    """Step ``venv`` with seeded random actions: (env transitions, seconds, step() calls).

    In NEXT_STEP autoreset mode, a sub-env whose episode ended resets on the next call
    and ignores its action; those sub-steps are not counted as transitions. With autoreset
    disabled, ended sub-envs are reset through ``reset(options={"reset_mask": ...})``."""
    rng = np.random.default_rng(seed)
    num_envs = venv.num_envs
    space = getattr(venv, "single_action_space", None)
    if space is not None:
        low, high = space.low, space.high
    else:
        low, high = venv.action_space.low[0], venv.action_space.high[0]
    shape = (num_envs, *low.shape)
    mode = autoreset_mode(venv)
    venv.reset(seed=seed)
    venv.step(rng.uniform(low, high, size=shape).astype(np.float32))  # warm-up, not timed
    venv.reset(seed=seed)
    pending = np.zeros(num_envs, dtype=bool)  # sub-envs whose next call is a reset
    transitions = calls = 0
    start = time.perf_counter()
    while True:
        actions = rng.uniform(low, high, size=shape).astype(np.float32)
        _, _, terminated, truncated, _ = venv.step(actions)
        calls += 1
        done = np.logical_or(terminated, truncated)
        if mode == AutoresetMode.NEXT_STEP:
            transitions += num_envs - int(pending.sum())
            pending = done
        else:
            transitions += num_envs
            if mode == AutoresetMode.DISABLED and done.any():
                venv.reset(options={"reset_mask": done})
        if calls >= min_calls and time.perf_counter() - start >= seconds:
            break
    return transitions, time.perf_counter() - start, calls


def bench_vector(
    bench: Bench, num_envs_list: Sequence[int], env_kwargs: dict[str, Any]
) -> list[dict[str, Any]]:
    bench.measure_reference("vector")
    batched_mode = "vector_entry_point" if has_vector_entry_point() else "sync"
    fallback = batched_mode != "vector_entry_point"
    if fallback:
        log(f"  {ENV_ID} has no vector_entry_point: the batched rows use sync (fallback)")
    rows: list[dict[str, Any]] = []
    for kind, mode in (("batched", batched_mode), ("sync", "sync")):
        for num_envs in num_envs_list:
            build_start = time.perf_counter()
            venv = make_vector_env(num_envs, mode, env_kwargs)
            build_seconds = time.perf_counter() - build_start
            calls = 0

            def run(venv: gym.vector.VectorEnv = venv) -> tuple[int, float]:
                nonlocal calls
                steps, elapsed, calls = run_vector_env(venv, bench.seconds)
                return steps, elapsed

            figure = timed_figure(bench, run)
            venv.close()
            row = {
                "kind": kind,
                "vectorization_mode": mode,
                "fallback": kind == "batched" and fallback,
                "num_envs": num_envs,
                "env_kwargs": env_kwargs,
                "step_calls": calls,
                "autoreset_mode": autoreset_mode(venv).value,
                "build_seconds": build_seconds,
                **figure,
            }
            rows.append(row)
            label = vector_label(row)
            log(f"  vector {label:<24} {num_envs:4d} envs {row['steps_per_s']:10,.0f} steps/s")
    sync_rates = {row["num_envs"]: row["steps_per_s"] for row in rows if row["kind"] == "sync"}
    for row in rows:
        row["ratio_to_sync"] = (
            row["steps_per_s"] / sync_rates[row["num_envs"]] if row["kind"] == "batched" else None
        )
    return rows


def vector_label(row: dict[str, Any]) -> str:
    if row["kind"] == "sync":
        return "sync (baseline)"
    return "sync (fallback)" if row["fallback"] else "batched"


# --------------------------------------------------------------------------------------
# PPO
# --------------------------------------------------------------------------------------


def available_vec_env_kinds() -> tuple[str, ...]:
    from bearing_env.train.training_envs import VEC_ENV_KINDS

    return tuple(VEC_ENV_KINDS)


def ppo_settings(
    env_kwargs: dict[str, Any], overrides: dict[str, Any]
) -> tuple[dict[str, Any], dict[str, Any] | None, dict[str, Any]]:
    """(PPO constructor kwargs, VecNormalize kwargs or None, env kwargs) from ppo.yml."""
    from bearing_env.train.zoo import parse_hyperparameters, read_hyperparameters

    raw = read_hyperparameters("ppo", ENV_ID)
    raw.update(overrides)
    raw["env_kwargs"] = {**(raw.get("env_kwargs") or {}), **env_kwargs}
    hyperparams = parse_hyperparameters(raw, "ppo")
    return dict(hyperparams.algorithm_kwargs), hyperparams.normalize, hyperparams.env_kwargs


@contextlib.contextmanager
def torch_threads(n: int) -> Iterator[None]:
    import torch

    previous = torch.get_num_threads()
    torch.set_num_threads(n)
    try:
        yield
    finally:
        torch.set_num_threads(previous)


@dataclass
class PPORun:
    """One vec env kind's PPO model, built and warmed up, ready for timed rounds."""

    kind: str
    measured_with: str
    model: Any
    venv: Any
    n_envs: int
    total_steps: int
    algorithm_kwargs: dict[str, Any]
    normalize: dict[str, Any] | None
    make_kwargs: dict[str, Any]
    build_seconds: float
    rounds: list[dict[str, Any]] = field(default_factory=list)

    def timed_round(self, bench: Bench) -> dict[str, Any]:
        before = int(self.model.num_timesteps)

        def run() -> tuple[int, float]:
            start = time.perf_counter()
            self.model.learn(total_timesteps=self.total_steps, reset_num_timesteps=False)
            return int(self.model.num_timesteps) - before, time.perf_counter() - start

        figure = timed_figure(bench, run)
        self.rounds.append(figure)
        return figure

    def close(self) -> None:
        with contextlib.suppress(EOFError, BrokenPipeError, ConnectionError, OSError):
            self.venv.close()

    def row(self, bench: Bench) -> dict[str, Any]:
        """The kind's figure: the median round (rates drift on a shared machine)."""
        rates = [figure["steps_per_s"] for figure in self.rounds]
        middle = self.rounds[len(self.rounds) // 2]
        rate = float(np.median(rates))
        return {
            "kind": self.kind,
            "measured_with": self.measured_with,
            "fallback": self.measured_with != self.kind,
            "n_envs": self.n_envs,
            "rollout_steps": int(self.algorithm_kwargs.get("n_steps", 2048)) * self.n_envs,
            "requested_steps": self.total_steps,
            "normalize": self.normalize is not None,
            "hyperparams": json_safe(self.algorithm_kwargs),
            "env_kwargs": self.make_kwargs,
            "setup_and_warmup_seconds": self.build_seconds,
            "steps": int(sum(figure["steps"] for figure in self.rounds)),
            "seconds": float(sum(figure["seconds"] for figure in self.rounds)),
            "steps_per_s": rate,
            "cartpole_reference": middle["cartpole_reference"],
            "cartpole_steps_per_s": middle["cartpole_steps_per_s"],
            "ratio_to_cartpole": float(
                np.median([figure["ratio_to_cartpole"] for figure in self.rounds])
            ),
            "ratio_to_cartpole_start": rate / bench.references[0].steps_per_s,
            "rounds": self.rounds,
        }


def build_ppo_run(
    bench: Bench,
    kind: str,
    n_envs: int,
    total_steps: int,
    env_kwargs: dict[str, Any],
    overrides: dict[str, Any],
) -> PPORun:
    """Build PPO on one vec env kind and warm it up (one rollout and one update)."""
    from bearing_env.train.training_envs import make_training_env
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    available = available_vec_env_kinds()
    measured_with = kind if kind in available else "dummy"
    algorithm_kwargs, normalize, make_kwargs = ppo_settings(env_kwargs, overrides)
    build_start = time.perf_counter()
    venv = make_training_env(ENV_ID, make_kwargs, n_envs, measured_with, None)
    try:
        if normalize is not None:
            venv = VecNormalize(venv, **normalize)
        model = PPO(env=venv, seed=0, device="cpu", verbose=0, **algorithm_kwargs)
        model.learn(total_timesteps=1)  # warm-up, not timed
    except BaseException:
        with contextlib.suppress(EOFError, BrokenPipeError, ConnectionError, OSError):
            venv.close()
        raise
    run = PPORun(
        kind,
        measured_with,
        model,
        venv,
        n_envs,
        total_steps,
        algorithm_kwargs,
        normalize,
        make_kwargs,
        time.perf_counter() - build_start,
    )
    bench.measure_reference(f"ppo/{kind}")
    return run


def bench_ppo(
    bench: Bench,
    kinds: Sequence[str],
    n_envs: int,
    total_steps: int,
    env_kwargs: dict[str, Any],
    overrides: dict[str, Any],
    rounds: int = DEFAULT_PPO_ROUNDS,
) -> list[dict[str, Any]]:
    """PPO throughput per vec env kind, in interleaved rounds.

    Every kind is built and warmed up first; then each round times every kind once, in
    turn, so that a drifting machine speed affects all kinds alike. A kind's rate is its
    median round, and its ratio to SubprocVecEnv is the median of the per-round ratios.
    """
    if "batched" in kinds and "batched" not in available_vec_env_kinds():
        log(
            "  bearing_env.train.training_envs.VEC_ENV_KINDS has no 'batched':"
            " that row uses dummy (fallback)"
        )
    runs: list[PPORun] = []
    try:
        with torch_threads(1):  # as bearing-env train (--torch-threads 1)
            for kind in kinds:
                log(f"  ppo {kind}: building {n_envs} envs and warming up ...")
                runs.append(build_ppo_run(bench, kind, n_envs, total_steps, env_kwargs, overrides))
            for number in range(1, rounds + 1):
                if number > 1:
                    bench.measure_reference(f"ppo/round {number}")
                for run in runs:
                    figure = run.timed_round(bench)
                    log(
                        f"  ppo {run.kind:<8} round {number}/{rounds}: "
                        f"{figure['steps_per_s']:10,.0f} env steps/s"
                    )
        rows = [run.row(bench) for run in runs]
    finally:
        for run in runs:
            run.close()
    subproc = next((run for run in runs if run.kind == "subproc"), None)
    for run, row in zip(runs, rows, strict=True):
        row["ratio_to_subproc"] = (
            float(
                np.median(
                    [
                        mine["steps_per_s"] / theirs["steps_per_s"]
                        for mine, theirs in zip(run.rounds, subproc.rounds, strict=True)
                    ]
                )
            )
            if subproc is not None
            else None
        )
        log(f"  ppo {ppo_label(row):<24} {row['steps_per_s']:10,.0f} env steps/s (median)")
    return rows


def ppo_label(row: dict[str, Any]) -> str:
    if row["fallback"]:
        return f"{row['measured_with']} (fallback for {row['kind']})"
    return row["kind"] + (" (spawn)" if row["kind"] == "subproc" else "")


# --------------------------------------------------------------------------------------
# Targets
# --------------------------------------------------------------------------------------


def _target(
    key: str, value: float | None, note: str | None = None, fallback: bool = False
) -> dict[str, Any]:
    threshold = TARGET_THRESHOLDS[key]
    if value is None:
        met = None
    elif key in UPPER_BOUND_TARGETS:
        met = bool(value <= threshold)
    else:
        met = bool(value >= threshold)
    return {
        "id": key,
        "description": TARGETS[key],
        "value": value,
        "threshold": threshold,
        "met": met,
        "fallback": fallback,
        "note": note,
    }


def evaluate_targets(results: dict[str, Any]) -> list[dict[str, Any]]:
    single = {row["name"]: row for row in results.get("single", [])}
    vector = results.get("vector", [])
    ppo = {row["kind"]: row for row in results.get("ppo", [])}
    targets = []

    khepera = single.get("khepera")
    if khepera is None:
        targets.append(_target("a", None, "needs the single-env Khepera row"))
    else:
        targets.append(_target("a", khepera["ratio_to_cartpole"]))

    batched_64 = next(
        (row for row in vector if row["kind"] == "batched" and row["num_envs"] == 64), None
    )
    if batched_64 is None:
        targets.append(_target("b", None, "no batched row with 64 envs measured"))
    else:
        fallback = batched_64["fallback"]
        note = "measured with sync (fallback): no vector_entry_point" if fallback else None
        targets.append(
            _target("b", batched_64["ratio_to_cartpole"], note, fallback=batched_64["fallback"])
        )

    many = single.get("random_64")
    few = single.get("random_4")
    if many is None or few is None:
        targets.append(_target("c", None, "needs the 4- and 64-landmark single-env rows"))
    else:
        targets.append(_target("c", many["steps_per_s"] / few["steps_per_s"]))

    slam = {(row["transfer"], row["n_landmarks"]): row for row in results.get("slam", [])}
    update_4 = slam.get(("conservative", 4))
    if update_4 is None:
        targets.append(_target("e", None, "needs the slam section's 4-landmark row"))
    else:
        targets.append(_target("e", update_4["ratio_to_cartpole"]))
    startup = results.get("startup")
    if startup is None:
        targets.append(_target("f", None, "needs the startup section"))
    else:
        targets.append(_target("f", startup["warm_first_step_s"]))

    planning = results.get("planning")
    if planning is None:
        targets.append(_target("g", None, "needs the planning section"))
    else:
        targets.append(_target("g", planning["median_s"]))

    batched, subproc = ppo.get("batched"), ppo.get("subproc")
    if batched is None or subproc is None:
        targets.append(_target("d", None, "needs the batched and subproc PPO rows"))
    else:
        note = "batched measured with dummy (fallback)" if batched["fallback"] else None
        targets.append(
            _target(
                "d",
                # The median of the per-round ratios (rounds are interleaved), as in the table.
                batched.get("ratio_to_subproc") or batched["steps_per_s"] / subproc["steps_per_s"],
                note,
                fallback=batched["fallback"],
            )
        )
    return targets


# --------------------------------------------------------------------------------------
# Output
# --------------------------------------------------------------------------------------


def machine_info() -> dict[str, Any]:
    info: dict[str, Any] = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "python": sys.version.split()[0],
        "cpu_count": os.cpu_count(),
        "numpy": np.__version__,
        "gymnasium": gym.__version__,
        "bearing_env": bearing_env.__version__,
    }
    with contextlib.suppress(AttributeError):
        info["usable_cpus"] = len(os.sched_getaffinity(0))
    for module in ("torch", "stable_baselines3"):
        if module in sys.modules:
            info[module] = getattr(sys.modules[module], "__version__", None)
    return info


def _finite(value: Any) -> Any:
    """JSON without NaN/inf: non-finite floats become null."""
    if isinstance(value, dict):
        return {str(key): _finite(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(item) for item in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, np.generic):
        return _finite(value.item())
    return value


def write_json(path: Path, results: dict[str, Any]) -> None:
    """Write ``results`` to ``path`` atomically (temp file in the same folder + os.replace)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(_finite(results), indent=2, allow_nan=False) + "\n"
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(handle, "w") as fh:
            fh.write(text)
        os.replace(temporary, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary)
        raise


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{value:.2%}"


def _times(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}x"


def table_rows(results: dict[str, Any]) -> list[tuple[str, ...]]:
    """(section, case, steps/s, % nearest ref, ref, % start ref, relative) rows."""
    rows: list[tuple[str, ...]] = []

    def add(section: str, case: str, figure: dict[str, Any], relative: str) -> None:
        rows.append(
            (
                section,
                case,
                f"{figure['steps_per_s']:,.0f}",
                _pct(figure["ratio_to_cartpole"]),
                figure["cartpole_reference"],
                _pct(figure["ratio_to_cartpole_start"]),
                relative,
            )
        )

    for row in results.get("single", []):
        if row["name"] == "khepera":
            case = "khepera, 4 landmarks"
        elif row["name"] == "khepera_wrapped":
            case = "khepera, gym.make wrappers"
        else:
            case = f"random, {row['n_landmarks']} landmarks"
        relative = (
            f"{_times(row['ratio_to_4_landmarks'])} 4-landmark rate"
            if row["ratio_to_4_landmarks"] is not None
            else ""
        )
        add("single", case, row, relative)
    for row in results.get("vector", []):
        case = f"{vector_label(row)}, {row['num_envs']} envs"
        relative = (
            f"{_times(row['ratio_to_sync'])} sync" if row["ratio_to_sync"] is not None else ""
        )
        add("vector", case, row, relative)
    slam_rows = results.get("slam", [])
    for row in slam_rows:
        base = next(
            other["steps_per_s"]
            for other in slam_rows
            if other["transfer"] == row["transfer"] and other["n_landmarks"] == 4
        )
        case = f"update(), {row['transfer']}, {row['n_landmarks']} landmarks"
        add("slam", case, row, f"{_times(row['steps_per_s'] / base)} 4-landmark rate")
    for row in results.get("ppo", []):
        case = f"PPO {ppo_label(row)}, {row['n_envs']} envs"
        relative = (
            f"{_times(row['ratio_to_subproc'])} subproc"
            if row["ratio_to_subproc"] is not None
            else ""
        )
        add("ppo", case, row, relative)
    return rows


TABLE_HEADER: tuple[str, ...] = (
    "section",
    "case",
    "steps/s",
    "% CartPole",
    "(ref)",
    "% CartPole@start",
    "relative",
)
NUMERIC_COLUMNS = frozenset({2, 3, 5})


def references_line(results: dict[str, Any]) -> str:
    references = ", ".join(
        f"{ref['label']} {ref['steps_per_s']:,.0f}" for ref in results["cartpole_references"]
    )
    return f"CartPole-v1 env.step references (steps/s, same run): {references}"


def column_widths(rows: Sequence[Sequence[str]]) -> list[int]:
    return [max(len(text) for text in column) for column in zip(*rows, strict=True)]


def table_notes(results: dict[str, Any]) -> list[str]:
    """The targets and what the columns mean, printed under the table."""
    lines = []
    startup = results.get("startup")
    if startup is not None:
        warm = ", ".join(f"{t:.2f}" for t in startup["warm_runs_s"])
        lines += [
            "",
            f"Start-up (fresh processes): first env step {startup['cold_first_step_s']:.1f} s "
            f"compiling from an empty numba cache; {startup['warm_first_step_s']:.2f} s with "
            f"the cache warm (median of {warm} s).",
        ]
    planning = results.get("planning")
    if planning is not None:
        lines += [
            "",
            f"Planning: GreedyOneStep.act {planning['median_s'] * 1e3:.3f} ms per move "
            f"(median of {planning['moves']} moves; mean {planning['mean_s'] * 1e3:.3f} ms, "
            f"p90 {planning['p90_s'] * 1e3:.3f} ms).",
        ]
    lines += ["", "Targets:"]
    lines.extend("  " + format_target(target) for target in results["targets"])
    lines.append("")
    lines.append(
        f"{results['settings']['seconds']:g} s per measurement; % CartPole uses the reference "
        "measured closest in time ((ref)), % CartPole@start the first one."
    )
    if "ppo" in results:
        lines.append(
            "PPO: env steps per wall-second of model.learn() after a warm-up learn() "
            "(process start-up and torch init excluded); the median of "
            f"{results['settings'].get('ppo_rounds', 1)} interleaved rounds per kind."
        )
    return lines


def format_table(results: dict[str, Any]) -> str:
    """The results as a plain-text table, the CartPole references and the targets."""
    rows = table_rows(results)
    widths = column_widths([TABLE_HEADER, *rows])

    def line(cells: Sequence[str]) -> str:
        return "  ".join(
            cell.rjust(width) if index in NUMERIC_COLUMNS else cell.ljust(width)
            for index, (cell, width) in enumerate(zip(cells, widths, strict=True))
        ).rstrip()

    lines = [references_line(results), line(TABLE_HEADER), line(["-" * w for w in widths])]
    previous = None
    for row in rows:
        if previous is not None and row[0] != previous:
            lines.append("")
        lines.append(line(row))
        previous = row[0]
    return "\n".join([*lines, *table_notes(results)])


def format_target(target: dict[str, Any]) -> str:
    if target["met"] is None:
        status = "NOT MEASURED"
    else:
        status = "MET" if target["met"] else "NOT MET"
    value = target["value"]
    if value is None:
        shown = "-"
    elif target["id"] in ("a", "b", "e"):
        shown = f"{value:.2%} (need {target['threshold']:.0%})"
    elif target["id"] == "c":
        shown = f"{value:.3f} (need {target['threshold']:.4f})"
    elif target["id"] == "f":
        shown = f"{value:.2f} s (need <= {target['threshold']:g} s)"
    elif target["id"] == "g":
        shown = f"{value * 1e3:.3f} ms (need <= {target['threshold'] * 1e3:g} ms)"
    else:
        shown = f"{value:.2f}x (need {target['threshold']:.0f}x)"
    note = f"  [{target['note']}]" if target["note"] else ""
    return f"({target['id']}) {target['description']}: {shown} -> {status}{note}"


def print_table(results: dict[str, Any]) -> None:
    """A rich table when stdout is a terminal wide enough for it, else plain text."""
    rows = table_rows(results)
    if sys.stdout.isatty():
        try:
            from rich.console import Console
            from rich.table import Table
        except ImportError:
            pass
        else:
            console = Console()
            needed = sum(column_widths([TABLE_HEADER, *rows])) + 3 * len(TABLE_HEADER) + 1
            if console.width >= needed:
                table = Table(title=references_line(results))
                for index, name in enumerate(TABLE_HEADER):
                    justify = "right" if index in NUMERIC_COLUMNS else "left"
                    table.add_column(name, justify=justify, no_wrap=True)
                for row in rows:
                    table.add_row(*row)
                console.print(table)
                for text in table_notes(results):
                    console.print(text, markup=False, highlight=False)
                return
    print(format_table(results))


# --------------------------------------------------------------------------------------
# Profiling
# --------------------------------------------------------------------------------------


def profile(section: str, seconds: float, num_envs: int, env_kwargs: dict[str, Any]) -> None:
    """cProfile the single-env (Khepera) or vector-env loop; print the top 25 by tottime."""
    if section == "single":
        env: Any = make_single_env({"scenario": "khepera"})
        what = "single env, khepera (unwrapped)"

        def loop() -> None:
            run_single_env(env, seconds)
    else:
        mode = "vector_entry_point" if has_vector_entry_point() else "sync"
        env = make_vector_env(num_envs, mode, env_kwargs)
        what = f"vector env ({mode}), {num_envs} envs, {env_kwargs}"

        def loop() -> None:
            run_vector_env(env, seconds)

    print(f"cProfile: {what}, {seconds:g} s")
    profiler = cProfile.Profile()
    profiler.runcall(loop)
    env.close()
    pstats.Stats(profiler, stream=sys.stdout).sort_stats("tottime").print_stats(25)


# --------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------


def _split_list(values: Sequence[str]) -> list[str]:
    return [item for value in values for item in value.replace(",", " ").split()]


def _int_list(values: Sequence[str], option: str) -> list[int]:
    try:
        numbers = [int(item) for item in _split_list(values)]
    except ValueError as error:
        raise argparse.ArgumentTypeError(f"{option}: {error}") from error
    if not numbers or min(numbers) < 1:
        raise argparse.ArgumentTypeError(f"{option} needs positive integers")
    return numbers


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="bearing-env bench",
        description="BearingSLAM-v0 single-env, vector-env and PPO throughput, each as a ratio "
        "to CartPole-v1 steps/s measured in the same run; printed as a table and written to "
        "JSON. (The world-model update() benchmark: bearing-env bench --slam.)",
    )
    add = parser.add_argument
    add("--seconds", type=float, default=None, help=f"time per measurement ({DEFAULT_SECONDS:g})")
    add("--json", type=Path, default=DEFAULT_JSON, help="output JSON (default %(default)s)")
    add("--no-json", action="store_true", help="do not write the JSON")
    add(
        "--sections",
        nargs="+",
        default=[",".join(SECTIONS)],
        metavar="SECTION",
        help=f"comma/space separated subset of {','.join(SECTIONS)} (default all)",
    )
    add(
        "--num-envs",
        nargs="+",
        default=None,
        metavar="N",
        help="vector env sizes (default " + ",".join(map(str, DEFAULT_NUM_ENVS)) + ")",
    )
    add(
        "--landmarks",
        nargs="+",
        default=None,
        metavar="N",
        help="landmark counts of the single-env random scenario (default 4,16,64)",
    )
    add(
        "--env-kwargs",
        nargs="*",
        default=[],
        metavar="K=V",
        help="env kwargs of the vector and PPO sections (default scenario=khepera)",
    )
    add("--ppo-envs", type=int, default=None, help=f"PPO n_envs (default {DEFAULT_PPO_ENVS})")
    add(
        "--ppo-steps",
        type=int,
        default=None,
        help=f"timed PPO env steps, rounded up to whole rollouts (default {DEFAULT_PPO_STEPS})",
    )
    add(
        "--ppo-rounds",
        type=int,
        default=None,
        help=f"interleaved timed rounds per PPO kind; the median counts "
        f"(default {DEFAULT_PPO_ROUNDS}; --quick 1)",
    )
    add(
        "--ppo-kinds",
        nargs="+",
        default=[",".join(PPO_KINDS)],
        metavar="KIND",
        help=f"subset of {','.join(PPO_KINDS)} (default all)",
    )
    add(
        "--ppo-hyperparams",
        nargs="*",
        default=[],
        metavar="K=V",
        help="override ppo.yml entries (e.g. n_steps=128 batch_size=256)",
    )
    add(
        "--quick",
        action="store_true",
        help="tiny settings for tests: 0.05 s, 1 and 4 envs, PPO on 2 envs, 8-step rollouts",
    )
    add(
        "--profile",
        choices=("single", "vector"),
        help="cProfile that loop for --seconds, print the top 25 functions by tottime, exit",
    )
    add("--profile-num-envs", type=int, default=64, help="vector env size for --profile vector")
    add(
        "--slam",
        action="store_true",
        help="run the world-model benchmark (bench_slam.py) instead, with the other arguments",
    )
    return parser


@dataclass(frozen=True)
class Settings:
    seconds: float
    sections: tuple[str, ...]
    num_envs: tuple[int, ...]
    landmarks: tuple[int, ...]
    env_kwargs: dict[str, Any]
    ppo_envs: int
    ppo_steps: int
    ppo_rounds: int
    ppo_kinds: tuple[str, ...]
    ppo_overrides: dict[str, Any]
    quick: bool
    json_path: Path | None


def settings_from_args(args: argparse.Namespace, parser: argparse.ArgumentParser) -> Settings:
    sections = tuple(_split_list(args.sections))
    unknown = sorted(set(sections) - set(SECTIONS))
    if unknown or not sections:
        parser.error(f"--sections: unknown {unknown}; choose from {','.join(SECTIONS)}")
    kinds = tuple(_split_list(args.ppo_kinds))
    if not kinds or set(kinds) - set(PPO_KINDS):
        parser.error(f"--ppo-kinds: choose from {','.join(PPO_KINDS)}")
    try:
        num_envs = _int_list(args.num_envs, "--num-envs") if args.num_envs else None
        landmarks = _int_list(args.landmarks, "--landmarks") if args.landmarks else None
        env_kwargs = {"scenario": "khepera", **parse_key_values(args.env_kwargs, "--env-kwargs")}
        overrides = parse_key_values(args.ppo_hyperparams, "--ppo-hyperparams")
    except (argparse.ArgumentTypeError, ValueError) as error:
        parser.error(str(error))
    quick = bool(args.quick)
    seconds = args.seconds if args.seconds is not None else (0.05 if quick else DEFAULT_SECONDS)
    if not seconds > 0:
        parser.error("--seconds must be > 0")
    ppo_envs = args.ppo_envs if args.ppo_envs is not None else (2 if quick else DEFAULT_PPO_ENVS)
    ppo_steps = args.ppo_steps
    if ppo_steps is None:
        ppo_steps = 16 if quick else DEFAULT_PPO_STEPS
    ppo_rounds = args.ppo_rounds
    if ppo_rounds is None:
        ppo_rounds = 1 if quick else DEFAULT_PPO_ROUNDS
    if ppo_envs < 1 or ppo_steps < 1 or ppo_rounds < 1:
        parser.error("--ppo-envs, --ppo-steps and --ppo-rounds must be >= 1")
    if quick:
        quick_overrides = {**QUICK_PPO_OVERRIDES}
        quick_overrides["batch_size"] = int(overrides.get("n_steps", 8)) * ppo_envs
        overrides = {**quick_overrides, **overrides}
    return Settings(
        seconds=float(seconds),
        sections=tuple(section for section in SECTIONS if section in sections),
        num_envs=tuple(num_envs or ((1, 4) if quick else DEFAULT_NUM_ENVS)),
        landmarks=tuple(landmarks or DEFAULT_SINGLE_LANDMARKS),
        env_kwargs=env_kwargs,
        ppo_envs=ppo_envs,
        ppo_steps=ppo_steps,
        ppo_rounds=ppo_rounds,
        ppo_kinds=tuple(kind for kind in PPO_KINDS if kind in kinds),
        ppo_overrides=overrides,
        quick=quick,
        json_path=None if args.no_json else args.json,
    )


def run(settings: Settings) -> dict[str, Any]:
    """Run the selected sections; the results dict that is printed and written to JSON."""
    bench = Bench(settings.seconds)
    started = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    log(f"bench_env: sections {','.join(settings.sections)}, {settings.seconds:g} s per figure")
    bench.measure_reference("start")
    results: dict[str, Any] = {}
    if "single" in settings.sections:
        log("[single] one env, random actions, resets included")
        results["single"] = bench_single(bench, settings.landmarks)
    if "vector" in settings.sections:
        log(f"[vector] gym.make_vec, {settings.env_kwargs}, num_envs {settings.num_envs}")
        results["vector"] = bench_vector(bench, settings.num_envs, settings.env_kwargs)
    if "slam" in settings.sections:
        log("[slam] PolygonSLAM.update alone")
        results["slam"] = bench_slam_updates(bench)
    if "startup" in settings.sections:
        log("[startup] fresh processes: compile, then first step with a warm cache")
        results["startup"] = bench_startup()
    if "planning" in settings.sections:
        log("[planning] GreedyOneStep.act on Khepera")
        episodes = 2 if settings.quick else PLANNING_EPISODES
        results["planning"] = bench_planning(episodes)
    if "ppo" in settings.sections:
        log(
            f"[ppo] SB3 PPO on {settings.ppo_envs} envs, {settings.ppo_rounds} interleaved "
            f"rounds of {settings.ppo_steps} timed steps"
        )
        results["ppo"] = bench_ppo(
            bench,
            settings.ppo_kinds,
            settings.ppo_envs,
            settings.ppo_steps,
            settings.env_kwargs,
            settings.ppo_overrides,
            settings.ppo_rounds,
        )
    bench.measure_reference("end")
    return {
        "format": JSON_FORMAT,
        "benchmark": "bench_env",
        "started": started,
        "total_seconds": bench.now(),
        "machine": machine_info(),
        "settings": {
            "seconds": settings.seconds,
            "sections": list(settings.sections),
            "num_envs": list(settings.num_envs),
            "landmarks": list(settings.landmarks),
            "env_kwargs": settings.env_kwargs,
            "ppo_envs": settings.ppo_envs,
            "ppo_steps": settings.ppo_steps,
            "ppo_rounds": settings.ppo_rounds,
            "ppo_kinds": list(settings.ppo_kinds),
            "ppo_overrides": json_safe(settings.ppo_overrides),
            "quick": settings.quick,
            "vector_entry_point": has_vector_entry_point(),
        },
        "cartpole_references": [
            {"label": ref.label, "steps_per_s": ref.steps_per_s, "time_s": ref.time_s}
            for ref in bench.references
        ],
        **results,
        "targets": evaluate_targets(results),
    }


def main(argv: Sequence[str] | None = None) -> dict[str, Any] | None:
    arguments = sys.argv[1:] if argv is None else list(argv)
    if "--slam" in arguments:  # forward to the world-model benchmark, which has its own options
        from bearing_env.benchmarks import bench_slam

        sys.argv = ["bench_slam", *(arg for arg in arguments if arg != "--slam")]
        bench_slam.main()
        return None
    parser = build_parser()
    args = parser.parse_args(arguments)
    settings = settings_from_args(args, parser)
    if args.profile is not None:
        profile(args.profile, settings.seconds, args.profile_num_envs, settings.env_kwargs)
        return None
    results = run(settings)
    print_table(results)
    if settings.json_path is not None:
        write_json(settings.json_path, results)
        print(f"\nJSON: {settings.json_path}")
    return results


if __name__ == "__main__":
    main()
