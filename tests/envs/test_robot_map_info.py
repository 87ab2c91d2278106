"""The ``robot_map_info`` setting: infos without ``robot_map``, the same episodes, and
the planners that need the map saying so."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.agents import (
    GreedyOneStep,
    GreedyOracle,
    Lookahead,
    LookaheadOracle,
    Parallax,
    RandomPolygonal,
    SB3Policy,
    VectorPolicy,
)
from bearing_env.agents.env_access import MapReader, RobotMapUnavailableError
from bearing_env.envs import BearingSLAMEnv, BearingSLAMVectorEnv, robot_map
from bearing_env.envs.config import EnvConfig
from bearing_env.slam.batch import LANDMARK_AXES, VERTEX_COUNTS, BatchedPolygonSLAM
from tests.extras import needs

#: Short episodes, so that every autoreset mode resets sub-envs within a few steps.
SETTINGS: dict[str, Any] = {"scenario": "khepera", "max_moves": 3}
STEPS = 8


def test_the_setting_defaults_to_on_and_takes_only_bools() -> None:
    assert EnvConfig.create().robot_map_info is True
    off = EnvConfig.create(robot_map_info=np.bool_(False))
    assert off.observations.robot_map_info is False  # normalised to a Python bool
    assert off == EnvConfig.create(robot_map_info=False)
    for bad in (0, 1, "no", None):
        with pytest.raises(TypeError, match=rf"robot_map_info must be True or False, got {bad!r}"):
            EnvConfig.create(robot_map_info=bad)
    env = BearingSLAMEnv(**SETTINGS)
    env.robot_map_info = False  # an env attribute, like every setting
    assert env.config.observations.robot_map_info is False
    with pytest.raises(TypeError, match="robot_map_info must be True or False"):
        env.robot_map_info = "off"


def run_single(robot_map_info: bool) -> list[tuple[Any, ...]]:
    env = BearingSLAMEnv(**SETTINGS, robot_map_info=robot_map_info)
    rng = np.random.default_rng(3)
    observation, info = env.reset(seed=11)
    trace: list[tuple[Any, ...]] = [(observation, 0.0, False, False, info)]
    for _ in range(STEPS):
        observation, reward, terminated, truncated, info = env.step(
            rng.uniform(-1, 1, 2).astype(np.float32)
        )
        trace.append((observation, reward, terminated, truncated, info))
        if terminated or truncated:
            observation, info = env.reset()
            trace.append((observation, 0.0, False, False, info))
    return trace


def test_the_single_env_leaves_the_map_out_and_plays_the_same_episodes() -> None:
    on, off = run_single(True), run_single(False)
    assert len(on) == len(off) > STEPS  # an episode ended and reset within the run
    for (obs_on, r_on, te_on, tr_on, info_on), (obs_off, r_off, te_off, tr_off, info_off) in zip(
        on, off, strict=True
    ):
        np.testing.assert_array_equal(obs_on, obs_off)
        assert (r_on, te_on, tr_on) == (r_off, te_off, tr_off)
        assert robot_map.KEY in info_on and robot_map.KEY not in info_off
        assert set(info_on) - set(info_off) == {robot_map.KEY}
        for key, value in info_off.items():
            if isinstance(value, dict):
                assert value == info_on[key]
            else:
                np.testing.assert_array_equal(value, info_on[key])


def keys_of(infos: dict[str, Any]) -> set[str]:
    """Every key of nested vector infos, as paths."""
    keys = set()
    for key, value in infos.items():
        keys.add(key)
        if isinstance(value, dict):
            keys |= {f"{key}/{inner}" for inner in keys_of(value)}
    return keys


def assert_same_infos(on: dict[str, Any], off: dict[str, Any]) -> None:
    """``off`` is ``on`` less the robot map (and its masks), at every level."""
    assert robot_map.KEY not in off and f"_{robot_map.KEY}" not in off
    for key, value in off.items():
        if isinstance(value, dict):
            assert_same_infos(on[key], value)
        elif value.dtype == object:  # final observations, one array per sub-env
            for mine, theirs in zip(value, on[key], strict=True):
                np.testing.assert_array_equal(mine, theirs)
        else:
            np.testing.assert_array_equal(value, on[key])
    assert {key for key in on if robot_map.KEY not in key} == set(off)


def run_vector(robot_map_info: bool, mode: AutoresetMode) -> list[tuple[Any, ...]]:
    venv = BearingSLAMVectorEnv(4, autoreset_mode=mode, **SETTINGS, robot_map_info=robot_map_info)
    rng = np.random.default_rng(5)
    observations, infos = venv.reset(seed=[21, 22, 23, 24])
    trace: list[tuple[Any, ...]] = [(observations, infos)]
    for _ in range(STEPS):
        observations, rewards, terminations, truncations, infos = venv.step(
            rng.uniform(-1, 1, (4, 2)).astype(np.float32)
        )
        trace.append((observations, rewards, terminations, truncations, infos))
        ended = terminations | truncations
        if mode == AutoresetMode.DISABLED and ended.any():
            observations, infos = venv.reset(options={"reset_mask": ended})
            trace.append((observations, infos))
    return trace


@pytest.mark.parametrize("mode", list(AutoresetMode))
def test_the_vector_env_leaves_the_map_out_in_every_autoreset_mode(mode: AutoresetMode) -> None:
    on, off = run_vector(True, mode), run_vector(False, mode)
    assert len(on) == len(off)
    saw_final = False
    for step_on, step_off in zip(on, off, strict=True):
        for value_on, value_off in zip(step_on[:-1], step_off[:-1], strict=True):
            np.testing.assert_array_equal(value_on, value_off)
        infos_on, infos_off = step_on[-1], step_off[-1]
        assert robot_map.KEY in infos_on
        assert not any(robot_map.KEY in key for key in keys_of(infos_off))
        assert_same_infos(infos_on, infos_off)
        saw_final |= "final_info" in infos_off
    assert saw_final == (mode == AutoresetMode.SAME_STEP)


def test_the_vector_infos_of_all_sub_envs_at_once_decode_to_their_maps() -> None:
    """The vector env hands a step's batched arrays over without merging them row by row
    (one group stepped every sub-env): each row still decodes to that sub-env's map."""
    venv = BearingSLAMVectorEnv(6, **{**SETTINGS, "max_moves": 20})
    venv.reset(seed=31)
    rng = np.random.default_rng(7)
    for _ in range(5):
        *_, infos = venv.step(rng.uniform(-1, 1, (6, 2)).astype(np.float32))
    assert infos[f"_{robot_map.KEY}"].all()
    config = venv.get_attr("config")[0]
    for row, slam in enumerate(venv.get_attr("slam")):
        data = {key: value[row] for key, value in infos[robot_map.KEY].items()}
        decoded = robot_map.decode(data, 4, config.map_settings)
        assert slam.n_updates == decoded.n_updates > 0
        np.testing.assert_array_equal(slam.areas, decoded.areas)
        for mine, theirs in zip(slam.polygons, decoded.polygons, strict=True):
            assert (mine is None) == (theirs is None)
            if mine is not None:
                np.testing.assert_array_equal(mine, theirs)


def reference_encode(
    batch: BatchedPolygonSLAM, rows: np.ndarray[Any, Any], slots: int
) -> dict[str, Any]:
    """The encoding as numpy operations, one array at a time (the env's encoding before
    it was compiled): what the compiled one must reproduce, bit for bit."""
    out: dict[str, Any] = {}
    for name in batch.state_names:
        values = getattr(batch, name)[rows]
        if name in VERTEX_COUNTS:
            used = getattr(batch, VERTEX_COUNTS[name])[rows]
            values[np.arange(values.shape[-1]) >= used[..., None]] = 0
        elif name in robot_map.UNKNOWN_AS_INF:
            unknown = np.isnan(values)
            values[unknown] = complex(np.inf, np.inf) if values.dtype.kind == "c" else np.inf
        axis = LANDMARK_AXES.get(name)
        if axis is not None and slots > values.shape[axis]:
            shape = list(values.shape)
            shape[axis] = slots
            padded = np.full(shape, robot_map.PADDING.get(name, 0), dtype=values.dtype)
            used_slots = [slice(None)] * values.ndim
            used_slots[axis] = slice(0, values.shape[axis])
            padded[tuple(used_slots)] = values
            values = padded
        if values.dtype.kind == "c":
            values = values.view(np.float64).reshape(*values.shape, 2)
        out[name] = values
    return out


@pytest.mark.parametrize(
    "settings",
    [
        {"scenario": "khepera"},
        {"n_landmarks": 6, "max_landmarks": 6},
        {"n_landmarks": (4, 7), "fusion": "relaxed", "max_outliers": 1},
    ],
)
def test_the_compiled_encoding_is_the_numpy_one_and_decodes_to_the_map(
    settings: dict[str, Any],
) -> None:
    venv = BearingSLAMVectorEnv(12, **settings, noise={"kind": "uniform", "outlier_rate": 0.2})
    venv.reset(seed=51)
    rng = np.random.default_rng(9)
    for _ in range(12):
        venv.step(rng.uniform(-1, 1, (12, 2)).astype(np.float32))
    state, config = venv._state, venv.get_attr("config")[0]
    slots = config.observations.max_landmarks - 2
    checked, reused = 0, None
    for group_config, rows in venv._groups(np.arange(12)):
        group = venv._maps.group(state, rows, group_config)
        for some in (group.rows, group.rows[::-2]):  # every row, and some out of order
            compiled = robot_map.encode(group.batch, some, slots)
            reference = reference_encode(group.batch, some, slots)
            assert list(compiled) == list(reference) == list(group.batch.state_names)
            for name, values in reference.items():
                assert compiled[name].dtype == values.dtype, name
                np.testing.assert_array_equal(compiled[name], values, err_msg=name)
            for i, row in enumerate(some.tolist()):
                data = {name: values[i] for name, values in compiled.items()}
                back = robot_map.decode(data, group.n, config.map_settings).batch
                # Into the map of the last row: the same state as a new map.
                again = robot_map.decode(data, group.n, config.map_settings, into=reused)
                assert (again is reused) == (reused is not None and reused.n_landmarks == group.n)
                for name in group.batch.state_names:
                    np.testing.assert_array_equal(getattr(again.batch, name), getattr(back, name))
                reused = again
                for name in group.batch.state_names:
                    mine = getattr(group.batch, name)[row]
                    theirs = getattr(back, name)[0]
                    if name in VERTEX_COUNTS:  # unused vertex slots hold anything
                        used = getattr(group.batch, VERTEX_COUNTS[name])[row]
                        keep = np.arange(mine.shape[-1]) < used[..., None]
                        mine, theirs = mine[keep], theirs[keep]
                    np.testing.assert_array_equal(mine, theirs, err_msg=name)
                checked += 1
    groups = [rows for _, rows in venv._groups(np.arange(12))]
    assert checked == sum(rows.size + rows[::-2].size for rows in groups)
    assert ("window_vertices" in compiled) == (settings.get("fusion") == "relaxed")


MAP_POLICIES = (Parallax, GreedyOneStep, GreedyOracle, Lookahead, LookaheadOracle)


@pytest.mark.parametrize("policy_class", MAP_POLICIES)
def test_the_planners_that_read_the_map_refuse_an_env_without_it(policy_class: type) -> None:
    env = gym.make("BearingSLAM-v1", **SETTINGS, robot_map_info=False)
    message = (
        rf'^{policy_class.__name__} needs info\["robot_map"\]; make the env with '
        r"robot_map_info=True \(the default\)$"
    )
    with pytest.raises(RobotMapUnavailableError, match=message):
        policy_class(env)
    vector_env = BearingSLAMVectorEnv(2, **SETTINGS, robot_map_info=False)
    with pytest.raises(RobotMapUnavailableError, match=message):
        VectorPolicy(vector_env, policy_class)
    policy_class(gym.make("BearingSLAM-v1", **SETTINGS))  # with the map: built as ever


def test_a_map_read_from_an_info_without_it_names_the_setting() -> None:
    reader = MapReader(gym.make("BearingSLAM-v1", **SETTINGS))
    _, info = BearingSLAMEnv(**SETTINGS, robot_map_info=False).reset(seed=0)
    with pytest.raises(KeyError, match="robot_map_info=True"):
        reader.read(info, 4)


def play(policy: Any, env: gym.Env[Any, Any]) -> int:
    policy.reset(seed=0)
    observation, info = env.reset(seed=41)
    moves, done = 0, False
    while not done:
        observation, _, terminated, truncated, info = env.step(policy.act(observation, info))
        moves, done = moves + 1, terminated or truncated
    return moves


def test_the_random_policy_plays_without_the_map() -> None:
    env = gym.make("BearingSLAM-v1", **SETTINGS, robot_map_info=False)
    assert play(RandomPolygonal(env), env) == SETTINGS["max_moves"]
    vector_env = BearingSLAMVectorEnv(2, **SETTINGS, robot_map_info=False)
    policy = VectorPolicy(vector_env, RandomPolygonal)
    observations, infos = vector_env.reset(seed=0)
    policy.reset(seed=0)
    assert policy.act(observations, infos).shape == (2, 2)


@needs("train", "stable_baselines3", "torch")
def test_a_shipped_model_plays_without_the_map() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=3, robot_map_info=False)
    assert play(SB3Policy.pretrained("ppo_khepera", env), env) == 3
