# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""No lost work: a killed or stopped ``bearing-env train`` resumes with every counted step
trained on, ``run.json`` keeps the killed segment, and a killed ``compare`` takes its
workers with it.

The training runs are PPO with ``n_steps=8`` on 2 in-process envs: a rollout is 16 env
steps and each ``train()`` adds ``n_epochs=1`` to ``_n_updates``, so a model that trained
on every step it counts has ``_n_updates == num_timesteps / 16``.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from tests.extras import skip_module_without

skip_module_without("train")

import bearing_env.train.sb3.train as train_module
from bearing_env.agents.sb3 import load_model
from bearing_env.train.sb3 import train_cli
from bearing_env.train.sb3.callbacks import CheckpointStore, StopOnRequestCallback
from bearing_env.train.sb3.run_record import segments_after_a_kill
from bearing_env.train.sb3.train import TrainSettings, train

REPO_ROOT = Path(__file__).resolve().parents[2]
PYTHON = sys.executable
ROLLOUT = 16  # n_steps * n_envs
BUDGET = 1000  # not a multiple of ROLLOUT: learn() ends at the next boundary, 1008
HYPERPARAMS = {
    "n_steps": 8,
    "batch_size": 16,
    "n_epochs": 1,
    "policy_kwargs": "dict(net_arch=[16])",
}
SEED = 7
CHECKPOINT_FREQ = 32


def cli_arguments(run: Path, *extra: str) -> list[str]:
    return [
        "--algo", "ppo", "--output", str(run), "--vec-env", "dummy", "--n-envs", "2",
        "--timesteps", str(BUDGET), "--seed", str(SEED),
        "--hyperparams", *(f"{key}={value}" for key, value in HYPERPARAMS.items()),
        "--checkpoint-freq", str(CHECKPOINT_FREQ), "--eval-freq", "0",
        "--no-progress", "--no-tensorboard", *extra,
    ]  # fmt: skip


def settings(run: Path, **changes: Any) -> TrainSettings:
    base: dict[str, Any] = {
        "algo": "ppo",
        "env_id": "BearingSLAM-v1",
        "output": run,
        "hyperparam_overrides": dict(HYPERPARAMS),
        "timesteps": BUDGET,
        "seed": SEED,
        "n_envs": 2,
        "vec_env": "dummy",
        "eval_freq": 0,
        "checkpoint_freq": CHECKPOINT_FREQ,
        "progress_bar": False,
        "tensorboard": False,
    }
    return TrainSettings(**{**base, **changes})


def counts(model_path: Path) -> tuple[int, int]:
    model = load_model(model_path, "ppo")
    return int(model._n_updates), int(model.num_timesteps)


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory: pytest.TempPathFactory) -> tuple[int, int]:
    run = tmp_path_factory.mktemp("lost") / "whole"
    train(settings(run))
    return counts(run / "model.zip")


def test_an_uninterrupted_run_trains_on_every_step(uninterrupted: tuple[int, int]) -> None:
    assert uninterrupted == (63, 1008)


def test_sigkill_then_resume_gives_the_uninterrupted_counts(
    tmp_path: Path, uninterrupted: tuple[int, int]
) -> None:
    run = tmp_path / "killed"
    process = subprocess.Popen(
        [PYTHON, "-m", "bearing_env.train.cli", "train", *cli_arguments(run)],
        cwd=REPO_ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    store = CheckpointStore(run / "checkpoints")
    try:
        deadline = time.monotonic() + 60
        while store.latest() is None:
            assert process.poll() is None, process.communicate()[1]
            assert time.monotonic() < deadline, "no checkpoint within 60 s"
            time.sleep(0.01)
        os.killpg(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    assert process.returncode == -signal.SIGKILL
    last = store.latest()
    assert last is not None and 0 < last.timesteps < BUDGET, "killed too late"
    assert not (run / "model.zip").exists()
    # The checkpoint was written after train() consumed its last rollout.
    assert last.timesteps % ROLLOUT == 0
    assert counts(last.model_path) == (last.timesteps // ROLLOUT, last.timesteps)
    left = json.loads((run / "run.json").read_text())
    assert left["status"] == "running"
    # run.json is rewritten just after each checkpoint, so a kill between the two leaves
    # it one checkpoint behind, never ahead.
    assert left["num_timesteps"] in (last.timesteps, last.timesteps - CHECKPOINT_FREQ)
    assert left["segments"][-1]["status"] == "running"

    train_cli.main(["train", *cli_arguments(run, "--resume")][1:])

    assert counts(run / "model.zip") == uninterrupted == (63, 1008)
    record = json.loads((run / "run.json").read_text())
    assert record["status"] == "finished" and record["num_timesteps"] == 1008
    segments = [(s["status"], s["start_timesteps"], s["end_timesteps"]) for s in record["segments"]]
    assert segments == [("killed", 0, last.timesteps), ("finished", last.timesteps, 1008)]


class StopAtCall(StopOnRequestCallback):
    """Sets the stop request at the 13th vec step: in the middle of PPO's second rollout."""

    at_call = 13

    def _on_step(self) -> bool:
        if self.n_calls == self.at_call:
            self.request.set("SIGINT")
        return super()._on_step()


def test_a_stop_mid_rollout_counts_only_trained_steps(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, uninterrupted: tuple[int, int]
) -> None:
    run = tmp_path / "stopped"
    with monkeypatch.context() as patch:
        patch.setattr(train_module, "StopOnRequestCallback", StopAtCall)
        stopped = train(settings(run, checkpoint_freq=10_000))
    # 26 steps were taken, 16 trained on: the checkpoint counts those 16 only.
    assert stopped.interrupted and stopped.num_timesteps == ROLLOUT
    assert stopped.checkpoint is not None and stopped.checkpoint.timesteps == ROLLOUT
    assert counts(stopped.checkpoint.model_path) == (1, ROLLOUT)
    record = json.loads((run / "run.json").read_text())
    assert record["status"] == "interrupted" and record["num_timesteps"] == ROLLOUT
    assert record["segments"][-1]["status"] == "interrupted"

    train(settings(run, checkpoint_freq=10_000, resume=True))
    assert counts(run / "model.zip") == uninterrupted


def test_an_old_record_left_running_gets_its_killed_segment() -> None:
    from bearing_env.train.sb3.callbacks import Checkpoint

    old = {"status": "running", "n_envs": 2, "vec_env": "dummy", "segments": []}
    at = Checkpoint(48, Path("m"), Path("v"), Path("r"))
    segments = segments_after_a_kill(old, at)
    assert segments == [
        {"start_timesteps": 0, "end_timesteps": 48, "n_envs": 2, "vec_env": "dummy",
         "status": "killed"}
    ]  # fmt: skip
    assert segments_after_a_kill({**old, "status": "finished"}, at) == []


DQN_HYPERPARAMS = {
    "learning_starts": 0,
    "train_freq": 4,  # 4 vec steps of 2 envs: an update every 8 env steps
    "gradient_steps": 1,
    "batch_size": 8,
    "buffer_size": 1_000,
    "target_update_interval": 16,
    "policy_kwargs": "dict(net_arch=[16])",
}


def dqn_settings(run: Path, **changes: Any) -> TrainSettings:
    return settings(
        run,
        algo="dqn",
        env_id="BearingSLAMDiscrete-v1",
        hyperparam_overrides=dict(DQN_HYPERPARAMS),
        timesteps=200,
        checkpoint_freq=10_000,
        **changes,
    )


class StopAtDqnCall(StopAtCall):
    at_call = 15


def test_a_dqn_stop_mid_rollout_rewinds_the_replay_buffer(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    train(dqn_settings(tmp_path / "whole"))
    whole = load_model(tmp_path / "whole" / "model.zip", "dqn")
    assert (whole._n_updates, whole.num_timesteps) == (25, 200)

    run = tmp_path / "stopped"
    with monkeypatch.context() as patch:
        # Vec step 15, the third of the fourth rollout: steps 13 and 14 are in the buffer.
        patch.setattr(train_module, "StopOnRequestCallback", StopAtDqnCall)
        stopped = train(dqn_settings(run))
    assert stopped.checkpoint is not None and stopped.num_timesteps == 24  # not 30
    assert stopped.model.replay_buffer.size() == 12  # per env: steps 13 and 14 dropped
    saved = load_model(stopped.checkpoint.model_path, "dqn")
    assert (saved._n_updates, saved.num_timesteps, saved._n_calls) == (3, 24, 12)

    resumed = train(dqn_settings(run, resume=True))
    assert (resumed.model._n_updates, resumed.model.num_timesteps) == (25, 200)
