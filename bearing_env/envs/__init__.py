"""The Gymnasium environments: one per module."""

from bearing_env.envs.bearing_slam import BearingSLAMEnv
from bearing_env.envs.bearing_slam_discrete import BearingSLAMDiscreteEnv

__all__ = ["BearingSLAMDiscreteEnv", "BearingSLAMEnv"]
