# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""The permutation-invariant extractors (deep set, attention) and their training configs."""

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
from bearing_env.agents.extractors import (
    LandmarkAttentionExtractor,
    LandmarkAttentionPolicy,
    LandmarkSetExtractor,
    LandmarkSetPolicy,
    table_width,
)
from bearing_env.envs.observations import ENTITY_FEATURES
from bearing_env.train.sb3.train import train
from bearing_env.train.sb3.zoo import default_env_id, parse_hyperparameters, read_hyperparameters
from tests.tools.test_train import TINY_TIMESTEPS, tiny_settings

REPO_ROOT = Path(__file__).resolve().parents[2]
HYPERPARAMS = REPO_ROOT / "train" / "sb3" / "hyperparams"
CONF_FILE = HYPERPARAMS / "ppo_entities.yml"
WIDTH = len(ENTITY_FEATURES)
EXTRACTORS = (LandmarkSetExtractor, LandmarkAttentionExtractor)
#: Each extractor's policy, shipped hyperparameter file and observation kind.
CONFIGS = (
    (LandmarkSetExtractor, LandmarkSetPolicy, HYPERPARAMS / "ppo_entities.yml", "entities"),
    (
        LandmarkAttentionExtractor,
        LandmarkAttentionPolicy,
        HYPERPARAMS / "ppo_attention.yml",
        "entities",
    ),
    (LandmarkSetExtractor, LandmarkSetPolicy, HYPERPARAMS / "ppo_shapes.yml", "shapes"),
)
CONFIG_FIELDS = ("extractor_class", "policy_class", "conf_file", "kind")


def entity_batch(max_landmarks: int, seeds: range) -> dict[str, torch.Tensor]:
    env = gym.make(
        "BearingSLAM-v1", n_landmarks=(3, 6), max_landmarks=max_landmarks, observation="entities"
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


@pytest.mark.parametrize("extractor_class", EXTRACTORS)
def test_features_ignore_the_order_of_rows_and_the_padding(extractor_class: type) -> None:
    space = gym.make("BearingSLAM-v1", max_landmarks=8, observation="entities").observation_space
    torch.manual_seed(0)
    extractor = extractor_class(space, hidden=16, features_dim=8).eval()
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


@pytest.mark.parametrize("extractor_class", EXTRACTORS)
def test_extractor_refuses_the_flat_observation(extractor_class: type) -> None:
    flat = gym.make("BearingSLAM-v1").observation_space
    with pytest.raises(
        TypeError, match=f"{extractor_class.__name__} needs .*observation='entities'"
    ):
        extractor_class(flat)


@pytest.mark.parametrize("extractor_class", EXTRACTORS)
@pytest.mark.parametrize(("kind", "told"), [("shapes", "entities"), ("entities", "shapes")])
def test_extractor_refuses_a_table_of_another_kind(
    extractor_class: type, kind: str, told: str
) -> None:
    # 8 slots: 88 shape values are also 11 rows of 8, so the row size alone would pass.
    space = gym.make("BearingSLAM-v1", max_landmarks=8, observation=kind).observation_space
    with pytest.raises(ValueError, match=f"not rows of {table_width(told)} columns"):
        extractor_class(space, hidden=16, features_dim=8, observation=told)
    with pytest.raises(ValueError, match=r"observation must be one of .*got 'flat'"):
        extractor_class(space, hidden=16, features_dim=8, observation="flat")
    extractor_class(space, hidden=16, features_dim=8, observation=kind)


def test_attention_heads_must_divide_the_width() -> None:
    space = gym.make("BearingSLAM-v1", observation="entities").observation_space
    with pytest.raises(
        ValueError, match=r"hidden \(10\) must be a positive multiple of heads \(4\)"
    ):
        LandmarkAttentionExtractor(space, hidden=10, heads=4)


def test_attention_features_of_an_empty_table_are_finite() -> None:
    space = gym.make("BearingSLAM-v1", max_landmarks=8, observation="entities").observation_space
    torch.manual_seed(0)
    extractor = LandmarkAttentionExtractor(space, hidden=16, features_dim=8).eval()
    batch = entity_batch(8, range(2))
    empty = torch.zeros_like(batch["landmarks"])  # no present row at all
    features = extractor({"robot": batch["robot"], "landmarks": empty})
    assert torch.isfinite(features).all()


@pytest.mark.parametrize(CONFIG_FIELDS, CONFIGS)
def test_the_entities_configs_name_their_policy_class(
    extractor_class: type, policy_class: type, conf_file: Path, kind: str
) -> None:
    env_id = default_env_id("ppo", conf_file)  # the entry's key: a task id of that observation
    raw = read_hyperparameters("ppo", env_id, conf_file)
    parsed = parse_hyperparameters(raw)
    assert parsed.algorithm_kwargs["policy"] is policy_class
    assert gym.spec(env_id).kwargs["observation"] == kind
    extractor_kwargs = parsed.algorithm_kwargs["policy_kwargs"]["features_extractor_kwargs"]
    assert extractor_kwargs.get("observation", "entities") == kind
    assert parsed.normalize is not None and parsed.normalize["norm_obs_keys"] == ["robot"]


@pytest.mark.parametrize(CONFIG_FIELDS, CONFIGS)
def test_a_tiny_run_trains_and_its_model_plays_other_landmark_counts(
    tmp_path: Path, extractor_class: type, policy_class: type, conf_file: Path, kind: str
) -> None:
    settings = tiny_settings(
        "ppo",
        tmp_path / "run",
        env_id=default_env_id("ppo", conf_file),
        conf_file=conf_file,
        hyperparam_overrides={
            "n_steps": 64,
            "batch_size": 64,
            "n_epochs": 2,
            "policy_kwargs": "dict(features_extractor_kwargs=dict(hidden=16, features_dim=16, "
            f"observation={kind!r}))",
        },
    )
    result = train(settings)
    assert result.num_timesteps == TINY_TIMESTEPS
    assert type(result.model.policy.features_extractor) is extractor_class
    for count in (3, 16):
        env = gym.make(
            "BearingSLAM-v1",
            n_landmarks=count,
            max_landmarks=16,
            observation=kind,
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
