"""A permutation-invariant features extractor over the entity observation, for SB3.

With ``observation="entities"`` the env's observation is a ``Dict`` of the robot block
and a landmark table, one row per landmark slot (see the env's Observation Space
section). :class:`LandmarkSetExtractor` is a deep set over that table:

    features = rho( robot_mlp(robot), mean_i phi(row_i, robot), max_i phi(row_i, robot) )

with the mean and max over the *present* rows only (the table's ``present`` column). The
output does not depend on the order of the rows, nor on how many empty slots pad the
table, so one network runs on any landmark count up to the table's size, and a model
trained on ``max_landmarks = M`` reads tables of any other size the same way (it sees
rows, not slots). L1 and L2 are told apart by their ``is_frame`` column, not by position.

Keep the table out of ``VecNormalize`` (``norm_obs_keys=["robot"]``): normalising the
``present`` column would break the mask. The table's log-areas (down to ``log(1e-10)``)
are scaled by :data:`LOG_AREA_SCALE` here instead.

:class:`LandmarkSetPolicy` is SB3's ``MultiInputPolicy`` with this extractor: name it by
its dotted path (``policy: bearing_env.agents.extractors.LandmarkSetPolicy``) in a
hyperparameter file, for ``bearing-env train`` and rl-zoo3 alike
(``train/sb3/hyperparams/ppo_entities.yml``).
"""

from __future__ import annotations

from typing import Any

import torch
from gymnasium import spaces
from stable_baselines3.common.policies import MultiInputActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from bearing_env.envs.observations import ENTITY_FEATURES

#: The log-area column is divided by this (log-areas span about [-23, 14]).
LOG_AREA_SCALE = 10.0
_PRESENT = ENTITY_FEATURES.index("present")
_LOG_AREA = ENTITY_FEATURES.index("log_area")


class LandmarkSetExtractor(BaseFeaturesExtractor):
    """Deep-set features of an entity observation (see the module doc).

    Args:
        observation_space: the env's ``Dict`` space (keys ``"robot"``, ``"landmarks"``).
        hidden: width of the per-landmark encoder phi and of the robot encoder.
        features_dim: size of the output features.
    """

    def __init__(
        self, observation_space: spaces.Dict, hidden: int = 64, features_dim: int = 128
    ) -> None:
        if not isinstance(observation_space, spaces.Dict) or set(observation_space.spaces) != {
            "robot",
            "landmarks",
        }:
            raise TypeError(
                "LandmarkSetExtractor needs the entity observation (a Dict of 'robot' and "
                f"'landmarks': pass observation='entities' to the env), got {observation_space}"
            )
        if int(hidden) < 1 or int(features_dim) < 1:
            raise ValueError(f"hidden and features_dim must be >= 1, got {hidden}, {features_dim}")
        super().__init__(observation_space, int(features_dim))
        robot_space = observation_space["robot"]
        robot_dim = int(robot_space.shape[0]) if robot_space.shape else 0
        self.width = len(ENTITY_FEATURES)
        hidden = int(hidden)
        self.phi = nn.Sequential(
            nn.Linear(self.width + robot_dim, hidden),
            nn.ReLU(),
            nn.Linear(hidden, hidden),
            nn.ReLU(),
        )
        self.robot = nn.Sequential(nn.Linear(robot_dim, hidden), nn.ReLU())
        self.rho = nn.Sequential(nn.Linear(3 * hidden, int(features_dim)), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        robot = observations["robot"].float()
        table = observations["landmarks"].float().reshape(robot.shape[0], -1, self.width)
        scale = torch.ones(self.width, device=table.device)
        scale[_LOG_AREA] = 1.0 / LOG_AREA_SCALE
        table = table * scale
        present = (table[..., _PRESENT] > 0.5).unsqueeze(-1)  # (batch, rows, 1)
        context = robot.unsqueeze(1).expand(-1, table.shape[1], -1)
        encoded = self.phi(torch.cat([table, context], dim=-1))
        count = present.sum(dim=1).clamp(min=1)
        mean = (encoded * present).sum(dim=1) / count
        lowest = torch.finfo(encoded.dtype).min
        largest = torch.where(present, encoded, torch.full_like(encoded, lowest)).amax(dim=1)
        largest = torch.where(present.any(dim=1), largest, torch.zeros_like(largest))
        return self.rho(torch.cat([self.robot(robot), mean, largest], dim=-1))


class LandmarkSetPolicy(MultiInputActorCriticPolicy):
    """SB3's ``MultiInputPolicy`` (PPO, A2C) with :class:`LandmarkSetExtractor` by default."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("features_extractor_class", LandmarkSetExtractor)
        super().__init__(*args, **kwargs)
