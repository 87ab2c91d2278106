"""The timing of ``bearing-env bench``: every measured figure of BearingSLAM-v1 (single
env, batched vector env, world model, a fresh process's start-up, planning, PPO training) and the
CartPole-v1 reference each figure is divided by. What each section measures is in
:mod:`bearing_env.benchmarks.bench_env`'s docstring.
"""

from __future__ import annotations

import contextlib
import cProfile
import os
import pstats
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode

from bearing_env.benchmarks.bench_slam import cartpole_steps_per_second
from bearing_env.train.common.cli_values import json_safe

ENV_ID = "BearingSLAM-v1"
SECTIONS: tuple[str, ...] = (
    "single",
    "vector",
    "slam",
    "startup",
    "planning",
    "ppo",
    "throughput",
)
PPO_KINDS: tuple[str, ...] = ("batched", "subproc", "dummy")
DEFAULT_NUM_ENVS: tuple[int, ...] = (1, 4, 16, 64, 256)
DEFAULT_SINGLE_LANDMARKS: tuple[int, ...] = (4, 16, 64)
DEFAULT_SECONDS = 2.0
DEFAULT_PPO_ENVS = 16
DEFAULT_PPO_STEPS = 4096
#: Interleaved timed rounds per PPO kind (see :func:`bench_ppo`).
DEFAULT_PPO_ROUNDS = 3
#: Hyperparameter overrides of the ``--quick`` PPO runs: tiny rollouts, one epoch, and
#: (set where the number of envs is known) one minibatch of the whole rollout.
QUICK_PPO_OVERRIDES: dict[str, Any] = {"n_steps": 8, "n_epochs": 1}
#: Episodes of the planning section (Khepera, 20 moves each; --quick: 2).
PLANNING_EPISODES = 20
#: Timed pairs of fresh processes (bearing_env, CartPole-v1) of the startup section; the
#: medians count.
STARTUP_RUNS = 5
#: The same with --quick.
QUICK_STARTUP_RUNS = 1
#: The env the startup section's fresh processes make and step.
STARTUP_ENV_ID = "BearingSLAM-Khepera-v1"


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


#: The env setting of the rows that measure an env without ``info["robot_map"]``.
NO_ROBOT_MAP: dict[str, Any] = {"robot_map_info": False}
#: The vector section's kinds: (kind, vectorization mode, extra env kwargs).
VECTOR_KINDS: tuple[tuple[str, str, dict[str, Any]], ...] = (
    ("batched", "vector_entry_point", {}),
    ("batched_no_robot_map", "vector_entry_point", NO_ROBOT_MAP),
    ("sync", "sync", {}),
)


def single_env_cases(landmarks: Sequence[int]) -> list[tuple[str, dict[str, Any], bool]]:
    """(name, env kwargs, unwrapped) of the single-env rows."""
    cases: list[tuple[str, dict[str, Any], bool]] = [("khepera", {"scenario": "khepera"}, True)]
    for n in landmarks:
        cases.append(
            (f"random_{n}", {"scenario": "random", "n_landmarks": n, "max_landmarks": n}, True)
        )
    cases.append(("khepera_wrapped", {"scenario": "khepera"}, False))
    cases.append(("khepera_no_robot_map", {"scenario": "khepera", **NO_ROBOT_MAP}, True))
    cases.extend(SENSOR_CASES)
    return cases


#: The rows of the limited sensor: the furnished room with its furniture (obstacles that
#: block moves and sight) and without (the same room, the panoramic camera in an empty
#: arena: the reference of its cost), and the Khepera arena with a 90 degree camera.
SENSOR_CASES: tuple[tuple[str, dict[str, Any], bool], ...] = (
    ("furnished_room", {"scenario": "furnished_room"}, True),
    ("furnished_room_empty", {"scenario": "furnished_room", "obstacles": []}, True),
    ("khepera_camera90", {"scenario": "khepera", "field_of_view_deg": 90}, True),
)


def make_single_env(env_kwargs: dict[str, Any], unwrapped: bool = True) -> gym.Env[Any, Any]:
    env = gym.make(ENV_ID, **env_kwargs)
    return env.unwrapped if unwrapped else env


#: The seeded random actions a single-env row samples ahead of its timed loop, then cycles.
SINGLE_ACTION_BLOCK = 4096


def run_single_env(
    env: gym.Env[Any, Any], seconds: float, seed: int = 0, min_steps: int = 2
) -> tuple[int, float, int]:
    """Step ``env`` with seeded random actions for ``seconds``: (steps, seconds, resets).

    The actions (:data:`SINGLE_ACTION_BLOCK` of them, cycled) are sampled ahead, outside
    the timed loop, which times ``env.step`` and the resets alone."""
    rng = np.random.default_rng(seed)
    box = env.action_space
    assert isinstance(box, gym.spaces.Box), "the bench steps the continuous id"
    low, high = box.low, box.high
    block = rng.uniform(low, high, size=(SINGLE_ACTION_BLOCK, *low.shape)).astype(np.float32)
    env.reset(seed=seed)
    env.step(block[-1])  # warm-up, not timed
    env.reset(seed=seed)
    steps = resets = 0
    start = time.perf_counter()
    while True:
        _, _, terminated, truncated, _ = env.step(block[steps % SINGLE_ACTION_BLOCK])
        steps += 1
        if terminated or truncated:
            env.reset()
            resets += 1
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
            "actions": "sampled ahead",
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
    _step_cost_ratios(rows)
    return rows


def _step_cost_ratios(rows: list[dict[str, Any]]) -> None:
    """``step_cost_ratio``: a limited-sensor row's step time over its panoramic, empty
    reference's (the furnished room without its furniture, or Khepera); None elsewhere."""
    rates = {row["name"]: row["steps_per_s"] for row in rows}
    references = {"furnished_room": "furnished_room_empty", "khepera_camera90": "khepera"}
    for row in rows:
        reference = references.get(row["name"])
        row["step_cost_ratio"] = (
            rates[reference] / row["steps_per_s"] if reference in rates else None
        )


# --------------------------------------------------------------------------------------
# The world model alone, and a fresh process's start-up
# --------------------------------------------------------------------------------------


#: The slam section's synthetic (secondary) rows' landmark counts, and its runs per figure.
SLAM_SYNTHETIC_COUNTS: tuple[int, ...] = (4, 64)
SLAM_RUNS = 5


def bench_slam_updates(bench: Bench) -> list[dict[str, Any]]:
    """``PolygonSLAM.update`` on readings recorded from Khepera-v1 and Random8-v1
    episodes (the primary rows), then on the synthetic readings (secondary), both
    transfers: :func:`bearing_env.benchmarks.bench_slam.measure_updates`, whose runs
    each measure their own CartPole-v1 reference (their median joins the run's
    references as ``slam``)."""
    from bearing_env.benchmarks import bench_slam

    measured = bench_slam.workloads(SLAM_SYNTHETIC_COUNTS)
    bench_slam.warm_up(bench_slam.MEASURED_TRANSFERS, measured)
    begin = bench.now()
    rows, cartpole = bench_slam.measure_updates(
        measured, bench_slam.MEASURED_TRANSFERS, bench.seconds, SLAM_RUNS
    )
    reference = Reference("slam", float(np.median(cartpole)), 0.5 * (begin + bench.now()))
    bench.references.append(reference)
    start = bench.references[0].steps_per_s
    for row in rows:
        row["cartpole_reference"] = "slam"
        row["ratio_to_cartpole_start"] = row["steps_per_s"] / start
        log(
            f"  {bench_slam.row_case(row)}: {row['steps_per_s']:10,.0f} /s "
            f"({row['ratio_to_cartpole']:.1%} of CartPole-v1, median of {row['runs']} runs)"
        )
    return rows


#: The start-up section's scripts, each run whole in a fresh interpreter: imports, an env
#: made, reset and stepped once; each prints whether numba was imported (the core is
#: compiled at build time: nothing compiles, or loads a JIT compiler, at run time).
STARTUP_SCRIPTS: dict[str, str] = {
    "bearing_env": (
        "import gymnasium as gym\n"
        "import bearing_env\n"
        f'env = gym.make("{STARTUP_ENV_ID}")\n'
        "env.reset(seed=0)\n"
        "env.step(env.action_space.sample())\n"
        "import sys\n"
        'print("numba" in sys.modules)\n'
    ),
    "cartpole": (
        "import gymnasium as gym\n"
        'env = gym.make("CartPole-v1")\n'
        "env.reset(seed=0)\n"
        "env.step(env.action_space.sample())\n"
        "import sys\n"
        'print("numba" in sys.modules)\n'
    ),
}


def startup_environment(home: str, cache: str) -> dict[str, str]:
    """The children's environment: ``home`` and ``cache`` as HOME and XDG_CACHE_HOME, and
    no PYTHONDONTWRITEBYTECODE (a sandbox's setting no user has: with it every process
    compiles the project's sources again)."""
    environment = dict(os.environ, HOME=home, XDG_CACHE_HOME=cache)
    environment.pop("PYTHONDONTWRITEBYTECODE", None)
    return environment


def process_seconds(script: str, environment: dict[str, str]) -> tuple[float, bool]:
    """Run ``script`` in a fresh interpreter: (wall seconds from before its start to its
    exit, whether it imported numba)."""
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-c", script],
        capture_output=True,
        text=True,
        env=environment,
        cwd=environment["HOME"],  # not the checkout, whose bearing_env/ would come first
        timeout=900,
    )
    elapsed = time.perf_counter() - start
    lines = done.stdout.strip().splitlines()
    if done.returncode != 0 or not lines or lines[-1] not in ("True", "False"):
        raise RuntimeError(
            f"the start-up script exited with status {done.returncode}: "
            f"{(done.stderr or done.stdout).strip()[-2000:]}"
        )
    return elapsed, lines[-1] == "True"


def bench_startup(runs: int = STARTUP_RUNS) -> dict[str, Any]:
    """Time whole fresh processes (start to exit) that make and step BearingSLAM-Khepera-v1,
    and the same script on CartPole-v1 without bearing_env, alternately, ``runs`` pairs
    after one untimed pair (which writes the bytecode caches; its bearing_env run, from
    empty HOME and XDG_CACHE_HOME folders, is kept as the cold figure)."""
    if runs < 1:
        raise ValueError(f"runs must be >= 1, not {runs}")
    bearing: list[float] = []
    cartpole: list[float] = []
    with tempfile.TemporaryDirectory(prefix="bearing-env-startup-") as folder:
        home, cache = os.path.join(folder, "home"), os.path.join(folder, "cache")
        os.mkdir(home)
        os.mkdir(cache)
        environment = startup_environment(home, cache)
        log(f"  fresh processes: 1 untimed pair, then {runs} pairs, alternately ...")
        cold, numba = process_seconds(STARTUP_SCRIPTS["bearing_env"], environment)
        process_seconds(STARTUP_SCRIPTS["cartpole"], environment)
        for _ in range(runs):
            seconds, imported = process_seconds(STARTUP_SCRIPTS["bearing_env"], environment)
            bearing.append(seconds)
            numba = numba or imported
            seconds, _ = process_seconds(STARTUP_SCRIPTS["cartpole"], environment)
            cartpole.append(seconds)
    bearing_median, cartpole_median = float(np.median(bearing)), float(np.median(cartpole))
    ratio = bearing_median / cartpole_median
    log(
        f"  fresh process: {STARTUP_ENV_ID} {bearing_median:.3f} s, CartPole-v1 "
        f"{cartpole_median:.3f} s (medians): {ratio:.2f}x; first run {cold:.3f} s; "
        f"numba imported: {numba}"
    )
    return {
        "env_id": STARTUP_ENV_ID,
        "runs": runs,
        "bearing_env_runs_s": bearing,
        "cartpole_runs_s": cartpole,
        "bearing_env_median_s": bearing_median,
        "cartpole_median_s": cartpole_median,
        "ratio_to_cartpole": ratio,
        "cold_bearing_env_s": cold,
        "numba_imported": numba,
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
        box = venv.action_space
        assert isinstance(box, gym.spaces.Box), "the bench steps the continuous id"
        low, high = box.low[0], box.high[0]
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
    rows: list[dict[str, Any]] = []
    for kind, mode, extra_kwargs in VECTOR_KINDS:
        for num_envs in num_envs_list:
            kind_kwargs = {**env_kwargs, **extra_kwargs}
            build_start = time.perf_counter()
            venv = make_vector_env(num_envs, mode, kind_kwargs)
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
                "num_envs": num_envs,
                "env_kwargs": kind_kwargs,
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
            row["steps_per_s"] / sync_rates[row["num_envs"]] if row["kind"] != "sync" else None
        )
    return rows


def vector_label(row: dict[str, Any]) -> str:
    labels = {"sync": "sync (baseline)", "batched_no_robot_map": "batched, no robot_map"}
    return labels.get(row["kind"], row["kind"])


# --------------------------------------------------------------------------------------
# PPO
# --------------------------------------------------------------------------------------


def ppo_settings(
    env_kwargs: dict[str, Any], overrides: dict[str, Any]
) -> tuple[dict[str, Any], dict[str, Any] | None, dict[str, Any]]:
    """(PPO constructor kwargs, VecNormalize kwargs or None, env kwargs) from ppo.yml."""
    from bearing_env.train.sb3.zoo import parse_hyperparameters, read_hyperparameters

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
    model: Any
    venv: Any
    n_envs: int
    total_steps: int
    algorithm_kwargs: dict[str, Any]
    normalize: dict[str, Any] | None
    make_kwargs: dict[str, Any]
    build_seconds: float
    rounds: list[dict[str, Any]] = field(default_factory=list)
    env_id: str = ENV_ID

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
            "env_id": self.env_id,
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
    env_id: str = ENV_ID,
) -> PPORun:
    """Build PPO on one vec env kind and warm it up (one rollout and one update).

    ``env_id`` other than BearingSLAM-v1 (CartPole-v1 in the throughput section) trains
    that env, with its default kwargs, on BearingSLAM-v1's hyperparameters."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import VecNormalize

    from bearing_env.train.sb3.training_envs import make_training_env

    algorithm_kwargs, normalize, make_kwargs = ppo_settings(env_kwargs, overrides)
    if env_id != ENV_ID:
        make_kwargs = {}
    build_start = time.perf_counter()
    venv = make_training_env(env_id, make_kwargs, n_envs, kind, None)
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
        model,
        venv,
        n_envs,
        total_steps,
        algorithm_kwargs,
        normalize,
        make_kwargs,
        time.perf_counter() - build_start,
        env_id=env_id,
    )
    bench.measure_reference(f"ppo/{kind}" if env_id == ENV_ID else f"ppo/{env_id} {kind}")
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
    """PPO throughput per vec env kind, in interleaved rounds (:func:`timed_ppo_rounds`);
    each kind's ratio to SubprocVecEnv is the median of the per-round ratios."""
    runs: list[PPORun] = []
    try:
        with torch_threads(1):  # as bearing-env train (--torch-threads 1)
            for kind in kinds:
                log(f"  ppo {kind}: building {n_envs} envs and warming up ...")
                runs.append(build_ppo_run(bench, kind, n_envs, total_steps, env_kwargs, overrides))
            rows = timed_ppo_rounds(bench, runs, rounds)
    finally:
        for run in runs:
            run.close()
    subproc = next((run for run in runs if run.kind == "subproc"), None)
    for run, row in zip(runs, rows, strict=True):
        row["ratio_to_subproc"] = median_round_ratio(run, subproc) if subproc is not None else None
        log(f"  ppo {ppo_label(row):<24} {row['steps_per_s']:10,.0f} env steps/s (median)")
    return rows


def timed_ppo_rounds(
    bench: Bench, runs: Sequence[PPORun], rounds: int, section: str = "ppo"
) -> list[dict[str, Any]]:
    """Time built, warmed-up ``runs`` in ``rounds`` rounds, each timing every run once, in
    turn, so that a drifting machine speed affects all runs alike; their rows (the median
    round counts). The CartPole references between rounds are labelled ``section/round N``."""
    for number in range(1, rounds + 1):
        if number > 1:
            bench.measure_reference(f"{section}/round {number}")
        for run in runs:
            figure = run.timed_round(bench)
            log(
                f"  ppo {run.kind:<8} {run.env_id} round {number}/{rounds}: "
                f"{figure['steps_per_s']:10,.0f} env steps/s"
            )
    return [run.row(bench) for run in runs]


def median_round_ratio(run: PPORun, reference: PPORun) -> float:
    """The median over the interleaved rounds of ``run``'s rate / ``reference``'s."""
    return float(
        np.median(
            [
                mine["steps_per_s"] / theirs["steps_per_s"]
                for mine, theirs in zip(run.rounds, reference.rounds, strict=True)
            ]
        )
    )


def ppo_label(row: dict[str, Any]) -> str:
    return row["kind"] + (" (spawn)" if row["kind"] == "subproc" else "")


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
        env = make_vector_env(num_envs, "vector_entry_point", env_kwargs)
        what = f"vector env (batched), {num_envs} envs, {env_kwargs}"

        def loop() -> None:
            run_vector_env(env, seconds)

    print(f"cProfile: {what}, {seconds:g} s")
    profiler = cProfile.Profile()
    profiler.runcall(loop)
    env.close()
    pstats.Stats(profiler, stream=sys.stdout).sort_stats("tottime").print_stats(25)
