# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""Ray: envs through the object store and in Ray tasks, ``compare --executor ray``, RLlib
PPO (``bearing-env rllib``) and a Ray Tune sweep (``bearing-env sweep``).

One local Ray instance (``ray.init(num_cpus=2)``) serves every test of this module: it is
started once by a module-scoped fixture and shut down after the last test.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from tests.extras import skip_module_without

skip_module_without("ray")

import ray

from bearing_env.agents.registry import make_policy, spec_files, with_files
from bearing_env.tasks import BASE_IDS
from bearing_env.train.compare.cli import main, reproducing_command
from bearing_env.train.compare.comparison import run_comparison
from bearing_env.train.compare.config import CompareConfig, policies_from_specs
from bearing_env.train.compare.log import LOG_NAME, EpisodeLog
from bearing_env.train.compare.runner import executor_named
from bearing_env.train.ray.ray_executor import materialise, read_bundle, run_on_ray
from bearing_env.train.ray.rllib import PROGRESS_NAME, RLlibSettings, train_rllib
from bearing_env.train.ray.sweep import SweepSettings, parse_grid, run_sweep
from tests.tools.test_extras import error_line, plain_cli

ROOT = Path(__file__).resolve().parents[2]
SMALL_ENV = {"scenario": "khepera", "max_moves": 5}
#: 4 policies x 12 episodes; the shipped model's files reach the workers through the
#: object store.
POLICIES = ["random", "parallax", "greedy", "pretrained:ppo_khepera"]
#: RLlib at its smallest: one iteration of 64 env steps, one SGD pass.
TINY_PPO: dict[str, Any] = {
    "env_kwargs": SMALL_ENV,
    "iterations": 1,
    "envs_per_runner": 2,
    "train_batch_size": 64,
    "minibatch_size": 32,
    "epochs": 1,
}


@pytest.fixture(scope="module")
def cluster() -> Iterator[Any]:
    """One local Ray instance for the module (Ray takes seconds to start)."""
    if ray.is_initialized():
        ray.shutdown()
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        yield ray
    finally:
        ray.shutdown()


def comparison() -> CompareConfig:
    return CompareConfig(
        policies=policies_from_specs(POLICIES),
        env_id="BearingSLAM-v1",
        env_kwargs=dict(SMALL_ENV),
        episodes=12,
        bootstrap=200,
    )


def compare(out: Path, **kwargs: Any) -> Any:
    return run_comparison(comparison(), out, progress=False, plots=False, **kwargs)


def episode_results(out: Path) -> list[dict[str, Any]]:
    """The logged episodes without their timings, in a canonical order."""
    records = EpisodeLog(out / LOG_NAME).load()
    for record in records:
        record.pop("policy_seconds")
    return sorted(records, key=lambda r: (r["policy"], r["seed"]))


@pytest.fixture(scope="module")
def ray_run(cluster: Any, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An uninterrupted ``--executor ray`` comparison (4 policies x 12 episodes)."""
    out = tmp_path_factory.mktemp("ray_run")
    result = compare(out, executor=executor_named("ray"))
    assert result.complete and len(result.records) == 48
    return out


# --------------------------------------------------------------------------------------
# Envs through the object store and in tasks
# --------------------------------------------------------------------------------------


def rollout(env: gym.Env, actions: list[Any]) -> list[tuple[Any, ...]]:
    steps = []
    for action in actions:
        observation, reward, terminated, truncated, _ = env.step(action)
        steps.append((observation.copy(), float(reward), terminated, truncated))
        if terminated or truncated:
            break
    return steps


def assert_same_steps(left: list[tuple[Any, ...]], right: list[tuple[Any, ...]]) -> None:
    assert len(left) == len(right) > 0
    for (obs_a, *rest_a), (obs_b, *rest_b) in zip(left, right, strict=True):
        np.testing.assert_array_equal(obs_a, obs_b)
        assert rest_a == rest_b


@ray.remote
def step_in_a_task(env: gym.Env, actions: list[Any]) -> list[tuple[Any, ...]]:
    return rollout(env, actions)


@pytest.mark.parametrize("env_id", sorted(BASE_IDS.values()))
def test_an_env_through_the_object_store_steps_like_the_original(cluster: Any, env_id: str) -> None:
    env = gym.make(f"bearing_env:{env_id}", **SMALL_ENV)
    env.reset(seed=11)
    env.action_space.seed(5)
    actions = [env.action_space.sample() for _ in range(4)]
    env.step(actions[0])  # mid-episode: the maps hold regions
    ref = ray.put(env)
    copy = ray.get(ref)
    assert copy is not env
    assert_same_steps(rollout(copy, actions[1:]), rollout(env, actions[1:]))
    # ... and inside a Ray task, in another process
    fresh = gym.make(f"bearing_env:{env_id}", **SMALL_ENV)
    fresh.reset(seed=11)
    fresh.step(actions[0])
    remote_steps = ray.get(step_in_a_task.remote(ray.put(fresh), actions[1:]))
    local = gym.make(f"bearing_env:{env_id}", **SMALL_ENV)
    local.reset(seed=11)
    local.step(actions[0])
    assert_same_steps(remote_steps, rollout(local, actions[1:]))


# --------------------------------------------------------------------------------------
# compare --executor ray
# --------------------------------------------------------------------------------------


def test_the_ray_executor_equals_two_local_workers(ray_run: Path, tmp_path: Path) -> None:
    local = compare(tmp_path / "local", workers=2)
    assert local.complete
    assert (ray_run / "summary.json").read_text() == (tmp_path / "local/summary.json").read_text()
    assert episode_results(ray_run) == episode_results(tmp_path / "local")
    assert set(json.loads((ray_run / "timing.json").read_text())["ms_per_move"]) == {
        "random_polygonal", "parallax", "greedy_one_step", "ppo_khepera",
    }  # fmt: skip


def test_a_resumed_ray_run_equals_the_uninterrupted_one(ray_run: Path, tmp_path: Path) -> None:
    partial = compare(tmp_path, executor=executor_named("ray"), stop_after=17)
    assert not partial.complete
    assert len(EpisodeLog(tmp_path / LOG_NAME).load()) == 17
    resumed = compare(tmp_path, executor=executor_named("ray"), resume=True)
    assert resumed.complete
    assert (ray_run / "summary.json").read_text() == (tmp_path / "summary.json").read_text()
    assert episode_results(ray_run) == episode_results(tmp_path)


def test_ctrl_c_of_a_ray_comparison_keeps_its_episodes_and_resumes(
    cluster: Any, ray_run: Path, tmp_path: Path
) -> None:
    """A real interruption: SIGINT to ``compare --executor ray --ray-address`` joined to
    this module's Ray instance, after some episodes are logged."""
    address = ray.get_runtime_context().gcs_address
    command = [
        sys.executable, "-m", "bearing_env.train.compare.cli", "--policies", *POLICIES,
        "--env", "BearingSLAM-v1", "--env-kwargs", "scenario=khepera", "max_moves=5",
        "--episodes", "12", "--bootstrap", "200", "--no-progress", "--no-plots",
        "--executor", "ray", "--ray-address", address, "--out", str(tmp_path),
    ]  # fmt: skip
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    process = subprocess.Popen(
        command,
        cwd=ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # A shell's background jobs ignore SIGINT, and a child inheriting that gets no
        # KeyboardInterrupt: it would run to the end and exit 0 (as test_compare's run).
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        log = tmp_path / LOG_NAME
        deadline = time.monotonic() + 240
        while not (log.exists() and len(log.read_text().splitlines()) >= 3):
            assert process.poll() is None, process.communicate()[1]
            assert time.monotonic() < deadline, "no episode within 240 s"
            time.sleep(0.05)
        process.send_signal(signal.SIGINT)
        _, stderr = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert process.returncode == 130, stderr
    assert "rerun the same command with --resume" in stderr
    kept = EpisodeLog(tmp_path / LOG_NAME).load()
    assert 3 <= len(kept) < 48
    resumed = compare(tmp_path, executor=executor_named("ray"), resume=True)
    assert resumed.complete
    assert (ray_run / "summary.json").read_text() == (tmp_path / "summary.json").read_text()


def test_no_tasks_start_no_cluster() -> None:
    assert list(run_on_ray([])) == []


def test_executor_options_are_checked(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    for argv, message in (
        (["--ray-address", "auto"], "--ray-address needs --executor ray"),
        (["--executor", "ray", "--workers", "2"], "--workers is for --executor local"),
    ):
        with pytest.raises(SystemExit) as stopped:
            main([*argv, "--policies", "random", "--out", str(tmp_path)])
        assert stopped.value.code == 2
        assert message in capsys.readouterr().err
    with pytest.raises(ValueError, match="executor must be one of"):
        executor_named("dask")
    # Where episodes run does not change the results: the report's command leaves it out.
    argv = ["--executor", "ray", "--ray-address=HOST:6379", "--episodes", "3"]
    assert reproducing_command(argv) == "bearing-env compare --episodes 3"


def test_a_policy_files_travel_as_bytes_and_act_alike(tmp_path: Path) -> None:
    spec = "pretrained:ppo_khepera"
    files = spec_files(spec)
    assert set(files) == {"path", "vecnormalize"}
    bundle = read_bundle(spec)
    assert {option: name for option, (name, _) in bundle.items()} == {
        option: path.name for option, path in files.items()
    }
    copied = materialise(spec, bundle, root=tmp_path)
    assert materialise(spec, bundle, root=tmp_path) == copied  # one folder per content
    copies = spec_files(copied)
    for option, path in copies.items():
        assert path.is_relative_to(tmp_path)
        assert path.read_bytes() == files[option].read_bytes()
    env = gym.make("bearing_env:BearingSLAM-v1", scenario="khepera")
    original, moved = make_policy(spec, env), make_policy(copied, env)
    assert moved.name == original.name == "ppo_khepera"
    observation, info = env.reset(seed=3)
    np.testing.assert_array_equal(original.act(observation, info), moved.act(observation, info))
    assert read_bundle("greedy") == {} and materialise("greedy", {}) == "greedy"
    with pytest.raises(ValueError, match="reads no files"):
        with_files("random", {"path": tmp_path / "x.zip"})
    with pytest.raises(ValueError, match="must name the model"):
        with_files(spec, {"vecnormalize": tmp_path / "x.pkl"})


# --------------------------------------------------------------------------------------
# RLlib and Tune
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", sorted(BASE_IDS.values()))
def test_rllib_ppo_trains_an_iteration_with_a_remote_env_runner(
    cluster: Any, env_id: str, tmp_path: Path
) -> None:
    settings = RLlibSettings(env_id=env_id, num_env_runners=1, seed=3, **TINY_PPO)
    result = train_rllib(settings, tmp_path, progress=False)
    assert result.complete and result.iterations == 1
    assert result.env_steps == 64
    (row,) = result.progress
    assert row["iteration"] == 1 and row["num_episodes"] >= 64 // SMALL_ENV["max_moves"] - 2
    assert math.isfinite(row["episode_return_mean"])
    assert (result.checkpoint / "rllib_checkpoint.json").is_file()
    record = json.loads((tmp_path / "run.json").read_text())
    assert record["status"] == "finished" and record["checkpoint_iteration"] == 1
    assert record["settings"]["env_id"] == f"bearing_env:{env_id}"


def test_an_rllib_run_resumes_from_its_checkpoint(cluster: Any, tmp_path: Path) -> None:
    settings = RLlibSettings(**{**TINY_PPO, "iterations": 2, "num_env_runners": 1})
    first = train_rllib(settings, tmp_path, progress=False, stop_after=1)
    assert not first.complete and first.iterations == 1
    with pytest.raises(FileExistsError, match="--resume"):
        train_rllib(settings, tmp_path, progress=False)
    with pytest.raises(ValueError, match="other settings"):
        train_rllib(RLlibSettings(**{**TINY_PPO, "iterations": 2, "lr": 0.1}), tmp_path,
                    resume=True, progress=False)  # fmt: skip
    second = train_rllib(settings, tmp_path, resume=True, progress=False)
    assert second.complete and second.iterations == 2 and second.env_steps == 128
    lines = (tmp_path / PROGRESS_NAME).read_text().splitlines()
    assert [json.loads(line)["iteration"] for line in lines] == [1, 2]
    segments = json.loads((tmp_path / "run.json").read_text())["segments"]
    # the resumed segment's env runners start from other seeds than the first one's
    assert segments == [
        {"start_iteration": 0, "seed": settings.seed},
        {"start_iteration": 1, "seed": settings.segment_seed(1)},
    ]
    assert settings.segment_seed(1) >= settings.seed + settings.seed_span


def test_rllib_settings_name_bad_values() -> None:
    with pytest.raises(ValueError, match="env id must be one of"):
        RLlibSettings(env_id="CartPole-v1")
    with pytest.raises(ValueError, match="seed must be in"):
        RLlibSettings(seed=999_999)
    with pytest.raises(ValueError, match="minibatch_size"):
        RLlibSettings(train_batch_size=32, minibatch_size=64)
    with pytest.raises(ValueError, match="iterations must be >= 1"):
        RLlibSettings(iterations=0)


def test_a_tune_sweep_runs_every_grid_point(cluster: Any, tmp_path: Path) -> None:
    sweep = SweepSettings(
        base=RLlibSettings(**{**TINY_PPO, "num_env_runners": 0}),
        grid=parse_grid(["lr=0.0001,0.001"], "--grid"),
        env_grid={},
    )
    rows = run_sweep(sweep, tmp_path, verbose=0)
    assert sorted(row["lr"] for row in rows) == [0.0001, 0.001]
    for row in rows:
        assert row["error"] is None and row["iterations"] == 1
        assert math.isfinite(row["episode_return_mean"])
        assert Path(row["checkpoint"]).is_dir()
    summary = json.loads((tmp_path / "sweep.json").read_text())
    assert summary["trials"] == rows
    with pytest.raises(FileExistsError, match="--resume"):
        run_sweep(sweep, tmp_path, verbose=0)


def test_sweep_grids_are_checked() -> None:
    assert parse_grid(["gamma=0.9,0.99", "scenario=khepera,random"], "--grid") == {
        "gamma": [0.9, 0.99],
        "scenario": ["khepera", "random"],
    }
    with pytest.raises(ValueError, match="not KEY=VALUE"):
        parse_grid(["lr"], "--grid")
    with pytest.raises(ValueError, match="cannot sweep"):
        SweepSettings(base=RLlibSettings(), grid={"num_env_runners": [1, 2]}, env_grid={})
    with pytest.raises(ValueError, match="gamma"):
        SweepSettings(base=RLlibSettings(), grid={"gamma": [0.9, 2.0]}, env_grid={})
    sweep = SweepSettings(
        base=RLlibSettings(), grid={"lr": [0.1, 0.2]}, env_grid={"scenario": ["khepera", "x"]}
    )
    assert len(sweep.combinations()) == 4
    assert sweep.settings_of({"lr": 0.2, "env.scenario": "x"}).env_kwargs["scenario"] == "x"


# --------------------------------------------------------------------------------------
# Without the ray extra
# --------------------------------------------------------------------------------------

RAY = 'pip install "bearing_env[ray]"'


@pytest.mark.parametrize(
    "argv",
    [
        ["compare", "--executor", "ray", "--policies", "random", "--episodes", "1"],
        ["rllib", "--iterations", "1"],
        ["sweep", "--grid", "lr=0.1,0.2"],
    ],
    ids=["compare", "rllib", "sweep"],
)
def test_without_ray_the_commands_say_to_install_the_ray_extra(
    tmp_path: Path, argv: list[str]
) -> None:
    result = plain_cli(argv, tmp_path, blocked=("ray",))
    prog = f"bearing-env {argv[0]}"
    line = error_line(result, prog)
    assert "'ray'" in line and RAY in line
    assert not any(tmp_path.iterdir())  # nothing was written


def test_the_ray_benchmark_reports_speed_ups_and_the_overhead_per_episode() -> None:
    from bearing_env.benchmarks.bench_compare import report

    times = {
        "local, 1 process": [10.0, 12.0],
        "local, 2 processes": [5.0, 8.0],
        "ray start-up (ray.init)": [3.0, 4.0],
        "ray, 1 CPU, empty tasks": [0.1, 0.3],
    }
    lines = report(times, episodes=100)
    assert lines[1].split()[-3:] == ["10.00-12.00", "1.00-1.00x", "0.50-0.67x"]
    assert lines[2].split()[-3:] == ["5.00-8.00", "1.50-2.00x", "1.00-1.00x"]  # 10/5, 12/8
    assert lines[3].split()[-1] == "3.00-4.00"  # start-up: no speed-up column
    assert "(1 CPU, empty tasks): 1.00-3.00 ms" in lines[-1]
    assert "100.00-120.00 ms in one local process" in lines[-1]
