# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""Every entry of the shipped rl-zoo3 hyperparameter files (``train/sb3/hyperparams/*.yml``)
trains on the env its key names, with nothing else.

rl-zoo3 gives an entry's ``env_kwargs`` to its training envs only and makes its
evaluation env from the id alone (``gym.make(key)``), so a setting that changes the env,
above all its observation space, must be the registered id's own. Here each entry's env
is made from its key alone: the entry has no ``env_kwargs``, its ``normalize`` settings
(``norm_obs_keys``), policy and algorithm fit that env's spaces (the SB3 model and
``VecNormalize`` are built on it), and rl-zoo3's own ``ExperimentManager`` trains it
for a few dozen steps and evaluates it on an env whose settings are the training envs'.
"""

from __future__ import annotations

import argparse
import contextlib
import io
from pathlib import Path
from typing import Any

import gymnasium as gym
import pytest
import yaml

from tests.extras import skip_module_without

skip_module_without("train")

from gymnasium import spaces
from stable_baselines3.common.callbacks import EvalCallback
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.vec_env import VecEnv, VecNormalize

import bearing_env  # noqa: F401  (registers the ids the files are keyed by)
from bearing_env.train.sb3.conf_files import HYPERPARAMS_DIR
from bearing_env.train.sb3.zoo import (
    DEFAULT_ENV_IDS,
    algorithm_class_for,
    parse_hyperparameters,
    read_hyperparameters,
    rl_zoo3_module,
)

FILES = sorted(Path(str(HYPERPARAMS_DIR)).glob("*.yml"))
#: Every entry: (file name without ``.yml``, key).
ENTRIES = [
    (path.stem, key)
    for path in FILES
    for key in yaml.safe_load(path.read_text(encoding="utf-8"))
]
#: The hyperparameters that make an rl-zoo3 run short (a rollout or a few updates).
TINY: dict[str, dict[str, Any]] = {
    "ppo": {"n_envs": 2, "n_steps": 32, "batch_size": 32, "n_epochs": 1},
    "sac": {"n_envs": 2, "learning_starts": 16, "buffer_size": 1000, "batch_size": 16},
    "dqn": {
        "n_envs": 2,
        "learning_starts": 16,
        "buffer_size": 1000,
        "batch_size": 16,
        "target_update_interval": 8,
    },
}
#: Timesteps of an rl-zoo3 run, and its evaluation interval (in steps of all envs).
TIMESTEPS, EVAL_FREQ = 64, 32


def algo_of(name: str) -> str:
    """A file's algorithm: ``ppo_entities`` trains PPO."""
    return name.split("_")[0]


def test_every_shipped_file_and_default_id_has_its_entries() -> None:
    assert {name for name, _ in ENTRIES} == {
        "dqn", "ppo", "ppo_attention", "ppo_candidates", "ppo_entities", "ppo_shapes", "sac",
    }  # fmt: skip
    for algo, env_id in DEFAULT_ENV_IDS.items():
        assert (algo, env_id) in ENTRIES


@pytest.mark.parametrize(("name", "key"), ENTRIES, ids=[f"{n}:{k}" for n, k in ENTRIES])
def test_an_entry_fits_the_env_its_key_alone_makes(name: str, key: str) -> None:
    algo = algo_of(name)
    raw = read_hyperparameters(algo, key, HYPERPARAMS_DIR / f"{name}.yml")
    # Settings in env_kwargs would reach rl-zoo3's training envs and not its evaluation env.
    assert "env_kwargs" not in raw, f"{name}.yml: key {key} by the id that carries its settings"
    parsed = parse_hyperparameters(raw, algo)
    with gym.make(key) as env:
        space = env.observation_space
    keys = (parsed.normalize or {}).get("norm_obs_keys")
    if keys is not None:
        assert isinstance(space, spaces.Dict), f"norm_obs_keys {keys} on {key}'s {space}"
        assert set(keys) <= set(space.spaces), f"norm_obs_keys {keys} not all in {space}"
    # The model and its VecNormalize build on the env: SB3 refuses a policy that does not
    # fit the observation space (MlpPolicy on a Dict) or an action space the algorithm
    # cannot act in, VecNormalize keys it cannot normalise.
    venv: VecEnv = make_vec_env(key, n_envs=parsed.n_envs)
    if parsed.normalize is not None:
        venv = VecNormalize(venv, **parsed.normalize)
    kwargs = {k: v for k, v in parsed.algorithm_kwargs.items() if k != "policy"}
    if algo != "ppo":
        kwargs["buffer_size"] = 10  # the model builds, without a big buffer
    else:  # every update's rollout splits into whole mini-batches
        assert (kwargs["n_steps"] * parsed.n_envs) % kwargs["batch_size"] == 0
    algorithm_class_for(algo)(parsed.algorithm_kwargs["policy"], venv, device="cpu", **kwargs)
    venv.close()


def env_settings(venv: VecEnv) -> str:
    """The settings of the first env of an SB3 vector env (through its wrappers)."""
    first = venv.unwrapped.envs[0]  # type: ignore[attr-defined]
    return repr(first.unwrapped.config)


def slow_unless_ppo(name: str) -> list[pytest.MarkDecorator]:
    """PPO's runs (1-2 s each) are in the default test run; SAC's and DQN's (3-7 s, their
    replay buffers and gradient steps) are slow, as in ``test_zoo_commands.py``."""
    return [] if algo_of(name) == "ppo" else [pytest.mark.slow]


@pytest.mark.parametrize(
    ("name", "key"),
    [pytest.param(n, k, marks=slow_unless_ppo(n), id=f"{n}:{k}") for n, k in ENTRIES],
)
def test_rl_zoo3_trains_and_evaluates_an_entry_on_its_id_alone(
    name: str, key: str, tmp_path: Path
) -> None:
    """What ``python -m rl_zoo3.train --algo ALGO --env KEY --conf-file FILE`` does, with
    no ``--eval-env-kwargs``, briefly and in this process."""
    algo = algo_of(name)
    experiment_manager = rl_zoo3_module("rl_zoo3.exp_manager").ExperimentManager
    manager = experiment_manager(
        argparse.Namespace(),
        algo,
        key,
        log_folder=str(tmp_path),
        n_timesteps=TIMESTEPS,
        eval_freq=EVAL_FREQ,
        n_eval_episodes=1,
        hyperparams=TINY[algo],
        config=str(HYPERPARAMS_DIR / f"{name}.yml"),
        seed=0,
        log_interval=-1,  # rl_zoo3.train's default (0 would divide by zero in SB3)
        device="cpu",
        verbose=0,
    )
    with contextlib.redirect_stdout(io.StringIO()):  # rl-zoo3 prints what it read
        setup = manager.setup_experiment()
        assert setup is not None
        model, _ = setup
        evaluations = [c for c in manager.callbacks if isinstance(c, EvalCallback)]
        assert len(evaluations) == 1
        trained_on = env_settings(model.get_env())
        with gym.make(key) as env:
            assert trained_on == repr(env.unwrapped.config)  # type: ignore[attr-defined]
        assert env_settings(evaluations[0].eval_env) == trained_on
        manager.learn(model)
        manager.save_trained_model(model)
    assert model.num_timesteps >= TIMESTEPS
    assert evaluations[0].n_calls > 0 and len(evaluations[0].evaluations_results) > 0
