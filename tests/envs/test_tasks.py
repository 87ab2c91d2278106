"""The registered tasks (``bearing_env.tasks``): the table and the registry agree, every
id makes, resets, steps, passes Gymnasium's and SB3's checkers without a warning, and
makes its batched vector env."""

from __future__ import annotations

import os
import re
import warnings

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from bearing_env.envs.bearing_slam_vector import BearingSLAMVectorEnv
from bearing_env.envs.config import DEFAULT_MAX_MOVES, EnvConfig
from bearing_env.registration import ENV_IDS, VECTOR_ENTRY_POINTS, register_envs
from bearing_env.tasks import BASE_IDS, TASKS, TASKS_BY_ID, TRAINING_TASKS, Task, task_named
from tests.extras import needs

TASK_IDS = [task.id for task in TASKS]
NAME = re.compile(
    r"^(?P<kind>BearingSLAM|BearingSLAMDiscrete)"
    r"-(?P<setting>Khepera|FurnishedRoom|Random(?P<n>\d+))"
    r"(?:-Camera(?P<camera>\d+))?(?:-(?P<fault>Outliers|Missed))?-v\d+$"
)
SCENARIO_OF_SETTING = {"Khepera": "khepera", "FurnishedRoom": "furnished_room"}


def test_the_table_and_the_registry_agree() -> None:
    register_envs()  # again: nothing changes
    assert len(TASKS) >= 6 and len(TASKS_BY_ID) == len(TASKS)
    registered = sorted(
        spec.id
        for spec in gym.registry.values()
        if isinstance(spec.entry_point, str) and spec.entry_point.startswith("bearing_env.")
    )
    training_ids = [task.id for task in TRAINING_TASKS]
    assert registered == sorted([*ENV_IDS, *TASK_IDS, *training_ids])
    assert not set(training_ids) & set(TASKS_BY_ID)  # the suite cards the TASKS only
    for task in (*TASKS, *TRAINING_TASKS):
        spec = gym.spec(task.id)
        assert spec.entry_point == ENV_IDS[task.base_id]
        assert spec.vector_entry_point == VECTOR_ENTRY_POINTS[task.base_id]
        assert spec.kwargs == task.kwargs()
        assert spec.max_episode_steps is None


def test_the_base_ids_are_unchanged() -> None:
    for base in BASE_IDS.values():
        spec = gym.spec(base)
        assert spec.kwargs == {} and spec.max_episode_steps is None
        assert spec.entry_point == ENV_IDS[base]


@pytest.mark.parametrize("task", TASKS, ids=TASK_IDS)
def test_the_id_follows_the_naming_rule(task: Task) -> None:
    match = NAME.match(task.id)
    assert match is not None, task.id
    assert BASE_IDS["discrete" if match["kind"].endswith("Discrete") else "continuous"] == (
        task.base_id
    )
    config = EnvConfig.create(**task.kwargs())
    if match["n"] is None:
        assert config.scenario == SCENARIO_OF_SETTING[match["setting"]]
    else:
        assert config.scenario == "random"
        assert config.landmark_counts == (int(match["n"]), int(match["n"]))
    fault = match["fault"]
    assert (config.noise.outlier_rate > 0) == (fault == "Outliers")
    assert (config.noise.detection_rate < 1) == (fault == "Missed")
    assert (config.fusion == "relaxed") == (fault is not None)
    camera = match["camera"]
    assert config.field_of_view_deg == (360.0 if camera is None else float(camera))
    assert bool(config.obstacles) == (match["setting"] == "FurnishedRoom")


@pytest.mark.parametrize("task_id", TASK_IDS)
def test_each_id_makes_resets_and_steps_with_its_settings(task_id: str) -> None:
    task = TASKS_BY_ID[task_id]
    env = gym.make(f"bearing_env:{task_id}")
    assert env.unwrapped.config == EnvConfig.create(**task.kwargs())  # type: ignore[attr-defined]
    assert env.spec is not None and env.spec.max_episode_steps == DEFAULT_MAX_MOVES
    observation, _ = env.reset(seed=5)
    assert env.observation_space.contains(observation)
    env.action_space.seed(5)
    moves, done = 0, False
    while not done:
        observation, reward, terminated, truncated, _ = env.step(env.action_space.sample())
        assert env.observation_space.contains(observation) and np.isfinite(reward)
        moves += 1
        done = terminated or truncated
    assert moves <= DEFAULT_MAX_MOVES and (truncated == (moves == DEFAULT_MAX_MOVES))
    # make's keywords override the task's settings, as for any id.
    shorter = gym.make(task_id, max_moves=3)
    assert shorter.unwrapped.config == env.unwrapped.config.replace(max_moves=3)  # type: ignore[attr-defined]
    env.close()
    shorter.close()


@needs("render")  # the checker renders
@pytest.mark.parametrize("task_id", TASK_IDS)
def test_gymnasium_check_env_without_warnings(task_id: str) -> None:
    env = gym.make(task_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    env.close()


@needs("train", "stable_baselines3", "torch")
@needs("render")
@pytest.mark.parametrize("task_id", TASK_IDS)
def test_sb3_check_env_without_warnings(task_id: str) -> None:
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make(task_id)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_check_env(env)
    env.close()


@pytest.mark.parametrize("task_id", TASK_IDS)
def test_make_vec_builds_the_batched_vector_env_with_the_settings(task_id: str) -> None:
    task = TASKS_BY_ID[task_id]
    envs = gym.make_vec(task_id, num_envs=2)
    assert isinstance(envs, BearingSLAMVectorEnv)
    single = gym.make(task_id)
    assert envs.single_observation_space == single.observation_space
    assert envs.single_action_space == single.action_space
    assert envs.get_attr("config") == (EnvConfig.create(**task.kwargs()),) * 2
    observations, _ = envs.reset(seed=1)
    assert observations.shape[0] == 2
    envs.action_space.seed(1)
    _, rewards, _, _, _ = envs.step(envs.action_space.sample())
    assert rewards.shape == (2,) and np.all(np.isfinite(rewards))
    envs.close()
    single.close()


def test_a_task_cannot_be_changed_through_its_settings() -> None:
    task = TASKS_BY_ID["BearingSLAM-Khepera-Outliers-v0"]
    with pytest.raises(TypeError):
        task.settings["scenario"] = "random"  # type: ignore[index]
    copied = task.kwargs()
    copied["noise"]["outlier_rate"] = 0.5
    assert task.kwargs()["noise"]["outlier_rate"] == 0.05
    assert gym.spec(task.id).kwargs["noise"]["outlier_rate"] == 0.05


def test_an_unknown_task_is_named() -> None:
    assert task_named("bearing_env:BearingSLAM-Random8-v0") is TASKS_BY_ID["BearingSLAM-Random8-v0"]
    with pytest.raises(ValueError, match=r"'BearingSLAM-Random9-v0'.*BearingSLAM-Khepera-v0"):
        task_named("BearingSLAM-Random9-v0")
    with pytest.raises(ValueError, match="base_id"):
        Task("X-v0", "CartPole-v1", {}, "no")
