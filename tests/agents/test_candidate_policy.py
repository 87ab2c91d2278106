"""The candidate scorer: one network shared by the candidates, trained by PPO, saved and
loaded as any SB3 policy."""

from __future__ import annotations

from pathlib import Path

import gymnasium as gym
import pytest

from tests.extras import skip_module_without

skip_module_without("train")

import torch  # noqa: E402
from stable_baselines3 import PPO  # noqa: E402

import bearing_env  # noqa: E402,F401  (registers the ids)
from bearing_env.agents.candidate_policy import CandidateScorer, CandidateScorerPolicy  # noqa: E402

KHEPERA = "bearing_env:BearingSLAMDiscrete-Khepera-Planner-v1"


def test_permuting_the_candidates_permutes_their_logits() -> None:
    torch.manual_seed(0)
    scorer = CandidateScorer(latent_dim=6, count=16, width=5, hidden=8)
    latent, rows = torch.randn(3, 6), torch.randn(3, 16, 5)
    order = torch.randperm(16)
    logits = scorer(latent, rows.reshape(3, -1))
    permuted = scorer(latent, rows[:, order].reshape(3, -1))
    torch.testing.assert_close(permuted, logits[:, order])
    # Equal rows score equally: one network for all of them.
    same = scorer(latent, rows[:, :1].expand(-1, 16, -1).reshape(3, -1))
    torch.testing.assert_close(same, same[:, :1].expand(-1, 16))


def test_ppo_trains_it_and_a_saved_model_acts_the_same(tmp_path: Path) -> None:
    env = gym.make(KHEPERA)
    model = PPO(
        CandidateScorerPolicy, env, n_steps=64, batch_size=32, n_epochs=2, seed=1,
        policy_kwargs={"net_arch": [16], "score_hidden": 8}, device="cpu",
    )  # fmt: skip
    assert isinstance(model.policy.action_net, CandidateScorer)
    optimised = {id(p) for group in model.policy.optimizer.param_groups for p in group["params"]}
    assert all(id(p) in optimised for p in model.policy.action_net.parameters())
    before = [p.detach().clone() for p in model.policy.action_net.parameters()]
    model.learn(128)
    after = list(model.policy.action_net.parameters())
    assert any(not torch.equal(a, b) for a, b in zip(before, after, strict=True))
    model.save(tmp_path / "model.zip")
    loaded = PPO.load(tmp_path / "model.zip", device="cpu")
    assert loaded.policy.score_hidden == 8
    observation, _ = env.reset(seed=3)
    for _ in range(5):
        action, _ = model.predict(observation, deterministic=True)
        assert loaded.predict(observation, deterministic=True)[0] == action
        observation, *_ = env.step(int(action))


def test_it_refuses_an_observation_without_candidates() -> None:
    env = gym.make("bearing_env:BearingSLAMDiscrete-Khepera-v1")
    with pytest.raises(TypeError, match="planner_features"):
        PPO(CandidateScorerPolicy, env, device="cpu")


def test_its_saved_model_is_read_as_ppo(tmp_path: Path) -> None:
    from bearing_env.agents.sb3 import infer_algorithm

    env = gym.make(KHEPERA)
    model = PPO(CandidateScorerPolicy, env, n_steps=16, batch_size=16, device="cpu")
    model.save(tmp_path / "model.zip")
    assert infer_algorithm(tmp_path / "model.zip") == "PPO"
