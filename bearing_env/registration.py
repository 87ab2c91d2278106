"""Gymnasium registration of the bearing_env ids.

Called on ``import bearing_env``. ``gym.make("bearing_env:BearingSLAM-v0")`` works without
importing first because Gymnasium imports the module named before the colon (Gymnasium
1.x no longer loads ``gymnasium.envs`` entry-point plugins). Importing this module stays
cheap: the environment modules load on first make.
"""

from __future__ import annotations

import gymnasium as gym

#: The registered ids, their entry points, and the default episode length. The spec's
#: ``max_episode_steps`` equals the environments' default ``max_moves`` so the two
#: truncations agree.
ENV_IDS: dict[str, str] = {
    "BearingSLAM-v0": "bearing_env.envs.bearing_slam:BearingSLAMEnv",
    "BearingSLAMDiscrete-v0": "bearing_env.envs.bearing_slam_discrete:BearingSLAMDiscreteEnv",
}
#: The batched vector environments, registered as each id's ``vector_entry_point``.
VECTOR_ENTRY_POINTS: dict[str, str] = {
    "BearingSLAM-v0": "bearing_env.envs.bearing_slam_vector:BearingSLAMVectorEnv",
    "BearingSLAMDiscrete-v0": "bearing_env.envs.bearing_slam_vector:BearingSLAMDiscreteVectorEnv",
}
MAX_EPISODE_STEPS = 20


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
            max_episode_steps=MAX_EPISODE_STEPS,
        )
