"""Exploration policies for the bearing-only SLAM envs.

Every policy is built from the env it acts in, ``Policy(env, **options)``, and driven with
``reset(seed)`` and ``act(observation, info) -> action``; see :class:`agents.base.Policy`.
"""

from agents.base import ActionCodec, Movement, Policy
from agents.heuristics import GreedyOneStep, GreedyOracle, Parallax, RandomPolygonal

__all__ = [
    "ActionCodec",
    "GreedyOneStep",
    "GreedyOracle",
    "Movement",
    "Parallax",
    "Policy",
    "RandomPolygonal",
]
