"""EnvConfig: one frozen, validated, hashable object with every setting of the envs."""

from __future__ import annotations

import dataclasses
import math
import pickle
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.envs import (
    BearingSLAMDiscreteEnv,
    BearingSLAMDiscreteVectorEnv,
    BearingSLAMEnv,
    BearingSLAMVectorEnv,
)
from bearing_env.envs.config import FIELDS, MAX_AREA_CAP, MAX_N_LANDMARKS, SETTINGS, EnvConfig
from bearing_env.world import Arena, NoiseModel


def test_create_resolves_the_scenario_defaults() -> None:
    config = EnvConfig.create(scenario="khepera")
    assert config.scenario == "khepera"
    assert config.landmark_counts == (4, 4)
    assert config.landmarks is not None and len(config.landmarks) == 4
    assert config.arena == Arena(1.05, 0.68)
    assert config.noise == NoiseModel()
    assert config.move_length == pytest.approx((0.05, 0.30))
    assert config.max_landmarks == 8
    assert config.epsilon == pytest.approx(math.radians(2.0))
    random = EnvConfig.create(n_landmarks=(4, 12))
    assert random.scenario == "random" and random.landmarks is None
    assert random.layout.has_count_range and random.max_landmarks == 12
    assert EnvConfig.create(landmarks=[[0.1, 0.1], [0.5, 0.1], [0.3, 0.4]]).scenario == "custom"


def test_equal_settings_give_equal_hashable_configs() -> None:
    a = EnvConfig.create(scenario="random", n_landmarks=5, noise={"kind": "gaussian"})
    b = EnvConfig.create(n_landmarks=np.int64(5), noise=NoiseModel("gaussian"), area_cap=10)
    assert a == b and hash(a) == hash(b)
    assert type(b.area_cap) is float and type(b.landmark_counts[0]) is int
    c = a.replace(path_cost=1.0)
    assert c != a and len({a, b, c}) == 2
    assert pickle.loads(pickle.dumps(c)) == c


def test_configs_are_frozen() -> None:
    config = EnvConfig.create()
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.area_cap = 5.0  # type: ignore[misc]


@pytest.mark.parametrize(
    ("change", "error", "fragment"),
    [
        ({"area_cap": -1.0}, ValueError, "area_cap.*-1.0"),
        ({"max_moves": 2.5}, TypeError, "max_moves.*2.5"),
        ({"reward": "fun"}, ValueError, "'fun'"),
        ({"landmark_counts": (5, 4)}, ValueError, "n_landmarks.*4"),
        ({"max_landmarks": 3}, ValueError, "max_landmarks.*3"),
        ({"n_turns": 0}, ValueError, "n_turns.*0"),
        ({"no_such_field": 1}, TypeError, "no_such_field"),
    ],
)
def test_replace_and_direct_construction_are_validated(
    change: dict[str, Any], error: type, fragment: str
) -> None:
    config = EnvConfig.create()
    with pytest.raises(error, match=fragment):
        config.replace(**change)
    if "no_such_field" not in change:
        # Directly: the changed field's group built with the bad value (the groups
        # validate themselves; EnvConfig what spans them, such as max_landmarks >= count).
        ((name, value),) = change.items()
        group = FIELDS[name].group
        groups = {f.name: getattr(config, f.name) for f in dataclasses.fields(config)}
        with pytest.raises(error, match=fragment):
            changed = dataclasses.replace(groups[group], **{name: value})
            EnvConfig(**{**groups, group: changed})


def test_fixed_landmarks_must_match_the_count() -> None:
    config = EnvConfig.create(scenario="khepera")
    with pytest.raises(ValueError, match="contradicts"):
        config.replace(landmark_counts=(5, 5))


@pytest.mark.parametrize("env_class", [BearingSLAMEnv, BearingSLAMDiscreteEnv])
@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"n_landmarks": MAX_N_LANDMARKS + 1}, "n_landmarks.*1025"),
        ({"n_landmarks": (4, 2000)}, "n_landmarks.*2000"),
        ({"n_landmarks": 8, "max_landmarks": 5000}, "max_landmarks.*5000"),
        ({"area_cap": 1e300}, "area_cap.*1e\\+300"),
        ({"area_cap": 2 * MAX_AREA_CAP}, "area_cap.*2000000"),
    ],
)
def test_upper_bounds_name_the_value(
    env_class: type[BearingSLAMEnv], kwargs: dict[str, Any], fragment: str
) -> None:
    with pytest.raises(ValueError, match=fragment):
        env_class(**kwargs)


def test_the_largest_accepted_area_cap_keeps_area_rewards_finite() -> None:
    env = BearingSLAMEnv(reward="area", area_cap=MAX_AREA_CAP, n_landmarks=12)
    env.reset(seed=0)
    env.action_space.seed(0)
    for _ in range(5):
        _, reward, *_ = env.step(env.action_space.sample())
        assert math.isfinite(reward)


@pytest.mark.parametrize(
    ("env_id", "extra"), [("BearingSLAM-v1", {}), ("BearingSLAMDiscrete-v1", {"n_turns": 4})]
)
def test_an_env_from_a_config_equals_one_from_keywords(env_id: str, extra: dict[str, Any]) -> None:
    kwargs = {"scenario": "khepera", "path_cost": 0.5, "noise": "gaussian", **extra}
    config = EnvConfig.create(**kwargs)
    from_config = gym.make(env_id, config=config)
    from_keywords = gym.make(env_id, **kwargs)
    assert from_config.unwrapped.config == from_keywords.unwrapped.config == config
    assert from_config.action_space == from_keywords.action_space
    from_config.action_space.seed(1)
    assert np.array_equal(from_config.reset(seed=4)[0], from_keywords.reset(seed=4)[0])
    for _ in range(5):
        action = from_config.action_space.sample()
        a, b = from_config.step(action), from_keywords.step(action)
        assert np.array_equal(a[0], b[0]) and a[1] == b[1]


def test_a_config_and_keywords_together_are_refused() -> None:
    config = EnvConfig.create(scenario="khepera")
    with pytest.raises(TypeError, match="path_cost"):
        BearingSLAMEnv(config=config, path_cost=1.0)
    with pytest.raises(TypeError, match="n_turns"):
        BearingSLAMDiscreteEnv(config=config, n_turns=4)
    with pytest.raises(TypeError, match="config"):
        BearingSLAMEnv(config={"scenario": "khepera"})  # type: ignore[arg-type]
    # A keyword equal to its default conflicts too: config's epsilon_deg might not be 2.
    with pytest.raises(TypeError, match="epsilon_deg"):
        BearingSLAMEnv(config=EnvConfig.create(epsilon_deg=5.0), epsilon_deg=2.0)
    with pytest.raises(TypeError, match=r"n_turns.*discrete action grid"):
        BearingSLAMEnv(n_turns=4)


def test_the_constructors_show_the_settings_of_envconfig_create() -> None:
    """The settings are written once (the groups' fields, SETTINGS); create's and the
    envs' signatures are made from them, so help() and inspect show every setting."""
    import inspect

    create = inspect.signature(EnvConfig.create).parameters
    assert list(create) == [spec.keyword for spec in SETTINGS]
    continuous = inspect.signature(BearingSLAMEnv).parameters
    discrete = inspect.signature(BearingSLAMDiscreteEnv).parameters
    assert list(discrete) == ["render_mode", "config", *create]
    assert list(continuous) == [
        name for name in discrete if name not in ("n_turns", "n_move_lengths")
    ]
    assert continuous["max_moves"].default == create["max_moves"].default == 20


def test_the_discrete_grid_lives_in_the_config() -> None:
    env = BearingSLAMDiscreteEnv(config=EnvConfig.create(n_turns=6, move_length=(0.1, 0.2)))
    assert env.action_space.n == 6 * 3
    assert env.n_turns == 6 and env.n_move_lengths == 3
    np.testing.assert_allclose(env.move_lengths, [0.1, 0.15, 0.2])
    with pytest.raises(AttributeError, match="read-only"):
        env.n_turns = 4  # type: ignore[misc]


def test_setting_attributes_replace_the_config_validated() -> None:
    env = BearingSLAMEnv(scenario="khepera")
    before = env.config
    env.path_cost = 2.0
    assert env.config == before.replace(path_cost=2.0) and env.path_cost == 2.0
    with pytest.raises(ValueError, match=r"path_cost.*-3\.0"):
        env.path_cost = -3.0
    assert env.path_cost == 2.0  # a refused value changes nothing
    with pytest.raises(AttributeError, match="observation space"):
        env.max_landmarks = 10  # type: ignore[misc]
    assert env.reward_kind == "log_area" and env.epsilon == pytest.approx(math.radians(2))


@pytest.mark.parametrize("vector_class", [BearingSLAMVectorEnv, BearingSLAMDiscreteVectorEnv])
def test_the_vector_env_takes_a_config_too(vector_class: type[BearingSLAMVectorEnv]) -> None:
    config = EnvConfig.create(scenario="khepera", max_moves=5)
    env = vector_class(2, config=config)
    assert env.get_attr("config") == (config, config)
    assert env.get_attr("max_moves") == (5, 5)
    with pytest.raises(TypeError, match="max_moves"):
        vector_class(2, config=config, max_moves=6)


def test_vector_sub_envs_with_different_configs_step_like_single_envs() -> None:
    configs = [
        EnvConfig.create(scenario="khepera"),
        EnvConfig.create(scenario="khepera", noise={"kind": "gaussian", "outlier_rate": 0.2}),
        EnvConfig.create(scenario="khepera", epsilon_deg=4.0, transfer="paper"),
        EnvConfig.create(scenario="khepera", reward="area", target_area=0.5),
    ]
    batched = BearingSLAMVectorEnv(4, scenario="khepera")
    batched.set_attr("config", configs)
    singles = [BearingSLAMEnv(config=config) for config in configs]
    observations, _ = batched.reset(seed=3)
    for i, env in enumerate(singles):
        assert np.array_equal(observations[i], env.reset(seed=3 + i)[0])
    actions = np.random.default_rng(4).uniform(-1, 1, (30, 4, 2)).astype(np.float32)
    done = np.zeros(4, dtype=bool)
    for step_actions in actions:
        observations, rewards, terminated, truncated, infos = batched.step(step_actions)
        for i, env in enumerate(singles):
            if done[i]:  # the vector env's autoreset step
                observation, _ = env.reset()
                assert rewards[i] == 0.0
            else:
                observation, reward, term, trunc, info = env.step(step_actions[i])
                assert (rewards[i], terminated[i], truncated[i]) == (reward, term, trunc)
                assert np.array_equal(infos["landmark_area"][i], info["landmark_area"])
            assert np.array_equal(observations[i], observation), i
        done = terminated | truncated
    # Four configs, so four groups, each stepped with its own settings.
    assert len(set(batched.get_attr("config"))) == 4
    assert batched.get_attr("reward_kind") == ("log_area",) * 3 + ("area",)


def test_vector_set_attr_validates_every_value_before_applying_any() -> None:
    env = BearingSLAMVectorEnv(3)
    with pytest.raises(ValueError, match=r"area_cap.*-1"):
        env.set_attr("area_cap", [5.0, -1, 5.0])
    assert env.get_attr("area_cap") == (10.0, 10.0, 10.0)
    with pytest.raises(AttributeError, match="read-only"):
        env.set_attr("max_landmarks", 12)
    with pytest.raises(AttributeError, match="no_such_attribute"):
        env.get_attr("no_such_attribute")
    with pytest.raises(AttributeError, match="'label'"):  # not a setting: refused
        env.set_attr("label", ["a", "b", "c"])


def test_a_new_epsilon_gives_a_new_empty_map() -> None:
    env = BearingSLAMEnv(scenario="khepera")
    env.reset(seed=0)
    for turn in (0.5, -0.6, 0.7, -0.4):
        env.step(np.array([turn, 0.5], dtype=np.float32))
    assert np.isfinite(env.slam.areas).any()  # the 2-degree map has regions
    two_degree_batch = env.slam.batch
    env.epsilon_deg = 3.0
    assert env.slam.batch is not two_degree_batch
    assert not np.isfinite(env.slam.areas).any()
    env.step(np.array([0.5, 0.5], dtype=np.float32))
    env.epsilon_deg = 2.0  # back: an empty map again, not the stale 2-degree one
    assert not np.isfinite(env.slam.areas).any()
    with pytest.raises(ValueError, match="max_landmarks"):
        env.config = env.config.replace(max_landmarks=10)
    with pytest.raises(TypeError, match="EnvConfig"):
        env.config = {"scenario": "khepera"}  # type: ignore[assignment]
