"""What a step hands out is the caller's: the step kernels write into output arrays they
reuse from step to step (``core._outputs``), so the envs hand out copies. A kept
observation, reward or info must not change when the env steps on."""

from __future__ import annotations

import copy
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from tests.envs.test_env_vector import assert_same

#: Each fusion encodes its own robot map; "mixed" varies the landmark count per episode,
#: so a batched step has groups of some rows only (views of the reused arrays).
SETTINGS: dict[str, dict[str, Any]] = {
    "intersect": {"scenario": "khepera", "fusion": "intersect"},
    "robust": {"scenario": "random", "n_landmarks": 5, "fusion": "robust"},
    "relaxed": {"scenario": "random", "n_landmarks": 4, "fusion": "relaxed"},
    "mixed": {"scenario": "random", "n_landmarks": (3, 6)},
    "entities": {"scenario": "random", "n_landmarks": 4, "observation": "entities"},
}


@pytest.mark.parametrize("name", sorted(SETTINGS))
def test_a_single_env_step_is_not_changed_by_the_next_steps(name: str) -> None:
    env = gym.make("BearingSLAM-v1", **SETTINGS[name], max_moves=5)
    first = env.reset(seed=3)
    env.action_space.seed(3)
    kept: list[tuple[Any, Any]] = [(first, copy.deepcopy(first))]  # resets reuse them too
    for _ in range(12):
        step = env.step(env.action_space.sample())
        kept.append((step, copy.deepcopy(step)))
        if step[2] or step[3]:
            again = env.reset()
            kept.append((again, copy.deepcopy(again)))
    changed = 0
    for step, snapshot in kept:
        assert_same(step, snapshot)
        changed += not np.array_equal(_flat(step[0]), _flat(kept[-1][0][0]))
    assert changed > 0  # the steps differ: had they shared arrays, the asserts would fail
    assert len(kept) > 14  # and resets were kept among them


@pytest.mark.parametrize("name", sorted(SETTINGS))
def test_a_batched_step_is_not_changed_by_the_next_steps(name: str) -> None:
    # Episodes of 5 moves: autoresets write their first observations among the steps'.
    envs = gym.make_vec("BearingSLAM-v1", num_envs=3, **SETTINGS[name], max_moves=5)
    first = envs.reset(seed=5)
    envs.action_space.seed(5)
    kept: list[tuple[Any, Any]] = [(first, copy.deepcopy(first))]
    for _ in range(12):
        step = envs.step(envs.action_space.sample())
        kept.append((step, copy.deepcopy(step)))
    for step, snapshot in kept:
        assert_same(step, snapshot)
    assert not np.array_equal(_flat(kept[0][0][0]), _flat(kept[-1][0][0]))


def _flat(observation: Any) -> np.ndarray:
    if isinstance(observation, dict):
        return np.concatenate([np.ravel(value) for value in observation.values()])
    return np.ravel(observation)
