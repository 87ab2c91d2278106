"""The models shipped under agents/pretrained/ still fit the envs they were trained on."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.agents import SB3Policy, pretrained_names, pretrained_record
from bearing_env.agents.sb3 import PRETRAINED_DIR
from tests.extras import needs

SHIPPED = ("ppo_khepera", "ppo_random", "ppo_generalist")


def test_the_shipped_models_are_listed() -> None:
    assert set(SHIPPED) <= set(pretrained_names())


@needs("train", "stable_baselines3", "torch")
@pytest.mark.parametrize("name", SHIPPED)
def test_a_shipped_model_acts_on_the_env_of_its_record(name: str) -> None:
    # A change to the observation or action layout would break the shipped models: the
    # spaces are checked on load, and the policy must drive a whole episode.
    record = pretrained_record(name)
    env = gym.make(record["env_id"], **record["env_kwargs"])
    policy = SB3Policy.pretrained(name, env)
    policy.reset(seed=0)
    observation, info = env.reset(seed=1_000_000)
    done, moves = False, 0
    while not done:
        action = policy.act(observation, info)
        assert env.action_space.contains(action)
        observation, _, terminated, truncated, info = env.step(action)
        done, moves = terminated or truncated, moves + 1
    assert moves >= 1 and np.isfinite(info["total_area"])
    env.close()


@needs("train", "stable_baselines3", "torch")
@pytest.mark.parametrize("name", SHIPPED)
def test_a_shipped_model_acts_alike_on_the_vector_env(name: str) -> None:
    # Sub-env i of the batched vector env acts as the single env seeded seed + i does.
    from bearing_env.agents import VectorPolicy

    record = pretrained_record(name)
    vector_env = gym.make_vec(record["env_id"], num_envs=2, **record["env_kwargs"])
    policy = VectorPolicy(vector_env, lambda env: SB3Policy.pretrained(name, env))
    observations, infos = vector_env.reset(seed=1_000_000)
    policy.reset(seed=1_000_000)
    batches = []
    for _ in range(3):
        batch = policy.act(observations, infos)
        assert vector_env.action_space.contains(batch)
        batches.append(np.asarray(batch))
        observations, _, _, _, infos = vector_env.step(batch)
    single = gym.make(record["env_id"], **record["env_kwargs"])
    for row in range(2):
        one = SB3Policy.pretrained(name, single)
        one.reset(seed=1_000_000 + row)
        observation, info = single.reset(seed=1_000_000 + row)
        for batch in batches:
            action = one.act(observation, info)
            np.testing.assert_allclose(np.asarray(action), batch[row], rtol=1e-5, atol=1e-6)
            observation, _, terminated, truncated, info = single.step(action)
            if terminated or truncated:
                break
    vector_env.close()


@needs("train", "stable_baselines3", "torch")
@pytest.mark.parametrize("count", [3, 16])
def test_the_generalist_runs_on_counts_outside_its_training_range(count: int) -> None:
    # Trained on 3 to 16 landmarks; its deep set reads any count (more slots beyond 16).
    record = pretrained_record("ppo_generalist")
    assert record["env_kwargs"]["n_landmarks"] == [3, 16]
    assert record["env_kwargs"]["max_landmarks"] == 16
    env = gym.make(record["env_id"], **{**record["env_kwargs"], "n_landmarks": count})
    policy = SB3Policy.pretrained("ppo_generalist", env)
    policy.reset(seed=0)
    observation, info = env.reset(seed=1_000_000)
    first_area = info["total_area"]
    for _ in range(10):
        observation, _, terminated, truncated, info = env.step(policy.act(observation, info))
        if terminated or truncated:
            break
    assert len(info["landmark_area"]) == count - 2
    assert np.all(np.isfinite(info["landmark_area"]))  # every landmark got a region
    assert info["total_area"] < first_area
    env.close()


@needs("train", "stable_baselines3", "torch")
def test_generalisation_table_covers_every_policy_count_and_model(tmp_path: Path) -> None:
    # A second model: an exported copy of the first (a .zip with its record), on the
    # same envs, so the study reuses the first model's baselines for it.
    for suffix in (".zip", ".json", "_vecnormalize.pkl"):
        shutil.copyfile(PRETRAINED_DIR / f"ppo_random{suffix}", tmp_path / f"copy{suffix}")
    out = tmp_path / "generalisation"
    command = [sys.executable, "-m", "bearing_env.train.studies.generalisation",
               "--model", "ppo_random", str(tmp_path / "copy.zip"), "--counts", "3",
               "--episodes", "1", "--workers", "1", "--out", str(out)]  # fmt: skip
    result = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    results = json.loads((out / "generalisation.json").read_text())
    assert set(results) == {"ppo_random", "copy"} and set(results["ppo_random"]) == {"3"}
    figures = results["ppo_random"]["3"]
    baselines = {"random_polygonal", "parallax", "greedy_one_step", "lookahead"}
    assert set(figures) == baselines | {"ppo_random"}
    for values in figures.values():
        assert set(values) == {"median", "p90", "worst5_mean"}
        # One episode: its area is the median, the 90th percentile and the worst 5%.
        assert np.isfinite(values["median"]) and values["median"] > 0
        assert values["median"] == values["p90"] == values["worst5_mean"]
    copied = results["copy"]["3"]
    assert set(copied) == baselines | {"copy"}
    assert all(copied[label] == figures[label] for label in baselines)
    assert copied["copy"] == figures["ppo_random"]  # the same weights on the same episode
    # The copy's comparison ran the model alone: the baselines were not run again.
    ran = json.loads((out / "copy" / "n3" / "config.json").read_text())
    assert [spec.split(",label=")[-1] for spec in ran["policies"]] == ["copy"]
    assert (out / "generalisation.png").stat().st_size > 10_000


def test_generalisation_names_a_model_it_cannot_find(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "bearing_env.train.studies.generalisation", "--model",
         str(tmp_path / "missing.zip")],
        capture_output=True,
        text=True,
        timeout=120,
    )  # fmt: skip
    assert result.returncode == 2
    assert "unknown model" in result.stderr and "missing.zip" in result.stderr


@pytest.mark.parametrize(
    ("model", "slots"),
    # ppo_khepera's record names no count or slots: the env's defaults (4, 8 slots) apply.
    # ppo_generalist is a set policy: it runs on any count (below).
    [("ppo_random", 10), ("ppo_khepera", 8)],
)
def test_generalisation_rejects_counts_beyond_the_observation_slots(model: str, slots: int) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "bearing_env.train.studies.generalisation", "--model", model,
         "--counts", "3", str(slots + 1)],
        capture_output=True,
        text=True,
        timeout=120,
    )  # fmt: skip
    assert result.returncode == 2
    assert f"--counts must lie in [3, {slots}]" in result.stderr


def test_generalisation_gives_a_set_policy_the_slots_a_count_needs() -> None:
    from bearing_env.train.studies.generalisation import env_kwargs_for_count

    trained = {"scenario": "random", "n_landmarks": [3, 12], "max_landmarks": 16}
    assert env_kwargs_for_count(trained, 8, 16) == {**trained, "n_landmarks": 8}
    assert env_kwargs_for_count(trained, 24, 16) == {
        **trained, "n_landmarks": 24, "max_landmarks": 24,
    }  # fmt: skip
    assert env_kwargs_for_count(trained, 24) == {**trained, "n_landmarks": 24}


def test_models_trained_on_other_counts_share_the_studys_envs() -> None:
    from bearing_env.agents.model_task import ModelTask
    from bearing_env.train.studies.generalisation import StudyModel, baseline_envs, study_envs

    def model(**kwargs: object) -> StudyModel:
        trained = {"scenario": "random", "max_landmarks": 16, "observation": "entities", **kwargs}
        return StudyModel("m", "spec", ModelTask("BearingSLAM-v0", trained))

    counts = [3, 8, 24]
    narrow, wide = model(n_landmarks=[3, 12]), model(n_landmarks=[3, 16])
    assert study_envs(narrow, counts) == study_envs(wide, counts)  # the count is replaced
    assert study_envs(wide, counts)[2]["max_landmarks"] == 24
    assert study_envs(model(n_landmarks=[3, 12], max_landmarks=12), counts) != study_envs(
        narrow, counts
    )
    # The baselines' episodes do not depend on the observation kind.
    shapes = model(n_landmarks=[3, 16], observation="shapes")
    assert study_envs(shapes, counts) != study_envs(wide, counts)
    assert baseline_envs(shapes, counts) == baseline_envs(wide, counts)
    assert baseline_envs(model(n_landmarks=[3, 12], max_landmarks=12), counts) != baseline_envs(
        narrow, counts
    )
