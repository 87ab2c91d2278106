"""Saved models know their task: the shipped models make their own env from their JSON
record, and refuse an env of another task in one short line naming the settings."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path
from typing import Any

import gymnasium as gym
import pytest

from bearing_env.agents import ModelLoadError, SB3Policy, pretrained_record
from bearing_env.agents.model_task import (
    TASK_SETTINGS,
    ModelTask,
    TaskMismatchError,
    task_record_of,
)
from bearing_env.agents.sb3 import PRETRAINED_DIR, pretrained_task
from bearing_env.envs.config import SETTINGS, EnvConfig
from tests.extras import skip_module_without

skip_module_without("train")

#: The longest message a refusal may print (it names settings, never dumps spaces).
MAX_MESSAGE_LINES = 5


def named_settings(message: str) -> set[str]:
    """The settings a mismatch message names: each ``name <value> (env: <value>)``."""
    return set(re.findall(r"(\w+) \S+(?: \S+)? \(env: ", message))


def assert_short(message: str) -> None:
    assert len(message.splitlines()) <= MAX_MESSAGE_LINES, message
    assert len(message) < 600, message
    # No space's bounds: Box's repr carries its dtype, a bounds array numpy's "array(".
    assert "float32" not in message and "array(" not in message, message


def test_the_generalist_plays_an_episode_with_no_env_given() -> None:
    policy = SB3Policy.pretrained("ppo_generalist")
    env = policy.make_env()
    record = pretrained_record("ppo_generalist")
    assert env.spec is not None and env.spec.id == record["env_id"]
    # Its own id, BearingSLAM-v0, with that version's transfer under the record's kwargs.
    trained = EnvConfig.create(**{**gym.spec(record["env_id"]).kwargs, **record["env_kwargs"]})
    assert env.unwrapped.config == trained  # type: ignore[attr-defined]
    assert trained.transfer == "conservative_global"
    observation, info = env.reset(seed=1_000_000)
    policy.reset(seed=1_000_000)
    moves, done = 0, False
    while not done:
        action = policy.act(observation, info)
        assert env.action_space.contains(action)
        observation, _, terminated, truncated, info = env.step(action)
        moves += 1
        done = terminated or truncated
    assert 1 <= moves <= EnvConfig.create(**record["env_kwargs"]).max_moves
    env.close()


@pytest.mark.parametrize(
    ("name", "env_id", "env_kwargs", "differing"),
    [
        ("ppo_generalist", "BearingSLAM-v1", {"scenario": "khepera"},
         {"observation", "max_landmarks", "scenario"}),
        ("ppo_khepera", "BearingSLAM-v1", {}, {"scenario"}),
        ("ppo_khepera", "BearingSLAMDiscrete-v1", {"scenario": "khepera"}, {"action"}),
        ("ppo_random", "BearingSLAM-v1", {"scenario": "random", "n_landmarks": (4, 8)},
         {"max_landmarks"}),
        ("ppo_khepera", "BearingSLAM-v1", {"scenario": "khepera", "move_length": 0.25},
         {"move_length"}),
    ],
)  # fmt: skip
def test_an_env_of_another_task_is_refused_naming_the_settings(
    name: str, env_id: str, env_kwargs: dict[str, Any], differing: set[str]
) -> None:
    env = gym.make(env_id, **env_kwargs)
    with pytest.raises(TaskMismatchError) as refused:
        SB3Policy.pretrained(name, env)
    message = str(refused.value)
    assert_short(message)
    assert named_settings(message) == differing
    assert message.startswith(f"model {name!r} was trained on another task than this env: ")
    # The model's own task, from its JSON, so the user can make the right env.
    for key, value in pretrained_record(name)["env_kwargs"].items():
        assert f"{key}={value!r}" in message
    assert isinstance(refused.value, ValueError)
    env.close()


def test_the_generalist_message_reads_as_documented() -> None:
    with pytest.raises(TaskMismatchError) as refused:
        SB3Policy.pretrained("ppo_generalist", gym.make("BearingSLAM-v1", scenario="khepera"))
    assert str(refused.value) == (
        "model 'ppo_generalist' was trained on another task than this env: "
        "observation 'entities' (env: 'flat'), max_landmarks 16 (env: 8), "
        "scenario 'random' (env: 'khepera'); its task (ppo_generalist.json): "
        "BearingSLAM-v0 with max_landmarks=16, n_landmarks=[3, 16], "
        "observation='entities', scenario='random'"
    )


@pytest.mark.parametrize(
    "overrides",
    [
        {"n_landmarks": 16},  # a count it never saw: the generalisation study's question
        {"max_moves": 10},  # a shorter episode: compare --quick
        {"noise": {"kind": "gaussian", "sigma_deg": 1.0}, "fusion": "relaxed"},
        {"reward": "area", "target_area": 0.01, "path_cost": 0.1},
    ],
)
def test_settings_outside_the_task_are_accepted(overrides: dict[str, Any]) -> None:
    policy = SB3Policy.pretrained("ppo_generalist")
    env = policy.make_env(**overrides)
    SB3Policy.pretrained("ppo_generalist", env)  # and so is the same env given
    observation, info = env.reset(seed=3)
    assert env.action_space.contains(policy.act(observation, info))
    env.close()


@pytest.mark.parametrize("count", [16, 24, 32])
def test_a_set_policy_acts_with_more_landmark_slots_than_it_was_trained_with(count: int) -> None:
    """The generalist's deep set reads a longer landmark table as it is: more slots than
    its 16 are still its task, and it acts on counts it has no training slots for."""
    policy = SB3Policy.pretrained("ppo_generalist")
    assert policy.task is not None and policy.task.slot_free
    env = policy.make_env(n_landmarks=count, max_landmarks=32)
    observation, info = env.reset(seed=11)
    assert observation["landmarks"].shape == (32 * 8,)
    for _ in range(3):
        action = policy.act(observation, info)
        assert env.action_space.contains(action)
        observation, _, _, _, info = env.step(action)
    SB3Policy.pretrained("ppo_generalist", env)  # given the env, the same check passes
    env.close()


def test_a_set_policy_still_refuses_fewer_slots_and_a_flat_policy_more() -> None:
    with pytest.raises(TaskMismatchError, match=r"max_landmarks 16 \(env: 12\)"):
        # (12 slots hold at most 12 landmarks: the count comes down with them)
        SB3Policy.pretrained("ppo_generalist").make_env(max_landmarks=12, n_landmarks=(3, 12))
    assert not SB3Policy.pretrained("ppo_random").task.slot_free  # type: ignore[union-attr]
    with pytest.raises(TaskMismatchError, match=r"max_landmarks 10 \(env: 12\)"):
        SB3Policy.pretrained("ppo_random").make_env(max_landmarks=12)


def test_make_env_refuses_overrides_that_change_the_task() -> None:
    policy = SB3Policy.pretrained("ppo_random")
    with pytest.raises(TaskMismatchError, match=r"max_landmarks 10 \(env: 12\)") as refused:
        policy.make_env(max_landmarks=12)
    assert_short(str(refused.value))


def test_every_shipped_record_is_a_task_its_model_fits() -> None:
    for path in sorted(PRETRAINED_DIR.glob("*.zip")):
        task = pretrained_task(path.stem)
        assert task == task_record_of(path)
        env = task.make_env()
        assert task.differences(env) == []
        SB3Policy(env, path, task=task)  # the spaces fit too
        env.close()


def test_task_settings_are_fields_of_the_env_config() -> None:
    # config.<field> reads a setting of one of EnvConfig's groups.
    fields = {spec.field for spec in SETTINGS}
    assert set(TASK_SETTINGS) <= fields


def test_an_exported_model_reads_the_record_beside_it(tmp_path: Path) -> None:
    # bearing-env train --export writes <name>.json beside <name>.zip: any exported model
    # knows its task, not only the shipped ones.
    model = tmp_path / "mine.zip"
    shutil.copy(PRETRAINED_DIR / "ppo_khepera.zip", model)
    model.with_suffix(".json").write_text(json.dumps(pretrained_record("ppo_khepera")))
    policy = SB3Policy(None, model, vecnormalize=None)
    assert policy.task == ModelTask("BearingSLAM-Khepera-v1", {}, "mine", "mine.json")
    env = policy.make_env()
    with pytest.raises(TaskMismatchError, match=r"^model 'mine' .* scenario 'khepera' \(env"):
        SB3Policy(gym.make("BearingSLAM-v1"), model)
    observation, info = env.reset(seed=0)
    assert env.action_space.contains(policy.act(observation, info))
    env.close()


def test_a_model_without_a_record_checks_spaces_in_a_short_message(tmp_path: Path) -> None:
    model = tmp_path / "bare.zip"
    shutil.copy(PRETRAINED_DIR / "ppo_generalist.zip", model)
    policy = SB3Policy(None, model, vecnormalize=None)
    assert policy.task is None
    with pytest.raises(ValueError, match="has no record of its task"):
        policy.make_env()
    with pytest.raises(ModelLoadError) as refused:
        SB3Policy(gym.make("BearingSLAM-v1"), model)
    message = str(refused.value)
    assert_short(message)
    assert "expects observations Dict(landmarks: Box(128,), robot: Box(9,))" in message
    assert "but the env gives Box(63,)" in message


def test_a_record_without_an_env_id_is_not_a_task(tmp_path: Path) -> None:
    model = tmp_path / "m.zip"
    model.write_bytes(b"")
    model.with_suffix(".json").write_text(json.dumps({"env_kwargs": {}}))
    assert task_record_of(model) is None
    with pytest.raises(ValueError, match="names no env_id"):
        ModelTask.from_record({"env_id": ""}, "m", "m.json")
    with pytest.raises(ValueError, match="env_kwargs must be a mapping"):
        ModelTask.from_record({"env_id": "BearingSLAM-v0", "env_kwargs": [1]}, "m", "m.json")
