"""The Gymnasium environments: API conformance, determinism, rewards, validation."""

from __future__ import annotations

import math
import os
import pickle
import subprocess
import sys
import warnings
from pathlib import Path
from typing import Any

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bearing_env
from bearing_env.envs import BearingSLAMDiscreteEnv, BearingSLAMEnv
from bearing_env.envs.bearing_slam import (
    AREA_FLOOR,
    DEFAULT_AREA_CAP,
    DEFAULT_MAX_MOVES,
    ROBOT_FEATURES,
    observation_size,
    observation_slices,
)
from bearing_env.registration import ENV_IDS as ALL_BASE_IDS
from bearing_env.registration import register_envs
from bearing_env.slam.batch import RELAXED_STATE_ARRAYS, ROBUST_STATE_ARRAYS, STATE_ARRAYS
from bearing_env.tasks import BASE_IDS, REGISTERED_TASKS_BY_ID
from tests.extras import needs

#: The current base ids, one per action kind (the task ids built on them and the older
#: versions: tests/envs/test_tasks.py).
ENV_IDS = sorted(BASE_IDS.values())
INFO_KEYS = {
    "landmark_area",
    "landmark_error",
    "landmark_contains_truth",
    "total_area",
    "robot_error",
    "frame_changed",
    "inconsistent",
    "outliers",
    "path_length",
    "robot_map",
    "rewards",
}


def test_both_ids_are_registered_without_a_time_limit() -> None:
    assert ENV_IDS == ["BearingSLAM-v1", "BearingSLAMDiscrete-v1"]
    for env_id in ENV_IDS:
        assert gym.spec(env_id).max_episode_steps is None
        env = gym.make(env_id)
        assert env.spec is not None and env.spec.max_episode_steps == DEFAULT_MAX_MOVES


def moves_until_the_end(env: gym.Env[Any, Any]) -> int:
    env.reset(seed=3)
    env.action_space.seed(3)
    moves = 0
    while True:
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        moves += 1
        if terminated or truncated:
            assert truncated and not terminated
            return moves


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_max_moves_is_the_one_episode_cap(env_id: str) -> None:
    """gym.make(id, max_moves=40) runs 40 moves (a registered TimeLimit once cut it at
    20); the spec reads the cap, and gym.make of that spec runs as many."""
    kwargs = {"scenario": "khepera", "target_area": 1e-9}
    env = gym.make(env_id, max_moves=40, **kwargs)
    assert moves_until_the_end(env) == 40
    assert env.spec is not None and env.spec.max_episode_steps == 40
    assert moves_until_the_end(gym.make(env.spec)) == 40
    env.unwrapped.max_moves = 7  # type: ignore[attr-defined]
    spec = env.unwrapped.spec  # (gymnasium's wrappers cache the spec they were made with)
    assert spec is not None and spec.max_episode_steps == 7 and moves_until_the_end(env) == 7
    # An explicit max_episode_steps still adds gymnasium's TimeLimit on top, as for any id.
    assert moves_until_the_end(gym.make(env_id, max_episode_steps=5, **kwargs)) == 5


def test_registration_can_run_twice_silently() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        register_envs()
        register_envs()
        bearing_env.register_envs()
    registered = sorted(i for i in gym.registry if i.startswith("BearingSLAM"))
    assert registered == sorted([*ALL_BASE_IDS, *REGISTERED_TASKS_BY_ID])


def test_make_by_module_prefixed_id_without_importing_first() -> None:
    code = (
        "import sys, gymnasium as gym\n"
        "assert 'bearing_env' not in sys.modules\n"
        "for i in ('BearingSLAM-v1', 'BearingSLAMDiscrete-v1'):\n"
        "    env = gym.make('bearing_env:' + i, n_landmarks=8)\n"
        "    obs, _ = env.reset(seed=0)\n"
        "    env.action_space.seed(0)\n"
        "    env.step(env.action_space.sample())\n"
        "# Rendering is optional: nothing imported pygame; shapely only serves obstacles\n"
        "# and one-off geometry (a process's start-up pays for it only there).\n"
        "assert 'pygame' not in sys.modules and 'shapely' not in sys.modules\n"
        "print('ok', obs.shape)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "ok (63,)"


# --------------------------------------------------------------------------------------
# API conformance, for every registered id
# --------------------------------------------------------------------------------------


@needs("render")
@pytest.mark.parametrize("observation", ["flat", "entities", "shapes"])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_gymnasium_check_env_without_warnings(env_id: str, observation: str) -> None:
    env = gym.make(env_id, observation=observation)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped)
    env.close()


@needs("train", "stable_baselines3", "torch")
@needs("render")
@pytest.mark.parametrize("observation", ["flat", "entities", "shapes"])
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_sb3_check_env_without_warnings(env_id: str, observation: str) -> None:
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    env = gym.make(env_id, observation=observation)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_check_env(env)
    env.close()


def assert_same(a: Any, b: Any) -> None:
    """Exact equality, nested, with NaN equal to NaN and types compared."""
    assert type(a) is type(b), (a, b)
    if isinstance(a, dict):
        assert a.keys() == b.keys()
        for key in a:
            assert_same(a[key], b[key])
    elif isinstance(a, (tuple, list)):
        assert len(a) == len(b)
        for item_a, item_b in zip(a, b, strict=True):
            assert_same(item_a, item_b)
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape
        np.testing.assert_array_equal(a, b)
    elif isinstance(a, float) and math.isnan(a):
        assert math.isnan(b)
    else:
        assert a == b


def rollout(env: gym.Env, seed: int, steps: int) -> list[tuple[Any, ...]]:
    env.action_space.seed(seed)
    observation, info = env.reset(seed=seed)
    record: list[tuple[Any, ...]] = [(observation, info)]
    for _ in range(steps):
        observation, reward, terminated, truncated, info = env.step(env.action_space.sample())
        record.append((observation, reward, terminated, truncated, info))
        if terminated or truncated:
            observation, info = env.reset()
            record.append((observation, info))
    return record


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_same_seed_same_episode_bit_for_bit(env_id: str) -> None:
    kwargs = {"noise": {"kind": "gaussian", "outlier_rate": 0.05}, "n_landmarks": 5}
    first = rollout(gym.make(env_id, **kwargs), seed=42, steps=50)
    second = rollout(gym.make(env_id, **kwargs), seed=42, steps=50)
    assert len(first) == len(second) > 50
    for a, b in zip(first, second, strict=True):
        assert_same(a, b)
    other = rollout(gym.make(env_id, **kwargs), seed=43, steps=5)
    assert not np.array_equal(first[0][0], other[0][0])


@needs("render")
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_pickle_round_trip_continues_identically(env_id: str) -> None:
    env = gym.make(env_id, render_mode="rgb_array")
    env.action_space.seed(0)
    env.reset(seed=3)
    for _ in range(3):
        env.step(env.action_space.sample())
    env.render()  # a live pygame surface must not break pickling
    clone = pickle.loads(pickle.dumps(env))
    actions = [env.action_space.sample() for _ in range(5)]
    for action in actions:
        result = env.step(action)
        assert_same(result, clone.step(action))
        if result[2] or result[3]:  # an ended episode must be reset before stepping on
            assert_same(env.reset(), clone.reset())
    assert clone.render().shape == env.render().shape


def _make_and_step(env_id: str) -> tuple[int, bool]:
    """Run in a spawned process: import, make, step."""
    env = gym.make(env_id)
    env.action_space.seed(0)
    observation, _ = env.reset(seed=0)
    observation, *_ = env.step(env.action_space.sample())
    return observation.shape[0], bool(np.all(np.isfinite(observation)))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_make_in_a_spawned_process(env_id: str) -> None:
    import multiprocessing

    with multiprocessing.get_context("spawn").Pool(1) as pool:
        size, finite = pool.apply(_make_and_step, (env_id,))
    assert size == observation_size(8) and finite


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("mode", ["sync", "async"])
def test_make_vec_runs(env_id: str, mode: str) -> None:
    vector_kwargs = {"context": "spawn"} if mode == "async" else {}
    envs = gym.make_vec(
        env_id, num_envs=2, vectorization_mode=mode, vector_kwargs=vector_kwargs, n_landmarks=5
    )
    try:
        envs.action_space.seed(0)
        observations, infos = envs.reset(seed=[1, 2])
        assert observations.shape == (2, observation_size(8))
        assert not np.array_equal(observations[0], observations[1])
        episode_ends = 0
        for _ in range(25):  # crosses the 20-move truncation and the autoreset
            observations, rewards, terminated, truncated, infos = envs.step(
                envs.action_space.sample()
            )
            assert np.all(np.isfinite(observations)) and np.all(np.isfinite(rewards))
            episode_ends += int(np.sum(terminated | truncated))
        assert episode_ends >= 2
        assert infos["landmark_area"].shape == (2, 3)
    finally:
        envs.close()


@needs("train", "stable_baselines3", "torch")
def test_sb3_subproc_vec_env_with_spawn() -> None:
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import SubprocVecEnv

    venv = make_vec_env(
        # A spawned worker has not imported bearing_env: the module prefix does it.
        "bearing_env:BearingSLAMDiscrete-v1",
        n_envs=2,
        seed=0,
        vec_env_cls=SubprocVecEnv,
        vec_env_kwargs={"start_method": "spawn"},
    )
    try:
        observations = venv.reset()
        for _ in range(3):
            observations, _, _, infos = venv.step(np.array([0, 5]))
        assert observations.shape == (2, observation_size(8))
        assert set(infos[0]) >= INFO_KEYS
    finally:
        venv.close()


# --------------------------------------------------------------------------------------
# Observation and info
# --------------------------------------------------------------------------------------


def test_info_keys_and_shapes() -> None:
    env = BearingSLAMEnv(n_landmarks=6)
    env.action_space.seed(0)
    _, info = env.reset(seed=0)
    assert set(info) == INFO_KEYS
    assert np.all(np.isinf(info["landmark_area"])) and math.isinf(info["total_area"])
    for _ in range(8):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:  # an ended episode must be reset before stepping on
            env.reset()
        assert set(info) == INFO_KEYS
        assert info["landmark_area"].shape == (4,)
        assert info["landmark_error"].shape == (4,)
        assert info["landmark_contains_truth"].dtype == bool
        assert info["total_area"] == pytest.approx(float(np.sum(info["landmark_area"])))
        assert isinstance(info["frame_changed"], bool)
        assert isinstance(info["inconsistent"], int)
        assert 0.0 <= info["path_length"] <= env.move_length[1]
        assert reward == pytest.approx(sum(info["rewards"].values()))
        assert info["robot_map"]["vertices"].shape[:-2] == info["robot_map"]["counts"].shape
        # The strict map carries no relaxed-fusion window and no robust-fusion levels (its
        # info has only what it uses).
        fused_only = set(RELAXED_STATE_ARRAYS) | set(ROBUST_STATE_ARRAYS)
        assert set(info["robot_map"]) == set(STATE_ARRAYS) - fused_only
        # Not initialised <=> infinite area <=> infinite error.
        assert np.array_equal(np.isinf(info["landmark_area"]), np.isinf(info["landmark_error"]))


@pytest.mark.parametrize("fusion", ["intersect", "relaxed", "robust"])
def test_a_kept_observation_and_info_stay_as_they_were(fusion: str) -> None:
    # The step reuses its output arrays: what it hands out must be the caller's own, so
    # later steps and resets leave a kept observation and info as they were.
    env = BearingSLAMEnv(scenario="khepera", fusion=fusion, sensor_info=True)
    env.action_space.seed(1)
    kept = [env.reset(seed=1)]
    for _ in range(12):
        observation, _, terminated, truncated, info = env.step(env.action_space.sample())
        kept.append((observation, info))
        if terminated or truncated:
            kept.append(env.reset())
    snapshots = [pickle.loads(pickle.dumps(item)) for item in kept]
    for _ in range(12):
        _, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if terminated or truncated:
            env.reset()
    changed = [k for k, (a, b) in enumerate(zip(kept, snapshots, strict=True)) if not same(a, b)]
    assert changed == []
    assert len({id(info["robot_map"]["vertices"]) for _, info in kept}) == len(kept)


def same(a: Any, b: Any) -> bool:
    """Whether two observations, infos or (observation, info) pairs are equal, bit for bit."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same(a[key], b[key]) for key in a)
    if isinstance(a, tuple):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


def test_observation_layout_and_padding() -> None:
    env = BearingSLAMEnv(scenario="khepera", max_landmarks=6)
    assert env.observation_space.shape == (observation_size(6),) == (9 + 5 * 4 + 3 * 6,)
    observation, _ = env.reset(seed=0)
    blocks = observation_slices(6)
    landmarks = observation[blocks["landmarks"]].reshape(4, 5)
    bearings = observation[blocks["bearings"]].reshape(6, 3)
    np.testing.assert_array_equal(landmarks[:, 0], [1, 1, 0, 0])  # L3, L4 present
    np.testing.assert_array_equal(landmarks[:2, 1], [1, 1])  # not initialised yet
    np.testing.assert_array_equal(landmarks[2:], 0)  # padding is all zeros
    np.testing.assert_array_equal(bearings[:, 0], [1, 1, 1, 1, 0, 0])
    np.testing.assert_array_equal(bearings[4:], 0)
    np.testing.assert_allclose(np.hypot(bearings[:4, 1], bearings[:4, 2]), 1, rtol=1e-6)
    assert observation[3] == 1.0  # robot region unknown before any movement
    for _ in range(10):
        observation, _, _, _, info = env.step(np.array([0.7, 1.0], dtype=np.float32))
        landmarks = observation[blocks["landmarks"]].reshape(4, 5)
        initialised = np.isfinite(info["landmark_area"])
        np.testing.assert_array_equal(landmarks[:2, 1], ~initialised)
        logs = np.log(np.clip(info["landmark_area"], AREA_FLOOR, DEFAULT_AREA_CAP))
        np.testing.assert_allclose(landmarks[:2, 4], logs, rtol=1e-5)
        assert observation[7] == float(info["frame_changed"])
    assert observation[3] == 0.0 and observation[4] ** 2 + observation[5] ** 2 == pytest.approx(1)


def test_observation_does_not_depend_on_the_true_layout_beyond_bearings() -> None:
    # Same bearings, scaled world: the robot cannot tell the difference, nor can the
    # observation (FL coordinates are scale free and no metric truth leaks in).
    small = BearingSLAMEnv(
        landmarks=[[0.4, 0.2], [0.6, 0.2], [0.5, 0.5]], arena=(1.0, 1.0), noise="none"
    )
    large = BearingSLAMEnv(
        landmarks=[[0.8, 0.4], [1.2, 0.4], [1.0, 1.0]], arena=(2.0, 2.0), noise="none"
    )
    obs_small, _ = small.reset(seed=5)
    obs_large, _ = large.reset(seed=5)
    np.testing.assert_allclose(obs_small, obs_large, atol=1e-5)
    for action in ([0.3, 0.0], [-0.8, 0.5], [0.5, -0.5], [0.9, 1.0]):
        obs_small, *_ = small.step(np.array(action, dtype=np.float32))
        obs_large, *_ = large.step(np.array(action, dtype=np.float32))
        np.testing.assert_allclose(obs_small, obs_large, atol=1e-4)


def test_conservative_regions_contain_the_truth() -> None:
    env = BearingSLAMEnv(n_landmarks=6)
    env.action_space.seed(1)
    for seed in range(3):
        env.reset(seed=seed)
        for _ in range(15):
            _, _, terminated, _, info = env.step(env.action_space.sample())
            initialised = np.isfinite(info["landmark_area"])
            assert np.all(info["landmark_contains_truth"][initialised])
            assert info["inconsistent"] == 0
            if terminated:
                break


def test_stuck_at_the_wall_does_not_update_the_map() -> None:
    env = BearingSLAMEnv(scenario="khepera", move_length=5.0)
    env.reset(seed=0)
    straight = np.array([0.0, 0.0], dtype=np.float32)
    observation, *_, info = env.step(straight)
    assert observation[8] == 1.0  # stopped by the wall
    assert info["path_length"] > 0
    observation, reward, _, _, info = env.step(straight)
    assert info["path_length"] == 0.0
    assert info["frame_changed"] is False and reward == 0.0
    assert observation[7] == 0.0 and observation[8] == 1.0


# --------------------------------------------------------------------------------------
# Rewards and episode end
# --------------------------------------------------------------------------------------


def capped_potential(areas: np.ndarray, cap: float, kind: str) -> float:
    capped = np.clip(areas, AREA_FLOOR, cap)
    return float(np.sum(np.log(capped))) if kind == "log_area" else float(np.sum(capped))


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("reward", ["log_area", "area"])
def test_return_telescopes(env_id: str, reward: str) -> None:
    env = gym.make(env_id, reward=reward, n_landmarks=5, target_area=1e-6)
    env.action_space.seed(7)
    _, info = env.reset(seed=7)
    total, steps, done = 0.0, 0, False
    while not done:
        _, step_reward, terminated, truncated, info = env.step(env.action_space.sample())
        total += float(step_reward)
        steps += 1
        done = terminated or truncated
    assert steps == DEFAULT_MAX_MOVES
    initial = capped_potential(np.full(3, np.inf), DEFAULT_AREA_CAP, reward)
    final = capped_potential(info["landmark_area"], DEFAULT_AREA_CAP, reward)
    assert initial > final  # something was learnt about the map
    assert total == pytest.approx(initial - final, rel=1e-9, abs=1e-9)


def test_costs_are_named_parts_of_the_reward() -> None:
    env = BearingSLAMEnv(path_cost=0.5, move_cost=0.1)
    env.action_space.seed(0)
    env.reset(seed=0)
    for _ in range(5):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        parts = info["rewards"]
        assert set(parts) == {"uncertainty", "path_cost", "move_cost"}
        assert parts["path_cost"] == pytest.approx(-0.5 * info["path_length"])
        assert parts["move_cost"] == pytest.approx(-0.1)
        assert reward == pytest.approx(sum(parts.values()))
        if terminated or truncated:
            env.reset()


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_success_terminates(env_id: str) -> None:
    # Any region at all is below this target: success as soon as all are initialised.
    env = gym.make(env_id, scenario="khepera", target_area=1e6)
    env.action_space.seed(0)
    env.reset(seed=0)
    for _ in range(DEFAULT_MAX_MOVES):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        initialised = bool(np.all(np.isfinite(info["landmark_area"])))
        assert terminated == initialised
        if terminated:
            assert not truncated
            break
    assert terminated


def test_truncation_after_max_moves() -> None:
    env = BearingSLAMEnv(max_moves=3, target_area=1e-9)
    env.action_space.seed(0)
    env.reset(seed=0)
    flags = [env.step(env.action_space.sample())[2:4] for _ in range(3)]
    assert flags == [(False, False), (False, False), (False, True)]


# --------------------------------------------------------------------------------------
# Bad input
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "error", "fragment"),
    [
        ({"n_landmarks": 2}, ValueError, "n_landmarks.*2"),
        ({"n_landmarks": 3.5}, TypeError, "3.5"),
        ({"epsilon_deg": 0.0}, ValueError, "epsilon_deg.*0.0"),
        ({"epsilon_deg": -2.0}, ValueError, "-2.0"),
        ({"epsilon_deg": 90.0}, ValueError, "90.0"),  # the world model's bound: (0, 90) degrees
        ({"epsilon_deg": math.nan}, ValueError, "nan"),
        ({"arena": (0.0, 1.0)}, ValueError, "arena width.*0.0"),
        ({"arena": (1.0, -0.5)}, ValueError, "arena height.*-0.5"),
        ({"arena": (1.0, 2.0, 3.0)}, ValueError, "3.0"),
        ({"scenario": "moon"}, ValueError, "'moon'"),
        ({"reward": "happiness"}, ValueError, "'happiness'"),
        ({"transfer": "magic"}, ValueError, "'magic'"),
        ({"noise": {"kind": "laplace"}}, ValueError, "'laplace'"),
        ({"noise": {"kind": "uniform", "outlier_rate": 2.0}}, ValueError, "2.0"),
        ({"target_area": 0.0}, ValueError, "target_area.*0.0"),
        ({"max_moves": 0}, ValueError, "max_moves.*0"),
        ({"move_length": (0.3, 0.1)}, ValueError, r"\(0.3, 0.1\)"),
        ({"move_length": -1.0}, ValueError, "-1.0"),
        ({"path_cost": -1.0}, ValueError, "path_cost.*-1.0"),
        ({"max_landmarks": 2}, ValueError, "max_landmarks.*2"),
        ({"render_mode": "ascii"}, ValueError, "'ascii'"),
        ({"scenario": "khepera", "n_landmarks": 5}, ValueError, "n_landmarks=5"),
        ({"scenario": "custom"}, ValueError, "landmarks"),
        ({"landmarks": [[0.1, 0.1], [0.2, 0.1]]}, ValueError, "landmarks.*2"),
        ({"landmarks": [[0.1, 0.1], [0.2, 0.1], [5.0, 0.3]]}, ValueError, r"\[5.0, 0.3\]"),
        ({"landmarks": [[0.1, 0.1], [0.1, 0.1], [0.3, 0.3]]}, ValueError, "distinct"),
        (
            {"scenario": "khepera", "landmarks": [[0.1, 0.1], [0.2, 0.1], [0.3, 0.3]]},
            ValueError,
            "khepera",
        ),
        ({"colour": "red"}, TypeError, "colour"),
    ],
)
@pytest.mark.parametrize("env_class", [BearingSLAMEnv, BearingSLAMDiscreteEnv])
def test_invalid_kwargs_raise_naming_the_value(
    env_class: type[BearingSLAMEnv], kwargs: dict[str, Any], error: type, fragment: str
) -> None:
    with pytest.raises(error, match=fragment):
        env_class(**kwargs)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_invalid_kwargs_through_make(env_id: str) -> None:
    with pytest.raises(TypeError, match="colour"):
        gym.make(env_id, colour="red")
    with pytest.raises(ValueError, match=r"epsilon_deg.*90"):
        gym.make(env_id, epsilon_deg=90)


@pytest.mark.parametrize(
    "action",
    [
        [math.nan, 0.0],
        [0.0, math.inf],
        [1.5, 0.0],
        [0.0, -1.01],
        [0.1, 0.2, 0.3],
        "left",
    ],
)
def test_bad_continuous_actions_raise(action: Any) -> None:
    env = BearingSLAMEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(np.array(action, dtype=object) if isinstance(action, str) else action)


def test_continuous_action_accepts_lists_and_float64_at_the_bounds() -> None:
    env = BearingSLAMEnv(move_length=(0.1, 0.2))
    env.reset(seed=0)
    env.step([1.0, -1.0])
    env.step(np.array([-1.0, 1.0]))
    assert env._decode_action([1.0, -1.0]) == (math.pi, 0.1)
    assert env._decode_action(np.float32([-1.0, 1.0]))[1] == pytest.approx(0.2)


@pytest.mark.parametrize("action", [-1, 24, 2.5, math.nan, True, [1, 2]])
def test_bad_discrete_actions_raise(action: Any) -> None:
    env = BearingSLAMDiscreteEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(action)


def test_discrete_action_table() -> None:
    env = BearingSLAMDiscreteEnv(move_length=(0.1, 0.3), n_turns=4, n_move_lengths=3)
    assert env.action_space.n == 12
    np.testing.assert_allclose(env.turn_angles, [0, np.pi / 2, -np.pi, -np.pi / 2])
    np.testing.assert_allclose(env.move_lengths, [0.1, 0.2, 0.3])
    assert env._decode_action(np.int64(7)) == pytest.approx((-np.pi, 0.2))
    assert BearingSLAMDiscreteEnv(move_length=0.25).action_space.n == 8


def test_step_before_reset_raises() -> None:
    with pytest.raises(RuntimeError, match="reset"):
        BearingSLAMEnv().step([0.0, 0.0])


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_reset_refuses_options_naming_them(env_id: str) -> None:
    env = gym.make(env_id, scenario="khepera")
    expected = env.reset(seed=2)
    with pytest.raises(TypeError, match=r"unknown reset options \['reset_mask'\]"):
        env.reset(seed=2, options={"reset_mask": np.array([True])})
    with pytest.raises(TypeError, match="dict or None, got 'area_cap'"):
        env.reset(seed=2, options="area_cap")  # type: ignore[arg-type]
    for options in (None, {}):  # no options at all is fine, and the same reset
        observation, info = env.reset(seed=2, options=options)
        np.testing.assert_array_equal(observation, expected[0])
        assert info.keys() == expected[1].keys()


# --------------------------------------------------------------------------------------
# Fuzz: observations stay finite and in the space
# --------------------------------------------------------------------------------------

configurations = st.fixed_dictionaries(
    {
        "scenario": st.sampled_from(["random", "khepera", "paper_sim"]),
        "n_landmarks": st.integers(3, 9),
        "epsilon_deg": st.floats(0.2, 30.0),
        "noise": st.fixed_dictionaries(
            {
                "kind": st.sampled_from(["uniform", "gaussian", "none"]),
                "bound_deg": st.none() | st.floats(0.0, 20.0),
                "outlier_rate": st.sampled_from([0.0, 0.1, 0.5]),
            }
        ),
        "transfer": st.sampled_from(["conservative", "paper"]),
        "reward": st.sampled_from(["log_area", "area"]),
        "move_length": st.sampled_from([None, 0.01, (0.001, 1.0), (0.2, 3.0)]),
        "area_cap": st.sampled_from([0.5, 10.0, 1e4]),
        "arena": st.sampled_from([None, (0.3, 2.0), (4.0, 4.0)]),
    }
)
unit = st.floats(-1.0, 1.0)


@settings(
    max_examples=20,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    config=configurations,
    actions=st.lists(st.tuples(unit, unit), min_size=1, max_size=12),
    seed=st.integers(0, 2**31 - 1),
)
def test_fuzz_observations_stay_finite(
    config: dict[str, Any], actions: list[tuple[float, float]], seed: int
) -> None:
    if config["scenario"] != "random":
        config = {**config, "n_landmarks": None}
        if config["arena"] is not None:
            config = {**config, "arena": None}  # fixed layouts need their own arena
    env = BearingSLAMEnv(**config)
    observation, _ = env.reset(seed=seed)
    assert env.observation_space.contains(observation)
    for action in actions:
        observation, reward, terminated, truncated, info = env.step(
            np.array(action, dtype=np.float32)
        )
        assert env.observation_space.contains(observation), observation
        assert math.isfinite(reward)
        assert set(info) == INFO_KEYS
        if terminated or truncated:
            observation, _ = env.reset()


# --------------------------------------------------------------------------------------
# Training smoke test
# --------------------------------------------------------------------------------------


@needs("train", "stable_baselines3", "torch")
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_ppo_learns_a_few_hundred_steps(env_id: str) -> None:
    from stable_baselines3 import PPO

    env = gym.make(env_id, scenario="khepera")
    model = PPO("MlpPolicy", env, n_steps=64, batch_size=32, n_epochs=2, seed=0, device="cpu")
    model.learn(total_timesteps=256)
    assert model.num_timesteps >= 256
    observation, _ = env.reset(seed=0)
    action, _ = model.predict(observation, deterministic=True)
    assert env.action_space.contains(action)
    env.step(action)


def test_a_landmark_count_range_draws_a_count_per_episode() -> None:
    env = gym.make("BearingSLAM-v1", n_landmarks=(4, 8))
    env.action_space.seed(0)
    assert (
        env.observation_space.shape
        == gym.make("BearingSLAM-v1", n_landmarks=8).observation_space.shape
    )
    counts = set()
    for seed in range(30):
        observation, info = env.reset(seed=seed)
        n = env.unwrapped.n_landmarks
        counts.add(n)
        assert len(info["landmark_area"]) == n - 2
        observation, _, _, _, info = env.step(env.action_space.sample())
        assert len(info["landmark_area"]) == n - 2
        assert env.observation_space.contains(observation)
    assert counts == {4, 5, 6, 7, 8}
    # The same seed gives the same count and layout.
    first, _ = env.reset(seed=11)
    again, _ = env.reset(seed=11)
    np.testing.assert_array_equal(first, again)
    with pytest.raises(ValueError, match="fixed landmark positions"):
        gym.make("BearingSLAM-v1", scenario="khepera", n_landmarks=(4, 6))
    with pytest.raises(ValueError, match="n_landmarks"):
        gym.make("BearingSLAM-v1", n_landmarks=(6, 4))


def test_the_map_and_the_ground_truth_are_public_and_apart() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera")
    assert env.unwrapped.world is None  # no ground truth before the first reset
    env.reset(seed=0)
    world, slam = env.unwrapped.world, env.unwrapped.slam
    assert world.landmarks.shape == (4, 2) and slam.n_landmarks == 4
    env.step(np.array([0.5, 1.0], dtype=np.float32))
    assert env.unwrapped.slam is slam  # the same map, updated in place


# --------------------------------------------------------------------------------------
# Clear errors for malformed input
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "action",
    [
        ["0.5", "0.1"],
        np.array(["0.5", "0.1"]),
        [True, False],
        np.array([True, True]),
        [0.5 + 1j, 0.0],
        np.array([0.1, 0.2], dtype=complex),
        np.array([0.1, "x"], dtype=object),
    ],
    ids=["str-list", "str-array", "bool-list", "bool-array", "complex", "complex-array", "obj"],
)
def test_continuous_actions_that_are_not_real_numbers_raise(action: Any) -> None:
    env = BearingSLAMEnv()
    env.reset(seed=0)
    with pytest.raises(ValueError, match="real numbers"):
        env.step(action)


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_stepping_an_ended_episode_without_reset_raises(env_id: str) -> None:
    env = gym.make(env_id, max_moves=2, target_area=1e-9).unwrapped
    env.action_space.seed(0)
    env.reset(seed=0)
    action = env.action_space.sample()
    env.step(action)
    *_, terminated, truncated, _ = env.step(action)
    assert terminated or truncated
    with pytest.raises(RuntimeError, match=r"ended.*reset"):
        env.step(action)
    env.reset()
    env.step(action)  # a reset starts a new episode


def test_the_world_is_a_read_only_live_view() -> None:
    env = BearingSLAMEnv(scenario="khepera")
    env.reset(seed=0)
    world = env.world
    assert world is not None
    start = world.position.copy()
    with pytest.raises(ValueError, match="read-only"):
        world.position[0] = 0.5
    with pytest.raises(ValueError, match="read-only"):
        world.landmarks[0, 0] = 0.5
    with pytest.raises(AttributeError):
        world.heading = 1.0  # type: ignore[misc]
    env.step(np.array([0.0, 1.0], dtype=np.float32))
    assert env.world is world and not np.array_equal(world.position, start)
    snapshot = world.copy()  # a mutable, independent World
    snapshot.position = np.array([0.3, 0.3])
    assert not np.array_equal(world.position, snapshot.position)
    np.testing.assert_array_equal(world.true_bearings(), world.copy().true_bearings())


def _read_only_clone(env: Any) -> Any:
    """A pickle round trip whose out-of-band buffers come back read-only."""
    buffers: list[pickle.PickleBuffer] = []
    data = pickle.dumps(env, protocol=5, buffer_callback=buffers.append)
    assert buffers  # the arrays really travelled out of band
    return pickle.loads(data, buffers=[memoryview(b.raw()).toreadonly() for b in buffers])


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_the_envs_own_arrays_are_writable_after_a_read_only_unpickle(env_id: str) -> None:
    env = gym.make(env_id, scenario="khepera").unwrapped
    env.reset(seed=0)
    clone = _read_only_clone(env)
    state = clone._state
    arrays = {name: value for name, value in vars(state).items() if isinstance(value, np.ndarray)}
    assert "positions" in arrays and "noise_offsets" in arrays
    for name, value in arrays.items():
        assert value.flags.writeable, name
    assert clone._rows.flags.writeable  # the step kernels' row indices


def test_packed_obstacles_are_not_pickled_but_made_again() -> None:
    env = gym.make("BearingSLAM-v1", scenario="furnished_room").unwrapped
    env.reset(seed=0)
    packed = env.config.layout.packed_obstacles
    clone = _read_only_clone(env)
    again = clone.config.layout.packed_obstacles
    for before, after in zip(packed, again, strict=True):
        np.testing.assert_array_equal(before, after)
        assert after.flags.writeable


def test_a_read_only_unpickle_steps_in_a_fresh_process(tmp_path: Path) -> None:
    """Ray's case: the env arrives in a new process whose numba kernels load from the
    cache, with read-only buffers (once a segfault in the step kernel: the parallel
    runtime unstarted, see ``tests/slam/test_parallel_runtime.py``)."""
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=5)
    env.reset(seed=11)
    env.action_space.seed(5)
    actions = [env.action_space.sample() for _ in range(4)]
    env.step(actions[0])
    buffers: list[pickle.PickleBuffer] = []
    data = pickle.dumps(env, protocol=5, buffer_callback=buffers.append)
    (tmp_path / "env.pkl").write_bytes(pickle.dumps((data, [bytes(b.raw()) for b in buffers])))
    expected = [float(env.step(action)[1]) for action in actions[1:]]
    script = (
        "import pickle, sys\n"
        f"data, buffers = pickle.loads(open({str(tmp_path / 'env.pkl')!r}, 'rb').read())\n"
        "env = pickle.loads(data, buffers=[memoryview(b) for b in buffers])\n"
        f"for action in {[a.tolist() for a in actions[1:]]!r}:\n"
        "    import numpy as np\n"
        "    print(repr(float(env.step(np.array(action, dtype=np.float32))[1])))\n"
    )
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert [float(line) for line in result.stdout.split()] == expected


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_an_env_from_a_read_only_unpickle_still_steps(env_id: str) -> None:
    env = gym.make(env_id, scenario="khepera").unwrapped
    env.reset(seed=0)
    env.action_space.seed(0)
    actions = [env.action_space.sample() for _ in range(6)]
    clone = _read_only_clone(env)
    for action in actions:
        assert_same(env.step(action), clone.step(action))


# --------------------------------------------------------------------------------------
# The entity observation
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_entity_observation_is_the_flat_one_rearranged(env_id: str) -> None:
    from gymnasium.wrappers import FlattenObservation

    from bearing_env.envs.observations import ENTITY_FEATURES

    flat_env = gym.make(env_id, n_landmarks=(3, 6), max_landmarks=7)
    entity_env = gym.make(env_id, n_landmarks=(3, 6), max_landmarks=7, observation="entities")
    assert isinstance(entity_env.observation_space, gym.spaces.Dict)
    slots, width = 7, len(ENTITY_FEATURES)
    column = {name: index for index, name in enumerate(ENTITY_FEATURES)}
    for seed in (0, 1, 2):
        flat, _ = flat_env.reset(seed=seed)
        entities, _ = entity_env.reset(seed=seed)
        flat_env.action_space.seed(seed)
        for _ in range(4):
            assert entity_env.observation_space.contains(entities)
            n = entity_env.unwrapped.n_landmarks
            table = entities["landmarks"].reshape(slots, width)
            blocks = observation_slices(7)
            np.testing.assert_array_equal(entities["robot"], flat[blocks["robot"]])
            np.testing.assert_array_equal(table[:, column["present"]], np.arange(slots) < n)
            np.testing.assert_array_equal(table[:, column["is_frame"]], np.arange(slots) < 2)
            np.testing.assert_array_equal(table[:2, column["x"]], [0.0, 1.0])
            np.testing.assert_array_equal(table[n:], 0.0)  # absent slots are empty
            mapped = flat[blocks["landmarks"]].reshape(slots - 2, -1)
            np.testing.assert_array_equal(table[2:, column["x"]], mapped[:, 2])
            np.testing.assert_array_equal(table[2:, column["log_area"]], mapped[:, 4])
            bearings = flat[blocks["bearings"]].reshape(slots, -1)
            np.testing.assert_array_equal(table[:, column["bearing_sin"]], bearings[:, 2])
            action = flat_env.action_space.sample()
            flat, _, terminated, truncated, _ = flat_env.step(action)
            entities, *_ = entity_env.step(action)
            if terminated or truncated:
                break
    wrapped = FlattenObservation(entity_env)
    observation, _ = wrapped.reset(seed=0)
    assert wrapped.observation_space.contains(observation)
    assert observation.shape == (len(ROBOT_FEATURES) + slots * width,)
    clone = pickle.loads(pickle.dumps(entity_env))
    assert_same(clone.reset(seed=5), entity_env.reset(seed=5))


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_entity_observation_on_the_vector_env(env_id: str) -> None:
    kwargs = {"scenario": "khepera", "observation": "entities"}
    batched = gym.make_vec(env_id, num_envs=3, **kwargs)
    reference = gym.make_vec(env_id, num_envs=3, vectorization_mode="sync", **kwargs)
    assert batched.observation_space == reference.observation_space
    batched.action_space.seed(3)
    first, _ = batched.reset(seed=3)
    second, _ = reference.reset(seed=3)
    for _ in range(25):  # through an autoreset
        assert batched.observation_space.contains(first)
        for key in ("robot", "landmarks"):
            np.testing.assert_array_equal(first[key], second[key])
        actions = batched.action_space.sample()
        first, *_ = batched.step(actions)
        second, *_ = reference.step(actions)


def test_observation_kind_is_validated_and_fixed() -> None:
    with pytest.raises(ValueError, match="unknown observation 'image'"):
        gym.make("BearingSLAM-v1", observation="image")
    with pytest.raises(TypeError, match="observation must be a str"):
        gym.make("BearingSLAM-v1", observation=1)
    env = BearingSLAMEnv(observation="entities")
    assert env.observation_kind == "entities"
    with pytest.raises(AttributeError, match="read-only"):
        env.observation_kind = "flat"
    with pytest.raises(ValueError, match="observation cannot change"):
        env.config = env.config.replace(observation="flat")


def test_reading_the_generator_mid_episode_changes_nothing_but_the_draws_it_makes() -> None:
    """The env draws its moves' noise ahead; reading ``np_random`` hands the unspent draws
    back, so a draw from it is the one it would be had the env drawn move by move, and the
    episode goes on the same when nothing is drawn."""
    actions = np.random.default_rng(3).uniform(-1, 1, (8, 2)).astype(np.float32)
    read, plain = (gym.make("BearingSLAM-v1", scenario="khepera").unwrapped for _ in range(2))
    read.reset(seed=5)
    plain.reset(seed=5)
    for k, action in enumerate(actions):
        if k == 4:
            assert isinstance(read.np_random, np.random.Generator)
        got, want = read.step(action), plain.step(action)
        np.testing.assert_array_equal(got[0], want[0])
        assert got[1] == want[1]
    # Both generators are now where eight moves' draws left them.
    assert read.np_random.random() == plain.np_random.random()
