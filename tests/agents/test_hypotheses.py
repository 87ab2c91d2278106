"""The planners' moves before the map, planned in hypothesised worlds (a limited camera)."""

from __future__ import annotations

import math
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.agents import GreedyOneStep, Lookahead
from bearing_env.agents.belief import resect_position
from bearing_env.agents.hypotheses import RayMemory
from bearing_env.agents.visibility import travel_until

from .test_agents import PoisonedWorld, play, play_with_truth_swapped, same_actions

CAMERA180 = "bearing_env:BearingSLAM-Khepera-Camera180-v1"
#: Evaluation episodes of the 180 degree task (compare's seeds) where the old bootstrap
#: maps no landmark in 20 moves and the hypothesised worlds map both.
SEEDS_WHERE_IT_HELPS = (1_000_000, 1_000_002, 1_000_004, 1_000_009)


def _final_total_area(env: gym.Env, policy: Any, seed: int) -> float:
    """The episode's total area, every landmark capped at the env's ``area_cap`` (an
    uninitialised one counts at the cap), as compare reports it."""
    observation, info = env.reset(seed=seed)
    policy.reset(seed=seed)
    done = False
    while not done:
        observation, _, terminated, truncated, info = env.step(policy.act(observation, info))
        done = terminated or truncated
    cap = env.unwrapped.config.task.area_cap  # type: ignore[attr-defined]
    areas = np.asarray(info["landmark_area"], dtype=np.float64)
    return float(np.minimum(np.where(np.isfinite(areas), areas, cap), cap).sum())


def test_the_panoramic_planners_plan_no_hypothesised_worlds() -> None:
    """With the paper's camera and no obstacles nothing of the new path is built (the
    golden traces check that the moves are the same as before)."""
    env = gym.make("BearingSLAM-v1", scenario="khepera")
    for policy in (GreedyOneStep(env), Lookahead(env)):
        assert policy.before_map is None
        assert not policy.avoid_bumps
    limited = gym.make(CAMERA180)
    assert GreedyOneStep(limited).before_map is not None
    assert GreedyOneStep(limited, bootstrap_worlds=0).before_map is None
    room = gym.make("bearing_env:BearingSLAM-FurnishedRoom-v1")
    assert GreedyOneStep(room).avoid_bumps


@pytest.mark.parametrize("policy_class", [GreedyOneStep, Lookahead])
def test_the_new_path_never_reads_ground_truth(policy_class: type[GreedyOneStep]) -> None:
    """The same moves when the world fails on any access and info on every key but the
    robot's map, while the policy decides."""
    env = gym.make(CAMERA180, max_moves=8)
    reference, _, _ = play(env, policy_class(env), seed=1_000_003)
    poisoned = play_with_truth_swapped(
        env, policy_class(env), 1_000_003, lambda _: PoisonedWorld(), poison_info=True
    )
    assert same_actions(reference, poisoned)


def test_the_new_path_is_deterministic_under_a_seed() -> None:
    env = gym.make(CAMERA180, max_moves=8)
    first, _, _ = play(env, Lookahead(env), seed=1_000_001)
    again, _, _ = play(env, Lookahead(env), seed=1_000_001)
    other, _, _ = play(env, Lookahead(env), seed=1_000_002)
    assert same_actions(first, again)
    assert not same_actions(first, other)


@pytest.mark.parametrize("policy_class", [GreedyOneStep, Lookahead])
def test_hypothesised_worlds_map_more_than_the_bearing_memory_bootstrap(
    policy_class: type[GreedyOneStep],
) -> None:
    """On a few of the first evaluation episodes of the 180 degree task (where the
    difference is large: the old bootstrap maps no landmark in them) the planner ends
    with a much smaller total area than the same planner with the old bootstrap alone."""
    env = gym.make(CAMERA180)
    for seed in SEEDS_WHERE_IT_HELPS:
        new = _final_total_area(env, policy_class(env), seed)
        old = _final_total_area(env, policy_class(env, bootstrap_worlds=0), seed)
        assert new < old - 5.0, (seed, new, old)


def test_travel_stops_at_a_bump_disc() -> None:
    starts = np.zeros(3, dtype=np.complex128)
    headings = np.array([0.0, math.pi / 2, 0.0])
    lengths = np.array([1.0, 1.0, 0.2])
    travelled = travel_until(starts, headings, lengths, np.array([0.5 + 0.0j]), 0.1)
    np.testing.assert_allclose(travelled, [0.4, 1.0, 0.2])
    # From inside the disc toward its centre: nowhere; away from it: the full length.
    inside = travel_until(np.array([0.45 + 0j]), np.array([0.0]), np.array([1.0]),
                          np.array([0.5 + 0j]), 0.1)  # fmt: skip
    away = travel_until(np.array([0.45 + 0j]), np.array([math.pi]), np.array([1.0]),
                        np.array([0.5 + 0j]), 0.1)  # fmt: skip
    assert inside[0] == 0.0 and away[0] == 1.0


def test_resection_finds_the_position_from_two_bearings() -> None:
    position, heading = 0.3 - 1.2j, 0.4
    landmarks = np.array([0.0, 1.0, 2.0 + 2.0j], dtype=np.complex128)
    bearings = np.angle(landmarks - position) - heading
    found = resect_position(heading, bearings, landmarks)
    assert found is not None and abs(found - position) < 1e-9
    # One landmark missed: still two lines; two missed: none.
    missed = bearings.copy()
    missed[2] = np.nan
    assert abs(resect_position(heading, missed, landmarks) - position) < 1e-9  # type: ignore[operator]
    missed[1] = np.nan
    assert resect_position(heading, missed, landmarks) is None


def test_the_ray_memory_triangulates_what_it_saw_from_two_places() -> None:
    memory = RayMemory(epsilon=math.radians(2.0))
    landmark = 1.0 + 1.0j
    memory.observe(np.array([np.angle(landmark)]), np.array([True]), fresh=True, blocked=False)
    memory.commanded(0.0, 0.5)  # straight ahead along x
    memory.observe(np.array([np.angle(landmark - 0.5)]), np.array([True]), False, False)
    offsets = memory.offsets(16, (0.1, 10.0), np.random.default_rng(0))
    # Within +-25% of the triangulated range along the last ray, from the robot at 0.5.
    ranges = np.abs(offsets[:, 0])
    assert np.all(ranges >= 0.8 * abs(landmark - 0.5) - 1e-9)
    assert np.all(ranges <= 1.25 * abs(landmark - 0.5) + 1e-9)
    np.testing.assert_allclose(np.angle(offsets[:, 0]), np.angle(landmark - 0.5))
    # A landmark never seen stays unknown; a blocked move leaves a bump ahead.
    memory.commanded(0.0, 0.4)
    memory.observe(np.array([0.0]), np.array([False]), False, blocked=True)
    assert memory.bumps and abs(memory.bumps[0] - (0.7 + 0.05)) < 1e-9
