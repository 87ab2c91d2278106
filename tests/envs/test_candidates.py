"""The planner features (``planner_features=True``): layout, agreement with the planners'
scoring, the belief they come from, no ground truth, and the Gymnasium contract."""

from __future__ import annotations

import math
import pickle
import warnings
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from gymnasium.vector import AutoresetMode

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.agents.planning import landmark_positions_fl, simulate_potentials
from bearing_env.envs import candidates, core
from bearing_env.envs.actions import DISCRETE
from bearing_env.envs.candidates import CANDIDATE_FEATURES
from bearing_env.envs.observations import observation_size
from bearing_env.tasks import PLANNER_TASKS
from tests.extras import needs

from .test_env_vector import assert_pair_agrees, assert_same, make_pair

KHEPERA = "bearing_env:BearingSLAMDiscrete-Khepera-Planner-v1"
RANDOM = "bearing_env:BearingSLAMDiscrete-Random3to16-Planner-v1"
F = len(CANDIDATE_FEATURES)
PREDICTED, GAIN, SEES_L1, SEES_L2, BLOCKED = range(F)
#: The world's truth in the env state: what the features must not read.
TRUTH = ("landmarks", "positions", "headings", "frame_origin", "frame_unit", "landmarks_fl")


def features_of(env: gym.Env, observation: Any) -> np.ndarray:
    """The (K, F) features of one observation."""
    config = env.unwrapped.config  # type: ignore[attr-defined]
    count = candidates.candidate_count(config)
    flat = observation["candidates"] if isinstance(observation, dict) else observation
    return np.asarray(flat[-count * F :]).reshape(count, F)


def test_the_planner_ids_have_16_candidates_after_the_flat_vector() -> None:
    env = gym.make(KHEPERA)
    config = env.unwrapped.config  # type: ignore[attr-defined]
    assert [task.id for task in PLANNER_TASKS] == [KHEPERA.split(":")[1], RANDOM.split(":")[1]]
    assert env.action_space == gym.spaces.Discrete(16)
    assert env.observation_space.shape == (observation_size(8) + 16 * F,)
    observation, _ = env.reset(seed=0)
    assert env.observation_space.contains(observation)
    # Before any move there is no pose to predict from: every feature is 0.
    assert not features_of(env, observation).any()
    turns, lengths = candidates.candidate_moves(config)
    expected_turns, expected_lengths = DISCRETE.decode(config, np.arange(16))
    assert np.array_equal(turns, expected_turns) and np.array_equal(lengths, expected_lengths)


def test_a_dict_observation_carries_them_as_candidates() -> None:
    env = gym.make(RANDOM, observation="entities")
    observation, _ = env.reset(seed=1)
    assert set(observation) == {"robot", "landmarks", "candidates"}
    assert observation["candidates"].shape == (16 * F,)
    for action in (1, 3, 5, 7, 9, 11, 13, 15):  # the long moves
        observation, *_ = env.step(action)
        assert env.observation_space.contains(observation)
    assert features_of(env, observation)[:, PREDICTED].all()


def believed_pose(env: gym.Env) -> tuple[complex, float, float] | None:
    """The env's believed pose of its robot (position, heading in FL, metres per FL unit)."""
    base = env.unwrapped
    state, config = base._state, base.config  # type: ignore[attr-defined]
    slam = base._maps.view(int(state.n_landmarks[0]), config, 0)  # type: ignore[attr-defined]
    rows = np.array([0])
    fix = np.array([complex(*slam.robot_estimate)])
    position, heading, scale, ready = state.beliefs.poses(rows, fix, np.array([slam.robot_heading]))
    if not ready[0]:
        return None
    return complex(position[0]), float(heading[0]), float(scale[0])


@pytest.mark.parametrize("env_id", [KHEPERA, RANDOM])
def test_the_gains_are_the_planners_scores_from_the_believed_pose(env_id: str) -> None:
    """Differential: the planners' own scoring (``simulate_potentials``, whose bearings
    and updates are computed by another native kernel) from the same pose and map."""
    env = gym.make(env_id)
    config = env.unwrapped.config  # type: ignore[attr-defined]
    turns, lengths = candidates.candidate_moves(config)
    rng = np.random.default_rng(3)
    compared = 0
    for seed in range(3):
        observation, _ = env.reset(seed=seed)
        for _ in range(12):
            observation, _, terminated, truncated, _ = env.step(int(rng.integers(16)))
            if terminated or truncated:
                break
            pose = believed_pose(env)
            features = features_of(env, observation)
            assert features[:, PREDICTED].all() == (pose is not None)
            if pose is None:
                continue
            position, heading, scale = pose
            base = env.unwrapped
            slam = base._maps.view(base._state.n_landmarks[0], config, 0)  # type: ignore[attr-defined]
            potentials = simulate_potentials(
                slam, position, landmark_positions_fl(slam), heading + turns, lengths / scale,
                config.area_cap, min_distance=config.arena.min_baseline / scale,
            )  # fmt: skip
            before = base._state.potentials[0]  # type: ignore[attr-defined]
            expected = np.float32(before - potentials)
            np.testing.assert_allclose(features[:, GAIN], expected, rtol=1e-6, atol=1e-6)
            assert features[:, SEES_L1].all() and features[:, SEES_L2].all()  # panoramic
            compared += 1
    assert compared >= 20


def test_scale_is_exact_without_noise() -> None:
    """Noise-free readings triangulate L1 and L2 exactly: the scale is |L1 - L2|."""
    env = gym.make(RANDOM, noise="none")
    state = env.unwrapped._state  # type: ignore[attr-defined]
    for seed in range(3):
        env.reset(seed=seed)
        for action in (15, 5, 9, 3, 13, 7, 11, 1):
            env.step(action)
            if np.isfinite(state.beliefs.scale[0]):
                break
        truth = np.hypot(*(state.landmarks[0, 1] - state.landmarks[0, 0]))
        assert state.beliefs.scale[0] == pytest.approx(truth, rel=1e-9)


def test_a_limited_camera_predicts_losing_l1_and_l2() -> None:
    env = gym.make(KHEPERA, field_of_view_deg=90)
    rng = np.random.default_rng(0)
    seen = []
    for seed in range(8):
        env.reset(seed=seed)
        for _ in range(15):
            observation, _, terminated, truncated, _ = env.step(int(rng.integers(16)))
            features = features_of(env, observation)
            seen.append(features[features[:, PREDICTED] > 0][:, [SEES_L1, SEES_L2]])
            if terminated or truncated:
                break
    flags = np.concatenate(seen)
    assert flags.size and 0 < flags.mean() < 1  # some candidates keep them, some lose them


def test_after_a_stopped_move_the_moves_ahead_are_predicted_blocked() -> None:
    env = gym.make(KHEPERA)
    turns, _ = candidates.candidate_moves(env.unwrapped.config)  # type: ignore[attr-defined]
    env.reset(seed=0)
    for _ in range(12):  # straight ahead, longest: the wall stops it
        observation, *_ = env.step(1)
        features = features_of(env, observation)
        stopped = bool(env.unwrapped._state.blocked[0])  # type: ignore[attr-defined]
        assert np.array_equal(features[:, BLOCKED] > 0, stopped & (np.abs(turns) < math.pi / 3))
        if stopped:
            return
    pytest.fail("the robot never reached the wall")


def _corrupting(original: Any, rng: np.random.Generator, names: tuple[str, ...]) -> Any:
    """``write_features`` with the state's ``names`` arrays replaced by garbage while it
    runs (restored after), and the map's centroids for ``"centroids"``."""

    def run(state: Any, rows: Any, batch: Any, *args: Any) -> None:
        kept = {}
        for name in names:
            owner = batch if name == "centroids" else state
            array = getattr(owner, name)
            kept[name] = (owner, array.copy())
            array[...] = rng.uniform(-3.0, 3.0, size=array.shape).astype(array.dtype)
        try:
            original(state, rows, batch, *args)
        finally:
            for name, (owner, values) in kept.items():
                getattr(owner, name)[...] = values

    return run


def _episode(env_id: str, seed: int) -> list[np.ndarray]:
    env = gym.make_vec(env_id, num_envs=3, vectorization_mode="vector_entry_point")
    env.action_space.seed(seed)
    observations = [env.reset(seed=seed)[0]]
    for _ in range(25):
        observations.append(env.step(env.action_space.sample())[0])
    env.close()
    return observations


@pytest.mark.parametrize("env_id", [KHEPERA, RANDOM])
def test_corrupting_the_truth_while_they_are_computed_changes_nothing(
    env_id: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    reference = _episode(env_id, seed=4)
    rng = np.random.default_rng(0)
    original = candidates.write_features
    monkeypatch.setattr(candidates, "write_features", _corrupting(original, rng, TRUTH))
    corrupted = _episode(env_id, seed=4)
    for a, b in zip(reference, corrupted, strict=True):
        np.testing.assert_array_equal(a, b)
    # The swap is a real test: corrupting what the robot knows (its map) does change them.
    monkeypatch.setattr(candidates, "write_features", _corrupting(original, rng, ("centroids",)))
    changed = _episode(env_id, seed=4)
    assert any(not np.array_equal(a, b) for a, b in zip(reference, changed, strict=True))


@pytest.mark.parametrize("env_id", [KHEPERA, RANDOM])
def test_the_batched_env_reproduces_single_envs(env_id: str) -> None:
    # One landmark count: single envs of different counts give infos of different shapes.
    kwargs = {"n_landmarks": 6} if env_id == RANDOM else {}
    assert_pair_agrees(*make_pair(env_id, 4, AutoresetMode.NEXT_STEP, **kwargs), seed=2, steps=45)


@needs("render")  # the checker renders every mode the metadata lists
@pytest.mark.parametrize("observation", ["flat", "entities"])
@pytest.mark.parametrize("env_id", [KHEPERA, RANDOM])
def test_gymnasiums_checker_passes_without_warnings(env_id: str, observation: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(gym.make(env_id, observation=observation).unwrapped)


@needs("train", "stable_baselines3", "torch")
@pytest.mark.parametrize("observation", ["flat", "entities"])
@pytest.mark.parametrize("env_id", [KHEPERA, RANDOM])
def test_sb3s_checker_passes_without_warnings(env_id: str, observation: str) -> None:
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        sb3_check_env(gym.make(env_id, observation=observation))


def test_a_pickled_env_continues_identically() -> None:
    env = gym.make(RANDOM)
    env.reset(seed=6)
    for action in (3, 7, 11):
        env.step(action)
    clone = pickle.loads(pickle.dumps(env))
    for action in (1, 5, 9, 13, 15):
        assert_same(env.step(action), clone.step(action))


def test_the_setting_is_validated_and_fixed_on_a_live_env() -> None:
    with pytest.raises(TypeError, match="planner_features"):
        gym.make(KHEPERA, planner_features="yes")
    env = gym.make(KHEPERA)
    with pytest.raises(AttributeError, match="planner_features is read-only"):
        env.unwrapped.planner_features = False  # type: ignore[attr-defined]


def test_the_features_come_from_one_scoring_call_per_group(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    calls = []
    original = core._core._score_rows

    def counted(*args: Any) -> Any:
        calls.append(args[1].size)
        return original(*args)

    monkeypatch.setattr(core._core, "_score_rows", counted)
    env = gym.make_vec(KHEPERA, num_envs=6, vectorization_mode="vector_entry_point")
    env.reset(seed=0)
    for _ in range(4):
        env.step(np.full(6, 15))
    # At most one call per step, of every ready row's moves that update a map.
    config = env.get_attr("config")[0]
    lengths = candidates.candidate_moves(config)[1]
    moving = int(np.count_nonzero(lengths >= config.arena.min_baseline))
    assert 1 <= len(calls) <= 4 and all(size % moving == 0 and size <= 6 * moving for size in calls)
