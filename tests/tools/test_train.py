# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""``bearing-env train``: tiny runs of each algorithm, save/load, resume, Ctrl-C, rl-zoo3.

Runs are a few hundred steps with small networks and in-process envs (``DummyVecEnv``);
one test runs the real command in a subprocess with ``SubprocVecEnv`` (spawn) and
interrupts it with Ctrl-C. The documented ``python -m rl_zoo3`` commands run in
``tests/tools/test_zoo_commands.py``.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
import zipfile
from dataclasses import replace
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from tests.extras import skip_module_without

skip_module_without("train")

import torch
from stable_baselines3 import PPO
from stable_baselines3.common.utils import ConstantSchedule

import bearing_env.train.sb3.train as train_module
from bearing_env.agents import SB3Policy
from bearing_env.agents.sb3 import ModelLoadError, load_model, load_vecnormalize
from bearing_env.train.common.cli_values import parse_key_values
from bearing_env.train.common.seeds import (
    MAX_VALIDATION_EPISODES,
    TRAINING_SEED_LIMIT,
    VALIDATION_SEED_START,
    training_seed_start,
)
from bearing_env.train.sb3 import train_cli
from bearing_env.train.sb3.callbacks import BEST_MODEL_NAME, BEST_SUMMARY_NAME, CheckpointStore
from bearing_env.train.sb3.export import export_run
from bearing_env.train.sb3.train import (
    TrainResult,
    TrainSettings,
    train,
)
from bearing_env.train.sb3.train_cli import EXIT_INTERRUPTED
from bearing_env.train.sb3.training_envs import EnvFactory, EpisodeSeedCycle, make_validation_env
from bearing_env.train.sb3.zoo import (
    DEFAULT_ENV_IDS,
    algorithm_class_for,
    parse_hyperparameters,
    read_hyperparameters,
    rl_zoo3_module,
)

REPO_ROOT = Path(__file__).resolve().parents[2]
ALGOS = ("ppo", "sac", "dqn")
TINY_NET = "dict(net_arch=[32, 32])"
#: Small versions of the shipped configs: same files, a few hundred steps.
TINY_HYPERPARAMS: dict[str, dict[str, Any]] = {
    "ppo": {"n_steps": 64, "batch_size": 64, "n_epochs": 2, "policy_kwargs": TINY_NET},
    "sac": {
        "learning_starts": 64,
        "batch_size": 32,
        "buffer_size": 2_000,
        "gradient_steps": 1,
        "policy_kwargs": TINY_NET,
    },
    "dqn": {
        "learning_starts": 64,
        "batch_size": 32,
        "buffer_size": 2_000,
        "train_freq": 1,
        "gradient_steps": 1,
        "target_update_interval": 64,
        "policy_kwargs": TINY_NET,
    },
}
TINY_TIMESTEPS = 256
PYTHON = sys.executable


def tiny_settings(algo: str, output: Path, **changes: Any) -> TrainSettings:
    settings = TrainSettings(
        algo=algo,
        env_id=DEFAULT_ENV_IDS[algo],
        output=output,
        hyperparam_overrides=dict(TINY_HYPERPARAMS[algo]),
        timesteps=TINY_TIMESTEPS,
        seed=3,
        n_envs=2,
        vec_env="dummy",
        eval_freq=128,
        eval_episodes=2,
        checkpoint_freq=128,
        progress_bar=False,
        tensorboard=False,
        verbose=0,
    )
    return replace(settings, **changes)


@pytest.fixture(scope="module")
def tiny_runs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, TrainResult]:
    """One tiny finished run per algorithm (PPO also writes TensorBoard logs)."""
    root = tmp_path_factory.mktemp("runs")
    return {
        algo: train(tiny_settings(algo, root / algo, tensorboard=algo == "ppo")) for algo in ALGOS
    }


def _observations(env_id: str, count: int = 16) -> np.ndarray:
    env = gym.make(env_id, scenario="khepera")
    env.action_space.seed(0)
    observations = []
    obs, _ = env.reset(seed=VALIDATION_SEED_START)
    for _ in range(count):
        observations.append(obs)
        obs, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            obs, _ = env.reset()
    env.close()
    return np.asarray(observations, dtype=np.float32)


# --------------------------------------------------------------------------------------
# Tiny runs, save/load
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("algo", ALGOS)
def test_tiny_run_writes_a_complete_run_folder(
    tiny_runs: dict[str, TrainResult], algo: str
) -> None:
    result = tiny_runs[algo]
    run = result.run_dir
    assert result.num_timesteps == TINY_TIMESTEPS and not result.interrupted
    record = json.loads((run / "run.json").read_text())
    assert record["status"] == "finished"
    assert record["num_timesteps"] == TINY_TIMESTEPS
    # The shipped YAML's entry is keyed by the Khepera task id, whose kwargs hold the scenario.
    assert record["env_id"].rpartition(":")[2] == DEFAULT_ENV_IDS[algo]
    assert record["env_kwargs"] == {}
    assert record["seeds"]["validation"] == [VALIDATION_SEED_START, VALIDATION_SEED_START + 2]
    for name in ("model.zip", "vecnormalize.pkl", "best/best_model.zip", "best/vecnormalize.pkl"):
        assert (run / name).is_file(), name
    summary = json.loads((run / "best" / BEST_SUMMARY_NAME).read_text())
    assert {"mean_reward", "median_total_area_10", "median_total_area_final"} <= summary.keys()
    latest = CheckpointStore(run / "checkpoints").latest()
    assert latest is not None and latest.timesteps == TINY_TIMESTEPS
    assert latest.vecnormalize_path.is_file()
    assert latest.replay_buffer_path.is_file() == (algo != "ppo")
    expected_space = gym.spaces.Discrete if algo == "dqn" else gym.spaces.Box
    assert isinstance(result.model.action_space, expected_space)
    assert (run / "monitor" / "0.monitor.csv").is_file()
    assert any((run / "tensorboard").rglob("events.out.tfevents.*")) == (algo == "ppo")


@pytest.mark.parametrize("algo", ALGOS)
def test_saved_model_and_statistics_predict_like_the_trained_model(
    tiny_runs: dict[str, TrainResult], algo: str
) -> None:
    result = tiny_runs[algo]
    raw = _observations(DEFAULT_ENV_IDS[algo])
    trained_normalizer = result.model.get_vec_normalize_env()
    assert trained_normalizer is not None
    expected, _ = result.model.predict(trained_normalizer.normalize_obs(raw), deterministic=True)

    loaded = load_model(result.run_dir / "model.zip", algo)
    eval_venv = make_validation_env(DEFAULT_ENV_IDS[algo], {"scenario": "khepera"}, 1)
    loaded_normalizer = load_vecnormalize(result.run_dir / "vecnormalize.pkl", eval_venv)
    actual, _ = loaded.predict(loaded_normalizer.normalize_obs(raw), deterministic=True)
    eval_venv.close()
    # Without a venv (as SB3Policy loads them) the same statistics, frozen.
    frozen = load_vecnormalize(result.run_dir / "vecnormalize.pkl")
    assert not frozen.training and not frozen.norm_reward
    np.testing.assert_array_equal(frozen.normalize_obs(raw), loaded_normalizer.normalize_obs(raw))
    np.testing.assert_array_equal(actual, expected)
    assert loaded.num_timesteps == TINY_TIMESTEPS


def test_same_seed_gives_the_same_model(tmp_path: Path) -> None:
    settings = tiny_settings("ppo", tmp_path / "a", timesteps=128, eval_freq=0)
    first = train(settings)
    second = train(replace(settings, output=tmp_path / "b"))
    for (name, a), (_, b) in zip(
        first.model.policy.state_dict().items(),
        second.model.policy.state_dict().items(),
        strict=True,
    ):
        assert np.array_equal(a.numpy(), b.numpy()), name


# --------------------------------------------------------------------------------------
# Fine-tuning: --init-from
# --------------------------------------------------------------------------------------


def test_init_from_starts_a_new_run_from_the_models_weights_and_statistics(
    tiny_runs: dict[str, TrainResult], tmp_path: Path
) -> None:
    source = tiny_runs["ppo"]
    # learning_rate 0: the weights stay the source's, so any difference is the loading's.
    settings = tiny_settings(
        "ppo",
        tmp_path / "fine",
        init_from=source.run_dir,  # a run folder: its best model (or model.zip)
        timesteps=128,
        eval_freq=0,
        hyperparam_overrides={**TINY_HYPERPARAMS["ppo"], "learning_rate": 0.0},
    )
    tuned = train(settings)
    started_from = load_model(train_module.resolve_model_path(source.run_dir), "ppo")
    for (name, a), (_, b) in zip(
        tuned.model.policy.state_dict().items(),
        started_from.policy.state_dict().items(),
        strict=True,
    ):
        assert np.array_equal(a.numpy(), b.numpy()), name
    fresh = train(replace(settings, output=tmp_path / "fresh", init_from=None))
    assert any(
        not np.array_equal(a.numpy(), b.numpy())
        for a, b in zip(
            fresh.model.policy.state_dict().values(),
            started_from.policy.state_dict().values(),
            strict=True,
        )
    )
    # The statistics continue from the source's: more observations than this run made.
    source_stats = load_vecnormalize(source.run_dir / "vecnormalize.pkl")
    tuned_stats = tuned.model.get_vec_normalize_env()
    fresh_stats = fresh.model.get_vec_normalize_env()
    assert tuned_stats is not None and fresh_stats is not None
    assert tuned_stats.obs_rms.count > source_stats.obs_rms.count > fresh_stats.obs_rms.count
    record = json.loads((tmp_path / "fine" / "run.json").read_text())
    assert record["init_from"] == str(settings.init_from)


def test_init_from_refuses_weights_that_do_not_fit(
    tiny_runs: dict[str, TrainResult], tmp_path: Path
) -> None:
    wider = {**TINY_HYPERPARAMS["ppo"], "policy_kwargs": "dict(net_arch=[48, 48])"}
    settings = tiny_settings(
        "ppo",
        tmp_path / "wide",
        init_from=tiny_runs["ppo"].run_dir / "model.zip",
        hyperparam_overrides=wider,
    )
    with pytest.raises(ValueError, match=r"--init-from: the weights of .*model\.zip do not fit"):
        train(settings)


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--init-from", "pretrained:no_such_model"], "no pretrained model named 'no_such_model'"),
        (["--init-from", "missing_dir/model.zip"], "SB3 model file not found"),
    ],
)
def test_init_from_errors_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(["--algo", "ppo", "--output", str(tmp_path / "run"), *extra])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err


# --------------------------------------------------------------------------------------
# Resume, interruption
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("algo", ["ppo", "dqn"])
def test_resume_continues_from_the_latest_checkpoint(
    tmp_path: Path, algo: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    run = tmp_path / algo
    first = train(tiny_settings(algo, run, eval_freq=128))
    assert first.num_timesteps == TINY_TIMESTEPS

    loaded_paths: list[Path] = []
    real_load_model = train_module.load_model

    def spy_load_model(path: str | Path, *args: Any, **kwargs: Any) -> Any:
        loaded_paths.append(Path(path))
        return real_load_model(path, *args, **kwargs)

    monkeypatch.setattr(train_module, "load_model", spy_load_model)
    resumed = train(tiny_settings(algo, run, timesteps=2 * TINY_TIMESTEPS, resume=True))

    assert loaded_paths == [run / "checkpoints" / f"rl_model_{TINY_TIMESTEPS}_steps.zip"]
    assert resumed.num_timesteps == 2 * TINY_TIMESTEPS
    record = json.loads((run / "run.json").read_text())
    assert [(s["start_timesteps"], s["end_timesteps"]) for s in record["segments"]] == [
        (0, TINY_TIMESTEPS),
        (TINY_TIMESTEPS, 2 * TINY_TIMESTEPS),
    ]
    evaluations = np.load(run / "best" / "evaluations.npz")
    assert list(evaluations["timesteps"]) == [128, 256, 384, 512]  # history carried over
    if algo == "dqn":  # the replay buffer came back with the checkpoint
        buffer = resumed.model.replay_buffer
        assert buffer is not None and buffer.size() == 2 * TINY_TIMESTEPS // 2  # per env
    latest = CheckpointStore(run / "checkpoints").latest()
    assert latest is not None and latest.timesteps == 2 * TINY_TIMESTEPS
    # An already finished run: nothing to do, nothing changes.
    again = train(tiny_settings(algo, run, timesteps=2 * TINY_TIMESTEPS, resume=True))
    assert again.num_timesteps == 2 * TINY_TIMESTEPS


def test_a_new_run_refuses_to_overwrite_an_existing_one(tiny_runs: dict[str, TrainResult]) -> None:
    with pytest.raises(FileExistsError, match="--resume"):
        train(tiny_settings("ppo", tiny_runs["ppo"].run_dir))


def test_resume_refuses_other_settings(tiny_runs: dict[str, TrainResult], tmp_path: Path) -> None:
    run = tiny_runs["sac"].run_dir
    with pytest.raises(ValueError, match="env kwargs"):
        train(tiny_settings("sac", run, resume=True, env_kwargs={"scenario": "random"}))
    with pytest.raises(ValueError, match="replay buffer"):
        train(tiny_settings("sac", run, resume=True, n_envs=3))
    with pytest.raises(FileNotFoundError, match="no run to resume"):
        train(tiny_settings("ppo", tmp_path / "nothing", resume=True))


def test_ctrl_c_saves_a_checkpoint_and_resume_continues(tmp_path: Path) -> None:
    """The real command, SubprocVecEnv with spawn, Ctrl-C sent to the whole process group."""
    run = tmp_path / "interrupted"
    command = [
        PYTHON, "-m", "bearing_env.train.cli", "train", "--algo", "ppo", "--output", str(run),
        "--vec-env", "subproc", "--n-envs", "2", "--timesteps", "1000000", "--seed", "5",
        "--hyperparams", "n_steps=16", "batch_size=32", "n_epochs=1", f"policy_kwargs={TINY_NET}",
        "--checkpoint-freq", "32", "--eval-freq", "0", "--no-progress", "--no-tensorboard",
    ]  # fmt: skip
    process = subprocess.Popen(
        command,
        cwd=REPO_ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        start_new_session=True,  # its own process group, like a terminal job
    )
    store = CheckpointStore(run / "checkpoints")
    try:
        deadline = time.monotonic() + 90
        while store.latest() is None:
            assert process.poll() is None, process.communicate()[0]
            assert time.monotonic() < deadline, "no checkpoint within 90 s"
            time.sleep(0.2)
        periodic = store.latest()
        assert periodic is not None
        os.killpg(process.pid, signal.SIGINT)  # what Ctrl-C in a terminal does
        output, _ = process.communicate(timeout=60)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    assert process.returncode == EXIT_INTERRUPTED, output
    assert "--resume" in output
    record = json.loads((run / "run.json").read_text())
    latest = store.latest()
    assert latest is not None and record["status"] == "interrupted"
    # The stop saves the state after the last update: a stop in the rollout that follows
    # the periodic checkpoint saves that same count again.
    assert latest.timesteps == record["num_timesteps"] >= periodic.timesteps
    assert latest.timesteps % 32 == 0  # n_steps=16 x 2 envs: only trained steps count
    assert record["segments"][-1]["status"] == "interrupted"
    assert latest.vecnormalize_path.is_file()
    assert not (run / "model.zip").exists()  # the budget was not reached

    target = latest.timesteps + 64
    resumed = train(
        tiny_settings(
            "ppo",
            run,
            resume=True,
            timesteps=target,
            checkpoint_freq=64,
            eval_freq=0,
            seed=5,
            hyperparam_overrides={},
        )
    )
    assert resumed.num_timesteps >= target
    record = json.loads((run / "run.json").read_text())
    assert record["status"] == "finished"
    assert record["segments"][-1]["start_timesteps"] == latest.timesteps
    assert record["segments"][0]["vec_env"] == "subproc"


# --------------------------------------------------------------------------------------
# Clear errors for missing and corrupt files
# --------------------------------------------------------------------------------------


def test_missing_model_file_names_the_path(tmp_path: Path) -> None:
    missing = tmp_path / "nowhere" / "model.zip"
    with pytest.raises(FileNotFoundError, match=re.escape(str(missing))):
        load_model(missing, "ppo")


@pytest.mark.parametrize("damage", ["garbage", "truncated", "not_sb3"])
def test_corrupt_model_file_names_the_path(
    tiny_runs: dict[str, TrainResult], tmp_path: Path, damage: str
) -> None:
    path = tmp_path / "broken.zip"
    good = (tiny_runs["ppo"].run_dir / "model.zip").read_bytes()
    if damage == "garbage":
        path.write_bytes(b"this is not a model" * 100)
    elif damage == "truncated":
        path.write_bytes(good[: len(good) // 2])
    else:
        with zipfile.ZipFile(path, "w") as archive:
            archive.writestr("hello.txt", "a zip, but not a stable-baselines3 model")
    # The loader SB3Policy uses: the same named error for training and acting.
    with pytest.raises(ModelLoadError, match=re.escape(str(path))):
        load_model(path, "ppo")


def test_corrupt_statistics_and_checkpoint_name_the_path(
    tiny_runs: dict[str, TrainResult], tmp_path: Path
) -> None:
    stats = tmp_path / "vecnormalize.pkl"
    stats.write_bytes(b"\x80\x04 truncated pickle")
    venv = make_validation_env("BearingSLAM-v1", {"scenario": "khepera"}, 1)
    with pytest.raises(ModelLoadError, match=re.escape(str(stats))):
        load_vecnormalize(stats, venv)
    with pytest.raises(FileNotFoundError, match=re.escape("missing.pkl")):
        load_vecnormalize(tmp_path / "missing.pkl", venv)
    venv.close()

    run = tmp_path / "run"
    train(tiny_settings("ppo", run, timesteps=128, eval_freq=0))
    latest = CheckpointStore(run / "checkpoints").latest()
    assert latest is not None
    latest.model_path.write_bytes(b"damaged on disk")
    with pytest.raises(ValueError, match=re.escape(latest.model_path.name)):
        train(tiny_settings("ppo", run, timesteps=256, eval_freq=0, resume=True))


def test_cli_reports_errors_without_a_traceback(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(["--algo", "ppo", "--output", str(tmp_path / "none"), "--resume"])
    assert exit_info.value.code == 2
    assert "no run to resume" in capsys.readouterr().err


def test_an_export_that_cannot_be_written_fails_in_one_line(
    tiny_runs: dict[str, TrainResult], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    blocker = tmp_path / "a_file"
    blocker.write_text("")  # a folder below a regular file cannot be made, even by root
    destination = blocker / "pretrained" / "ppo_tiny"
    run = tiny_runs["ppo"].run_dir
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main(
            ["--algo", "ppo", "--output", str(run), "--export", str(destination), "--export-only"]
        )
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"bearing-env train: error: cannot write {destination.parent}")
    assert "choose another --export" in err


# --------------------------------------------------------------------------------------
# Export for agents/pretrained
# --------------------------------------------------------------------------------------


def test_export_writes_the_pretrained_layout(
    tiny_runs: dict[str, TrainResult], tmp_path: Path
) -> None:
    run = tiny_runs["ppo"].run_dir
    exported = export_run(run, tmp_path / "pretrained" / "ppo_tiny")
    folder = tmp_path / "pretrained"
    assert sorted(p.name for p in folder.iterdir()) == [
        "ppo_tiny.json",
        "ppo_tiny.zip",
        "ppo_tiny_vecnormalize.pkl",
    ]
    assert exported.source == "best"
    assert (folder / "ppo_tiny.zip").read_bytes() == (run / "best" / BEST_MODEL_NAME).read_bytes()
    metadata = json.loads((folder / "ppo_tiny.json").read_text())
    assert metadata["algo"] == "ppo" and metadata["env_id"] == "BearingSLAM-Khepera-v1"
    assert metadata["env_kwargs"] == {}
    assert metadata["files"] == {
        "model": "ppo_tiny.zip",
        "vecnormalize": "ppo_tiny_vecnormalize.pkl",
    }

    # The exported files act like the run's best model, through agents.SB3Policy.
    env = gym.make("BearingSLAM-v1", scenario="khepera")
    policy = SB3Policy(env, folder / "ppo_tiny.zip")
    best = load_model(run / "best" / BEST_MODEL_NAME, "ppo")
    venv = make_validation_env("BearingSLAM-v1", {"scenario": "khepera"}, 1)
    stats = load_vecnormalize(run / "best" / "vecnormalize.pkl", venv)
    observation, info = env.reset(seed=VALIDATION_SEED_START)
    expected, _ = best.predict(stats.normalize_obs(observation), deterministic=True)
    np.testing.assert_array_equal(policy.act(observation, info), expected)
    env.close()
    venv.close()


def test_exported_models_load_by_name_and_join_the_comparison(
    tiny_runs: dict[str, TrainResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import bearing_env.agents.sb3
    from bearing_env.agents import make_policy, pretrained_names
    from bearing_env.train.compare.cli import matching_pretrained

    folder = tmp_path / "pretrained"
    monkeypatch.setattr(bearing_env.agents.sb3, "PRETRAINED_DIR", folder)
    assert pretrained_names() == []
    export_run(tiny_runs["ppo"].run_dir, folder / "ppo_tiny")
    assert pretrained_names() == ["ppo_tiny"]

    env = gym.make("BearingSLAM-v1", scenario="khepera")
    by_name = SB3Policy.pretrained("ppo_tiny", env)
    by_spec = make_policy("pretrained:ppo_tiny", env)
    by_path = SB3Policy(env, folder / "ppo_tiny.zip")
    assert by_name.name == by_spec.name == "ppo_tiny"
    observation, info = env.reset(seed=3)
    np.testing.assert_array_equal(by_name.act(observation, info), by_path.act(observation, info))
    np.testing.assert_array_equal(by_spec.act(observation, info), by_path.act(observation, info))
    with pytest.raises(ValueError, match=r"'ppo_nope'.*ppo_tiny"):
        SB3Policy.pretrained("ppo_nope", env)
    env.close()

    # Compared by default only where it was trained: the same action kind and settings,
    # by the task id or by the base id with the task's kwargs.
    assert matching_pretrained("BearingSLAM-Khepera-v1", {}) == ["pretrained:ppo_tiny"]
    assert matching_pretrained("bearing_env:BearingSLAM-v1", {"scenario": "khepera"}) == [
        "pretrained:ppo_tiny"
    ]
    assert matching_pretrained("BearingSLAM-v1", {"scenario": "khepera", "max_moves": 10}) == [
        "pretrained:ppo_tiny"
    ]
    assert matching_pretrained("BearingSLAM-v1", {"scenario": "random"}) == []
    # Records are JSON: a tuple-valued kwarg must still match its JSON list.
    record = folder / "ppo_tiny.json"
    metadata = json.loads(record.read_text())
    metadata["env_id"] = "BearingSLAM-v1"
    metadata["env_kwargs"] = {"scenario": "random", "n_landmarks": [4, 8], "max_landmarks": 10}
    record.write_text(json.dumps(metadata))
    assert matching_pretrained(
        "BearingSLAM-v1", {"scenario": "random", "n_landmarks": (4, 8), "max_landmarks": 10}
    ) == ["pretrained:ppo_tiny"]
    # Settings that do not resolve match no model (the comparison reports them).
    assert matching_pretrained("BearingSLAM-v1", {"scenario": "khepera", "n_landmarks": 6}) == []
    assert matching_pretrained("BearingSLAMDiscrete-v1", {"scenario": "khepera"}) == []


# --------------------------------------------------------------------------------------
# Hyperparameter files, seeds, rl-zoo3
# --------------------------------------------------------------------------------------


def test_hyperparameters_are_preprocessed_by_rl_zoo3() -> None:
    raw = {
        "n_timesteps": 1e5,
        "policy": "MlpPolicy",
        "learning_rate": "lin_0.001",
        "clip_range": 0.2,
        "normalize": "dict(norm_obs=True, norm_reward=False)",
        "gamma": 0.9,
        "policy_kwargs": "dict(net_arch=[64, 64], activation_fn=nn.ReLU)",
        "train_freq": [4, "step"],
    }
    parsed = parse_hyperparameters(raw, "ppo")
    SimpleLinearSchedule = rl_zoo3_module("rl_zoo3.utils").SimpleLinearSchedule
    # rl-zoo3's own schedule classes: lin_<x> decays linearly, a number stays constant.
    schedule = parsed.algorithm_kwargs["learning_rate"]
    assert isinstance(schedule, SimpleLinearSchedule)
    assert schedule(1.0) == pytest.approx(1e-3) and schedule(0.5) == pytest.approx(5e-4)
    clip_range = parsed.algorithm_kwargs["clip_range"]
    assert isinstance(clip_range, ConstantSchedule) and clip_range(0.3) == pytest.approx(0.2)
    assert parsed.normalize == {"norm_obs": True, "norm_reward": False, "gamma": 0.9}
    assert parsed.algorithm_kwargs["policy_kwargs"]["activation_fn"] is torch.nn.ReLU
    assert parsed.algorithm_kwargs["train_freq"] == (4, "step")
    assert parsed.n_envs == 1 and parsed.n_timesteps == 100_000
    assert not {"n_timesteps", "normalize", "env_kwargs"} & parsed.algorithm_kwargs.keys()
    assert raw["learning_rate"] == "lin_0.001"  # the raw entry (run.json's record) is kept
    assert parse_hyperparameters({"n_timesteps": 10, "normalize": False}).normalize is None
    # SB3 takes them as they are: the model's learning rate follows the schedule.
    kwargs = {k: v for k, v in parsed.algorithm_kwargs.items() if k not in ("policy", "train_freq")}
    model = PPO("MlpPolicy", "BearingSLAM-v1", n_steps=8, batch_size=8, device="cpu", **kwargs)
    assert model.lr_schedule(0.5) == pytest.approx(5e-4)


def test_using_rl_zoo3_leaves_gymnasium_unpatched() -> None:
    """rl-zoo3 replaces TimeLimit on import; the trainer's use of it must not leak."""
    read_hyperparameters("ppo", "BearingSLAM-v1")
    algorithm_class_for("ppo")
    assert gym.wrappers.TimeLimit.__module__.startswith("gymnasium.")
    env = gym.make("BearingSLAM-v1", max_episode_steps=1)
    env.reset(seed=0)
    env.action_space.seed(0)
    info = env.step(env.action_space.sample())[4]
    assert "TimeLimit.truncated" not in info
    assert "bool8" not in vars(np)


def test_hyperparameters_that_this_trainer_cannot_apply_are_refused_by_name() -> None:
    with pytest.raises(ValueError, match="frame_stack"):
        parse_hyperparameters({"n_timesteps": 10, "frame_stack": 4})
    with pytest.raises(ValueError, match="policy_kwargs must evaluate to a dict"):
        parse_hyperparameters({"n_timesteps": 10, "policy_kwargs": "[1, 2]"})
    with pytest.raises(ValueError, match="n_envs and n_timesteps must be >= 1"):
        parse_hyperparameters({"n_timesteps": 10, "n_envs": 0})
    with pytest.raises(ValueError, match="needs n_timesteps"):
        parse_hyperparameters({"n_envs": 2})
    with pytest.raises(ValueError, match="learning_rate"):
        parse_hyperparameters({"n_timesteps": 10, "learning_rate": "lin_fast"})
    assert parse_key_values(["scenario=khepera", "move_length=(0.1, 0.3)", "n=4"], "x") == {
        "scenario": "khepera",
        "move_length": (0.1, 0.3),
        "n": 4,
    }
    with pytest.raises(ValueError, match="KEY=VALUE"):
        parse_key_values(["scenario"], "--env-kwargs")


def test_seed_ranges_are_disjoint_and_validation_episodes_repeat() -> None:
    from bearing_env.train.common.seeds import EVAL_SEED_START
    assert TRAINING_SEED_LIMIT <= VALIDATION_SEED_START
    assert VALIDATION_SEED_START + MAX_VALIDATION_EPISODES <= EVAL_SEED_START
    assert training_seed_start(7, 10**9, 8) + 8 <= TRAINING_SEED_LIMIT
    with pytest.raises(ValueError):
        training_seed_start(TRAINING_SEED_LIMIT, 0, 1)

    env = EpisodeSeedCycle(gym.make("BearingSLAM-v1"), [VALIDATION_SEED_START, 900_001])
    first = [env.reset()[0] for _ in range(3)]
    env.rewind_episode_seeds()
    again = env.reset()[0]
    np.testing.assert_array_equal(first[0], again)
    np.testing.assert_array_equal(first[0], first[2])  # cycles
    assert not np.array_equal(first[0], first[1])
    env.close()


def test_env_factory_raises_the_time_limit_with_max_moves() -> None:
    env = EnvFactory("BearingSLAM-v1", {"scenario": "khepera", "max_moves": 23})()
    assert env.spec is not None and env.spec.max_episode_steps == 23
    env.reset(seed=1)
    moves, done = 0, False
    while not done:
        _, _, terminated, truncated, info = env.step(np.array([0.5, 1.0], dtype=np.float32))
        moves += 1
        done = terminated or truncated
    assert moves == 23 or info["is_success"]
    env.close()


def test_train_is_a_bearing_env_subcommand() -> None:
    from bearing_env.train.cli import SUBCOMMANDS

    assert SUBCOMMANDS["train"][0] == "bearing_env.train.sb3.train_cli"


def test_checkpoints_keep_sb3_checkpoint_callback_names(tmp_path: Path) -> None:
    from stable_baselines3.common.callbacks import CheckpointCallback

    from bearing_env.train.sb3.callbacks import PeriodicCheckpointCallback

    checkpoint = CheckpointStore(tmp_path, keep=1).checkpoint_at(48)
    assert checkpoint.model_path == tmp_path / "rl_model_48_steps.zip"
    assert checkpoint.vecnormalize_path == tmp_path / "rl_model_vecnormalize_48_steps.pkl"
    assert checkpoint.replay_buffer_path == tmp_path / "rl_model_replay_buffer_48_steps.pkl"
    callback = PeriodicCheckpointCallback(CheckpointStore(tmp_path), save_freq=16)
    assert isinstance(callback, CheckpointCallback)
    assert callback._on_step() is True  # SB3's mid-rollout save never runs
    assert not list(tmp_path.iterdir())


def test_rl_zoo3_envs_run_max_moves() -> None:
    """rl-zoo3 makes its envs from the registered spec with the YAML's env_kwargs: with
    no registered TimeLimit, max_moves=40 runs 40 moves there too."""
    from bearing_env.train.sb3.zoo import _experiment_manager

    manager = _experiment_manager("ppo", "BearingSLAM-v1")
    manager.env_kwargs = {"scenario": "khepera", "max_moves": 40, "target_area": 1e-9}
    envs = manager.create_envs(n_envs=1, no_log=True)
    envs.seed(5)
    envs.reset()
    for move in range(1, 41):
        _, _, dones, infos = envs.step(np.array([[0.3, 0.5]], dtype=np.float32))
        assert bool(dones[0]) == (move == 40), move
    assert infos[0]["TimeLimit.truncated"]
    envs.close()
