"""EnvConfig's groups: the one home of the settings, and what is generated from it."""

from __future__ import annotations

import dataclasses
import inspect
import pickle
import subprocess
import sys
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.envs import BearingSLAMDiscreteEnv, BearingSLAMEnv, BearingSLAMVectorEnv, core
from bearing_env.envs.config import (
    GROUPS,
    SETTINGS,
    ActionSettings,
    EnvConfig,
    LayoutSettings,
    MappingSettings,
    ObservationSettings,
    SensorSettings,
    TaskSettings,
)
from bearing_env.envs.state import BatchState
from bearing_env.slam import MapSettings, PolygonSLAM
from bearing_env.world import Arena, NoiseModel, World


def test_every_group_field_is_one_setting_and_the_signatures_are_generated_from_them() -> None:
    fields = [
        (name, field.name)
        for name, group in GROUPS.items()
        for field in dataclasses.fields(group)  # type: ignore[arg-type]
    ]
    assert [(spec.group, spec.field) for spec in SETTINGS] == fields
    keywords = [spec.keyword for spec in SETTINGS]
    assert len(set(keywords)) == len(keywords) == 30
    expected = [spec.parameter() for spec in SETTINGS]
    assert list(inspect.signature(EnvConfig.create).parameters.values()) == expected
    discrete = list(inspect.signature(BearingSLAMDiscreteEnv).parameters.values())
    continuous = list(inspect.signature(BearingSLAMEnv).parameters.values())
    assert [p.name for p in discrete[:2]] == ["render_mode", "config"]
    assert discrete[2:] == expected
    assert continuous[2:] == [
        p for p, spec in zip(expected, SETTINGS, strict=True) if not spec.grid
    ]
    # Keywords that take other forms than the field say so, with their own default.
    n_landmarks = inspect.signature(BearingSLAMEnv).parameters["n_landmarks"]
    assert n_landmarks.annotation == "int | tuple[int, int] | None"
    assert n_landmarks.default is None


def test_create_routes_each_keyword_to_its_group() -> None:
    config = EnvConfig.create(
        n_landmarks=6, noise="gaussian", fusion="relaxed", path_cost=0.5, n_turns=4
    )
    assert config.layout.landmark_counts == (6, 6)
    assert config.sensor.noise == NoiseModel("gaussian")
    assert config.mapping.fusion == "relaxed"
    assert config.task.path_cost == 0.5
    assert config.actions.n_turns == 4
    # Every keyword whose default is its field's lands there unchanged.
    default = EnvConfig.create()
    for spec in SETTINGS:
        assert getattr(config, spec.field) == getattr(getattr(config, spec.group), spec.field)
        field = {f.name: f for f in dataclasses.fields(GROUPS[spec.group])}[spec.field]  # type: ignore[arg-type]
        if spec.default == field.default:
            assert getattr(getattr(default, spec.group), spec.field) == spec.default, spec


@pytest.mark.parametrize(
    ("make", "fragment"),
    [
        (lambda: EnvConfig.create(epsilon_degrees=2.0), r"'epsilon_degrees'.*'epsilon_deg'"),
        (lambda: BearingSLAMEnv(max_move=3), r"'max_move'.*'max_moves'"),
        (lambda: gym.make("BearingSLAM-v1", zzz=1), r"'zzz'"),
        (lambda: BearingSLAMVectorEnv(2, landmark_count=4), r"'landmark_count'"),
    ],
)
def test_an_unknown_keyword_names_itself(make: Any, fragment: str) -> None:
    with pytest.raises(TypeError, match=f"unexpected keyword argument {fragment}"):
        make()


@pytest.mark.parametrize(
    ("make", "error", "fragment"),
    [
        (lambda: LayoutSettings("moon", (4, 4), None, Arena(1, 1)), ValueError, "'moon'"),
        (lambda: LayoutSettings("random", (5, 3), None, Arena(1, 1)), ValueError, "n_landmarks"),
        (lambda: LayoutSettings("random", (4, 4), None, (1.0,)), ValueError, "arena"),  # type: ignore[arg-type]
        (lambda: SensorSettings(epsilon_deg=95.0), ValueError, "epsilon_deg.*95"),
        (lambda: SensorSettings(noise="loud"), ValueError, "loud"),  # type: ignore[arg-type]
        (lambda: MappingSettings(fusion="vote"), ValueError, "'vote'"),
        (lambda: MappingSettings(max_outliers=8), ValueError, "max_outliers must be <= 7"),
        (lambda: TaskSettings(max_moves=0), ValueError, "max_moves.*0"),
        (lambda: TaskSettings(reward="fun"), ValueError, "'fun'"),
        (lambda: ActionSettings(move_length=(0.3, 0.1)), ValueError, "lo <= hi"),
        (lambda: ActionSettings((0.1, 0.2), n_turns=5000), ValueError, "n_turns.*5000"),
        (lambda: ObservationSettings(observation="pixels"), ValueError, "'pixels'"),
        (lambda: ObservationSettings(max_landmarks=2.5), TypeError, "max_landmarks.*2.5"),
        (lambda: MapSettings(epsilon=2.0), ValueError, "epsilon must be in"),
        (lambda: MapSettings(0.1, window=4, max_outliers=4), ValueError, "max_outliers.*4"),
    ],
)
def test_each_group_validates_its_fields(make: Any, error: type, fragment: str) -> None:
    with pytest.raises(error, match=fragment):
        make()


def test_groups_normalise_so_equal_settings_are_equal_and_hashable() -> None:
    a, b = TaskSettings(area_cap=10, max_moves=np.int64(7)), TaskSettings(max_moves=7)
    assert a == b and hash(a) == hash(b) and type(a.area_cap) is float
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.max_moves = 3  # type: ignore[misc]
    assert MapSettings(0.1, max_outliers=np.int64(1)) == MapSettings(0.1, max_outliers=1)
    with pytest.raises(TypeError, match="sensor must be a SensorSettings"):
        EnvConfig.create().replace(sensor=TaskSettings())


def test_the_map_settings_are_the_world_models_own() -> None:
    config = EnvConfig.create(epsilon_deg=3.0, transfer="paper", fusion="relaxed")
    settings = config.map_settings
    assert settings == MapSettings(np.radians(3.0), transfer="paper", fusion="relaxed")
    assert (
        settings
        == EnvConfig.create(epsilon_deg=3.0, transfer="paper", fusion="relaxed").map_settings
    )
    env = BearingSLAMEnv(config=config)
    env.reset(seed=0)
    assert env.slam.settings == settings and env.slam.batch.settings == settings
    assert PolygonSLAM.from_settings(4, settings).settings == settings
    assert pickle.loads(pickle.dumps(config)).map_settings == settings


def test_env_attributes_are_generated_from_the_groups() -> None:
    continuous, discrete = BearingSLAMEnv(scenario="khepera"), BearingSLAMDiscreteEnv()
    for spec in SETTINGS:
        if spec.attribute is None:
            assert not hasattr(continuous, spec.keyword) or spec.keyword == "n_landmarks"
            continue
        assert getattr(discrete, spec.attribute) == getattr(discrete.config, spec.field)
        assert hasattr(continuous, spec.attribute) != spec.grid, spec
    continuous.area_cap = 5.0
    assert continuous.config.task.area_cap == 5.0
    with pytest.raises(AttributeError, match="n_turns is read-only: it fixes the action space"):
        discrete.n_turns = 4  # type: ignore[misc]


def _reset_batch(config: EnvConfig, rows: int) -> tuple[BatchState, core.MapBank]:
    state = BatchState.empty(rows, config.observations.max_landmarks)
    maps = core.MapBank(rows)
    rngs = [np.random.default_rng(seed) for seed in range(rows)]
    core.reset_rows(state, np.arange(rows), config, rngs, maps)
    return state, maps


def test_the_world_view_reads_only_what_it_is_given() -> None:
    config = EnvConfig.create(n_landmarks=5, arena=(2.0, 1.5))
    state, _ = _reset_batch(config, 2)
    view = core.WorldView(state, 1, config)
    assert view.n_landmarks == 5 and view.arena == Arena(2.0, 1.5)
    np.testing.assert_array_equal(view.landmarks, state.landmarks[1, :5])
    np.testing.assert_array_equal(view.position, state.positions[1])
    assert view.heading == state.headings[1] and view.epsilon == config.epsilon
    with pytest.raises(ValueError, match="read-only"):
        view.position[0] = 0.0
    state.positions[1] = (0.5, 0.25)  # live: it reads the state it was given
    np.testing.assert_array_equal(view.position, (0.5, 0.25))
    view.config = config.replace(noise="gaussian")
    assert view.noise == NoiseModel("gaussian")
    snapshot = view.copy()
    assert isinstance(snapshot, World) and snapshot.noise == NoiseModel("gaussian")


def test_the_envs_world_view_follows_config_changes_and_pickling() -> None:
    env = BearingSLAMEnv(scenario="khepera")
    env.reset(seed=2)
    world = env.world
    assert world is not None
    env.epsilon_deg = 4.0
    assert world.epsilon == pytest.approx(np.radians(4.0))
    copy = pickle.loads(pickle.dumps(env))
    copy.step(np.array([0.3, 0.5], dtype=np.float32))
    assert copy.world is not None and copy.world is not world
    np.testing.assert_array_equal(copy.world.position, copy._state.positions[0])
    assert not np.array_equal(copy.world.position, world.position)
    vector = BearingSLAMVectorEnv(2, scenario="khepera")
    vector.reset(seed=0)
    vector.set_attr("noise", ["none", "gaussian"])
    worlds = vector.get_attr("world")
    assert (worlds[0].noise.kind, worlds[1].noise.kind) == ("none", "gaussian")


def test_the_functional_core_does_not_import_rendering() -> None:
    code = (
        "import sys, bearing_env.envs.core, bearing_env.envs; "
        "print('bearing_env.rendering' in sys.modules)"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == "False"
