"""The registered tasks (``bearing_env.tasks``): the table and the registry agree, every
id makes, resets, steps, passes Gymnasium's and SB3's checkers without a warning, and
makes its batched vector env; every version of an id is registered with its settings."""

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
from bearing_env.tasks import (
    BASE_ID_KINDS,
    BASE_IDS,
    HISTORY,
    OLDER_TASKS,
    REGISTERED_TASKS_BY_ID,
    TASKS,
    TASKS_BY_ID,
    TRAINING_TASKS,
    VERSION,
    VERSIONS,
    Task,
    current_id,
    split_id,
    task_named,
)
from tests.extras import needs

TASK_IDS = [task.id for task in TASKS]
#: Every registered id: the base ids and the tasks, every version.
ALL_IDS = sorted([*ENV_IDS, *REGISTERED_TASKS_BY_ID])
#: The transfer each version's ids resolve to.
TRANSFER_OF_VERSION = {0: "conservative_global", 1: "conservative"}
NAME = re.compile(
    r"^(?P<kind>BearingSLAM|BearingSLAMDiscrete)"
    r"-(?P<setting>Khepera|FurnishedRoom|Random(?P<n>\d+)(?:to(?P<most>\d+))?)"
    r"(?:-Camera(?P<camera>\d+))?(?:-(?P<fault>Outliers|Missed))?"
    r"(?:-(?P<observation>Entities|Shapes|Planner))?-v\d+$"
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
    assert registered == ALL_IDS
    assert sorted(REGISTERED_TASKS_BY_ID) == sorted(
        [*TASK_IDS, *training_ids, *(task.id for task in OLDER_TASKS)]
    )
    assert not set(training_ids) & set(TASKS_BY_ID)  # the suite cards the TASKS only
    for task in REGISTERED_TASKS_BY_ID.values():
        spec = gym.spec(task.id)
        assert spec.entry_point == ENV_IDS[task.base_id]
        assert spec.vector_entry_point == VECTOR_ENTRY_POINTS[task.base_id]
        assert spec.kwargs == task.kwargs()
        assert spec.max_episode_steps is None


def test_every_task_is_registered_in_every_version() -> None:
    assert VERSION == max(VERSIONS) == 1 and VERSIONS[VERSION] == {}
    assert len(HISTORY) == len(VERSIONS)
    for task in (*TASKS, *TRAINING_TASKS):
        assert task.version == VERSION and task.base_id == BASE_IDS[task.action_kind]
        assert [line.split(":")[0] for line in task.history] == [f"v{v}" for v in VERSIONS]
        for version, added in VERSIONS.items():
            older = REGISTERED_TASKS_BY_ID[f"{task.name}-v{version}"]
            assert older == task.at_version(version)
            assert split_id(older.base_id) == (split_id(task.base_id)[0], version)
            assert older.kwargs() == {**added, **task.kwargs()}
            assert older.description == task.description
            assert older.history == task.history[: version + 1]
            assert current_id(older.id) == task.id
            assert current_id(f"bearing_env:{older.id}") == f"bearing_env:{task.id}"
    assert current_id("CartPole-v1") == "CartPole-v1"


def test_the_base_ids_register_their_version_only() -> None:
    assert sorted(ENV_IDS) == sorted(BASE_ID_KINDS) == [
        "BearingSLAM-v0", "BearingSLAM-v1", "BearingSLAMDiscrete-v0", "BearingSLAMDiscrete-v1",
    ]  # fmt: skip
    assert sorted(BASE_IDS.values()) == ["BearingSLAM-v1", "BearingSLAMDiscrete-v1"]
    for base in ENV_IDS:
        spec = gym.spec(base)
        assert spec.kwargs == VERSIONS[split_id(base)[1]] and spec.max_episode_steps is None
        assert spec.entry_point == ENV_IDS[base]
        assert current_id(base) == BASE_IDS[BASE_ID_KINDS[base]]
    assert gym.spec("BearingSLAM-v0").kwargs == {"transfer": "conservative_global"}
    assert gym.spec("BearingSLAMDiscrete-v1").kwargs == {}


@pytest.mark.filterwarnings("ignore:.*is out of date:DeprecationWarning")
@pytest.mark.parametrize("env_id", ALL_IDS)
def test_every_id_makes_its_version_with_the_max_moves_spec(env_id: str) -> None:
    """Every id makes; its transfer is its version's (-v0 the global bound, -v1 the
    default local one), a keyword overrides it, and the spec reads max_moves."""
    version = split_id(env_id)[1]
    env = gym.make(env_id)
    assert env.unwrapped.config.transfer == TRANSFER_OF_VERSION[version]  # type: ignore[attr-defined]
    assert env.spec is not None and env.spec.max_episode_steps == DEFAULT_MAX_MOVES
    assert gym.spec(env_id).max_episode_steps is None
    env.close()
    other = "conservative" if version == 0 else "conservative_global"
    overridden = gym.make(env_id, transfer=other, max_moves=7)
    assert overridden.unwrapped.config.transfer == other  # type: ignore[attr-defined]
    assert overridden.spec is not None and overridden.spec.max_episode_steps == 7
    overridden.close()


@pytest.mark.filterwarnings("ignore:.*is out of date:DeprecationWarning")
@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_the_batched_vector_env_of_every_version_has_its_transfer(env_id: str) -> None:
    version = split_id(env_id)[1]
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode="vector_entry_point")
    assert [c.transfer for c in envs.get_attr("config")] == [TRANSFER_OF_VERSION[version]] * 2
    envs.close()
    envs = gym.make_vec(
        env_id, num_envs=2, vectorization_mode="vector_entry_point", transfer="paper"
    )
    assert [c.transfer for c in envs.get_attr("config")] == ["paper"] * 2
    envs.close()


def test_an_older_version_warns_as_gymnasium_does() -> None:
    """Gymnasium's own note on an older version: the -v0 ids stay for reproducing."""
    with pytest.warns(DeprecationWarning, match="BearingSLAM-Khepera-v0 is out of date"):
        gym.make("BearingSLAM-Khepera-v0").close()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gym.make("BearingSLAM-Khepera-v1").close()


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
        most = int(match["most"] or match["n"])
        assert config.landmark_counts == (int(match["n"]), most)
    fault = match["fault"]
    assert (config.noise.outlier_rate > 0) == (fault == "Outliers")
    assert (config.noise.detection_rate < 1) == (fault == "Missed")
    assert (config.fusion == "relaxed") == (fault is not None)
    camera = match["camera"]
    assert config.field_of_view_deg == (360.0 if camera is None else float(camera))
    assert bool(config.obstacles) == (match["setting"] == "FurnishedRoom")
    observation = match["observation"]
    assert config.observation == (
        "flat" if observation in (None, "Planner") else observation.lower()
    )
    assert config.planner_features == (observation == "Planner")
    if observation == "Planner":  # GreedyOneStep's grid, on the discrete id
        assert (config.n_turns, config.n_move_lengths, task.action_kind) == (8, 2, "discrete")


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
    task = TASKS_BY_ID["BearingSLAM-Khepera-Outliers-v1"]
    with pytest.raises(TypeError):
        task.settings["scenario"] = "random"  # type: ignore[index]
    copied = task.kwargs()
    copied["noise"]["outlier_rate"] = 0.5
    assert task.kwargs()["noise"]["outlier_rate"] == 0.05
    assert gym.spec(task.id).kwargs["noise"]["outlier_rate"] == 0.05


def test_an_unknown_task_is_named() -> None:
    assert task_named("bearing_env:BearingSLAM-Random8-v1") is TASKS_BY_ID["BearingSLAM-Random8-v1"]
    with pytest.raises(ValueError, match=r"'BearingSLAM-Random9-v1'.*BearingSLAM-Khepera-v1"):
        task_named("BearingSLAM-Random9-v1")
    with pytest.raises(ValueError, match=r"older version of BearingSLAM-Random8-v1"):
        task_named("BearingSLAM-Random8-v0")
    with pytest.raises(ValueError, match="base_id"):
        Task("X-v0", "CartPole-v1", {}, "no")
    with pytest.raises(ValueError, match="base_id"):  # a base id of another version
        Task("X-v1", "BearingSLAM-v0", {}, "no")
    with pytest.raises(ValueError, match="versioned id"):
        split_id("BearingSLAM")
