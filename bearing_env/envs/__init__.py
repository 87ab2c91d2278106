"""The Gymnasium environments (one per module), their shared config and functional core.

- :mod:`~bearing_env.envs.config`: :class:`EnvConfig`, every setting, validated;
- :mod:`~bearing_env.envs.core` (over :mod:`~bearing_env.envs.state`): the world state
  and bookkeeping of a batch of envs as arrays, and the pure functions that reset, step
  and observe it;
- :mod:`~bearing_env.envs.actions`, :mod:`~bearing_env.envs.observations`: one spec per
  action kind and per observation kind (space, decoding or writing);
- :mod:`~bearing_env.envs.robot_map`: the robot's own map in ``info["robot_map"]``,
  encoded by the envs and decoded by the agents;
- :mod:`~bearing_env.envs.bearing_slam`, :mod:`~bearing_env.envs.bearing_slam_discrete`:
  the single envs (a batch of one);
- :mod:`~bearing_env.envs.bearing_slam_vector`: the batched vector envs.
- :mod:`~bearing_env.envs.manual_control`: a pygame window to play the single envs by
  hand (``bearing-env play``).
"""

from bearing_env.envs.bearing_slam import BearingSLAMEnv
from bearing_env.envs.bearing_slam_discrete import BearingSLAMDiscreteEnv
from bearing_env.envs.bearing_slam_vector import BearingSLAMDiscreteVectorEnv, BearingSLAMVectorEnv
from bearing_env.envs.config import EnvConfig

__all__ = [
    "BearingSLAMDiscreteEnv",
    "BearingSLAMDiscreteVectorEnv",
    "BearingSLAMEnv",
    "BearingSLAMVectorEnv",
    "EnvConfig",
]
