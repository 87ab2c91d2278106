"""The one place where policies reach into the env, split by what the robot may know.

The env exposes the robot's map as ``env.unwrapped.slam`` and the ground truth as
``env.unwrapped.world``; this module keeps the two apart for policies.

- :func:`slam_of` is the robot's own knowledge: its map (landmark regions and estimates
  in FL, its own region and heading estimate). Any policy may read it.
- :func:`world_of` is ground truth (true landmark positions, the robot's true pose). Only
  policies labelled *privileged* (:class:`agents.GreedyOracle`) may read it.
"""

from __future__ import annotations

import gymnasium as gym

from bearing_env.envs.bearing_slam import BearingSLAMEnv
from bearing_env.envs.core import WorldView
from bearing_env.slam import PolygonSLAM


def bearing_env_of(env: gym.Env) -> BearingSLAMEnv:
    """The ``BearingSLAMEnv`` under any stack of wrappers (TypeError if there is none)."""
    base = getattr(env, "unwrapped", env)
    if not isinstance(base, BearingSLAMEnv):
        raise TypeError(
            f"expected a BearingSLAM-v0 / BearingSLAMDiscrete-v0 env (possibly wrapped), "
            f"got {type(base).__name__}"
        )
    return base


def slam_of(env: gym.Env) -> PolygonSLAM:
    """The robot's map (what the robot knows)."""
    return bearing_env_of(env).slam


def world_of(env: gym.Env) -> WorldView:
    """Ground truth (a read-only live view): privileged policies only. RuntimeError
    before the first reset."""
    world = bearing_env_of(env).world
    if world is None:
        raise RuntimeError("the env has no world yet: call env.reset() first")
    return world
