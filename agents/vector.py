"""Policies on vector envs: one policy per sub-env, a batched ``act``.

A vector env returns observations stacked along a first axis and infos batched key by key
(Gymnasium 1.x: ``infos[key][i]`` is sub-env ``i``'s value where ``infos["_" + key][i]``).
:class:`VectorPolicy` keeps one policy per sub-env (each has its own belief about its
robot), hands each its row of the observations and of the infos, and stacks the actions.
It works on :class:`~bearing_env.envs.bearing_slam_vector.BearingSLAMVectorEnv` and on
Gymnasium's own ``gym.make_vec`` of either id, since the policies only read the
observation and ``info["robot_map"]`` (privileged ones also read their sub-env's
``world``, through ``get_attr("world")``).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any, cast

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from bearing_env.envs.bearing_slam import BearingSLAMEnv
from bearing_env.envs.bearing_slam_discrete import BearingSLAMDiscreteEnv
from bearing_env.envs.core import WorldView

from .base import Policy

#: Keys of batched infos that are not one row per sub-env's own info.
_NOT_ROW_KEYS = ("final_obs", "final_info")


def info_row(infos: dict[str, Any], row: int) -> dict[str, Any]:
    """Sub-env ``row``'s info from a vector env's batched infos (nested dicts included;
    the ``_key`` masks and the autoreset's ``final_obs``/``final_info`` are left out)."""
    info: dict[str, Any] = {}
    for key, value in infos.items():
        if key.startswith("_") or key in _NOT_ROW_KEYS:
            continue
        mask = infos.get(f"_{key}")
        if mask is not None and not bool(mask[row]):
            continue
        info[key] = info_row(value, row) if isinstance(value, dict) else value[row]
    return info


def _observation_row(observations: Any, row: int) -> Any:
    if isinstance(observations, Mapping):
        return {key: value[row] for key, value in observations.items()}
    return observations[row]


def sub_env_template(vector_env: gym.vector.VectorEnv, row: int) -> BearingSLAMEnv:
    """A single env with sub-env ``row``'s settings (never stepped): what a policy is
    built from, to read the settings and spaces."""
    config = _sub_env_attribute(vector_env, "config", row)
    discrete = isinstance(vector_env.single_action_space, spaces.Discrete)
    env_class = BearingSLAMDiscreteEnv if discrete else BearingSLAMEnv
    return env_class(config=config)


class VectorPolicy:
    """One policy per sub-env of ``vector_env``, driven with batched observations and infos.

    Args:
        vector_env: a vector env of either id (``BearingSLAMVectorEnv`` or ``gym.make_vec``).
        factory: builds one policy from a single env with a sub-env's settings, e.g. a
            policy class (``GreedyOneStep``) or ``lambda env: make_policy(spec, env)``.

    ``reset(seeds)`` takes one seed for all (sub-env ``i`` gets ``seed + i``, as the vector
    env's ``reset`` does) or one per sub-env. A sub-env that autoresets starts its new
    episode from an observation with progress 0, which resets its policy's belief; its
    random stream goes on.
    """

    def __init__(
        self, vector_env: gym.vector.VectorEnv, factory: Callable[[gym.Env], Policy]
    ) -> None:
        if not isinstance(vector_env, gym.vector.VectorEnv):
            raise TypeError(f"expected a gymnasium VectorEnv, got {type(vector_env).__name__}")
        self.num_envs = int(vector_env.num_envs)
        self.policies: list[Policy] = []
        for row in range(self.num_envs):
            policy = factory(sub_env_template(vector_env, row))
            if getattr(policy, "privileged", False):
                # A privileged policy reads its own sub-env's truth, not the template's.
                policy.world_source = _RowWorld(vector_env, row)  # type: ignore[attr-defined]
            self.policies.append(policy)
        self.name = self.policies[0].name

    def reset(self, seed: int | Sequence[int | None] | None = None) -> None:
        if seed is None or isinstance(seed, (int, np.integer)):
            seeds: list[int | None] = [
                None if seed is None else int(seed) + row for row in range(self.num_envs)
            ]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"expected {self.num_envs} seeds, got {len(seeds)}: {seed!r}")
        for policy, row_seed in zip(self.policies, seeds, strict=True):
            policy.reset(seed=row_seed)

    def act(
        self, observations: NDArray[np.float32] | Mapping[str, Any], infos: dict[str, Any]
    ) -> NDArray[Any]:
        """The actions (num_envs, ...) for a vector env's observations (flat, or entity
        dicts of batched arrays) and infos."""
        first = next(iter(observations.values())) if isinstance(observations, Mapping) else None
        count = len(first) if first is not None else len(observations)
        if count != self.num_envs:
            raise ValueError(f"expected observations for {self.num_envs} sub-envs, got {count}")
        actions = [
            policy.act(_observation_row(observations, row), info_row(infos, row))
            for row, policy in enumerate(self.policies)
        ]
        return np.stack([np.asarray(action) for action in actions])


class _RowWorld:
    """Sub-env ``row``'s ground truth, read from the vector env when asked (picklable)."""

    def __init__(self, vector_env: gym.vector.VectorEnv, row: int) -> None:
        self.vector_env = vector_env
        self.row = row

    def __call__(self) -> WorldView:
        world = _sub_env_attribute(self.vector_env, "world", self.row)
        if world is None:
            raise RuntimeError("the vector env has no world yet: call reset() first")
        return cast(WorldView, world)


def _sub_env_attribute(vector_env: gym.vector.VectorEnv, name: str, row: int) -> Any:
    """``vector_env.get_attr(name)[row]`` (every Gymnasium vector env has ``get_attr``;
    the base class does not declare it)."""
    return cast(Any, vector_env).get_attr(name)[row]
