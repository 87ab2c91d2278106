"""Exploration policies: full episodes on both ids, no ground truth, codec, SB3 loading."""

from __future__ import annotations

import copy
import math
import pickle
import zipfile
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.agents import (
    ActionCodec,
    GreedyOneStep,
    GreedyOracle,
    ModelLoadError,
    Parallax,
    Policy,
    RandomPolygonal,
    SB3Policy,
    make_policy,
    parse_policy_spec,
)
from bearing_env.agents.belief import ObservationReader, scale_sample, triangulate_fr
from bearing_env.agents.env_access import MapReader
from bearing_env.agents.lookahead import Lookahead, LookaheadOracle, sample_in_polygon
from bearing_env.agents.vector import VectorPolicy
from bearing_env.slam import world_to_fl
from tests.extras import needs

ENV_IDS = ("BearingSLAM-v1", "BearingSLAMDiscrete-v1")
HEURISTICS = (RandomPolygonal, Parallax, GreedyOneStep, GreedyOracle, Lookahead, LookaheadOracle)
#: Policies that must act on the robot's knowledge only.
ROBOT_POLICIES = (RandomPolygonal, Parallax, GreedyOneStep, Lookahead)
#: The privileged upper references (they read ground truth).
ORACLES = (GreedyOracle, LookaheadOracle)


def play(env: gym.Env, policy: Any, seed: int) -> tuple[list[Any], dict[str, Any], int]:
    """One full episode; the actions, the last info and the number of moves."""
    observation, info = env.reset(seed=seed)
    policy.reset(seed=seed)
    actions = []
    terminated = truncated = False
    while not (terminated or truncated):
        action = policy.act(observation, info)
        assert env.action_space.contains(action), action
        actions.append(copy.deepcopy(action))
        observation, _, terminated, truncated, info = env.step(action)
    return actions, info, len(actions)


def same_actions(first: list[Any], second: list[Any]) -> bool:
    return len(first) == len(second) and all(
        np.array_equal(np.asarray(a), np.asarray(b)) for a, b in zip(first, second, strict=True)
    )


# --------------------------------------------------------------------------------------
# Every policy on both ids
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("policy_class", HEURISTICS, ids=lambda c: c.__name__)
def test_policy_runs_full_episodes(env_id: str, policy_class: type) -> None:
    env = gym.make(env_id, scenario="khepera", max_moves=8, max_episode_steps=8)
    policy = policy_class(env)
    assert isinstance(policy, Policy)
    assert isinstance(policy.name, str) and policy.name
    for seed in (3, 4):
        _, info, moves = play(env, policy, seed)
        assert 1 <= moves <= 8
        assert np.isfinite(info["total_area"]) or moves == 8


@pytest.mark.parametrize("policy_class", HEURISTICS, ids=lambda c: c.__name__)
def test_policy_runs_on_random_layouts_with_more_landmarks(policy_class: type) -> None:
    env = gym.make("BearingSLAM-v1", n_landmarks=6, max_moves=5, max_episode_steps=5)
    _, info, moves = play(env, policy_class(env), seed=11)
    success = bool(np.all(info["landmark_area"] <= env.unwrapped.target_area))
    assert moves == 5 or (moves < 5 and success)


@pytest.mark.parametrize("policy_class", HEURISTICS, ids=lambda c: c.__name__)
def test_policy_is_deterministic_for_a_seed(policy_class: type) -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=6, max_episode_steps=6)
    first, _, _ = play(env, policy_class(env), seed=5)
    second, _, _ = play(env, policy_class(env), seed=5)
    assert same_actions(first, second)


def test_random_polygonal_lengths_are_configurable() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", move_length=(0.1, 0.3))
    codec = ActionCodec(env)
    fixed = RandomPolygonal(env, length=0.2)
    fixed.reset(seed=0)
    observation, info = env.reset(seed=0)
    lengths = {round(codec.decode(fixed.act(observation, info))[1], 6) for _ in range(20)}
    assert lengths == {0.2}
    varying = RandomPolygonal(env)
    varying.reset(seed=0)
    drawn = [codec.decode(varying.act(observation, info)) for _ in range(200)]
    turns, lengths_drawn = np.array(drawn).T
    assert 0.1 - 1e-6 <= lengths_drawn.min() < 0.13 and 0.27 < lengths_drawn.max() <= 0.3 + 1e-6
    assert turns.min() < -2.5 and turns.max() > 2.5
    with pytest.raises(ValueError, match="outside the env's move_length"):
        RandomPolygonal(env, length=0.5)


def test_policy_rng_is_independent_of_the_env_stream() -> None:
    # The env seeds default_rng(seed); a policy on the same stream would turn in step
    # with the noise. Its first turn must not be the env's first uniform draw.
    env = gym.make("BearingSLAM-v1", scenario="khepera")
    policy = RandomPolygonal(env)
    policy.reset(seed=42)
    observation, info = env.reset(seed=42)
    action = policy.act(observation, info)
    assert float(action[0]) != pytest.approx(np.random.default_rng(42).uniform(-1.0, 1.0))


def test_greedy_candidate_sets() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera")
    assert len(GreedyOneStep(env).candidates) == 16  # 8 turns x 2 lengths
    assert len(GreedyOneStep(env, n_turns=16, lengths=1).candidates) == 16
    discrete = gym.make("BearingSLAMDiscrete-v1", scenario="khepera")
    # The table's 8 turns x its 2 longest lengths; lengths=3 is the whole table.
    assert len(GreedyOneStep(discrete).candidates) == 16
    every = GreedyOneStep(discrete, lengths=3).candidates
    assert sorted(c.action for c in every) == list(range(discrete.action_space.n))
    fixed = gym.make("BearingSLAM-v1", scenario="khepera", move_length=0.25)
    assert len(GreedyOneStep(fixed).candidates) == 8  # equal lengths are one candidate


# --------------------------------------------------------------------------------------
# The robot policies never read ground truth
# --------------------------------------------------------------------------------------


class GroundTruthRead(AssertionError):
    pass


class PoisonedWorld:
    """Stands in for the env's world during act(): any attribute access is a failure."""

    def __getattr__(self, name: str) -> Any:
        raise GroundTruthRead(f"the policy read world.{name}")


class PoisonedInfo(dict):
    """An info dict whose every read is a failure (info holds ground truth), but for the
    robot's own map (``info["robot_map"]``), which it holds when built from a real info."""

    def __init__(self, info: dict[str, Any] | None = None) -> None:
        super().__init__()
        self._robot_map = None if info is None else info["robot_map"]

    def _fail(self, *args: Any, **kwargs: Any) -> Any:
        raise GroundTruthRead("the policy read info beyond the robot's map")

    def __getitem__(self, key: str) -> Any:
        if key == "robot_map" and self._robot_map is not None:
            return self._robot_map
        raise GroundTruthRead(f"the policy read info[{key!r}]")

    def __contains__(self, key: object) -> bool:
        if key == "robot_map" and self._robot_map is not None:
            return True
        raise GroundTruthRead(f"the policy asked for info[{key!r}]")

    get = keys = items = values = __iter__ = _fail  # type: ignore[assignment]


def _corrupted_world(world: Any, rng: np.random.Generator) -> Any:
    """A copy of the world with every true quantity replaced by garbage."""
    fake = copy.deepcopy(world)
    fake.landmarks = rng.uniform(0.0, 1.0, size=world.landmarks.shape)
    fake.position = rng.uniform(0.1, 0.5, size=2)
    fake.heading = float(rng.uniform(-np.pi, np.pi))
    return fake


def play_with_truth_swapped(
    env: gym.Env, policy: Any, seed: int, replacement: Any, poison_info: bool
) -> list[Any]:
    """An episode where, only while the policy decides, the env's world is ``replacement(
    true_world)`` (and info is poisoned); the truth is restored before every step."""
    base = env.unwrapped
    observation, info = env.reset(seed=seed)
    policy.reset(seed=seed)
    actions = []
    terminated = truncated = False
    while not (terminated or truncated):
        true_world = base._world
        base._world = replacement(true_world)
        try:
            action = policy.act(observation, PoisonedInfo(info) if poison_info else info)
        finally:
            base._world = true_world
        actions.append(copy.deepcopy(action))
        observation, _, terminated, truncated, info = env.step(action)
    return actions


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("policy_class", ROBOT_POLICIES, ids=lambda c: c.__name__)
def test_robot_policies_never_touch_the_world_or_info(env_id: str, policy_class: type) -> None:
    env = gym.make(env_id, scenario="khepera", max_moves=10, max_episode_steps=10)
    reference, _, _ = play(env, policy_class(env), seed=7)
    poisoned = play_with_truth_swapped(
        env, policy_class(env), 7, lambda _: PoisonedWorld(), poison_info=True
    )
    assert same_actions(reference, poisoned)


@pytest.mark.parametrize("policy_class", ROBOT_POLICIES, ids=lambda c: c.__name__)
def test_corrupting_the_truth_does_not_change_robot_policies(policy_class: type) -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=10, max_episode_steps=10)
    rng = np.random.default_rng(0)
    for seed in (1, 2):
        reference, _, _ = play(env, policy_class(env), seed)
        corrupted = play_with_truth_swapped(
            env, policy_class(env), seed, lambda w: _corrupted_world(w, rng), poison_info=False
        )
        assert same_actions(reference, corrupted)


@pytest.mark.parametrize("oracle_class", ORACLES, ids=lambda c: c.__name__)
def test_the_oracle_does_read_the_truth(oracle_class: type) -> None:
    # The swap above is a real test: the privileged oracles' choices do change with it.
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=6, max_episode_steps=6)
    assert oracle_class.privileged and not GreedyOneStep.privileged and not Lookahead.privileged
    reference, _, _ = play(env, oracle_class(env), seed=1)
    rng = np.random.default_rng(0)
    corrupted = play_with_truth_swapped(
        env, oracle_class(env), 1, lambda w: _corrupted_world(w, rng), poison_info=False
    )
    assert not same_actions(reference, corrupted)
    with pytest.raises(GroundTruthRead):
        play_with_truth_swapped(env, oracle_class(env), 1, lambda _: PoisonedWorld(), False)


def test_a_poisoned_info_does_fail_on_ground_truth() -> None:
    # The whitelist above is a real test: reading any other key of it fails.
    env = gym.make("BearingSLAM-v1", scenario="khepera")
    _, info = env.reset(seed=0)
    poisoned = PoisonedInfo(info)
    assert poisoned["robot_map"] is info["robot_map"]
    for key in ("total_area", "landmark_error", "robot_error"):
        with pytest.raises(GroundTruthRead):
            poisoned[key]


@pytest.mark.parametrize(
    "map_kwargs",
    [{}, {"fusion": "relaxed", "noise": {"kind": "uniform", "outlier_rate": 0.1}}],
    ids=["intersect", "relaxed"],
)
@pytest.mark.parametrize("env_id", ENV_IDS)
def test_the_robot_map_in_info_is_the_robots_map_and_holds_no_truth(
    env_id: str, map_kwargs: dict[str, Any]
) -> None:
    env = gym.make(env_id, scenario="khepera", max_moves=10, max_episode_steps=10, **map_kwargs)
    base = env.unwrapped
    policy = GreedyOneStep(env)
    reader = MapReader(env)
    observation, info = env.reset(seed=3)
    policy.reset(seed=3)
    terminated = truncated = False
    while not (terminated or truncated):
        live = base.slam
        rebuilt = reader.read(info, base.n_landmarks)
        # The same map, bit for bit, as the robot's own...
        for name in ("areas", "estimates", "robot_estimate", "robot_area", "robot_heading"):
            assert np.array_equal(getattr(rebuilt, name), getattr(live, name), equal_nan=True)
        for mine, theirs in zip(rebuilt.polygons, live.polygons, strict=True):
            assert (mine is None and theirs is None) or np.array_equal(mine, theirs)
        assert np.array_equal(rebuilt.robot_polygon, live.robot_polygon)  # type: ignore[arg-type]
        assert (rebuilt.n_updates, rebuilt.n_frame_changes) == (
            live.n_updates,
            live.n_frame_changes,
        )
        assert np.array_equal(rebuilt.outliers, live.outliers)
        # ...and no array of it holds a true position (FL landmarks or robot).
        world = base.world
        l1, l2 = world.landmarks[0], world.landmarks[1]
        truths = world_to_fl(np.vstack([world.landmarks[2:], world.position[None]]), l1, l2)
        for name, values in info["robot_map"].items():
            points = np.asarray(values)
            if points.shape[-1:] == (2,):  # FL points as (x, y)
                for truth in truths:
                    hits = np.all(np.abs(points.reshape(-1, 2) - truth) < 1e-9, axis=1)
                    assert not np.any(hits), name
        action = policy.act(observation, info)
        observation, _, terminated, truncated, info = env.step(action)
    # A copy of the env (pickled, as a remote worker would get it) gives the same map data.
    clone = pickle.loads(pickle.dumps(env))
    assert np.array_equal(
        clone.unwrapped.slam.batch.vertices[0], base.slam.batch.vertices[0], equal_nan=True
    )


@pytest.mark.parametrize("seed", [1, 3, 4])
def test_no_phantom_landmarks_when_the_count_varies(seed: int) -> None:
    # One reader, built once, for episodes of 3 to 8 landmarks: the count is read from
    # each observation's present flags (it used to be fixed at build time, which gave
    # phantom landmarks at bearing 0 in the empty slots).
    env = gym.make("BearingSLAM-v1", n_landmarks=(3, 8))
    reader = ObservationReader(env)
    counts = set()
    for episode in range(6):
        observation, _ = env.reset(seed=seed + 7 * episode)
        view = reader.read(observation)
        n = env.unwrapped.n_landmarks
        counts.add(n)
        assert view.n_landmarks == n
        truth = env.unwrapped.world.true_bearings()
        gap = np.abs(np.angle(np.exp(1j * (view.bearings - truth))))
        assert np.all(gap <= env.unwrapped.epsilon + 1e-6)
    assert len(counts) > 1  # the count did vary
    # The policies built once run on every count (their map is sized by the observation).
    for policy_class in HEURISTICS:
        policy = policy_class(env)
        for episode in range(3):
            play(env, policy, seed + 7 * episode)


# --------------------------------------------------------------------------------------
# The robot's belief about itself
# --------------------------------------------------------------------------------------


def test_triangulation_in_the_robot_frame() -> None:
    point = complex(0.3, 0.8)  # R1 = 0, R2 = 1
    bearing_start = math.atan2(point.imag, point.real)
    bearing_end = math.atan2(point.imag, point.real - 1.0)
    assert triangulate_fr(bearing_start, bearing_end) == pytest.approx(point)
    assert triangulate_fr(0.5, 0.5) is None  # parallel rays
    # L1 and L2 two metres apart, the move 0.5 m: 4 FR units apart -> 0.5 m per FR unit.
    l1, l2 = complex(-1.0, 2.0), complex(3.0, 2.0)
    start = np.array([np.angle(l1), np.angle(l2)])
    end = np.array([np.angle(l1 - 1.0), np.angle(l2 - 1.0)])
    assert scale_sample(start, end, 0.5, math.radians(2.0)) == pytest.approx(0.5 * 4.0)


def test_greedy_belief_tracks_the_true_pose_and_scale() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=10, max_episode_steps=10)
    policy = GreedyOneStep(env)
    base = env.unwrapped
    position_errors, heading_errors = [], []
    for seed in range(4):
        observation, info = env.reset(seed=seed)
        policy.reset(seed=seed)
        terminated = truncated = False
        while not (terminated or truncated):
            action = policy.act(observation, info)
            # The pose the decision was based on (act() has just accounted for the last
            # move), against the truth at the same instant.
            pose = policy.belief.pose(base.slam)
            world = base._world
            if pose is not None:
                l1, l2 = world.landmarks[:2]
                truth = world_to_fl(world.position, l1, l2)
                true_heading = world.heading - math.atan2(l2[1] - l1[1], l2[0] - l1[0])
                position_errors.append(abs(pose.position - complex(*truth)))
                heading_errors.append(abs(math.remainder(pose.heading - true_heading, math.tau)))
            observation, _, terminated, truncated, info = env.step(action)
        scale = policy.belief.metres_per_unit()
        assert scale is not None and scale == pytest.approx(0.20, rel=0.2)  # |L1 L2| = 20 cm
    # In FL units (1 = 20 cm) and radians: typically a few cm and a few degrees.
    assert np.median(position_errors) < 0.3
    assert np.median(heading_errors) < math.radians(6.0)


# --------------------------------------------------------------------------------------
# Action codec and registry
# --------------------------------------------------------------------------------------


def test_codec_round_trips_continuous_actions() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", move_length=(0.1, 0.3))
    codec = ActionCodec(env)
    for turn, length in ((0.0, 0.1), (1.0, 0.2), (-2.5, 0.3), (math.pi - 1e-3, 0.25)):
        action = codec.encode(turn, length)
        assert env.action_space.contains(action)
        decoded_turn, decoded_length = codec.decode(action)
        assert decoded_turn == pytest.approx(turn, abs=1e-6)
        assert decoded_length == pytest.approx(length, abs=1e-6)
        # The env reads the action exactly as the codec does.
        assert base_decode(env, action) == pytest.approx((decoded_turn, decoded_length))


def base_decode(env: gym.Env, action: Any) -> tuple[float, float]:
    return env.unwrapped._decode_action(action)


def test_codec_maps_to_the_nearest_discrete_action() -> None:
    env = gym.make("BearingSLAMDiscrete-v1", scenario="khepera")
    codec = ActionCodec(env)
    table_turns = env.unwrapped.turn_angles
    table_lengths = env.unwrapped.move_lengths
    for action in range(env.action_space.n):
        turn, length = codec.decode(action)
        assert codec.encode(turn + 0.1, length + 0.01) == action
        assert base_decode(env, action) == pytest.approx((turn, length))
    # 170 degrees is nearest to the table's -180.
    turn, _ = codec.decode(codec.encode(math.radians(170.0), table_lengths[-1]))
    assert turn == pytest.approx(-math.pi)
    assert set(np.round(table_turns, 6)) == {round(float(t), 6) for t in table_turns}


def test_policy_specs_parse_and_build() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera")
    spec = parse_policy_spec("greedy:n_turns=12,lengths=(0.2, 0.3),label=g12")
    assert spec.kind == "greedy" and spec.options == {"n_turns": 12, "lengths": (0.2, 0.3)}
    assert spec.label == "g12"
    assert parse_policy_spec(spec.to_string()) == spec
    policy = make_policy(spec, env)
    assert isinstance(policy, GreedyOneStep) and policy.name == "g12"
    assert len(policy.candidates) == 24
    assert parse_policy_spec("greedy_one_step").kind == "greedy"
    assert make_policy("random:length=0.25", env).name == "random_polygonal[length=0.25]"
    assert parse_policy_spec("sb3:runs/x/model.zip").options == {"path": "runs/x/model.zip"}
    with pytest.raises(ValueError, match="unknown policy"):
        parse_policy_spec("teleport")
    with pytest.raises(ValueError, match="bad options"):
        make_policy("parallax:speed=3", env)
    with pytest.raises(ValueError, match="needs a model path"):
        parse_policy_spec("sb3")


def test_policies_reject_envs_they_cannot_drive() -> None:
    with pytest.raises(TypeError, match="BearingSLAM"):
        GreedyOneStep(gym.make("CartPole-v1"))


# --------------------------------------------------------------------------------------
# SB3Policy
# --------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def tiny_ppo(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A PPO model trained for a few hundred steps, saved with VecNormalize statistics."""
    from stable_baselines3 import PPO
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import VecNormalize

    folder = tmp_path_factory.mktemp("ppo")
    venv = VecNormalize(
        make_vec_env(
            "BearingSLAM-v1", n_envs=1, seed=0, env_kwargs={"scenario": "khepera", "max_moves": 5}
        ),
        norm_reward=False,
    )
    model = PPO(
        "MlpPolicy",
        venv,
        n_steps=64,
        batch_size=32,
        n_epochs=1,
        seed=0,
        device="cpu",
        policy_kwargs={"net_arch": [16]},
    )
    model.learn(192)
    model.save(folder / "model.zip")
    venv.save(folder / "vecnormalize.pkl")
    return folder / "model.zip"


@pytest.fixture(scope="module")
def tiny_dqn(tmp_path_factory: pytest.TempPathFactory) -> Path:
    from stable_baselines3 import DQN

    folder = tmp_path_factory.mktemp("dqn")
    env = gym.make("BearingSLAMDiscrete-v1", scenario="khepera", max_moves=5, max_episode_steps=5)
    model = DQN(
        "MlpPolicy",
        env,
        learning_starts=20,
        train_freq=4,
        seed=0,
        device="cpu",
        policy_kwargs={"net_arch": [16]},
    )
    model.learn(100)
    model.save(folder / "dqn_model")
    return folder / "dqn_model.zip"


@needs("train")
def test_sb3_policy_runs_episodes_with_its_vecnormalize(tiny_ppo: Path) -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=6, max_episode_steps=6)
    policy = SB3Policy(env, tiny_ppo)
    assert policy.algo == "PPO"
    assert policy.vecnormalize_path == tiny_ppo.parent / "vecnormalize.pkl"
    assert policy.name == "sb3_ppo_model"
    first, _, moves = play(env, policy, seed=1)
    assert moves == 6
    second, _, _ = play(env, SB3Policy(env, tiny_ppo.parent), seed=1)  # a directory works
    assert same_actions(first, second)
    # The observation really goes through the saved statistics.
    observation, _ = env.reset(seed=2)
    expected = policy.model.predict(
        policy.obs_normalizer.normalize_obs(observation), deterministic=True
    )[0]
    np.testing.assert_allclose(policy.act(observation, {}), expected)
    raw = SB3Policy(env, tiny_ppo, vecnormalize=None)
    assert raw.obs_normalizer is None
    assert isinstance(make_policy(f"sb3:path={tiny_ppo}", env), SB3Policy)


@needs("train")
def test_sb3_policy_runs_a_dqn_on_the_discrete_id(tiny_dqn: Path) -> None:
    env = gym.make("BearingSLAMDiscrete-v1", scenario="khepera", max_moves=5, max_episode_steps=5)
    policy = SB3Policy(env, tiny_dqn.with_suffix(""))  # SB3-style path without .zip
    assert policy.algo == "DQN" and policy.obs_normalizer is None
    actions, _, moves = play(env, policy, seed=0)
    assert moves == 5 and all(isinstance(a, int) for a in actions)


@needs("train")
@pytest.mark.parametrize("env_id", ["BearingSLAM-v1", "BearingSLAMDiscrete-v1"])
def test_the_greedy_path_acts_as_sb3_predict(env_id: str, tmp_path: Path) -> None:
    # SB3Policy's greedy actor-critic path runs SB3's own operations without predict's
    # machinery: the same action on every observation, inside the space and far outside.
    import torch
    from stable_baselines3 import PPO

    env = gym.make(env_id, scenario="khepera", max_moves=5, max_episode_steps=5)
    model = PPO("MlpPolicy", env, seed=3, device="cpu", policy_kwargs={"net_arch": [16]})
    with torch.no_grad():  # outputs well outside [-1, 1], so that predict's clip matters
        model.policy.action_net.weight.mul_(50.0)
    model.save(tmp_path / "model.zip")
    policy = SB3Policy(env, tmp_path / "model.zip")
    assert policy._greedy is not None
    rng = np.random.default_rng(0)
    shape = env.observation_space.shape
    for scale in (0.1, 1.0, 100.0):
        for _ in range(50):
            observation = rng.normal(0.0, scale, shape).astype(np.float32)
            expected, _ = model.predict(observation, deterministic=True)
            action = policy.act(observation, {})
            assert np.array_equal(np.asarray(action).reshape(-1), np.asarray(expected).reshape(-1))
            assert env.action_space.contains(action)
    assert SB3Policy(env, tmp_path / "model.zip", deterministic=False)._greedy is None


@needs("train")
def test_sb3_policy_load_errors(tiny_ppo: Path, tmp_path: Path) -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera")
    with pytest.raises(FileNotFoundError, match="not found"):
        SB3Policy(env, tmp_path / "missing.zip")
    with pytest.raises(FileNotFoundError, match="no SB3 model in directory"):
        SB3Policy(env, tmp_path)
    garbage = tmp_path / "garbage.zip"
    garbage.write_bytes(b"this is not a zip archive")
    with pytest.raises(ModelLoadError, match="not a stable-baselines3 model"):
        SB3Policy(env, garbage)
    # A valid archive whose parameters are damaged.
    damaged = tmp_path / "damaged.zip"
    with zipfile.ZipFile(tiny_ppo) as source, zipfile.ZipFile(damaged, "w") as target:
        for item in source.infolist():
            data = source.read(item.filename)
            if item.filename.endswith(".pth"):
                data = data[: len(data) // 3]
            target.writestr(item, data)
    with pytest.raises(ModelLoadError, match="could not load PPO model"):
        SB3Policy(env, damaged)
    with pytest.raises(FileNotFoundError, match="VecNormalize statistics not found"):
        SB3Policy(env, tiny_ppo, vecnormalize=tmp_path / "nope.pkl")
    bad_stats = tmp_path / "bad_stats.pkl"
    bad_stats.write_bytes(b"\x80\x04not a pickle")
    with pytest.raises(ModelLoadError, match="could not load VecNormalize"):
        SB3Policy(env, tiny_ppo, vecnormalize=bad_stats)
    wrong_stats = tmp_path / "wrong_stats.pkl"
    wrong_stats.write_bytes(pickle.dumps({"not": "vecnormalize"}))
    with pytest.raises(ModelLoadError, match="not VecNormalize"):
        SB3Policy(env, tiny_ppo, vecnormalize=wrong_stats)
    discrete = gym.make("BearingSLAMDiscrete-v1", scenario="khepera")
    with pytest.raises(ModelLoadError, match="outputs actions"):
        SB3Policy(discrete, tiny_ppo)
    wide = gym.make("BearingSLAM-v1", scenario="khepera", max_landmarks=10)
    with pytest.raises(ModelLoadError, match="expects observations"):
        SB3Policy(wide, tiny_ppo)
    assert issubclass(ModelLoadError, ValueError)


# --------------------------------------------------------------------------------------
# Vector envs: a batched act
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("policy_class", HEURISTICS, ids=lambda c: c.__name__)
def test_vector_policy_acts_like_one_policy_per_sub_env(env_id: str, policy_class: type) -> None:
    # Sub-env i of the vector env, seeded seed + i, with its own policy, takes the actions
    # the same policy takes on the single env seeded seed + i.
    kwargs = {"scenario": "khepera", "max_moves": 5}
    vector_env = gym.make_vec(env_id, num_envs=3, **kwargs)
    policy = VectorPolicy(vector_env, policy_class)
    observations, infos = vector_env.reset(seed=20)
    policy.reset(seed=20)
    actions: list[list[Any]] = [[], [], []]
    for _ in range(5):
        batch = policy.act(observations, infos)
        assert vector_env.action_space.contains(batch)
        for row in range(3):
            actions[row].append(batch[row])
        observations, _, _, _, infos = vector_env.step(batch)
    single = gym.make(env_id, max_episode_steps=5, **kwargs)
    for row in range(3):
        expected, _, _ = play(single, policy_class(single), seed=20 + row)
        assert same_actions(actions[row][: len(expected)], expected)


def test_vector_policy_runs_on_varying_counts_and_sync_vector_envs() -> None:
    for vector_env in (
        gym.make_vec("BearingSLAM-v1", num_envs=2, n_landmarks=(3, 8), max_moves=4),
        gym.make_vec("BearingSLAM-v1", num_envs=2, vectorization_mode="sync", scenario="khepera"),
    ):
        policy = VectorPolicy(vector_env, GreedyOneStep)
        observations, infos = vector_env.reset(seed=1)
        policy.reset(seed=1)
        for _ in range(9):  # through an autoreset
            observations, _, _, _, infos = vector_env.step(policy.act(observations, infos))
    with pytest.raises(TypeError, match="VectorEnv"):
        VectorPolicy(gym.make("BearingSLAM-v1"), GreedyOneStep)  # type: ignore[arg-type]


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("policy_class", HEURISTICS, ids=lambda c: c.__name__)
def test_policies_act_alike_on_the_entity_observation(env_id: str, policy_class: type) -> None:
    kwargs = {"scenario": "khepera", "max_moves": 6, "max_episode_steps": 6}
    flat = gym.make(env_id, **kwargs)
    entities = gym.make(env_id, observation="entities", **kwargs)
    reference, _, _ = play(flat, policy_class(flat), seed=9)
    actions, _, _ = play(entities, policy_class(entities), seed=9)
    assert same_actions(reference, actions)
    vector_env = gym.make_vec(env_id, num_envs=2, observation="entities", scenario="khepera")
    policy = VectorPolicy(vector_env, policy_class)
    observations, infos = vector_env.reset(seed=9)
    policy.reset(seed=9)
    batch = policy.act(observations, infos)
    assert vector_env.action_space.contains(batch)
    assert np.array_equal(np.asarray(batch[0]), np.asarray(reference[0]))


# --------------------------------------------------------------------------------------
# Lookahead
# --------------------------------------------------------------------------------------


def test_lookahead_of_depth_one_in_one_world_is_the_greedy_planner() -> None:
    # One move ahead, scored at the estimates only, over GreedyOneStep's candidates: the
    # same decisions (the search is a generalisation, not a different rule).
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=10, max_episode_steps=10)
    for seed in (2, 5):
        greedy, _, _ = play(env, GreedyOneStep(env), seed)
        one_step, _, _ = play(env, Lookahead(env, depth=1, hypotheses=1, n_turns=8), seed)
        assert same_actions(greedy, one_step)


def test_lookahead_options_and_planning_times() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=5, max_episode_steps=5)
    policy = Lookahead(env, depth=3, width=4, n_turns=12, lengths=2, hypotheses=3)
    assert len(policy.candidates) == 24
    _, _, moves = play(env, policy, seed=4)
    # Every move after the bootstrap is planned, and timed.
    assert 1 <= len(policy.planning_times) <= moves
    assert all(t > 0.0 for t in policy.planning_times)
    for bad, error in (
        ({"depth": 0}, ValueError),
        ({"width": -1}, ValueError),
        ({"hypotheses": 1.5}, TypeError),  # the project's rule: the wrong kind of value
        ({"depth": True}, TypeError),
    ):
        with pytest.raises(error, match=next(iter(bad))):
            Lookahead(env, **bad)
    spec = make_policy("lookahead:depth=3,hypotheses=2", env)
    assert isinstance(spec, Lookahead) and (spec.depth, spec.hypotheses) == (3, 2)
    assert isinstance(make_policy("lookahead_oracle", env), LookaheadOracle)


def test_hypotheses_change_the_plans_and_follow_the_seed() -> None:
    env = gym.make("BearingSLAM-v1", scenario="khepera", max_moves=8, max_episode_steps=8)
    single, _, _ = play(env, Lookahead(env, hypotheses=1), seed=6)
    first, _, _ = play(env, Lookahead(env, hypotheses=4), seed=6)
    again, _, _ = play(env, Lookahead(env, hypotheses=4), seed=6)
    assert same_actions(first, again)
    assert not same_actions(first, single)


def test_samples_fall_inside_the_polygon_uniformly() -> None:
    square = np.array([0, 2, 2 + 1j, 1j], dtype=np.complex128)  # 2 x 1, CCW
    points = sample_in_polygon(square, 4000, np.random.default_rng(0))
    assert np.all((points.real >= 0) & (points.real <= 2) & (points.imag >= 0) & (points.imag <= 1))
    assert abs(points.mean() - (1 + 0.5j)) < 0.03
    assert abs(np.mean(points.real < 1.0) - 0.5) < 0.03  # uniform, not per-triangle
    assert sample_in_polygon(square[:1], 3, np.random.default_rng(0)).tolist() == [0j] * 3


@pytest.mark.parametrize("reward", ["log_area", "area"])
def test_the_planner_scores_moves_with_the_potential_the_env_rewards(reward: str) -> None:
    """The reward is the decrease of the env's potential; the planner's potential is the
    same function, for either reward (the old copy always took log areas)."""
    from bearing_env.agents.heuristics import GreedyOneStep
    from bearing_env.agents.planning import uncertainty_potential

    env = gym.make("BearingSLAM-v1", scenario="khepera", reward=reward)
    env.reset(seed=5)
    env.action_space.seed(5)
    planner = GreedyOneStep(env)
    assert planner.log_area is (reward == "log_area")
    cap = env.unwrapped.area_cap
    before = uncertainty_potential(env.unwrapped.slam.areas, cap, planner.log_area)
    rewards = []
    for _ in range(10):
        _, step_reward, terminated, truncated, _ = env.step(env.action_space.sample())
        after = uncertainty_potential(env.unwrapped.slam.areas, cap, planner.log_area)
        assert float(before - after) == pytest.approx(float(step_reward), rel=1e-12, abs=1e-12)
        rewards.append(step_reward)
        before = after
        if terminated or truncated:
            break
    assert any(r != 0.0 for r in rewards)
    env.close()
