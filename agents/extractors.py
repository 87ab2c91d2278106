"""Permutation-invariant features extractors over the entity observation, for SB3.

With ``observation="entities"`` the env's observation is a ``Dict`` of the robot block
and a landmark table, one row per landmark slot (see the env's Observation Space
section). Two extractors read that table as a set.

:class:`LandmarkSetExtractor` is a deep set over it:

    features = rho( robot_mlp(robot), mean_i phi(row_i, robot), max_i phi(row_i, robot) )

with the mean and max over the *present* rows only (the table's ``present`` column). The
output does not depend on the order of the rows, nor on how many empty slots pad the
table, so one network runs on any landmark count up to the table's size, and a model
trained on ``max_landmarks = M`` reads tables of any other size the same way (it sees
rows, not slots). L1 and L2 are told apart by their ``is_frame`` column, not by position.

Keep the table out of ``VecNormalize`` (``norm_obs_keys=["robot"]``): normalising the
``present`` column would break the mask. The table's log-areas (down to ``log(1e-10)``)
are scaled by :data:`LOG_AREA_SCALE` here instead.

:class:`LandmarkAttentionExtractor` lets the landmarks attend to one another first (a
self-attention block over the present rows, so a landmark's features can depend on the
others: which are already small, which share a direction), then pools them with the
robot as the query token (attention weights over the present rows), beside their mean:

    h = block(embed(rows))                      # self-attention + feed-forward, masked
    features = rho( robot_mlp(robot), attend(query(robot), h), mean_i h_i )

It has the deep set's invariances: the order of the rows and the padding change nothing.

:class:`LandmarkSetPolicy` and :class:`LandmarkAttentionPolicy` are SB3's
``MultiInputPolicy`` with each extractor: name one by its dotted path (``policy:
bearing_env.agents.extractors.LandmarkSetPolicy``) in a hyperparameter file, for
``bearing-env train`` and rl-zoo3 alike (``train/sb3/hyperparams/ppo_entities.yml`` and
``ppo_attention.yml``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import torch
from gymnasium import spaces
from stable_baselines3.common.policies import MultiInputActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from bearing_env.envs.observations import ENTITY_FEATURES, SPECS, EntityObservation

#: The log-area column is divided by this (log-areas span about [-23, 14]).
LOG_AREA_SCALE = 10.0
_PRESENT = ENTITY_FEATURES.index("present")
_LOG_AREA = ENTITY_FEATURES.index("log_area")


def table_width(observation: str) -> int:
    """The landmark table's columns in observation kind ``observation`` (``"entities"``
    or ``"shapes"``; ValueError for a kind without a table)."""
    spec = SPECS.get(observation)
    if not isinstance(spec, EntityObservation):
        kinds = [kind for kind, spec in SPECS.items() if isinstance(spec, EntityObservation)]
        raise ValueError(
            f"observation must be one of {kinds} (a landmark table), got {observation!r}"
        )
    return len(spec.features)


def _check_entity_space(
    extractor: str, observation_space: spaces.Dict, hidden: int, features_dim: int, width: int
) -> int:
    """The robot block's size, after checking the space is the entity observation with
    ``width`` columns per table row."""
    if not isinstance(observation_space, spaces.Dict) or set(observation_space.spaces) != {
        "robot",
        "landmarks",
    }:
        raise TypeError(
            f"{extractor} needs the entity observation (a Dict of 'robot' and "
            f"'landmarks': pass observation='entities' to the env), got {observation_space}"
        )
    if int(hidden) < 1 or int(features_dim) < 1:
        raise ValueError(f"hidden and features_dim must be >= 1, got {hidden}, {features_dim}")
    # Every row of a table has the same bounds: rows of another width would not.
    table = observation_space["landmarks"]
    high = np.asarray(getattr(table, "high", ()), dtype=np.float64).ravel()
    if high.size % width or not (high.reshape(-1, width) == high[:width]).all():
        raise ValueError(
            f"{extractor}: the landmark table ({high.size} values) is not rows of {width} "
            "columns: pass the env's observation kind as observation= ('entities' or 'shapes')"
        )
    robot_space = observation_space["robot"]
    return int(robot_space.shape[0]) if robot_space.shape else 0


def _robot_and_table(
    observations: dict[str, torch.Tensor], width: int
) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """The robot block (batch, robot), the scaled table (batch, rows, ``width``) and the
    present mask (batch, rows, 1)."""
    robot = observations["robot"].float()
    table = observations["landmarks"].float().reshape(robot.shape[0], -1, width)
    scale = torch.ones(width, device=table.device)
    scale[_LOG_AREA] = 1.0 / LOG_AREA_SCALE
    table = table * scale
    present = (table[..., _PRESENT] > 0.5).unsqueeze(-1)
    return robot, table, present


def _masked_mean(encoded: torch.Tensor, present: torch.Tensor) -> torch.Tensor:
    """The mean over the present rows (zeros for a table with none)."""
    count = present.sum(dim=1).clamp(min=1)
    return (encoded * present).sum(dim=1) / count


class LandmarkSetExtractor(BaseFeaturesExtractor):
    """Deep-set features of an entity observation (see the module doc).

    Args:
        observation_space: the env's ``Dict`` space (keys ``"robot"``, ``"landmarks"``).
        hidden: width of the per-landmark encoder phi and of the robot encoder.
        features_dim: size of the output features.
        observation: the env's observation kind, ``"entities"`` or ``"shapes"`` (its
            table has three more columns).
    """

    def __init__(
        self,
        observation_space: spaces.Dict,
        hidden: int = 64,
        features_dim: int = 128,
        observation: str = "entities",
    ) -> None:
        width = table_width(observation)
        robot_dim = _check_entity_space(
            "LandmarkSetExtractor", observation_space, hidden, features_dim, width
        )
        super().__init__(observation_space, int(features_dim))
        self.width = width
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
        robot, table, present = _robot_and_table(observations, self.width)
        context = robot.unsqueeze(1).expand(-1, table.shape[1], -1)
        encoded = self.phi(torch.cat([table, context], dim=-1))
        mean = _masked_mean(encoded, present)
        lowest = torch.finfo(encoded.dtype).min
        largest = torch.where(present, encoded, torch.full_like(encoded, lowest)).amax(dim=1)
        largest = torch.where(present.any(dim=1), largest, torch.zeros_like(largest))
        return self.rho(torch.cat([self.robot(robot), mean, largest], dim=-1))


class LandmarkAttentionExtractor(BaseFeaturesExtractor):
    """Attention features of an entity observation: self-attention over the landmarks,
    then the robot as the query token (see the module doc).

    Args:
        observation_space: the env's ``Dict`` space (keys ``"robot"``, ``"landmarks"``).
        hidden: width of the landmark embeddings (a multiple of ``heads``).
        features_dim: size of the output features.
        heads: attention heads.
        observation: the env's observation kind, ``"entities"`` or ``"shapes"``.
    """

    def __init__(
        self,
        observation_space: spaces.Dict,
        hidden: int = 64,
        features_dim: int = 128,
        heads: int = 4,
        observation: str = "entities",
    ) -> None:
        width = table_width(observation)
        robot_dim = _check_entity_space(
            "LandmarkAttentionExtractor", observation_space, hidden, features_dim, width
        )
        hidden, heads = int(hidden), int(heads)
        if heads < 1 or hidden % heads:
            raise ValueError(f"hidden ({hidden}) must be a positive multiple of heads ({heads})")
        super().__init__(observation_space, int(features_dim))
        self.width = width
        self.embed = nn.Sequential(nn.Linear(width + robot_dim, hidden), nn.ReLU())
        self.self_attention = nn.MultiheadAttention(hidden, heads, batch_first=True)
        self.norm_attention = nn.LayerNorm(hidden)
        self.feed_forward = nn.Sequential(
            nn.Linear(hidden, 2 * hidden), nn.ReLU(), nn.Linear(2 * hidden, hidden)
        )
        self.norm_feed_forward = nn.LayerNorm(hidden)
        self.robot = nn.Sequential(nn.Linear(robot_dim, hidden), nn.ReLU())
        self.query = nn.Linear(hidden, hidden)
        self.pool = nn.MultiheadAttention(hidden, heads, batch_first=True)
        self.rho = nn.Sequential(nn.Linear(3 * hidden, int(features_dim)), nn.ReLU())

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        robot, table, present = _robot_and_table(observations, self.width)
        context = robot.unsqueeze(1).expand(-1, table.shape[1], -1)
        rows = self.embed(torch.cat([table, context], dim=-1))
        # A table with no present row would leave attention nothing to weigh (NaN): let
        # it attend to its first (empty) row, and zero what comes out below.
        any_present = present.any(dim=1)  # (batch, 1)
        ignored = ~present.squeeze(-1)
        ignored[:, 0] &= any_present.squeeze(-1)
        attended, _ = self.self_attention(rows, rows, rows, key_padding_mask=ignored)
        rows = self.norm_attention(rows + attended)
        rows = self.norm_feed_forward(rows + self.feed_forward(rows))
        robot_features = self.robot(robot)
        query = self.query(robot_features).unsqueeze(1)
        pooled, _ = self.pool(query, rows, rows, key_padding_mask=ignored)
        pooled = torch.where(any_present, pooled.squeeze(1), torch.zeros_like(pooled.squeeze(1)))
        mean = _masked_mean(rows, present)
        return self.rho(torch.cat([robot_features, pooled, mean], dim=-1))


class LandmarkSetPolicy(MultiInputActorCriticPolicy):
    """SB3's ``MultiInputPolicy`` (PPO, A2C) with :class:`LandmarkSetExtractor` by default."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("features_extractor_class", LandmarkSetExtractor)
        super().__init__(*args, **kwargs)


class LandmarkAttentionPolicy(MultiInputActorCriticPolicy):
    """SB3's ``MultiInputPolicy`` (PPO, A2C) with :class:`LandmarkAttentionExtractor` by
    default."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("features_extractor_class", LandmarkAttentionExtractor)
        super().__init__(*args, **kwargs)
