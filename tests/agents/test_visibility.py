"""The planners' visibility prediction (agents.visibility) and the forward-camera moves."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.agents.base import ActionCodec
from bearing_env.agents.belief import ObservationView, scale_sample
from bearing_env.agents.heuristics import GreedyOneStep, Parallax, limited_view_movement
from bearing_env.agents.visibility import BearingMemory, VisibilityPredictor, keep_in_view


def _predictor(**settings: object) -> VisibilityPredictor:
    return VisibilityPredictor(gym.make("BearingSLAM-v1", scenario="khepera", **settings))


def test_the_panoramic_camera_predicts_everything_seen() -> None:
    predictor = _predictor()
    assert predictor.trivial
    bearings = np.array([[0.1, 0.2, 3.0]])
    landmarks = np.array([0.0, 1.0, -2.0 + 0j])
    assert predictor.missed(bearings, np.array([0.5j]), np.array([0.0]), landmarks, 0.2) is bearings


def test_field_of_view_range_and_bumps_hide_landmarks() -> None:
    predictor = _predictor(field_of_view_deg=90, max_range=0.3)
    landmarks = np.array([0.0, 1.0, 3.0 + 0j, complex(np.nan, np.nan)])
    # From (-1, 0) facing +x: L1 at 1 unit (0.2 m), L2 at 2 units (0.4 m: beyond range),
    # the third at 4 units (beyond range); the unknown one is predicted seen.
    seen = predictor.seen(np.array([-1.0 + 0j]), np.array([0.0]), landmarks, 0.2)
    assert seen.tolist() == [[True, False, False, True]]
    # Facing away: nothing known is in view.
    seen = predictor.seen(np.array([-1.0 + 0j]), np.array([math.pi]), landmarks, 0.2)
    assert seen.tolist() == [[False, False, False, True]]
    # A bump just ahead of (-1, 0) toward +x hides L1 from there.
    wide = _predictor()
    wide.bumped(-1.0 + 0j, 0.0, 0.2)
    assert not wide.trivial
    seen = wide.seen(np.array([-1.0 + 0j, -1.0 + 2j]), np.array([0.0, 0.0]), landmarks, 0.2)
    assert seen.tolist() == [[False, False, False, True], [True, True, True, True]]
    wide.reset()
    assert wide.trivial


def test_missed_readings_become_nan_and_broadcast_over_worlds() -> None:
    predictor = _predictor(field_of_view_deg=90)
    worlds = np.array([[0.0, 1.0, 0.5 + 1j], [0.0, 1.0, 0.5 - 1j]])  # (H=2, n=3)
    positions = np.full((4, 2), 0.5 - 2j)  # (K=4, H=2), facing +y
    headings = np.full((4, 2), math.pi / 2)
    bearings = np.zeros((4, 2, 3))
    out = predictor.missed(bearings, positions, headings, worlds, 1.0)
    assert out.shape == (4, 2, 3)
    assert np.isnan(out).sum() == 0  # all ahead within 45 degrees
    out = predictor.missed(bearings, positions, -headings, worlds, 1.0)
    assert np.isnan(out).all()  # facing away


def test_the_bearing_memory_carries_bearings_through_turns() -> None:
    memory = BearingMemory()
    memory.observe(np.array([0.5, 0.0, -0.2]), np.array([True, False, True]), fresh=True)
    assert np.isnan(memory.bearings[1])
    memory.commanded(0.5)
    memory.observe(np.array([0.0, 0.1, 0.0]), np.array([False, True, False]), fresh=False)
    assert memory.bearings == pytest.approx([0.0, 0.1, -0.7])
    memory.observe(np.zeros(3), np.zeros(3, dtype=bool), fresh=True)
    assert np.isnan(memory.bearings).all()


def test_keep_in_view_prefers_turns_that_keep_l1_and_l2_in_view() -> None:
    memory = np.array([0.6, 0.8, math.nan, -2.0])
    turns = np.array([0.0, 0.7, math.pi])
    scores = keep_in_view(memory, turns, math.radians(45))
    assert int(np.argmax(scores)) == 1 and scores[2] == 0.0


def test_a_forward_camera_looks_around_then_turns_toward_l1_and_l2() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", field_of_view_deg=90)
    codec = ActionCodec(env)
    half_fov = math.radians(45)
    view = ObservationView(0.1, False, False, np.zeros(4), np.zeros(4, dtype=bool))
    turns = np.linspace(-math.pi, math.pi, 72, endpoint=False)
    looking = limited_view_movement(codec, view, turns, np.full(4, np.nan), half_fov)
    assert looking.turn == pytest.approx(1.8 * half_fov) and looking.length == codec.length_range[0]
    memory = np.array([1.0, 1.2, np.nan, np.nan])  # L1 and L2 20 degrees apart, to the left
    toward = limited_view_movement(codec, view, turns, memory, half_fov)
    assert abs(1.0 - toward.turn) < 0.7 * half_fov and abs(1.2 - toward.turn) < 0.7 * half_fov
    assert toward.length == codec.max_length
    close = np.array([1.0, -1.0, np.nan, np.nan])  # far apart: too close to both
    back = limited_view_movement(codec, view, turns, close, half_fov)
    assert abs(abs(back.turn) - math.pi) < 1e-9


def test_a_missed_l1_or_l2_gives_no_scale_sample() -> None:
    start, end = np.array([0.3, 0.5]), np.array([0.6, 0.9])
    assert scale_sample(start, end, 0.2, math.radians(2)) is not None
    assert scale_sample(np.array([np.nan, 0.5]), end, 0.2, math.radians(2)) is None


@pytest.mark.parametrize("policy", [GreedyOneStep, Parallax])
def test_planners_change_frames_with_a_forward_camera(
    policy: type[GreedyOneStep] | type[Parallax],
) -> None:
    """Over a few episodes they find L1 and L2 and keep them in view over moves."""
    env = gym.make("bearing_env:BearingSLAM-Khepera-Camera90-v1", sensor_info=True)
    agent = policy(env)
    frames = 0
    for seed in range(1_000_000, 1_000_005):  # the first evaluation episodes of compare
        agent.reset(seed=seed)
        observation, info = env.reset(seed=seed)
        done = False
        while not done:
            observation, _, terminated, truncated, info = env.step(agent.act(observation, info))
            frames += bool(info["frame_changed"])
            done = terminated or truncated
    assert frames >= 3
    env.close()


def test_the_oracles_true_sensor_misses_what_the_camera_cannot_see() -> None:
    """FL poses map back to the world: a bearing is kept exactly when the true landmark
    lies within half the field of view of the pose's world heading."""
    from bearing_env.agents.env_access import world_of
    from bearing_env.agents.visibility import TrueSensor

    env = gym.make("bearing_env:BearingSLAM-Khepera-Camera90-v1")
    env.reset(seed=4)
    world = world_of(env)
    sensor = TrueSensor(world)
    assert not sensor.trivial
    rng = np.random.default_rng(3)
    positions = rng.uniform(-1, 2, 50) + 1j * rng.uniform(-1, 2, 50)
    headings = rng.uniform(-math.pi, math.pi, 50)
    bearings = rng.uniform(-1, 1, (50, 4))
    kept = sensor(bearings, positions, headings)
    l1, l2 = (complex(*point) for point in world.landmarks[:2])
    at = l1 + (l2 - l1) * positions
    world_headings = headings + np.angle(l2 - l1)
    targets = world.landmarks[:, 0] + 1j * world.landmarks[:, 1]
    directions = np.angle(targets[None] - at[:, None]) - world_headings[:, None]
    angles = np.angle(np.exp(1j * directions))
    outside = np.abs(angles) > math.radians(45)
    np.testing.assert_array_equal(np.isnan(kept), outside)
    np.testing.assert_array_equal(kept[~outside], bearings[~outside])
    env.close()


def test_the_oracles_true_moves_stop_at_the_furniture_as_the_env_does() -> None:
    from bearing_env.agents.env_access import world_of
    from bearing_env.agents.visibility import TrueSensor

    env = gym.make("bearing_env:BearingSLAM-FurnishedRoom-v1")
    codec = ActionCodec(env)
    blocked = 0
    for seed in range(6):
        env.reset(seed=seed)
        world = world_of(env)
        sensor = TrueSensor(world)
        for turn in (-2.0, 0.0, 1.0, 2.5):
            heading = world.heading + turn
            predicted = sensor.travel(np.array(world.position), heading, codec.max_length)
            _, _, _, _, info = env.step(codec.movement(turn, codec.max_length).action)
            assert info["path_length"] == pytest.approx(predicted, abs=1e-6)  # float32 info
            blocked += predicted < codec.max_length
    assert blocked > 0  # some of those moves did run into a wall or the furniture
    env.close()
