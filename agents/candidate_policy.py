"""A policy that scores each candidate move with one shared network, for the
planner-features ids (``planner_features=True``, ``bearing_env.envs.candidates``).

With the planner features the discrete action ``k`` is candidate move ``k``, and the
observation ends with ``K`` rows of :data:`~bearing_env.envs.candidates.CANDIDATE_FEATURES`.
SB3's ``MlpPolicy`` maps the whole vector to ``K`` logits through one linear layer, so it
must learn for every candidate separately that a larger predicted gain is better.
:class:`CandidateScorerPolicy` keeps that layer's job to one network shared by the
candidates instead:

    logit_k = score( latent(observation), features_k )

where ``latent`` is the actor's MLP over the whole (normalised) observation, as in
``MlpPolicy``, and ``score`` a small MLP applied to each candidate's row. Whatever it
learns about one candidate holds for all, and the order of the candidates is only their
index. The value network is ``MlpPolicy``'s. Name it by its dotted path
(``policy: bearing_env.agents.candidate_policy.CandidateScorerPolicy``) in a
hyperparameter file (``train/sb3/hyperparams/ppo_candidates.yml``).
"""

from __future__ import annotations

from typing import Any

import torch
from gymnasium import spaces
from stable_baselines3.common.distributions import Distribution
from stable_baselines3.common.policies import ActorCriticPolicy
from stable_baselines3.common.type_aliases import PyTorchObs
from torch import nn

from bearing_env.envs.candidates import CANDIDATE_FEATURES

#: Width of the candidate scorer's hidden layer.
SCORE_HIDDEN = 64


class CandidateScorer(nn.Module):
    """The logits (batch, K) of K candidates: one MLP over [latent, candidate row]."""

    def __init__(self, latent_dim: int, count: int, width: int, hidden: int) -> None:
        super().__init__()
        self.count, self.width = count, width
        self.score = nn.Sequential(
            nn.Linear(latent_dim + width, hidden), nn.Tanh(), nn.Linear(hidden, 1)
        )

    def forward(self, latent: torch.Tensor, rows: torch.Tensor) -> torch.Tensor:
        rows = rows.reshape(-1, self.count, self.width)
        shared = latent.unsqueeze(1).expand(-1, self.count, -1)
        return self.score(torch.cat([shared, rows], dim=-1)).squeeze(-1)


class CandidateScorerPolicy(ActorCriticPolicy):
    """``MlpPolicy`` (PPO, A2C) whose logits come from :class:`CandidateScorer`: a
    ``Discrete(K)`` action over a flat observation that ends with K candidate rows."""

    def __init__(
        self,
        observation_space: spaces.Space[Any],
        action_space: spaces.Space[Any],
        *args: Any,
        score_hidden: int = SCORE_HIDDEN,
        **kwargs: Any,
    ) -> None:
        if not isinstance(action_space, spaces.Discrete) or not isinstance(
            observation_space, spaces.Box
        ):
            raise TypeError(
                "CandidateScorerPolicy needs a Discrete action (the candidates) and a flat "
                "Box observation that ends with their planner features (planner_features="
                f"True, observation='flat'), got {action_space} and "
                f"{type(observation_space).__name__}"
            )
        self.count, self.width = int(action_space.n), len(CANDIDATE_FEATURES)
        shape = observation_space.shape
        if shape is None or len(shape) != 1 or shape[0] <= self.count * self.width:
            raise TypeError(
                f"an observation of shape {shape} cannot end with the planner features of "
                f"{self.count} candidates ({self.width} each): make the env with "
                "planner_features=True"
            )
        self.score_hidden = int(score_hidden)
        super().__init__(observation_space, action_space, *args, **kwargs)

    def _build(self, lr_schedule: Any) -> None:
        super()._build(lr_schedule)
        latent = self.mlp_extractor.latent_dim_pi
        self.action_net = CandidateScorer(latent, self.count, self.width, self.score_hidden)
        # The optimiser was made over the linear head the scorer replaces.
        self.optimizer = self.optimizer_class(  # type: ignore[call-arg]
            self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs
        )

    def _get_constructor_parameters(self) -> dict[str, Any]:
        return {**super()._get_constructor_parameters(), "score_hidden": self.score_hidden}

    def _latents(self, obs: PyTorchObs) -> tuple[torch.Tensor, torch.Tensor]:
        """The actor's and the critic's latents, as ``ActorCriticPolicy.forward`` makes them."""
        features = self.extract_features(obs)
        if isinstance(features, torch.Tensor):  # one extractor for both
            return self.mlp_extractor(features)
        pi_features, vf_features = features
        return self.mlp_extractor.forward_actor(pi_features), self.mlp_extractor.forward_critic(
            vf_features
        )

    def _distribution(self, obs: PyTorchObs, latent_pi: torch.Tensor) -> Distribution:
        if not isinstance(obs, torch.Tensor):
            raise TypeError("CandidateScorerPolicy reads a flat observation")
        rows = obs.float()[..., -self.count * self.width :]
        return self.action_dist.proba_distribution(action_logits=self.action_net(latent_pi, rows))

    def forward(
        self, obs: PyTorchObs, deterministic: bool = False
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        latent_pi, latent_vf = self._latents(obs)
        distribution = self._distribution(obs, latent_pi)
        actions = distribution.get_actions(deterministic=deterministic)
        return actions, self.value_net(latent_vf), distribution.log_prob(actions)

    def evaluate_actions(
        self, obs: PyTorchObs, actions: torch.Tensor
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor | None]:
        latent_pi, latent_vf = self._latents(obs)
        distribution = self._distribution(obs, latent_pi)
        return self.value_net(latent_vf), distribution.log_prob(actions), distribution.entropy()

    def get_distribution(self, obs: PyTorchObs) -> Distribution:
        features = super().extract_features(obs, self.pi_features_extractor)
        assert isinstance(features, torch.Tensor)  # one extractor's output
        return self._distribution(obs, self.mlp_extractor.forward_actor(features))
