"""The readings the update() benchmarks replay (benchmarks/bench_readings.py): recorded
from the named task's episodes, deterministic per seed, exactly what the env's own map
was fed."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

from bearing_env.agents import RandomPolygonal
from bearing_env.benchmarks import bench_readings, bench_slam
from bearing_env.slam import PolygonSLAM

TASKS = bench_readings.RECORDED_TASKS


def task_landmarks(env_id: str) -> int:
    env = gym.make(env_id)
    env.reset(seed=0)
    n = int(env.unwrapped.n_landmarks)  # type: ignore[attr-defined]
    env.close()
    return n


def test_the_recorded_tasks_are_khepera_and_random8() -> None:
    assert TASKS == ("BearingSLAM-Khepera-v1", "BearingSLAM-Random8-v1")
    assert [task_landmarks(env_id) for env_id in TASKS] == [4, 8]


@pytest.mark.parametrize("env_id", TASKS)
def test_readings_have_the_tasks_shape_and_are_bearings(env_id: str) -> None:
    recording = bench_readings.record(env_id, episodes=3, seed=5)
    assert recording.env_id == env_id and recording.seed == 5
    n = task_landmarks(env_id)
    assert recording.start.shape == recording.end.shape == (recording.movements, n)
    assert recording.n_landmarks == n
    assert recording.episodes.shape == (recording.movements,)
    assert sorted(set(recording.episodes.tolist())) == [0, 1, 2]
    assert np.all(np.diff(recording.episodes) >= 0)  # episode by episode, in order
    max_moves = gym.make(env_id).unwrapped.config.task.max_moves  # type: ignore[attr-defined]
    assert np.all(np.bincount(recording.episodes) <= max_moves)
    for bearings in (recording.start, recording.end):
        assert bearings.dtype == np.float64
        seen = bearings[~np.isnan(bearings)]
        assert not np.isinf(bearings).any() and seen.size > 0
        assert np.all((seen > -math.pi - 1e-12) & (seen <= math.pi + 1e-12))
    pairs = recording.readings()
    assert len(pairs) == recording.movements
    assert sum(len(episode) for episode in recording.episode_readings()) == recording.movements


@pytest.mark.parametrize("env_id", TASKS)
def test_readings_are_deterministic_per_seed(env_id: str) -> None:
    first, again = (bench_readings.record(env_id, episodes=2, seed=11) for _ in range(2))
    other = bench_readings.record(env_id, episodes=2, seed=12)
    np.testing.assert_array_equal(first.start, again.start)
    np.testing.assert_array_equal(first.end, again.end)
    np.testing.assert_array_equal(first.episodes, again.episodes)
    assert first.start.shape[1] == other.start.shape[1]
    n = min(first.movements, other.movements)
    assert not np.array_equal(first.start[:n], other.start[:n], equal_nan=True)


@pytest.mark.parametrize("env_id", TASKS)
def test_readings_are_what_the_envs_map_was_fed(env_id: str) -> None:
    # The same episode played by hand: replayed into a fresh map with the env's settings,
    # the recorded readings give the env's own map, area for area, after every movement.
    seed = 7
    env = gym.make(env_id)
    policy = RandomPolygonal(env)
    observation, info = env.reset(seed=seed)
    policy.reset(seed=seed)
    areas = []
    done = False
    while not done:
        observation, _, terminated, truncated, info = env.step(policy.act(observation, info))
        areas.append(env.unwrapped.slam.areas.copy())  # type: ignore[attr-defined]
        done = bool(terminated or truncated)
    settings = env.unwrapped.slam.settings  # type: ignore[attr-defined]
    env.close()
    recording = bench_readings.record(env_id, episodes=1, seed=seed)
    assert recording.settings == settings and recording.movements == len(areas)
    slam = PolygonSLAM.from_settings(recording.n_landmarks, recording.settings)
    for (b1, b2), expected in zip(recording.readings(), areas, strict=True):
        slam.update(b1, b2)
        np.testing.assert_array_equal(slam.areas, expected)


def test_the_workloads_are_the_recorded_tasks_then_the_synthetic_readings() -> None:
    workloads = bench_slam.workloads((4, 64))
    assert [(w.key, w.primary, w.env_id) for w in workloads] == [
        ("khepera", True, "BearingSLAM-Khepera-v1"),
        ("random8", True, "BearingSLAM-Random8-v1"),
        ("synthetic_4", False, None),
        ("synthetic_64", False, None),
    ]
    khepera = workloads[0]
    assert len(khepera.episodes) == bench_readings.RECORDED_EPISODES
    assert khepera.label == "Khepera-v1 readings" and khepera.n_landmarks == 4
    assert workloads[2].label == bench_readings.SYNTHETIC_LABEL
    assert workloads[2].movements == bench_slam.SYNTHETIC_MOVES
    # The synthetic readings are today's bench-slam readings, unchanged.
    (b1, b2), *_ = workloads[3].episodes[0]
    expected = bench_slam.make_readings(64, bench_slam.SYNTHETIC_MOVES, seed=64)[0]
    np.testing.assert_array_equal(b1, expected[0])
    np.testing.assert_array_equal(b2, expected[1])
