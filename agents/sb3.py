"""Trained stable-baselines3 agents as policies, and the one place saved models and
VecNormalize statistics are loaded.

:class:`SB3Policy` loads a saved model (``model.save(path)``, a ``.zip``) and, if there is
one, the ``VecNormalize`` statistics saved beside it, and applies them to observations
exactly as training did (``training=False``: the statistics are frozen).
:func:`load_model` and :func:`load_vecnormalize` are what it loads them with, and what
``bearing-env train`` (resume, export) uses too: a missing file is a
``FileNotFoundError``, an unusable one a :class:`ModelLoadError`, each naming the path.
"""

from __future__ import annotations

import json
import pickle
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces
from numpy.typing import NDArray

from bearing_env.envs.observations import ENTITY_FEATURES
from bearing_env.extras import require
from bearing_env.shipped import shipped_dir

from .base import Action
from .model_task import ModelTask, task_record_of

#: File names tried, in order, when ``path`` is a directory.
MODEL_FILE_NAMES = ("best_model.zip", "model.zip", "final_model.zip")
#: VecNormalize statistics looked for beside a model ``<dir>/<stem>.zip`` (first found wins).
VECNORMALIZE_FILE_NAMES = ("{stem}_vecnormalize.pkl", "{stem}.vecnormalize.pkl", "vecnormalize.pkl")

#: Algorithms by the module of the saved policy class (all that ``predict`` needs).
_ALGORITHM_BY_POLICY_MODULE = {
    "stable_baselines3.sac.policies": "SAC",
    "stable_baselines3.dqn.policies": "DQN",
    "stable_baselines3.td3.policies": "TD3",
    "sb3_contrib.tqc.policies": "TQC",
    "sb3_contrib.qrdqn.policies": "QRDQN",
}
_ALGORITHM_MODULES = {
    "PPO": "stable_baselines3",
    "A2C": "stable_baselines3",
    "SAC": "stable_baselines3",
    "TD3": "stable_baselines3",
    "DDPG": "stable_baselines3",
    "DQN": "stable_baselines3",
    "TQC": "sb3_contrib",
    "QRDQN": "sb3_contrib",
    "RecurrentPPO": "sb3_contrib",
}


#: Where shipped models live: ``<name>.zip``, ``<name>_vecnormalize.pkl`` and a
#: ``<name>.json`` record of how the model was trained (env id and kwargs, timesteps).
PRETRAINED_DIR = shipped_dir("bearing_env.agents", "pretrained")


def pretrained_names() -> list[str]:
    """Names of the models shipped under ``agents/pretrained/``, sorted."""
    if not PRETRAINED_DIR.is_dir():
        return []
    return sorted(path.stem for path in PRETRAINED_DIR.glob("*.zip"))


def pretrained_record(name: str) -> dict[str, Any]:
    """The training record of a shipped model (env id, env kwargs, timesteps, ...)."""
    record = PRETRAINED_DIR / f"{name}.json"
    if not record.is_file():
        raise FileNotFoundError(f"no training record for pretrained model {name!r}: {record}")
    return dict(json.loads(record.read_text()))


def pretrained_task(name: str) -> ModelTask:
    """The task a shipped model was trained on, from its record ``<name>.json``.

    Raises:
        ValueError: no shipped model has this name (the message lists them).
    """
    names = pretrained_names()
    if name not in names:
        raise ValueError(f"no pretrained model named {name!r}; available: {names}")
    return ModelTask.from_record(pretrained_record(name), name, f"{name}.json")


class ModelLoadError(ValueError):
    """A model or VecNormalize file exists but cannot be used."""


def resolve_model_path(path: str | Path) -> Path:
    """The ``.zip`` a path designates: the file itself (``.zip`` optional, as SB3 allows),
    or in a directory the first of :data:`MODEL_FILE_NAMES`.

    Raises:
        FileNotFoundError: nothing to load there.
    """
    candidate = Path(path).expanduser()
    if candidate.is_dir():
        for name in MODEL_FILE_NAMES:
            if (candidate / name).is_file():
                return candidate / name
        zips = sorted(candidate.glob("*.zip"))
        if len(zips) == 1:
            return zips[0]
        raise FileNotFoundError(
            f"no SB3 model in directory {candidate}: expected one of {MODEL_FILE_NAMES} "
            f"(or a single .zip), found {[z.name for z in zips]}"
        )
    if candidate.is_file():
        return candidate
    with_suffix = candidate.with_name(candidate.name + ".zip")
    if candidate.suffix != ".zip" and with_suffix.is_file():
        return with_suffix
    raise FileNotFoundError(f"SB3 model file not found: {candidate}")


def find_vecnormalize(model_path: Path) -> Path | None:
    """The VecNormalize statistics saved beside ``model_path``, if any."""
    for pattern in VECNORMALIZE_FILE_NAMES:
        candidate = model_path.parent / pattern.format(stem=model_path.stem)
        if candidate.is_file():
            return candidate
    return None


#: The modules of the actor-critic policies (SB3's and this package's own).
ACTOR_CRITIC_MODULES: tuple[str, ...] = (
    "stable_baselines3.common.policies",
    "bearing_env.agents.extractors",
    "bearing_env.agents.candidate_policy",
)


def infer_algorithm(model_path: Path) -> str:
    """The algorithm name (``"PPO"``, ``"SAC"``, ...) of a saved model, from its metadata."""
    try:
        with zipfile.ZipFile(model_path) as archive:
            data = json.loads(archive.read("data"))
    except (zipfile.BadZipFile, KeyError, json.JSONDecodeError, UnicodeDecodeError) as error:
        raise ModelLoadError(
            f"{model_path} is not a stable-baselines3 model archive ({error})"
        ) from error
    module = str(data.get("policy_class", {}).get("__module__", ""))
    if module in _ALGORITHM_BY_POLICY_MODULE:
        return _ALGORITHM_BY_POLICY_MODULE[module]
    if module.startswith("sb3_contrib.common.recurrent"):
        return "RecurrentPPO"
    if module in ACTOR_CRITIC_MODULES:
        # Actor-critic: PPO and A2C share the policy; PPO alone saves n_epochs.
        return "PPO" if "n_epochs" in data else "A2C"
    raise ModelLoadError(
        f"cannot tell the algorithm of {model_path} (policy module {module!r}); "
        "pass algo='PPO' (or SAC, DQN, ...) explicitly"
    )


def _algorithm_class(name: str) -> tuple[str, Any]:
    """The canonical name (``"PPO"``) and the class of an algorithm, by any-case name."""
    key = {k.lower(): k for k in _ALGORITHM_MODULES}.get(name.lower())
    if key is None:
        raise ValueError(
            f"unknown algorithm {name!r}; expected one of {sorted(_ALGORITHM_MODULES)}"
        )
    module_name = _ALGORITHM_MODULES[key]
    extra = "train" if module_name == "stable_baselines3" else None  # sb3_contrib: no extra
    module = require(module_name, f"a {key} model", extra=extra)
    return key, getattr(module, key)


def load_model(
    path: str | Path,
    algo: str | None = None,
    env: Any = None,
    device: str = "cpu",
    **kwargs: Any,
) -> Any:
    """Load a saved SB3 model (``<Algorithm>.load``; ``kwargs`` go to it).

    Args:
        path: as :func:`resolve_model_path` takes it (``.zip`` optional, or a directory).
        algo: ``"PPO"``, ``"ppo"``, ``"SAC"``, ...; default inferred from the archive.
        env: the (vector) env to attach, as SB3's ``load`` takes it.

    Raises:
        FileNotFoundError: nothing to load at ``path``.
        ModelLoadError (a ValueError): the file is not a loadable ``algo`` model (corrupt,
            truncated, another algorithm, or spaces that do not fit ``env``); the message
            names the path.
    """
    model_path = resolve_model_path(path)
    if not zipfile.is_zipfile(model_path):
        raise ModelLoadError(f"{model_path} is not a stable-baselines3 model archive (no zip)")
    name, algorithm_class = _algorithm_class(
        algo if algo is not None else infer_algorithm(model_path)
    )
    try:
        return algorithm_class.load(str(model_path), env=env, device=device, **kwargs)
    except Exception as error:  # SB3 raises many kinds on damaged or foreign archives
        raise ModelLoadError(
            f"could not load {name} model {model_path}: {type(error).__name__}: {error}"
        ) from error


def load_vecnormalize(path: str | Path, venv: Any = None) -> Any:
    """Saved ``VecNormalize`` statistics, as ``VecNormalize.load(path, venv)`` gives them.

    With ``venv`` the statistics wrap it and keep their saved ``training`` flags (to go on
    training); without, they are frozen (``training=False``, ``norm_reward=False``) for
    :meth:`~VecNormalize.normalize_obs` alone.

    Raises:
        FileNotFoundError: no file at ``path``.
        ModelLoadError (a ValueError): the file is not VecNormalize statistics (truncated,
            foreign pickle); the message names the path.
    """
    stats_path = Path(path).expanduser()
    if not stats_path.is_file():
        raise FileNotFoundError(f"VecNormalize statistics not found: {stats_path}")
    vec_env = require("stable_baselines3.common.vec_env", "VecNormalize statistics", "train")
    try:
        with open(stats_path, "rb") as handle:
            normalizer = pickle.load(handle)
    except Exception as error:  # a truncated or foreign pickle raises many kinds
        raise ModelLoadError(
            f"could not load VecNormalize statistics {stats_path}: {type(error).__name__}: {error}"
        ) from error
    if not isinstance(normalizer, vec_env.VecNormalize):
        raise ModelLoadError(
            f"{stats_path} holds a {type(normalizer).__name__}, not VecNormalize statistics"
        )
    if venv is None:
        normalizer.training = False
        normalizer.norm_reward = False
    else:
        normalizer.set_venv(venv)
    return normalizer


def _spaces_match(model_space: spaces.Space[Any], env_space: spaces.Space[Any]) -> bool:
    if isinstance(env_space, spaces.Discrete):
        return isinstance(model_space, spaces.Discrete) and model_space.n == env_space.n
    if isinstance(env_space, spaces.Box):
        return isinstance(model_space, spaces.Box) and model_space.shape == env_space.shape
    if isinstance(env_space, spaces.Dict):
        return (
            isinstance(model_space, spaces.Dict)
            and model_space.keys() == env_space.keys()
            and all(_spaces_match(model_space[key], env_space[key]) for key in env_space)
        )
    return type(model_space) is type(env_space)


def _longer_table(model_space: spaces.Space[Any], env_space: spaces.Space[Any]) -> bool:
    """Whether ``env_space`` is the entity observation ``model_space`` with more landmark
    rows (the same robot block, a ``"landmarks"`` table of more rows of the same width)."""
    if not (isinstance(model_space, spaces.Dict) and isinstance(env_space, spaces.Dict)):
        return False
    if model_space.keys() != env_space.keys() or set(env_space.keys()) != {"robot", "landmarks"}:
        return False
    width = len(ENTITY_FEATURES)
    model_table, env_table = model_space["landmarks"], env_space["landmarks"]
    return (
        _spaces_match(model_space["robot"], env_space["robot"])
        and isinstance(model_table, spaces.Box)
        and isinstance(env_table, spaces.Box)
        and len(model_table.shape) == len(env_table.shape) == 1
        and env_table.shape[0] % width == 0
        and env_table.shape[0] > model_table.shape[0]
    )


def space_summary(space: spaces.Space[Any]) -> str:
    """A space in a few words, without its bounds: ``Box(61,)``, ``Discrete(24)``,
    ``Dict(landmarks: Box(16, 8), robot: Box(9,))``."""
    if isinstance(space, spaces.Box):
        return f"Box{space.shape}"
    if isinstance(space, spaces.Discrete):
        return f"Discrete({space.n})"
    if isinstance(space, spaces.Dict):
        parts = ", ".join(f"{key}: {space_summary(value)}" for key, value in space.items())
        return f"Dict({parts})"
    return type(space).__name__


def _greedy_actor(model: Any) -> Any:
    """``model.predict(obs, deterministic=True)`` for one Box observation, as a function,
    when the model is a plain actor-critic (PPO's, A2C's ``MlpPolicy``) with a categorical
    or unsquashed Gaussian head; None otherwise. It runs SB3's very operations (features,
    actor network, action head; the categorical mode as the argmax of the normalised
    probabilities; the Gaussian mode clipped to the space) without ``predict``'s batching,
    checks and distribution objects, which cost about half a move's decision time."""
    import torch
    from stable_baselines3.common.distributions import (
        CategoricalDistribution,
        DiagGaussianDistribution,
    )
    from stable_baselines3.common.policies import ActorCriticPolicy, BaseModel

    policy = model.policy
    head = getattr(policy, "action_dist", None)
    if type(policy) is not ActorCriticPolicy or policy.squash_output:
        return None
    if not isinstance(policy.observation_space, spaces.Box):
        return None
    categorical = type(head) is CategoricalDistribution
    if not categorical and type(head) is not DiagGaussianDistribution:
        return None
    policy.set_training_mode(False)
    space = model.action_space

    def greedy(obs: NDArray[np.float32]) -> Action:
        with torch.no_grad():
            tensor = torch.as_tensor(obs[None], device=policy.device)
            # (BaseModel's, as get_distribution calls it: the actor's features alone)
            features = BaseModel.extract_features(policy, tensor, policy.pi_features_extractor)
            output = policy.action_net(policy.mlp_extractor.forward_actor(features))
            if categorical:  # torch's Categorical: probs = softmax(logits - logsumexp)
                logits = output - output.logsumexp(dim=-1, keepdim=True)
                return int(torch.softmax(logits, dim=-1).argmax(dim=1)[0])
        mean = output.cpu().numpy().reshape(space.shape)
        return np.clip(mean, space.low, space.high).astype(np.float32).reshape(-1)

    return greedy


class SB3Policy:
    """A saved stable-baselines3 model, acting greedily (``deterministic=True``) by default.

    Args:
        env: the env it acts in: the model's task (see :mod:`bearing_env.agents.model_task`)
            when the model has a record, and in any case spaces that match the model's.
            None: no check; make one with :meth:`make_env`.
        path: the model ``.zip`` (the suffix may be left out), or a directory holding
            ``best_model.zip`` / ``model.zip`` / a single ``.zip``.
        vecnormalize: the ``VecNormalize`` statistics: ``"auto"`` (default) uses
            ``<stem>_vecnormalize.pkl``, ``<stem>.vecnormalize.pkl`` or ``vecnormalize.pkl``
            beside the model if present; a path uses that file (it must exist); None
            uses none.
        algo: the algorithm (``"PPO"``, ``"SAC"``, ``"DQN"``, ...); default inferred from
            the saved policy class.
        deterministic: act with the mode of the policy rather than sampling.
        device: torch device.
        name: label in reports; default ``sb3_<algo>_<model stem>``.
        task: what the model was trained on: ``"auto"`` (default) reads the record
            ``<stem>.json`` beside the model (``bearing-env train --export`` writes it),
            if there is one; None: unknown (only the spaces are checked).

    Raises:
        FileNotFoundError: the model, or an explicitly given VecNormalize file, is missing.
        TaskMismatchError (a ValueError): ``env`` is another task than the recorded one;
            the one-line message names the settings that differ.
        ModelLoadError (a ValueError): a file is corrupt, or its spaces do not fit the env.
    """

    privileged = False

    def __init__(
        self,
        env: gym.Env | None,
        path: str | Path,
        vecnormalize: str | Path | None = "auto",
        algo: str | None = None,
        deterministic: bool = True,
        device: str = "cpu",
        name: str | None = None,
        task: ModelTask | str | None = "auto",
    ) -> None:
        self.model_path = resolve_model_path(path)
        if isinstance(task, str) and task != "auto":
            raise ValueError(f"task must be 'auto', a ModelTask or None, got {task!r}")
        self.task = task_record_of(self.model_path) if isinstance(task, str) else task
        self.algo, _ = _algorithm_class(
            algo if algo is not None else infer_algorithm(self.model_path)
        )
        self.model = load_model(self.model_path, self.algo, device=device)
        if env is not None:
            self.check_env(env)
        self.vecnormalize_path = self._resolve_vecnormalize(vecnormalize)
        self.obs_normalizer = (
            None if self.vecnormalize_path is None else load_vecnormalize(self.vecnormalize_path)
        )
        self.deterministic = bool(deterministic)
        self.discrete = isinstance(self.model.action_space, spaces.Discrete)
        self.name = name or f"sb3_{self.algo.lower()}_{self.model_path.stem}"
        self._greedy = _greedy_actor(self.model) if self.deterministic else None

    def check_env(self, env: gym.Env) -> None:
        """Refuse an env the model cannot act in: another task than its recorded one
        (:class:`TaskMismatchError`), or spaces that differ from its own
        (:class:`ModelLoadError`)."""
        if self.task is not None:
            self.task.check(env)
        if (
            self.task is not None
            and self.task.slot_free
            and _longer_table(self.model.observation_space, env.observation_space)
        ):
            # A set policy's features do not depend on the table's length: it reads
            # the env's longer table as it is (the task check allowed the extra slots).
            self.model.observation_space = env.observation_space
            self.model.policy.observation_space = env.observation_space
        if not _spaces_match(self.model.observation_space, env.observation_space):
            raise ModelLoadError(
                f"model {self.model_path.name} expects observations "
                f"{space_summary(self.model.observation_space)}, but the env gives "
                f"{space_summary(env.observation_space)} (other observation or max_landmarks?)"
            )
        if not _spaces_match(self.model.action_space, env.action_space):
            raise ModelLoadError(
                f"model {self.model_path.name} outputs actions "
                f"{space_summary(self.model.action_space)}, but the env takes "
                f"{space_summary(env.action_space)} (continuous vs discrete id?)"
            )

    def make_env(self, **overrides: Any) -> gym.Env:
        """The env the model was trained on (its recorded env id and env kwargs), with
        ``overrides`` on top (``render_mode="human"``, ``n_landmarks=12``, ...).

        Raises:
            ValueError: the model has no record of its task.
            TaskMismatchError (a ValueError): an override changes the task.
        """
        if self.task is None:
            raise ValueError(
                f"model {self.model_path} has no record of its task "
                f"({self.model_path.with_suffix('.json').name}); make its env with gym.make"
            )
        env = self.task.make_env(**overrides)
        self.check_env(env)  # a set policy takes on the env's longer landmark table
        return env

    @classmethod
    def pretrained(cls, name: str, env: gym.Env | None = None, **options: Any) -> SB3Policy:
        """A model shipped with the package under ``agents/pretrained/``, by name.

        See :func:`pretrained_names` for what is available; ``options`` go to the
        constructor (e.g. ``deterministic=False``). Without ``env``, make the model's
        own with :meth:`make_env`::

            policy = SB3Policy.pretrained("ppo_generalist")
            env = policy.make_env()

        Raises:
            ValueError: no shipped model has this name (the message lists them).
            TaskMismatchError (a ValueError): ``env`` is another task than the model's.
        """
        options.setdefault("task", pretrained_task(name))
        options.setdefault("name", name)
        return cls(env, PRETRAINED_DIR / f"{name}.zip", **options)

    def _resolve_vecnormalize(self, vecnormalize: str | Path | None) -> Path | None:
        if vecnormalize is None:
            return None
        if isinstance(vecnormalize, str) and vecnormalize == "auto":
            return find_vecnormalize(self.model_path)
        return Path(vecnormalize).expanduser()  # load_vecnormalize: it must exist

    def reset(self, seed: int | None = None) -> None:
        if seed is not None:
            # Only matters with deterministic=False: sampling goes through torch.
            import torch

            torch.manual_seed(int(seed))

    def act(
        self, observation: NDArray[np.float32] | Mapping[str, Any], info: dict[str, Any]
    ) -> Action:
        obs: Any
        if isinstance(observation, Mapping):  # the entity observation
            obs = {key: np.asarray(value, dtype=np.float32) for key, value in observation.items()}
        else:
            obs = np.asarray(observation, dtype=np.float32)
        if self.obs_normalizer is not None:
            obs = self.obs_normalizer.normalize_obs(obs)
        if self._greedy is not None and isinstance(obs, np.ndarray):
            return self._greedy(obs)
        action, _ = self.model.predict(obs, deterministic=self.deterministic)
        if self.discrete:
            return int(np.asarray(action).reshape(-1)[0])
        return np.asarray(action, dtype=np.float32).reshape(-1)

    def __repr__(self) -> str:
        return f"SB3Policy(name={self.name!r}, path={str(self.model_path)!r})"
