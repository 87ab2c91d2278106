"""The stable-baselines3 / rl-zoo3 glue of ``bearing-env train``: hyperparameter entries
read and preprocessed by rl-zoo3's own code, and the algorithm classes. (Saved models and
VecNormalize statistics are loaded by :mod:`bearing_env.agents.sb3`.)

A hyperparameter file is rl-zoo3's format, so it means here what it means to
``python -m rl_zoo3.train``: :func:`read_hyperparameters` and
:func:`parse_hyperparameters` run ``rl_zoo3.exp_manager.ExperimentManager``'s
``read_hyperparameters`` and ``_preprocess_hyperparams`` (``lin_<x>`` becomes rl-zoo3's
``SimpleLinearSchedule``, a number SB3's ``ConstantSchedule``, ``normalize`` takes the
algorithm's ``gamma``, ``policy_kwargs`` strings are evaluated with ``nn`` and ``th`` in
scope, ``train_freq`` lists become tuples). The keys rl-zoo3 turns into wrappers,
callbacks or noise (:data:`UNSUPPORTED_ZOO_KEYS`) are refused: this trainer builds its
own envs and callbacks. The algorithm classes are rl-zoo3's ``ALGOS``.

Importing ``rl_zoo3`` patches Gymnasium for the whole process (``rl_zoo3.gym_patches``
replaces ``TimeLimit``, which then adds a ``TimeLimit.truncated`` info key to every
``gym.make`` env, and sets ``np.bool8``). :func:`rl_zoo3_module` imports it and puts
Gymnasium and numpy back as they were, so using rl-zoo3's code here leaves the envs'
contract untouched; under ``python -m rl_zoo3.train`` rl-zoo3 patches as it always does.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import io
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np
from stable_baselines3.common.base_class import BaseAlgorithm

from bearing_env.train.sb3.conf_files import default_conf_file
from bearing_env.validation import int_at_least, is_integer

#: The algorithms ``bearing-env train`` ships hyperparameters for, and the env id each
#: trains on by default: the Khepera task ids, whose registered kwargs carry the scenario
#: (the shipped files are keyed by them, as rl-zoo3 needs).
DEFAULT_ENV_IDS: dict[str, str] = {
    "ppo": "BearingSLAM-Khepera-v1",
    "sac": "BearingSLAM-Khepera-v1",
    "dqn": "BearingSLAMDiscrete-Khepera-v1",
}

#: rl-zoo3 keys that this trainer does not implement (rl-zoo3 itself does).
UNSUPPORTED_ZOO_KEYS: frozenset[str] = frozenset(
    {
        "env_wrapper",
        "vec_env_wrapper",
        "frame_stack",
        "callback",
        "monitor_kwargs",
        "noise_type",
        "noise_std",
        "replay_buffer_class",
    }
)


@dataclass(frozen=True)
class Hyperparameters:
    """One preprocessed entry of a hyperparameter file."""

    n_envs: int
    n_timesteps: int
    env_kwargs: dict[str, Any]
    #: VecNormalize keyword arguments, or None to train without VecNormalize.
    normalize: dict[str, Any] | None
    #: Keyword arguments of the SB3 algorithm's constructor (``policy`` included).
    algorithm_kwargs: dict[str, Any]


#: The Gymnasium attributes ``rl_zoo3.gym_patches`` replaces (module, attribute name).
_PATCHED_BY_RL_ZOO3: tuple[tuple[str, str], ...] = (
    ("gymnasium.wrappers", "TimeLimit"),
    ("gymnasium.wrappers.common", "TimeLimit"),
    ("gymnasium.envs.registration", "TimeLimit"),
)


_ABSENT = object()


def rl_zoo3_module(name: str) -> ModuleType:
    """``importlib.import_module(name)`` of an ``rl_zoo3`` module, with Gymnasium's
    ``TimeLimit`` and numpy's attributes restored after rl-zoo3's import-time patches."""
    saved = [
        (module, attribute, vars(module).get(attribute, _ABSENT))
        for module, attribute in [
            (importlib.import_module(module_name), attribute)
            for module_name, attribute in _PATCHED_BY_RL_ZOO3
        ]
    ]
    saved.append((np, "bool8", vars(np).get("bool8", _ABSENT)))
    try:
        return importlib.import_module(name)
    finally:
        for module, attribute, value in saved:
            if value is _ABSENT:
                vars(module).pop(attribute, None)
            else:
                setattr(module, attribute, value)


def default_env_id(algo: str, conf_file: Path | None = None) -> str:
    """The env id a run trains on when ``--env`` is not given: the one entry's key of a
    hyperparameter file with a single entry (``ppo_entities.yml``:
    ``BearingSLAM-Random3to16-Entities-v1``), else the algorithm's default
    (:data:`DEFAULT_ENV_IDS`)."""
    if conf_file is not None and conf_file.is_file():
        import yaml  # type: ignore[import-untyped]  # why: pyyaml ships no types

        try:
            entries = yaml.safe_load(conf_file.read_text(encoding="utf-8"))
        except yaml.YAMLError:
            entries = None  # read_hyperparameters says what is wrong with it
        if isinstance(entries, dict) and len(entries) == 1:
            return str(next(iter(entries)))
    return DEFAULT_ENV_IDS[algo]


def hyperparams_key(env_id: str) -> str:
    """The file key of an env id: ``bearing_env:BearingSLAM-v1`` -> ``BearingSLAM-v1``."""
    return env_id.split(":")[-1]


def _experiment_manager(algo: str, env_id: str, conf_file: Path | None = None) -> Any:
    """An rl-zoo3 ``ExperimentManager`` used only for its reading and preprocessing (it
    creates no folder and no env until ``setup_experiment``, which is never called)."""
    import bearing_env  # noqa: F401  (registers the env ids rl-zoo3 looks up)

    experiment_manager = rl_zoo3_module("rl_zoo3.exp_manager").ExperimentManager
    return experiment_manager(
        argparse.Namespace(),
        algo,
        hyperparams_key(env_id),
        log_folder=".",
        verbose=0,
        config=str(conf_file) if conf_file is not None else None,
    )


def read_hyperparameters(algo: str, env_id: str, conf_file: Path | None = None) -> dict[str, Any]:
    """The raw entry for ``env_id`` in ``conf_file`` (default: the shipped ``<algo>.yml``),
    read by rl-zoo3.

    Raises:
        FileNotFoundError: no such file.
        ValueError: the file does not parse, or holds no mapping for the env id.
    """
    path = conf_file if conf_file is not None else default_conf_file(algo)
    if not path.is_file():
        raise FileNotFoundError(f"hyperparameter file not found: {path}")
    manager = _experiment_manager(algo, env_id, path)
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # rl-zoo3 prints what it read
            entry, _ = manager.read_hyperparameters()
    except ValueError as error:  # rl-zoo3: no entry for this env id
        raise ValueError(f"no entry {hyperparams_key(env_id)!r} in {path}: {error}") from None
    except Exception as error:  # yaml.YAMLError, or a file that is not a mapping
        raise ValueError(f"cannot read hyperparameter file {path}: {error}") from error
    if not isinstance(entry, dict):
        raise ValueError(f"entry {hyperparams_key(env_id)!r} in {path} must be a mapping")
    return dict(entry)


#: The smallest accepted value of the algorithms' integer hyperparameters (``--hyperparams``
#: or the YAML): below it stable-baselines3 fails with an assertion, or never trains.
#: PPO's minibatch needs 2 samples (SB3 normalises advantages over it).
MIN_HYPERPARAMETERS: dict[str, int] = {
    "n_steps": 1,
    "batch_size": 1,
    "n_epochs": 1,
    "buffer_size": 1,
    "learning_starts": 0,
    "target_update_interval": 1,
}

_MIN_BY_ALGO: dict[str, dict[str, int]] = {"ppo": {"batch_size": 2}}


def check_hyperparameters(kwargs: Mapping[str, Any], algo: str) -> None:
    """ValueError (TypeError for a non-integer) naming the hyperparameter and its value
    when an integer hyperparameter is below :data:`MIN_HYPERPARAMETERS` (``train_freq``
    and ``gradient_steps`` too, when they are plain integers: >= 1, and >= 1 or -1)."""
    minimums = {**MIN_HYPERPARAMETERS, **_MIN_BY_ALGO.get(algo.lower(), {})}
    for key, minimum in minimums.items():
        if key in kwargs:
            int_at_least(kwargs[key], minimum, f"hyperparameter {key}")
    train_freq = kwargs.get("train_freq")
    if is_integer(train_freq):
        int_at_least(train_freq, 1, "hyperparameter train_freq")
    gradient_steps = kwargs.get("gradient_steps")
    if isinstance(gradient_steps, (int, np.integer)) and gradient_steps != -1:
        int_at_least(gradient_steps, 1, "hyperparameter gradient_steps (or -1)")


def parse_hyperparameters(raw: Mapping[str, Any], algo: str = "ppo") -> Hyperparameters:
    """Preprocess a raw rl-zoo3 entry with rl-zoo3's ``_preprocess_hyperparams`` into the
    env settings and the algorithm's constructor arguments.

    Raises:
        ValueError: a key this trainer does not implement, a missing or non-positive
            ``n_timesteps``/``n_envs``, an integer hyperparameter below its minimum
            (:func:`check_hyperparameters`), or a value rl-zoo3 cannot preprocess (the
            message names it).
    """
    entry = dict(raw)
    unsupported = sorted(UNSUPPORTED_ZOO_KEYS & entry.keys())
    if unsupported:
        raise ValueError(
            f"hyperparameters {unsupported} are rl-zoo3 features that bearing-env train does "
            "not implement; train this config with rl_zoo3.train instead"
        )
    if "n_timesteps" not in entry:
        raise ValueError("the hyperparameter entry needs n_timesteps")
    env_kwargs = entry.get("env_kwargs") or {}
    if not isinstance(env_kwargs, dict):
        raise ValueError(f"env_kwargs must be a mapping, got {env_kwargs!r}")
    entry["env_kwargs"] = env_kwargs
    manager = _experiment_manager(algo, DEFAULT_ENV_IDS.get(algo, "BearingSLAM-v1"))
    try:
        kwargs, *_ = manager._preprocess_hyperparams(entry)
    except Exception as error:  # rl-zoo3 raises what eval() or float() raised
        raise ValueError(
            f"cannot preprocess the hyperparameters {dict(raw)!r}: "
            f"{type(error).__name__}: {error}"
        ) from error
    for key in ("policy_kwargs", "replay_buffer_kwargs"):
        if key in kwargs and not isinstance(kwargs[key], dict):
            raise ValueError(f"{key} must evaluate to a dict, got {raw[key]!r}")
    check_hyperparameters(kwargs, algo)
    n_envs, n_timesteps = int(manager.n_envs), int(manager.n_timesteps)
    if n_envs < 1 or n_timesteps < 1:
        raise ValueError(f"n_envs and n_timesteps must be >= 1, got {n_envs}, {n_timesteps}")
    kwargs.setdefault("policy", "MlpPolicy")
    return Hyperparameters(
        n_envs=n_envs,
        n_timesteps=n_timesteps,
        env_kwargs=dict(manager.env_kwargs),
        normalize=dict(manager.normalize_kwargs) if manager.normalize else None,
        algorithm_kwargs=dict(kwargs),
    )


def algorithm_class_for(algo: str) -> type[BaseAlgorithm]:
    """rl-zoo3's class for a trainable ``algo`` (``"ppo"``, ``"sac"``, ``"dqn"``)."""
    key = algo.lower()
    if key not in DEFAULT_ENV_IDS:
        raise ValueError(f"unknown algorithm {algo!r}; expected one of {sorted(DEFAULT_ENV_IDS)}")
    algorithms: dict[str, type[BaseAlgorithm]] = rl_zoo3_module("rl_zoo3.utils").ALGOS
    return algorithms[key]

