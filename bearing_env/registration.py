"""Gymnasium registration of the bearing_env ids.

Called on ``import bearing_env``. ``gym.make("bearing_env:BearingSLAM-v0")`` works without
importing first because Gymnasium imports the module named before the colon (Gymnasium
1.x no longer loads ``gymnasium.envs`` entry-point plugins). Importing this module stays
cheap: the environment modules load on first make.
"""

from __future__ import annotations

import gymnasium as gym

#: The registered ids and their entry points. They register ``max_episode_steps=None``:
#: the envs' own ``max_moves`` is the one episode cap (a registered TimeLimit would cut
#: ``gym.make(id, max_moves=40)`` at its own length), and an env's ``spec`` reports its
#: ``max_moves`` as ``max_episode_steps`` for the libraries that read a horizon there.
ENV_IDS: dict[str, str] = {
    "BearingSLAM-v0": "bearing_env.envs.bearing_slam:BearingSLAMEnv",
    "BearingSLAMDiscrete-v0": "bearing_env.envs.bearing_slam_discrete:BearingSLAMDiscreteEnv",
}
#: The batched vector environments, registered as each id's ``vector_entry_point``.
VECTOR_ENTRY_POINTS: dict[str, str] = {
    "BearingSLAM-v0": "bearing_env.envs.bearing_slam_vector:BearingSLAMVectorEnv",
    "BearingSLAMDiscrete-v0": "bearing_env.envs.bearing_slam_vector:BearingSLAMDiscreteVectorEnv",
}


def register_envs() -> None:
    """Register the bearing_env ids; safe to call more than once."""
    for env_id, entry_point in ENV_IDS.items():
        # Registering an existing id again would make Gymnasium warn about overriding it.
        if env_id in gym.registry:
            continue
        gym.register(
            id=env_id,
            entry_point=entry_point,
            vector_entry_point=VECTOR_ENTRY_POINTS[env_id],
            max_episode_steps=None,
        )
