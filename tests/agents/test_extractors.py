# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""The permutation-invariant landmark-set extractor and its training config."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

from tests.extras import skip_module_without

skip_module_without("train")

import torch

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.agents import SB3Policy
from bearing_env.agents.extractors import LandmarkSetExtractor, LandmarkSetPolicy
from bearing_env.envs.observations import ENTITY_FEATURES
from bearing_env.train.sb3.train import train
from bearing_env.train.sb3.zoo import parse_hyperparameters, read_hyperparameters
from tests.tools.test_train import TINY_TIMESTEPS, tiny_settings

REPO_ROOT = Path(__file__).resolve().parents[2]
CONF_FILE = REPO_ROOT / "train" / "sb3" / "hyperparams" / "ppo_entities.yml"
WIDTH = len(ENTITY_FEATURES)


def entity_batch(max_landmarks: int, seeds: range) -> dict[str, torch.Tensor]:
    env = gym.make(
        "BearingSLAM-v0", n_landmarks=(3, 6), max_landmarks=max_landmarks, observation="entities"
    )
    env.action_space.seed(0)
    robots, tables = [], []
    for seed in seeds:
        observation, _ = env.reset(seed=seed)
        for _ in range(3):
            observation, *_ = env.step(env.action_space.sample())
        robots.append(observation["robot"])
        tables.append(observation["landmarks"])
    return {"robot": torch.tensor(np.array(robots)), "landmarks": torch.tensor(np.array(tables))}


def test_features_ignore_the_order_of_rows_and_the_padding() -> None:
    space = gym.make("BearingSLAM-v0", max_landmarks=8, observation="entities").observation_space
    torch.manual_seed(0)
    extractor = LandmarkSetExtractor(space, hidden=16, features_dim=8)
    batch = entity_batch(8, range(4))
    features = extractor(batch)
    assert features.shape == (4, 8)
    # Any order of the rows (the frame rows are told by is_frame, not by position).
    order = torch.tensor([5, 2, 7, 0, 3, 6, 1, 4])
    table = batch["landmarks"].reshape(4, 8, WIDTH)[:, order].reshape(4, -1)
    shuffled = extractor({"robot": batch["robot"], "landmarks": table})
    torch.testing.assert_close(shuffled, features, rtol=1e-5, atol=1e-6)
    # More empty slots (the same episodes with max_landmarks=16) change nothing.
    wide = entity_batch(16, range(4))
    torch.testing.assert_close(extractor(wide), features, rtol=1e-5, atol=1e-6)
    # But the landmarks themselves do matter.
    moved = batch["landmarks"].reshape(4, 8, WIDTH).clone()
    moved[:, 2, ENTITY_FEATURES.index("x")] += 0.5
    changed = extractor({"robot": batch["robot"], "landmarks": moved.reshape(4, -1)})
    assert not torch.allclose(changed, features)


def test_extractor_refuses_the_flat_observation() -> None:
    flat = gym.make("BearingSLAM-v0").observation_space
    with pytest.raises(TypeError, match="observation='entities'"):
        LandmarkSetExtractor(flat)  # type: ignore[arg-type]


def test_the_entities_config_names_the_policy_class() -> None:
    raw = read_hyperparameters("ppo", "BearingSLAM-v0", CONF_FILE)
    parsed = parse_hyperparameters(raw)
    assert parsed.algorithm_kwargs["policy"] is LandmarkSetPolicy
    assert parsed.env_kwargs["observation"] == "entities"
    assert parsed.normalize is not None and parsed.normalize["norm_obs_keys"] == ["robot"]


def test_a_tiny_run_trains_and_its_model_plays_other_landmark_counts(tmp_path: Path) -> None:
    settings = tiny_settings(
        "ppo",
        tmp_path / "run",
        env_id="BearingSLAM-v0",
        conf_file=CONF_FILE,
        hyperparam_overrides={
            "n_steps": 64,
            "batch_size": 64,
            "n_epochs": 2,
            "policy_kwargs": "dict(features_extractor_kwargs=dict(hidden=16, features_dim=16))",
        },
    )
    result = train(settings)
    assert result.num_timesteps == TINY_TIMESTEPS
    assert isinstance(result.model.policy.features_extractor, LandmarkSetExtractor)
    for count in (3, 16):
        env = gym.make(
            "BearingSLAM-v0",
            n_landmarks=count,
            max_landmarks=16,
            observation="entities",
            max_moves=4,
            max_episode_steps=4,
        )
        policy = SB3Policy(env, result.run_dir / "model.zip")
        observation, info = env.reset(seed=count)
        terminated = truncated = False
        while not (terminated or truncated):
            action = policy.act(observation, info)
            assert env.action_space.contains(action)
            observation, _, terminated, truncated, info = env.step(action)
