"""Gymnasium registration of the bearing_env ids.

Called on ``import bearing_env``. ``gym.make("bearing_env:BearingSLAM-v1")`` works without
importing first because Gymnasium imports the module named before the colon (Gymnasium
1.x no longer loads ``gymnasium.envs`` entry-point plugins). Importing this module stays
cheap: the environment modules load on first make.

Besides the base ids (one per action kind and version: ``BearingSLAM-v1``,
``BearingSLAMDiscrete-v1``, and the older ``-v0``), every task of :mod:`bearing_env.tasks`
(``BearingSLAM-Khepera-v1``, ``BearingSLAM-Random8-v1``, ..., and their older versions) is
registered as its own id: its base id's env and vector env with the task's settings as
``kwargs``, as Minigrid registers its variants; so is every training task
(``BearingSLAM-Random3to16-Entities-v1``, the id ``ppo_entities.yml`` is keyed by). An
older version's ids register the settings its version adds (:data:`bearing_env.tasks.VERSIONS`,
``-v0``: ``transfer="conservative_global"``); ``gym.make(id, **kwargs)`` overrides them as
any registered kwargs.
"""

from __future__ import annotations

import gymnasium as gym

from bearing_env.tasks import BASE_ID_KINDS, REGISTERED_TASKS_BY_ID, VERSIONS, split_id

#: The env and the batched vector env of each action kind.
ENTRY_POINTS: dict[str, str] = {
    "continuous": "bearing_env.envs.bearing_slam:BearingSLAMEnv",
    "discrete": "bearing_env.envs.bearing_slam_discrete:BearingSLAMDiscreteEnv",
}
VECTOR_ENTRY_POINTS_BY_KIND: dict[str, str] = {
    "continuous": "bearing_env.envs.bearing_slam_vector:BearingSLAMVectorEnv",
    "discrete": "bearing_env.envs.bearing_slam_vector:BearingSLAMDiscreteVectorEnv",
}

#: The registered base ids (every version) and their entry points. They register
#: ``max_episode_steps=None``: the envs' own ``max_moves`` is the one episode cap (a
#: registered TimeLimit would cut ``gym.make(id, max_moves=40)`` at its own length), and
#: an env's ``spec`` reports its ``max_moves`` as ``max_episode_steps`` for the libraries
#: that read a horizon there.
ENV_IDS: dict[str, str] = {base: ENTRY_POINTS[kind] for base, kind in BASE_ID_KINDS.items()}
#: The batched vector environments, registered as each id's ``vector_entry_point``.
VECTOR_ENTRY_POINTS: dict[str, str] = {
    base: VECTOR_ENTRY_POINTS_BY_KIND[kind] for base, kind in BASE_ID_KINDS.items()
}


def register_envs() -> None:
    """Register the bearing_env ids and the task ids; safe to call more than once."""
    for env_id, entry_point in ENV_IDS.items():
        added = dict(VERSIONS[split_id(env_id)[1]])
        _register(env_id, entry_point, VECTOR_ENTRY_POINTS[env_id], added)
    for task in REGISTERED_TASKS_BY_ID.values():
        base = task.base_id
        _register(task.id, ENV_IDS[base], VECTOR_ENTRY_POINTS[base], task.kwargs())


def _register(
    env_id: str, entry_point: str, vector_entry_point: str, kwargs: dict[str, object]
) -> None:
    # Registering an existing id again would make Gymnasium warn about overriding it.
    if env_id in gym.registry:
        return
    gym.register(
        id=env_id,
        entry_point=entry_point,
        vector_entry_point=vector_entry_point,
        max_episode_steps=None,
        kwargs=kwargs,
    )
