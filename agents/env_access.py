"""The one place where policies reach into the env, split by what the robot may know.

The robot's own map (landmark regions and estimates in FL, its own region and heading
estimate) reaches policies as data: every info carries it as ``info["robot_map"]`` (the
map's state arrays; see the env's Info section), and :class:`MapReader` rebuilds a
:class:`~bearing_env.slam.PolygonSLAM` from it. That works wherever an info goes: on the
vector envs (one row of the batched infos), across processes and on pickled copies, with
no reference to the live env. The rest of an info is ground truth (areas, errors):
robot policies read ``info["robot_map"]`` only.

- :func:`world_of` is ground truth (true landmark positions, the robot's true pose). Only
  policies labelled *privileged* (:class:`agents.GreedyOracle`) may read it.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import gymnasium as gym

from bearing_env.envs import robot_map
from bearing_env.envs.bearing_slam import BearingSLAMEnv
from bearing_env.envs.core import WorldView
from bearing_env.slam import MapSettings, PolygonSLAM

#: The one key of an info that robot policies read: the robot's own map.
ROBOT_MAP_KEY = robot_map.KEY


def bearing_env_of(env: gym.Env) -> BearingSLAMEnv:
    """The ``BearingSLAMEnv`` under any stack of wrappers (TypeError if there is none)."""
    base = getattr(env, "unwrapped", env)
    if not isinstance(base, BearingSLAMEnv):
        raise TypeError(
            f"expected a BearingSLAM-v1 / BearingSLAMDiscrete-v1 env (possibly wrapped), "
            f"got {type(base).__name__}"
        )
    return base


def world_of(env: gym.Env) -> WorldView:
    """Ground truth (a read-only live view): privileged policies only. RuntimeError
    before the first reset."""
    world = bearing_env_of(env).world
    if world is None:
        raise RuntimeError("the env has no world yet: call env.reset() first")
    return world


class MapReader:
    """Rebuilds the robot's map from ``info["robot_map"]`` (see the module doc).

    Built from the env (any wrapper stack) only to read the map's settings (epsilon,
    transfer, fusion, ...); :meth:`read` then needs nothing but the info and the landmark
    count (the observation's present bearing slots).
    """

    def __init__(self, env: gym.Env) -> None:
        base = bearing_env_of(env)
        #: The world model's settings (epsilon, transfer, fusion, ...).
        self.map_settings: MapSettings = base.config.map_settings
        #: Whether the env's infos carry the map (its ``robot_map_info`` setting).
        self.available = base.config.observations.robot_map_info

    def require(self, user: str) -> None:
        """Raise :class:`RobotMapUnavailableError` naming ``user`` (a policy) when the
        env's infos carry no map: a policy that reads the map calls this when it is built."""
        if not self.available:
            raise RobotMapUnavailableError(user)

    def read(
        self, info: Mapping[str, Any], n_landmarks: int, into: PolygonSLAM | None = None
    ) -> PolygonSLAM:
        """The map of an info: an independent copy (the policy may update it), written
        into ``into`` (the map an earlier call returned) when it fits, else new."""
        if ROBOT_MAP_KEY not in info:
            raise KeyError(
                f"the info has no {ROBOT_MAP_KEY!r} (keys: {sorted(info)}): pass the info "
                "the env returned with this observation, from an env made with "
                "robot_map_info=True (the default)"
            )
        return robot_map.decode(info[ROBOT_MAP_KEY], n_landmarks, self.map_settings, into)


class RobotMapUnavailableError(ValueError):
    """A policy that reads ``info["robot_map"]`` was given an env whose infos do not
    carry it (``robot_map_info=False``)."""

    def __init__(self, user: str) -> None:
        super().__init__(
            f'{user} needs info["{ROBOT_MAP_KEY}"]; make the env with robot_map_info=True '
            "(the default)"
        )
