# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""``bearing_env.train.sb3.vec_env``: the SB3 adapter for Gymnasium vector envs, and
``--vec-env batched``.

The adapter must be indistinguishable from a ``DummyVecEnv`` of the single envs that
training used before (``EnvFactory``: ``SuccessInfo`` and ``Monitor``), so the reference is
exactly that, stepped with the same seeds and actions. ``target_area=0.5`` and
``max_moves=10`` make episodes end often, by success (termination) as well as by the
time limit (truncation), so a short run crosses many episode ends.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode, VectorEnv, VectorWrapper

from tests.extras import skip_module_without

skip_module_without("train")

from stable_baselines3 import DQN, PPO
from stable_baselines3.common.vec_env import DummyVecEnv, VecEnv, VecMonitor, VecNormalize

from bearing_env.train.common.cli_values import parse_key_values
from bearing_env.train.sb3 import train_cli
from bearing_env.train.sb3.train import TrainSettings, train
from bearing_env.train.sb3.training_envs import EnvFactory, resolve_vec_env_kind
from bearing_env.train.sb3.vec_env import GymnasiumVecEnv, make_batched_vec_env

ENV_IDS = ("BearingSLAM-v1", "BearingSLAMDiscrete-v1")
ENDING_KWARGS: dict[str, Any] = {"scenario": "khepera", "target_area": 0.5, "max_moves": 10}
N_ENVS = 3
N_STEPS = 120
TINY_PPO = ["n_steps=16", "batch_size=32", "n_epochs=1", "policy_kwargs=dict(net_arch=[16])"]


def sync_vector_env(
    env_id: str,
    env_kwargs: dict[str, Any],
    n_envs: int = N_ENVS,
    autoreset_mode: AutoresetMode = AutoresetMode.SAME_STEP,
) -> VectorEnv[Any, Any, Any]:
    return gym.make_vec(
        env_id,
        num_envs=n_envs,
        vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": autoreset_mode},
        **env_kwargs,
    )


def reference_vec_env(env_id: str, env_kwargs: dict[str, Any], n_envs: int = N_ENVS) -> VecEnv:
    """What ``--vec-env dummy`` trains on."""
    return DummyVecEnv([EnvFactory(env_id, dict(env_kwargs)) for _ in range(n_envs)])


def random_actions(venv: VecEnv, count: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    space = venv.action_space
    if isinstance(space, gym.spaces.Discrete):
        return rng.integers(0, int(space.n), size=(count, venv.num_envs))
    return rng.uniform(-1.0, 1.0, size=(count, venv.num_envs, *space.shape)).astype(np.float32)


def assert_same(actual: Any, expected: Any, exact: bool, where: str) -> None:
    """Equal values of equal types (Python scalars stay Python scalars), recursively."""
    if isinstance(expected, dict):
        assert isinstance(actual, dict), where
        assert actual.keys() == expected.keys(), where
        for key in expected:
            assert_same(actual[key], expected[key], exact, f"{where}.{key}")
        return
    assert type(actual) is type(expected), (where, type(actual), type(expected))
    if isinstance(expected, np.ndarray):
        assert actual.dtype == expected.dtype and actual.shape == expected.shape, where
        if exact or expected.dtype.kind in "biu":
            np.testing.assert_array_equal(actual, expected, err_msg=where)
        else:
            np.testing.assert_allclose(actual, expected, rtol=1e-5, atol=1e-6, err_msg=where)
    elif isinstance(expected, float) and not exact:
        assert actual == pytest.approx(expected, rel=1e-5, abs=1e-6), where
    else:
        assert actual == expected, where


def compare_runs(
    adapted: VecEnv, reference: VecEnv, steps: int, seed: int, exact: bool = True
) -> tuple[int, int]:
    """Steps both with the same seeds and actions, comparing everything SB3 sees; returns the
    numbers of terminations and truncations."""
    assert_close = np.testing.assert_array_equal if exact else np.testing.assert_allclose
    adapted.seed(seed)
    reference.seed(seed)
    assert_close(adapted.reset(), reference.reset())
    reset_infos = adapted.unwrapped.reset_infos  # SB3's VecEnvWrappers do not forward them
    for index in range(adapted.num_envs):
        assert_same(reset_infos[index], reference.reset_infos[index], exact, "reset")
    terminations = truncations = 0
    for step, actions in enumerate(random_actions(reference, steps, seed)):
        obs, rewards, dones, infos = adapted.step(actions)
        ref_obs, ref_rewards, ref_dones, ref_infos = reference.step(actions)
        assert obs.dtype == ref_obs.dtype == np.float32 and rewards.dtype == np.float32
        assert_close(obs, ref_obs, err_msg=f"step {step}")
        assert_close(rewards, ref_rewards, err_msg=f"step {step}")
        np.testing.assert_array_equal(dones, ref_dones, err_msg=f"step {step}")
        for index, (info, ref_info) in enumerate(zip(infos, ref_infos, strict=True)):
            where = f"step {step} env {index}"
            episode, ref_episode = info.pop("episode", None), ref_info.pop("episode", None)
            assert_same(info, ref_info, exact, where)
            if ref_dones[index]:
                assert_same(reset_infos[index], reference.reset_infos[index], exact, where)
                terminations += not ref_info["TimeLimit.truncated"]
                truncations += ref_info["TimeLimit.truncated"]
                assert ref_info["is_success"] == (not ref_info["TimeLimit.truncated"])
            if isinstance(adapted, VecMonitor):  # its episode stats against Monitor's
                assert (episode is None) == (ref_episode is None), where
            if episode is not None and ref_episode is not None:
                assert episode["l"] == ref_episode["l"], where
                assert episode["is_success"] == ref_episode["is_success"], where
                assert float(episode["r"]) == pytest.approx(ref_episode["r"], abs=1e-4), where
    return terminations, truncations


@pytest.fixture
def no_vector_entry_point(monkeypatch: pytest.MonkeyPatch) -> None:
    """The ids as before their batched env: ``batched`` falls back to ``SyncVectorEnv``."""
    for env_id in ENV_IDS:
        monkeypatch.setattr(gym.spec(env_id), "vector_entry_point", None)


@pytest.fixture
def stub_vector_entry_point(monkeypatch: pytest.MonkeyPatch) -> Iterator[list[dict[str, Any]]]:
    """A registered ``vector_entry_point`` (a ``SyncVectorEnv`` in disguise) recording the
    keyword arguments ``gym.make_vec`` passes it."""
    calls: list[dict[str, Any]] = []
    for env_id in ENV_IDS:

        def make(num_envs: int, env_id: str = env_id, **kwargs: Any) -> VectorEnv[Any, Any, Any]:
            calls.append({"env_id": env_id, "num_envs": num_envs, **kwargs})
            mode = kwargs.pop("autoreset_mode")
            return gym.make_vec(
                env_id, num_envs, "sync", vector_kwargs={"autoreset_mode": mode}, **kwargs
            )

        monkeypatch.setattr(gym.spec(env_id), "vector_entry_point", make)
    yield calls


# --------------------------------------------------------------------------------------
# The adapter against DummyVecEnv
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_adapter_reproduces_dummy_vec_env(env_id: str) -> None:
    adapted = GymnasiumVecEnv(sync_vector_env(env_id, ENDING_KWARGS))
    reference = reference_vec_env(env_id, ENDING_KWARGS)
    try:
        terminations, truncations = compare_runs(adapted, reference, N_STEPS, seed=11)
    finally:
        adapted.close()
        reference.close()
    assert terminations >= 3 and truncations >= 3, (terminations, truncations)


@pytest.mark.usefixtures("no_vector_entry_point")
def test_sync_fallback_reproduces_dummy_vec_env_with_ragged_infos() -> None:
    """``make_batched_vec_env`` without a batched env: a ``SyncVectorEnv`` behind the adapter
    and ``VecMonitor``. Random layouts of 3 to 6 landmarks report info arrays
    (``landmark_area`` ...) of different lengths, which Gymnasium alone cannot stack."""
    kwargs = {"scenario": "random", "n_landmarks": (3, 6), "target_area": 0.5, "max_moves": 10}
    env_id = "BearingSLAMDiscrete-v1"
    adapted = make_batched_vec_env(env_id, kwargs, N_ENVS, monitor_path=None)
    reference = reference_vec_env(env_id, kwargs)
    try:
        assert isinstance(adapted, VecMonitor) and isinstance(adapted.venv, GymnasiumVecEnv)
        terminations, truncations = compare_runs(adapted, reference, 60, seed=5)
    finally:
        adapted.close()
        reference.close()
    assert terminations + truncations >= 6


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_training_vec_env_reproduces_dummy_vec_env(env_id: str) -> None:
    """``make_batched_vec_env`` as training builds it, with whatever vector env the id
    registers. Floats are compared with a tolerance: a batched env may round differently."""
    adapted = make_batched_vec_env(env_id, ENDING_KWARGS, N_ENVS, monitor_path=None)
    reference = reference_vec_env(env_id, ENDING_KWARGS)
    try:
        terminations, truncations = compare_runs(adapted, reference, 60, seed=3, exact=False)
    finally:
        adapted.close()
        reference.close()
    assert terminations + truncations >= 6


# --------------------------------------------------------------------------------------
# The VecEnv API
# --------------------------------------------------------------------------------------


def test_reset_and_step_follow_the_vec_env_api() -> None:
    venv = GymnasiumVecEnv(sync_vector_env("BearingSLAM-v1", {"scenario": "khepera"}))
    single = gym.make("BearingSLAM-v1", scenario="khepera")
    try:
        assert venv.num_envs == N_ENVS
        assert venv.observation_space == single.observation_space
        assert venv.action_space == single.action_space
        assert venv.render_mode is None and venv.spec is not None
        obs = venv.reset()
        assert isinstance(obs, np.ndarray)
        assert obs.shape == (N_ENVS, *single.observation_space.shape) and obs.dtype == np.float32
        assert len(venv.reset_infos) == N_ENVS and "total_area" in venv.reset_infos[0]
        obs, rewards, dones, infos = venv.step(random_actions(venv, 1)[0])
        assert obs.shape == (N_ENVS, *single.observation_space.shape) and obs.dtype == np.float32
        assert rewards.shape == (N_ENVS,) and rewards.dtype == np.float32
        assert dones.shape == (N_ENVS,) and dones.dtype == np.bool_
        assert isinstance(infos, list) and len(infos) == N_ENVS
        assert all(info["TimeLimit.truncated"] is False for info in infos)
        assert all(type(info["total_area"]) is float for info in infos)
        assert all(isinstance(info["rewards"]["uncertainty"], float) for info in infos)
        obs[:] = 0.0  # the caller owns what it gets
        assert not np.array_equal(venv.step(random_actions(venv, 1)[0])[0], obs)
    finally:
        venv.close()
        single.close()


def test_attributes_and_methods_reach_the_sub_envs() -> None:
    venv = GymnasiumVecEnv(sync_vector_env("BearingSLAM-v1", {"scenario": "khepera"}))
    try:
        assert venv.get_attr("area_cap") == [10.0] * N_ENVS  # a sub-env attribute
        assert venv.get_attr("area_cap", indices=[2]) == [10.0]
        assert venv.get_attr("single_action_space", 0) == [venv.action_space]  # the vector env's
        assert venv.has_attr("area_cap") and not venv.has_attr("no_such_attribute")
        venv.set_attr("area_cap", 5.0, indices=[1])  # SyncVectorEnv: per sub-env
        assert venv.get_attr("area_cap") == [10.0, 5.0, 10.0]
        venv.set_attr("area_cap", 7.0)
        assert venv.get_attr("area_cap") == [7.0] * N_ENVS
        assert venv.env_method("get_wrapper_attr", "area_cap") == [7.0] * N_ENVS
        with pytest.raises(ValueError, match="sub-envs \\[0\\] only"):
            venv.env_method("get_wrapper_attr", "area_cap", indices=0)
        assert venv.env_is_wrapped(gym.Wrapper) == [False] * N_ENVS
        assert venv.env_is_wrapped(gym.Wrapper, indices=[0, 1]) == [False, False]
        assert venv.get_images() == [None] * N_ENVS
    finally:
        venv.close()


def test_a_vector_env_without_sub_env_access_serves_only_whole_batch_requests() -> None:
    """A plain ``VectorWrapper`` has neither ``get_attr`` nor ``call``: its own attributes
    stand for every sub-env, and a request for some sub-envs only is refused."""
    venv = GymnasiumVecEnv(VectorWrapper(sync_vector_env("BearingSLAM-v1", {})))
    try:
        assert venv.get_attr("num_envs", indices=[0, 2]) == [N_ENVS, N_ENVS]
        with pytest.raises(AttributeError, match="area_cap"):
            venv.get_attr("area_cap")
        with pytest.raises(ValueError, match="only"):
            venv.set_attr("extra", 1, indices=[1])
        venv.set_attr("extra", 1)
        assert venv.get_attr("extra") == [1] * N_ENVS
        with pytest.raises(ValueError, match="only"):
            venv.env_method("reset", indices=[1])
        with pytest.raises(AttributeError, match="no_such_method"):
            venv.env_method("no_such_method")
    finally:
        venv.close()


class RecordingVectorEnv(VectorWrapper):
    """Records the arguments of every ``reset`` (the options go no further: the sub-envs
    take none and refuse any)."""

    def __init__(self, env: VectorEnv[Any, Any, Any]) -> None:
        super().__init__(env)
        self.resets: list[tuple[Any, Any]] = []

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        self.resets.append((seed, options))
        return self.env.reset(seed=seed)


def test_seeds_and_options_are_used_once() -> None:
    recorder = RecordingVectorEnv(sync_vector_env("BearingSLAM-v1", {"scenario": "random"}))
    venv = GymnasiumVecEnv(recorder)
    try:
        assert venv.seed(7) == [7, 8, 9]
        venv.set_options({"probe": 1})
        first = venv.reset()
        trajectory = [venv.step(actions)[0] for actions in random_actions(venv, 5)]
        later = venv.reset()  # runs on: neither the seeds nor the options again
        assert recorder.resets == [([7, 8, 9], {"probe": 1}), (None, None)]
        assert not np.array_equal(later, first)
        venv.seed(7)
        np.testing.assert_array_equal(venv.reset(), first)
        for expected, actions in zip(trajectory, random_actions(venv, 5), strict=True):
            np.testing.assert_array_equal(venv.step(actions)[0], expected)
        venv.set_options([{"probe": 1}, {"probe": 2}, {}])
        with pytest.raises(ValueError, match="different options"):
            venv.reset()
    finally:
        venv.close()


def test_a_vector_env_in_another_autoreset_mode_is_refused() -> None:
    for mode in (AutoresetMode.NEXT_STEP, AutoresetMode.DISABLED):
        vector_env = sync_vector_env("BearingSLAM-v1", {}, n_envs=1, autoreset_mode=mode)
        with pytest.raises(ValueError, match="SAME_STEP"):
            GymnasiumVecEnv(vector_env)
        vector_env.close()
    with pytest.raises(TypeError, match="VectorEnv"):
        GymnasiumVecEnv(gym.make("BearingSLAM-v1"))  # type: ignore[arg-type]


class DropFinalKey(VectorWrapper):
    """A broken SAME_STEP env: it does not report the finished episodes' ``key``."""

    def __init__(self, env: VectorEnv[Any, Any, Any], key: str) -> None:
        super().__init__(env)
        self.key = key

    def step(self, actions: Any) -> tuple[Any, Any, Any, Any, dict[str, Any]]:
        obs, rewards, terminated, truncated, infos = self.env.step(actions)
        infos.pop(self.key, None)
        infos.pop(f"_{self.key}", None)
        return obs, rewards, terminated, truncated, infos


@pytest.mark.parametrize("key", ["final_obs", "final_info"])
def test_a_finished_episode_without_its_final_observation_or_info_raises(key: str) -> None:
    vector_env = sync_vector_env("BearingSLAM-v1", {"max_moves": 2}, n_envs=2)
    venv = GymnasiumVecEnv(DropFinalKey(vector_env, key))
    try:
        venv.reset()
        venv.step(random_actions(venv, 1)[0])
        with pytest.raises(RuntimeError, match="did not report"):
            venv.step(random_actions(venv, 1)[0])
    finally:
        venv.close()


@pytest.mark.parametrize(
    ("env_id", "algorithm", "kwargs"),
    [
        ("BearingSLAM-v1", PPO, {"n_steps": 16, "batch_size": 32, "n_epochs": 1}),
        ("BearingSLAMDiscrete-v1", DQN, {"learning_starts": 16, "batch_size": 16}),
    ],
)
def test_sb3_learns_on_it_with_vecnormalize(
    env_id: str, algorithm: type[PPO] | type[DQN], kwargs: dict[str, Any]
) -> None:
    venv = VecNormalize(make_batched_vec_env(env_id, {"scenario": "khepera"}, 2, None))
    model = algorithm("MlpPolicy", venv, seed=0, policy_kwargs={"net_arch": [16]}, **kwargs)
    model.learn(64)
    assert model.num_timesteps == 64
    assert venv.obs_rms.count > 64  # the statistics saw every step
    venv.close()


# --------------------------------------------------------------------------------------
# make_batched_vec_env and bearing-env train
# --------------------------------------------------------------------------------------


def test_a_registered_vector_entry_point_is_used(
    stub_vector_entry_point: list[dict[str, Any]],
) -> None:
    venv = make_batched_vec_env("bearing_env:BearingSLAM-v1", {"max_moves": 7}, 2, None)
    venv.close()
    assert stub_vector_entry_point == [
        {
            "env_id": "BearingSLAM-v1",
            "num_envs": 2,
            "max_moves": 7,
            "autoreset_mode": AutoresetMode.SAME_STEP,
        }
    ]


def test_auto_is_batched_only_with_a_vector_entry_point(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    spec = gym.spec("BearingSLAM-v1")
    monkeypatch.setattr(spec, "vector_entry_point", None)
    assert resolve_vec_env_kind("auto", "BearingSLAM-v1") == "subproc"
    monkeypatch.setattr(spec, "vector_entry_point", "module:Class")
    assert resolve_vec_env_kind("auto", "bearing_env:BearingSLAM-v1") == "batched"
    assert resolve_vec_env_kind("dummy", "BearingSLAM-v1") == "dummy"
    with pytest.raises(ValueError, match="auto"):
        resolve_vec_env_kind("threads", "BearingSLAM-v1")
    assert TrainSettings("ppo", "BearingSLAM-v1", Path("x")).vec_env == "auto"
    assert train_cli.build_parser().parse_args(["--algo", "ppo"]).vec_env == "auto"


def run_cli(output: Path, timesteps: int, *extra: str) -> dict[str, Any]:
    train_cli.main(
        [
            "--algo", "ppo", "--env", "BearingSLAM-v1", "--output", str(output),
            "--n-envs", "2", "--seed", "4",
            "--timesteps", str(timesteps), "--hyperparams", *TINY_PPO,
            "--eval-freq", "32", "--eval-episodes", "1", "--checkpoint-freq", "32",
            "--no-progress", "--no-tensorboard", *extra,
        ]
    )  # fmt: skip
    return json.loads((output / "run.json").read_text())


def monitor_rows(path: Path) -> tuple[list[str], list[str]]:
    lines = path.read_text().splitlines()
    return [line for line in lines if line.startswith("#")], lines


def test_train_batched_writes_its_outputs_and_resumes(tmp_path: Path) -> None:
    run = tmp_path / "batched"
    record = run_cli(run, 64, "--vec-env", "batched")
    assert record["status"] == "finished" and record["vec_env"] == "batched"
    assert [segment["vec_env"] for segment in record["segments"]] == ["batched"]
    for name in ("model.zip", "vecnormalize.pkl", "best/best_model.zip", "best/best.json"):
        assert (run / name).is_file(), name
    assert sorted(path.name for path in (run / "monitor").iterdir()) == ["batched.monitor.csv"]
    headers, lines = monitor_rows(run / "monitor" / "batched.monitor.csv")
    assert len(headers) == 1 and json.loads(headers[0][1:])["env_id"] == "BearingSLAM-v1"
    assert lines[1] == "r,l,t,is_success"
    episodes = len(lines) - 2
    assert episodes >= 2  # 32 steps per env, 20-move episodes

    record = run_cli(run, 128, "--vec-env", "batched", "--resume")
    assert record["num_timesteps"] == 128 and record["status"] == "finished"
    assert [segment["vec_env"] for segment in record["segments"]] == ["batched", "batched"]
    headers, lines = monitor_rows(run / "monitor" / "batched.monitor.csv")
    assert len(headers) == 1 and len(lines) - 2 > episodes  # appended, not overwritten


def test_train_auto_uses_the_registered_batched_env(
    tmp_path: Path, stub_vector_entry_point: list[dict[str, Any]]
) -> None:
    record = run_cli(tmp_path / "auto", 32)  # --vec-env auto is the default
    assert record["vec_env"] == "batched" and record["segments"][0]["vec_env"] == "batched"
    assert [call["num_envs"] for call in stub_vector_entry_point] == [2]
    assert (tmp_path / "auto" / "monitor" / "batched.monitor.csv").is_file()
    assert (tmp_path / "auto" / "model.zip").is_file()


@pytest.mark.usefixtures("no_vector_entry_point")
def test_batched_and_dummy_train_the_same_model(tmp_path: Path) -> None:
    """The same seeds give the same data, hence bit for bit the same PPO model."""
    settings = TrainSettings(
        algo="ppo",
        env_id="BearingSLAM-v1",
        output=tmp_path / "dummy",
        hyperparam_overrides=parse_key_values(TINY_PPO, "--hyperparams"),
        timesteps=64,
        seed=9,
        n_envs=2,
        vec_env="dummy",
        eval_freq=0,
        checkpoint_freq=1_000,
        progress_bar=False,
        tensorboard=False,
    )
    dummy = train(settings)
    settings.output, settings.vec_env = tmp_path / "batched", "batched"
    batched = train(settings)
    for (name, a), (_, b) in zip(
        dummy.model.policy.state_dict().items(),
        batched.model.policy.state_dict().items(),
        strict=True,
    ):
        assert np.array_equal(a.numpy(), b.numpy()), name
    dummy_stats = dummy.model.get_vec_normalize_env()
    batched_stats = batched.model.get_vec_normalize_env()
    assert dummy_stats is not None and batched_stats is not None
    np.testing.assert_array_equal(dummy_stats.obs_rms.mean, batched_stats.obs_rms.mean)
