"""Exploration policies for the bearing-only SLAM envs.

Every policy is built from the env it acts in, ``Policy(env, **options)``, and driven with
``reset(seed)`` at the start of an episode and ``act(observation, info) -> action`` at
every step (see :class:`bearing_env.agents.base.Policy`). They act on the observation and
``info["robot_map"]`` (the robot's own map, as data), not on the live env, so they run on
vector envs and on remote copies. All work on both registered ids:

- :class:`RandomPolygonal`: the paper's random rotation then straight line;
- :class:`Parallax`: move across the line of sight of the most uncertain landmark;
- :class:`GreedyOneStep`: one-step look-ahead on the robot's own map (no ground truth);
- :class:`GreedyOracle`: the same on the true map (privileged upper reference);
- :class:`Lookahead`: receding-horizon beam search on the robot's own map, each plan
  scored over worlds drawn inside the uncertainty regions;
- :class:`LookaheadOracle`: the same search on the true map (privileged upper reference);
- :class:`VectorPolicy`: one policy per sub-env of a vector env, with a batched ``act``;
- :class:`SB3Policy`: a saved stable-baselines3 model; ``SB3Policy.pretrained(name)``
  loads one shipped under ``agents/pretrained/`` (:func:`pretrained_names` lists them),
  whose ``make_env()`` makes the env it was trained on; given an env of another task it
  raises :class:`TaskMismatchError` (see :mod:`bearing_env.agents.model_task`).

:func:`make_policy` builds one from a spec string such as ``"greedy:n_turns=16"``.
"""

from .base import ActionCodec, Movement, Policy
from .heuristics import GreedyOneStep, GreedyOracle, Parallax, RandomPolygonal
from .lookahead import Lookahead, LookaheadOracle
from .model_task import ModelTask, TaskMismatchError
from .registry import POLICY_CLASSES, PolicySpec, make_policy, parse_policy_spec
from .sb3 import ModelLoadError, SB3Policy, pretrained_names, pretrained_record, pretrained_task
from .vector import VectorPolicy

__all__ = [
    "POLICY_CLASSES",
    "ActionCodec",
    "GreedyOneStep",
    "GreedyOracle",
    "Lookahead",
    "LookaheadOracle",
    "ModelLoadError",
    "ModelTask",
    "Movement",
    "Parallax",
    "Policy",
    "PolicySpec",
    "RandomPolygonal",
    "SB3Policy",
    "TaskMismatchError",
    "VectorPolicy",
    "make_policy",
    "parse_policy_spec",
    "pretrained_names",
    "pretrained_record",
    "pretrained_task",
]
