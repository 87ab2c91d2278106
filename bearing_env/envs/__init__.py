"""The Gymnasium environments: one per module."""

from bearing_env.envs.bearing_slam import BearingSLAMEnv
from bearing_env.envs.bearing_slam_discrete import BearingSLAMDiscreteEnv
from bearing_env.envs.bearing_slam_vector import BearingSLAMDiscreteVectorEnv, BearingSLAMVectorEnv

__all__ = [
    "BearingSLAMDiscreteEnv",
    "BearingSLAMDiscreteVectorEnv",
    "BearingSLAMEnv",
    "BearingSLAMVectorEnv",
]
