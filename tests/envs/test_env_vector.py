"""The batched vector env: registered, exact against the single env, and well behaved."""

from __future__ import annotations

import multiprocessing as mp
import pickle
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode
from hypothesis import given, settings
from hypothesis import strategies as st

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.envs import BearingSLAMDiscreteVectorEnv, BearingSLAMVectorEnv
from bearing_env.slam import PolygonSLAM
from bearing_env.slam.batch import BatchedPolygonSLAM
from bearing_env.tasks import BASE_IDS
from tests.extras import needs

VECTOR_CLASSES = {
    "BearingSLAM-v1": BearingSLAMVectorEnv,
    "BearingSLAMDiscrete-v1": BearingSLAMDiscreteVectorEnv,
}


def assert_same(a: Any, b: Any, path: str = "") -> None:
    """Exact equality of nested step results (arrays bit for bit, dtypes included)."""
    if isinstance(a, tuple):
        assert isinstance(b, tuple) and len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{path}[{i}]")
    elif isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), (path, set(a) ^ set(b))
        for key in a:
            assert_same(a[key], b[key], f"{path}/{key}")
    elif isinstance(a, np.ndarray) and a.dtype == object:
        assert isinstance(b, np.ndarray) and a.shape == b.shape, path
        for x, y in zip(a, b, strict=True):
            assert_same(x, y, path)
    elif isinstance(a, np.ndarray):
        assert isinstance(b, np.ndarray), path
        assert a.dtype == b.dtype and a.shape == b.shape, (path, a.dtype, b.dtype)
        assert np.array_equal(a, b, equal_nan=True), (path, a, b)
    elif a is None:
        assert b is None, path
    else:
        assert a == b, (path, a, b)


def make_pair(
    env_id: str, n: int, mode: AutoresetMode, **kwargs: Any
) -> tuple[gym.vector.VectorEnv, gym.vector.VectorEnv]:
    batched = gym.make_vec(
        env_id, num_envs=n, vectorization_mode="vector_entry_point", autoreset_mode=mode, **kwargs
    )
    reference = gym.make_vec(
        env_id,
        num_envs=n,
        vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": mode},
        **kwargs,
    )
    return batched, reference


def assert_pair_agrees(
    batched: gym.vector.VectorEnv,
    reference: gym.vector.VectorEnv,
    seed: int,
    steps: int,
    action_seed: int | None = None,
) -> None:
    """``batched`` and ``reference`` give the same results, bit for bit, from a reset with
    ``seed`` over ``steps`` steps of the same sampled actions; both are closed after."""
    assert_same(batched.reset(seed=seed), reference.reset(seed=seed))
    batched.action_space.seed(seed if action_seed is None else action_seed)
    for _ in range(steps):
        actions = batched.action_space.sample()
        assert_same(batched.step(actions), reference.step(actions))
    batched.close()
    reference.close()


@pytest.mark.parametrize("env_id", sorted(BASE_IDS.values()))
def test_make_vec_returns_the_batched_env_with_the_spec_time_limit(env_id: str) -> None:
    env = gym.make_vec(env_id, num_envs=3, scenario="khepera")
    assert isinstance(env, VECTOR_CLASSES[env_id])
    assert env.max_episode_steps == gym.spec(env_id).max_episode_steps
    assert env.single_observation_space == gym.make(env_id, scenario="khepera").observation_space
    assert env.observation_space.shape == (3, *env.single_observation_space.shape)
    assert env.observation_space.dtype == np.float32
    env.close()


@pytest.mark.parametrize("env_id", sorted(BASE_IDS.values()))
@pytest.mark.parametrize("mode", [AutoresetMode.NEXT_STEP, AutoresetMode.SAME_STEP])
@pytest.mark.parametrize(
    "kwargs",
    [
        {"scenario": "khepera"},
        {"n_landmarks": 6, "transfer": "paper"},
        {"n_landmarks": 5, "noise": {"kind": "uniform", "bound_deg": 4.0}, "max_moves": 7},
        {"scenario": "khepera", "noise": {"kind": "gaussian", "outlier_rate": 0.2}},
        {
            "n_landmarks": 6,
            "noise": {"kind": "uniform", "outlier_rate": 0.1, "detection_rate": 0.9},
            "fusion": "relaxed",
            "max_outliers": 3,
        },
    ],
    ids=[
        "khepera",
        "random-paper",
        "random-outside-epsilon",
        "gaussian-outliers",
        "relaxed-outliers",
    ],
)
def test_reproduces_sync_vector_env_exactly(
    env_id: str, mode: AutoresetMode, kwargs: dict[str, Any]
) -> None:
    batched, reference = make_pair(env_id, 4, mode, **kwargs)
    assert_same(batched.reset(seed=11), reference.reset(seed=11))
    batched.action_space.seed(5)
    episode_ends = 0
    for _ in range(60):
        actions = batched.action_space.sample()
        result, expected = batched.step(actions), reference.step(actions)
        assert_same(result, expected)
        episode_ends += int(np.sum(result[2] | result[3]))
    assert episode_ends >= 4  # the comparison covered autoresets
    batched.close()
    reference.close()


def test_many_landmarks_reproduce_the_single_env_exactly() -> None:
    batched, reference = make_pair("BearingSLAM-v1", 3, AutoresetMode.NEXT_STEP, n_landmarks=24)
    assert_same(batched.reset(seed=2), reference.reset(seed=2))
    batched.action_space.seed(1)
    for _ in range(12):
        actions = batched.action_space.sample()
        assert_same(batched.step(actions), reference.step(actions))


def test_a_batch_large_enough_for_the_threads_matches_single_envs() -> None:
    from bearing_env.slam.batch import PARALLEL_MIN_MAPS

    # The map update is split over threads from this size (when there are two).
    batched, reference = make_pair(
        "BearingSLAM-v1", PARALLEL_MIN_MAPS, AutoresetMode.NEXT_STEP, scenario="khepera"
    )
    assert_same(batched.reset(seed=11), reference.reset(seed=11))
    batched.action_space.seed(11)
    for _ in range(4):
        actions = batched.action_space.sample()
        assert_same(batched.step(actions), reference.step(actions))


def test_landmark_count_ranges_match_single_envs_with_padded_infos() -> None:
    n, slots = 4, 8
    batched = gym.make_vec(
        "BearingSLAM-v1", num_envs=n, vectorization_mode="vector_entry_point", n_landmarks=(3, 6)
    )
    singles = [gym.make("BearingSLAM-v1", n_landmarks=(3, 6)) for _ in range(n)]
    observations, infos = batched.reset(seed=40)
    for i, env in enumerate(singles):
        observation, info = env.reset(seed=40 + i)
        assert np.array_equal(observations[i], observation)
        count = info["landmark_area"].shape[0]
        assert np.array_equal(infos["landmark_area"][i, :count], info["landmark_area"])
        assert np.all(np.isinf(infos["landmark_area"][i, count:]))
        assert infos["landmark_area"].shape == (n, slots - 2)
    counts = {env.unwrapped.n_landmarks for env in singles}
    batched.action_space.seed(3)
    done = np.zeros(n, dtype=bool)
    for _ in range(45):
        actions = batched.action_space.sample()
        observations, rewards, terminated, truncated, infos = batched.step(actions)
        for i, env in enumerate(singles):
            if done[i]:
                observation, info = env.reset()
                reward = 0.0
            else:
                observation, reward, term, trunc, info = env.step(actions[i])
                assert (term, trunc) == (terminated[i], truncated[i])
            assert np.array_equal(observations[i], observation)
            assert rewards[i] == reward
            count = info["landmark_error"].shape[0]
            assert np.array_equal(infos["landmark_error"][i, :count], info["landmark_error"])
            counts.add(env.unwrapped.n_landmarks)
        done = terminated | truncated
    assert len(counts) >= 2  # the episodes really had different landmark counts


def test_time_limit_truncates_like_gym_make() -> None:
    env = gym.make_vec(
        "BearingSLAM-v1", num_envs=2, vectorization_mode="vector_entry_point", max_episode_steps=3
    )
    env.reset(seed=0)
    actions = np.zeros((2, 2), dtype=np.float32)
    for _ in range(2):
        _, _, _, truncated, _ = env.step(actions)
        assert not truncated.any()
    _, _, terminated, truncated, _ = env.step(actions)
    assert np.all(truncated | terminated)
    observations, rewards, terminated, truncated, _ = env.step(actions)  # autoreset
    assert np.all(rewards == 0.0) and not (terminated | truncated).any()
    assert np.all(observations[:, 6] == 0.0)  # progress restarts


def test_same_step_autoreset_reports_final_observation_and_info() -> None:
    env = BearingSLAMVectorEnv(2, autoreset_mode="same_step", max_moves=2, scenario="khepera")
    env.reset(seed=0)
    actions = np.zeros((2, 2), dtype=np.float32)
    env.step(actions)
    observations, _, terminated, truncated, infos = env.step(actions)
    assert np.all(terminated | truncated)
    assert infos["_final_obs"].all() and infos["final_obs"][0].shape == observations[0].shape
    assert np.all(infos["final_obs"][0][6] == 1.0)  # the last observation: progress 1
    assert np.all(observations[:, 6] == 0.0)  # the returned one: already reset
    assert set(infos["final_info"]) >= {"landmark_area", "total_area", "rewards"}


def test_invalid_arguments_raise_clear_errors() -> None:
    with pytest.raises(ValueError, match="num_envs"):
        BearingSLAMVectorEnv(0)
    with pytest.raises(TypeError, match="num_envs"):
        BearingSLAMVectorEnv(2.5)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="autoreset_mode"):
        BearingSLAMVectorEnv(2, autoreset_mode="sometimes")
    with pytest.raises(ValueError, match="max_episode_steps"):
        BearingSLAMVectorEnv(2, max_episode_steps=0)
    with pytest.raises(ValueError, match="render_mode"):
        BearingSLAMVectorEnv(2, render_mode="human")
    with pytest.raises(ValueError, match="epsilon_deg"):
        BearingSLAMVectorEnv(2, epsilon_deg=-1.0)
    with pytest.raises(TypeError, match="unexpected keyword"):
        BearingSLAMVectorEnv(2, epsilon_degrees=2.0)
    env = BearingSLAMVectorEnv(2)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(np.zeros((2, 2), dtype=np.float32))
    env.reset(seed=0)
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros((3, 2), dtype=np.float32))
    with pytest.raises(ValueError, match="outside"):
        env.step(np.full((2, 2), 3.0, dtype=np.float32))
    with pytest.raises(ValueError, match="seeds"):
        env.reset(seed=[1, 2, 3])


def test_discrete_actions_must_be_integers_in_range() -> None:
    env = BearingSLAMDiscreteVectorEnv(2, scenario="khepera")
    env.reset(seed=0)
    n_actions = env.single_action_space.n
    with pytest.raises(ValueError, match="outside the action space"):
        env.step(np.array([0, n_actions]))
    with pytest.raises(ValueError, match="integers"):
        env.step(np.array([0.0, 1.5]))
    env.step(np.array([0.0, 3.0]))  # integral floats are fine, as in the single env


def test_class_metadata_is_not_mutated() -> None:
    BearingSLAMVectorEnv(2, autoreset_mode="same_step")
    assert BearingSLAMVectorEnv.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP


def test_pickle_round_trip_continues_identically() -> None:
    env = BearingSLAMVectorEnv(3, n_landmarks=5)
    env.reset(seed=9)
    actions = np.random.default_rng(0).uniform(-1, 1, (10, 3, 2)).astype(np.float32)
    for a in actions[:4]:
        env.step(a)
    clone = pickle.loads(pickle.dumps(env))
    for a in actions[4:]:
        assert_same(env.step(a), clone.step(a))
    # The clone's sub-envs still share one map batch of their own.
    clone_maps, maps = clone.get_attr("slam"), env.get_attr("slam")
    assert clone_maps[0].batch is clone_maps[2].batch
    assert clone_maps[0].batch is not maps[0].batch


def _step_in_subprocess(queue: Any) -> None:
    env = gym.make_vec("BearingSLAM-v1", num_envs=2, vectorization_mode="vector_entry_point")
    env.reset(seed=3)
    observations, *_ = env.step(np.zeros((2, 2), dtype=np.float32))
    queue.put(observations)


def test_make_vec_in_a_spawned_process() -> None:
    context = mp.get_context("spawn")
    queue = context.Queue()
    process = context.Process(target=_step_in_subprocess, args=(queue,))
    process.start()
    observations = queue.get(timeout=120)
    process.join(timeout=60)
    assert process.exitcode == 0
    env = gym.make_vec("BearingSLAM-v1", num_envs=2, vectorization_mode="vector_entry_point")
    env.reset(seed=3)
    expected, *_ = env.step(np.zeros((2, 2), dtype=np.float32))
    assert np.array_equal(observations, expected)


@needs("render")
def test_rgb_array_render_gives_one_frame_per_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SDL_VIDEODRIVER", "dummy")
    env = BearingSLAMVectorEnv(2, render_mode="rgb_array", scenario="khepera")
    env.reset(seed=0)
    env.step(np.zeros((2, 2), dtype=np.float32))
    frames = env.render()
    assert frames is not None and len(frames) == 2
    assert frames[0].ndim == 3 and frames[0].shape[2] == 3 and frames[0].std() > 0
    env.close()


def test_attribute_access() -> None:
    env = BearingSLAMVectorEnv(2, scenario="khepera")
    assert env.get_attr("n_landmarks") == (4, 4)
    env.set_attr("path_cost", [0.0, 1.0])
    assert env.get_attr("path_cost") == (0.0, 1.0)
    with pytest.raises(ValueError, match="expected 2 values"):
        env.set_attr("path_cost", [1.0])
    with pytest.raises(AttributeError, match="'nosuch'"):  # not silently kept
        env.set_attr("nosuch", 1)
    with pytest.raises(AttributeError, match="'nosuch'"):
        env.get_attr("nosuch")


def test_sub_envs_with_settings_changed_by_set_attr_step_like_single_envs() -> None:
    costs = [0.0, 2.0, 0.0, 5.0]
    batched = BearingSLAMVectorEnv(4, scenario="khepera")
    batched.set_attr("path_cost", costs)
    singles = [gym.make("BearingSLAM-v1", scenario="khepera", path_cost=c) for c in costs]
    batched.reset(seed=6)
    for i, env in enumerate(singles):
        env.reset(seed=6 + i)
    actions = np.random.default_rng(2).uniform(-1, 1, (5, 4, 2)).astype(np.float32)
    total_cost = np.zeros(4)
    for step_actions in actions:
        _, rewards, _, _, infos = batched.step(step_actions)
        for i, env in enumerate(singles):
            _, reward, _, _, info = env.step(step_actions[i])
            assert rewards[i] == reward
            assert infos["rewards"]["path_cost"][i] == info["rewards"]["path_cost"]
        total_cost += infos["rewards"]["path_cost"]
    # The costs really differ per sub-env (a batch using env 0's setting would give 0).
    assert total_cost[0] == total_cost[2] == 0.0
    assert total_cost[1] < 0.0 and total_cost[3] < 0.0


# ----------------------------------------------------------------------------------------
# reset(options={"reset_mask": ...}) and autoreset_mode="disabled"
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("env_id", "mode", "kwargs"),
    [
        ("BearingSLAM-v1", AutoresetMode.NEXT_STEP, {"scenario": "khepera"}),
        ("BearingSLAM-v1", AutoresetMode.SAME_STEP, {"scenario": "khepera"}),
        ("BearingSLAM-v1", AutoresetMode.DISABLED, {"scenario": "khepera"}),
        ("BearingSLAMDiscrete-v1", AutoresetMode.DISABLED, {"observation": "entities"}),
    ],
    ids=["next-step", "same-step", "disabled", "disabled-discrete-entities"],
)
def test_masked_resets_reproduce_sync_vector_env_exactly(
    env_id: str, mode: AutoresetMode, kwargs: dict[str, Any]
) -> None:
    """Resets of some sub-envs, mid-episode or after their end, seeded by an int, a list
    or not at all, between steps: every result equal to ``SyncVectorEnv``'s, masks included."""
    n = 3
    batched, reference = make_pair(env_id, n, mode, max_moves=4, **kwargs)
    assert_same(batched.reset(seed=3), reference.reset(seed=3))
    batched.action_space.seed(8)
    rng = np.random.default_rng(5)
    seeds: list[Any] = [None, 100, [None, 7, 9]]
    done = np.zeros(n, dtype=bool)
    mid_episode = ended = 0
    for step in range(16):
        mask = rng.random(n) < 0.3
        if mode == AutoresetMode.DISABLED:
            mask |= done  # an ended sub-env must be reset before it steps again
        if mask.any():
            seed = seeds[step % len(seeds)]
            # SyncVectorEnv pops the mask from the dict it is given: one dict each.
            result = batched.reset(seed=seed, options={"reset_mask": mask.copy()})
            assert_same(result, reference.reset(seed=seed, options={"reset_mask": mask.copy()}))
            assert result[1]["_total_area"].tolist() == mask.tolist()
            mid_episode += int(np.sum(mask & ~done))
            ended += int(np.sum(mask & done))
        actions = batched.action_space.sample()
        result = batched.step(actions)
        assert_same(result, reference.step(actions))
        done = result[2] | result[3]
    assert mid_episode >= 3 and ended >= 1  # both kinds of masked reset were compared
    batched.close()
    reference.close()


def test_disabled_mode_refuses_to_step_an_ended_sub_env_until_it_is_reset() -> None:
    batched, reference = make_pair(
        "BearingSLAM-v1", 2, AutoresetMode.DISABLED, scenario="khepera", max_moves=2
    )
    assert batched.metadata["autoreset_mode"] == AutoresetMode.DISABLED
    actions = np.zeros((2, 2), dtype=np.float32)
    for env in (batched, reference):
        env.reset(seed=0)
        env.step(actions)
        _, _, terminated, truncated, _ = env.step(actions)
        assert np.all(terminated | truncated)
    with pytest.raises(AssertionError):  # SyncVectorEnv's refusal
        reference.step(actions)
    with pytest.raises(RuntimeError, match=r"sub-envs \[0, 1\].*reset_mask"):
        batched.step(actions)
    mask = np.array([True, True])
    assert_same(
        batched.reset(options={"reset_mask": mask.copy()}),
        reference.reset(options={"reset_mask": mask.copy()}),
    )
    assert_same(batched.step(actions), reference.step(actions))


@pytest.mark.parametrize(
    ("options", "error", "shown"),
    [
        ({"reset_mask": [True]}, TypeError, "[True]"),
        ({"reset_mask": [True, False, True]}, TypeError, "list"),
        ({"reset_mask": None}, TypeError, "None"),
        ({"reset_mask": np.array([1, 0, 1])}, TypeError, "int64"),
        ({"reset_mask": np.array([True])}, ValueError, "shape (1,)"),
        ({"reset_mask": np.ones((1, 3), dtype=bool)}, ValueError, "shape (1, 3)"),
        ({"reset_mask": np.zeros(3, dtype=bool)}, ValueError, "at least one"),
        ({"reset_masks": np.ones(3, dtype=bool)}, TypeError, "'reset_masks'"),
        ({"seed": 1}, TypeError, "'seed'"),
        (["reset_mask"], TypeError, "['reset_mask']"),
    ],
    ids=[
        "one-entry-list",
        "list",
        "none",
        "int-array",
        "short",
        "2-d",
        "all-false",
        "unknown-key",
        "sub-env-key",
        "not-a-dict",
    ],
)
def test_a_malformed_reset_is_refused_like_sync_vector_env_and_changes_nothing(
    options: Any, error: type[Exception], shown: str
) -> None:
    batched, reference = make_pair("BearingSLAM-v1", 3, AutoresetMode.NEXT_STEP)
    twin = BearingSLAMVectorEnv(3, max_episode_steps=20)
    for env in (batched, reference, twin):
        env.reset(seed=1)
    with pytest.raises(error, match="reset") as raised:
        batched.reset(seed=4, options=options)
    assert shown in str(raised.value)
    with pytest.raises(error):  # SyncVectorEnv (or its sub-envs) refuse it too
        reference.reset(seed=4, options=dict(options) if isinstance(options, dict) else options)
    actions = np.zeros((3, 2), dtype=np.float32)
    assert_same(batched.step(actions), twin.step(actions))  # the refusal changed nothing


def test_the_first_reset_must_reset_every_sub_env() -> None:
    env = BearingSLAMVectorEnv(3)
    with pytest.raises(ValueError, match="first reset"):
        env.reset(seed=0, options={"reset_mask": np.array([True, False, True])})
    observations, infos = env.reset(seed=0, options={"reset_mask": np.ones(3, dtype=bool)})
    assert_same((observations, infos), BearingSLAMVectorEnv(3).reset(seed=0))


# ----------------------------------------------------------------------------------------
# The batched world model underneath
# ----------------------------------------------------------------------------------------


@settings(deadline=None, max_examples=15, derandomize=True)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_maps=st.integers(2, 9),
    n_landmarks=st.integers(3, 7),
    eps_deg=st.floats(0.5, 6.0),
    transfer=st.sampled_from(["conservative", "paper"]),
)
def test_a_maps_update_does_not_depend_on_its_batch(
    seed: int, n_maps: int, n_landmarks: int, eps_deg: float, transfer: str
) -> None:
    rng = np.random.default_rng(seed)
    eps = np.deg2rad(eps_deg)
    shape = (n_maps, n_landmarks)
    landmarks = rng.uniform(0, 10, shape) + 1j * rng.uniform(0, 10, shape)
    batch = BatchedPolygonSLAM(n_maps, n_landmarks, eps, transfer=transfer)
    singles = [PolygonSLAM(n_landmarks, eps, transfer=transfer) for _ in range(n_maps)]
    position = np.full(n_maps, 5.0 + 5.0j)
    for _ in range(8):
        step = 1.5 * np.exp(1j * rng.uniform(-np.pi, np.pi, n_maps))
        heading = step / np.abs(step)
        b1 = np.angle((landmarks - position[:, None]) / heading[:, None])
        b2 = np.angle((landmarks - (position + step)[:, None]) / heading[:, None])
        b1 += rng.uniform(-eps, eps, b1.shape)
        b2 += rng.uniform(-eps, eps, b2.shape)
        moving = np.flatnonzero(rng.random(n_maps) < 0.7)
        result = batch.update(b1[moving], b2[moving], maps=moving)
        for j, i in enumerate(moving):
            single = singles[i].update(b1[i], b2[i])
            assert single.frame_changed == result.frame_changed[j]
        position = position + step
    for i, single in enumerate(singles):
        view = PolygonSLAM.view(batch, i)
        assert same_regions(view, single)
        assert np.array_equal(view.areas, single.areas)
        assert np.array_equal(view.estimates, single.estimates, equal_nan=True)
        assert view.n_updates == single.n_updates
    assert batch.n_frame_changes.sum() > 0  # the comparison covered real fusions


def test_views_share_their_batch_and_copies_do_not() -> None:
    batch = BatchedPolygonSLAM(3, 4, np.deg2rad(2.0))
    view = PolygonSLAM.view(batch, 1)
    b1, b2 = np.array([0.3, 0.6, 1.2, 1.9]), np.array([0.5, 0.9, 1.5, 2.3])
    clone = view.copy()
    view.update(b1, b2)
    assert batch.n_updates.tolist() == [0, 1, 0]
    assert clone.n_updates == 0 and clone.batch is not batch
    with pytest.raises(IndexError):
        PolygonSLAM.view(batch, 3)


def test_replicated_maps_update_like_independent_copies() -> None:
    rng = np.random.default_rng(8)
    eps = np.deg2rad(2.0)
    slam = PolygonSLAM(5, eps)
    landmarks = rng.uniform(0, 10, 5) + 1j * rng.uniform(0, 10, 5)
    position = 5.0 + 5.0j
    for _ in range(3):  # give the map some history
        step = 2.0 * np.exp(1j * rng.uniform(-np.pi, np.pi))
        b1 = np.angle((landmarks - position) / (step / abs(step)))
        b2 = np.angle((landmarks - position - step) / (step / abs(step)))
        slam.update(b1, b2)
        position += step
    b1 = rng.uniform(-np.pi, np.pi, (6, 5))
    b2 = b1 + rng.uniform(0.05, 0.4, (6, 5))
    copies = slam.replicate(6)
    copies.update(b1, b2)
    for i in range(6):
        expected = slam.copy()
        expected.update(b1[i], b2[i])
        assert same_regions(PolygonSLAM.view(copies, i), expected)
        assert np.array_equal(copies.areas[i], expected.areas)
    assert slam.n_updates == 3  # the original is untouched


def same_regions(a: PolygonSLAM, b: PolygonSLAM) -> bool:
    """The two maps hold the same regions, vertex for vertex, and the same robot region."""
    pairs = [*zip(a.polygons, b.polygons, strict=True), (a.robot_polygon, b.robot_polygon)]
    return all(
        (p is None and q is None) or (p is not None and q is not None and np.array_equal(p, q))
        for p, q in pairs
    )


# ----------------------------------------------------------------------------------------
# Clear errors for malformed input
# ----------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "actions",
    [np.array([True, False]), np.array(["3", "5"]), ["3", "5"], np.array([1 + 0j, 2 + 0j])],
    ids=["bools", "str-array", "str-list", "complex"],
)
def test_discrete_actions_that_are_not_numbers_raise_like_the_single_env(actions: Any) -> None:
    env = BearingSLAMDiscreteVectorEnv(2, scenario="khepera")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        env.step(actions)
    single = gym.make("BearingSLAMDiscrete-v1", scenario="khepera").unwrapped
    single.reset(seed=0)
    with pytest.raises(ValueError, match="action"):
        single.step(np.asarray(actions)[0])


@pytest.mark.parametrize(
    "actions",
    [
        np.array([["0.5", "0.1"], ["0.2", "0.3"]]),
        np.array([[True, False], [False, True]]),
        np.array([[0.5 + 1j, 0.0], [0.1, 0.2]]),
    ],
    ids=["strings", "bools", "complex"],
)
def test_continuous_actions_that_are_not_real_numbers_raise(actions: Any) -> None:
    env = BearingSLAMVectorEnv(2, scenario="khepera")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="real numbers"):
        env.step(actions)


@pytest.mark.parametrize(
    ("seed", "shown"),
    [(1.5, "1.5"), ("7", "'7'"), ([1, 2.5], "2.5"), ([True, 2], "True"), (np.float64(3), "3.0")],
)
def test_reset_with_a_seed_that_is_not_an_int_names_it(seed: Any, shown: str) -> None:
    env = BearingSLAMVectorEnv(2)
    with pytest.raises(TypeError, match="seed") as raised:
        env.reset(seed=seed)
    assert shown in str(raised.value)


def _read_only_clone(env: Any) -> Any:
    """A pickle round trip whose out-of-band buffers come back read-only."""
    buffers: list[pickle.PickleBuffer] = []
    data = pickle.dumps(env, protocol=5, buffer_callback=buffers.append)
    assert buffers  # the arrays really travelled out of band
    return pickle.loads(data, buffers=[memoryview(b.raw()).toreadonly() for b in buffers])


def test_the_vector_envs_own_arrays_are_writable_after_a_read_only_unpickle() -> None:
    env = BearingSLAMVectorEnv(3, scenario="khepera")
    env.reset(seed=0)
    clone = _read_only_clone(env)
    for name, value in vars(clone._state).items():
        if isinstance(value, np.ndarray):
            assert value.flags.writeable, name
    for name in ("_config_index", "_autoreset_envs", "_elapsed_steps"):
        assert getattr(clone, name).flags.writeable, name


def test_a_vector_env_from_a_read_only_unpickle_still_steps() -> None:
    env = BearingSLAMVectorEnv(3, scenario="khepera")
    env.reset(seed=0)
    actions = np.random.default_rng(0).uniform(-1, 1, (6, 3, 2)).astype(np.float32)
    clone = _read_only_clone(env)
    for step_actions in actions:
        assert_same(env.step(step_actions), clone.step(step_actions))


def test_reading_the_sub_envs_generators_mid_episode_changes_no_step() -> None:
    """The sub-envs draw their moves' noise ahead; ``get_attr("np_random")`` hands the
    unspent draws back first, so the steps after it (and a draw from the generators)
    are the ones of a vector env whose generators were never read."""
    read, plain = (BearingSLAMVectorEnv(3, scenario="khepera") for _ in range(2))
    read.reset(seed=11)
    plain.reset(seed=11)
    actions = np.random.default_rng(2).uniform(-1, 1, (30, 3, 2)).astype(np.float32)
    for k, action in enumerate(actions):
        if k in (3, 17):
            assert all(isinstance(rng, np.random.Generator) for rng in read.get_attr("np_random"))
        got, want = read.step(action), plain.step(action)
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
    draws = [rng.random() for rng in read.get_attr("np_random")]
    assert draws == [rng.random() for rng in plain.get_attr("np_random")]
