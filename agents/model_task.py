"""The task a saved model was trained on, and the check that an env is that task.

A model exported by ``bearing-env train --export`` (the shipped ones under
``agents/pretrained/`` included) has a JSON record beside it, ``<stem>.json``, that
names the env id and env kwargs it was trained with. :class:`ModelTask` reads them, so
the model can make its own env (:meth:`ModelTask.make_env`) and refuse an env that is
another task (:meth:`ModelTask.check`, a :class:`TaskMismatchError` naming the settings
that differ).

Which settings make the task (:data:`TASK_SETTINGS`): those that change the observation
or action spaces, or what the observation and an action mean:

- the action kind (the continuous or the discrete env id), and the discrete grid
  (``n_turns``, ``n_move_lengths``, :data:`~bearing_env.envs.config.GRID_SETTINGS`);
- ``observation`` and ``max_landmarks`` (the observation space), ``area_cap`` (the
  log-areas' cap and the space's bounds);
- ``scenario`` and ``arena`` (the world: Khepera's fixed layout or random layouts, and
  their scale), ``move_length`` (what an action does).

Not part of the task, so a model runs with them changed: the landmark count and layout
(``n_landmarks``, ``landmarks``: running a model on counts it never saw, up to its
``max_landmarks``, is what ``python -m bearing_env.train.studies.generalisation`` does;
a model of a set policy, :data:`SLOT_FREE_POLICIES`, also runs with more
``max_landmarks`` slots than it was trained with, so on any count),
``max_moves`` (the episode length: ``bearing-env compare --quick`` plays 10 moves; the
observation's ``progress`` feature then runs twice as fast as in 20-move training), the
sensor and map settings (``epsilon_deg``, ``noise``, ``transfer``, ``fusion``,
``max_outliers``, ``on_inconsistency``: robustness is measured by changing them) and the
reward's (``reward``, ``target_area``, ``path_cost``, ``move_cost``), which change what
is scored, not what the policy sees or does.
"""

from __future__ import annotations

import inspect
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym

from bearing_env.envs.bearing_slam_discrete import BearingSLAMDiscreteEnv
from bearing_env.envs.config import GRID_SETTINGS, EnvConfig
from bearing_env.world import Arena

from .env_access import bearing_env_of

#: The env settings that make a model's task (see the module doc for why these).
TASK_SETTINGS: tuple[str, ...] = (
    "observation",
    "planner_features",
    "max_landmarks",
    "area_cap",
    "scenario",
    "arena",
    "move_length",
    *GRID_SETTINGS,
)

#: The policies whose features do not depend on how many landmark slots the entity
#: observation has (the set extractors of :mod:`bearing_env.agents.extractors`, whose
#: invariance to padding is tested there): their models run with more ``max_landmarks``
#: slots than they were trained with. Named by the dotted path their records give.
SLOT_FREE_POLICIES: tuple[str, ...] = (
    "bearing_env.agents.extractors.LandmarkSetPolicy",
    "bearing_env.agents.extractors.LandmarkAttentionPolicy",
)

#: The pseudo-setting naming the action kind in a mismatch: "continuous" or "discrete".
ACTION_KIND = "action"


class TaskMismatchError(ValueError):
    """An env is not the task a model was trained on; the message (one line) names the
    differing settings and the model's own task."""


def _shown(value: Any) -> str:
    if isinstance(value, Arena):
        return f"({value.width:g}, {value.height:g})"
    return repr(value)


def _action_kind(discrete: bool) -> str:
    return "discrete" if discrete else "continuous"


def task_settings(config: EnvConfig, discrete: bool) -> dict[str, Any]:
    """The task-making settings of an env config (:data:`TASK_SETTINGS`, the discrete
    grid only for a discrete env) and its action kind."""
    names = [name for name in TASK_SETTINGS if discrete or name not in GRID_SETTINGS]
    return {ACTION_KIND: _action_kind(discrete), **{name: getattr(config, name) for name in names}}


def setting_differences(
    expected: Mapping[str, Any], actual: Mapping[str, Any], actual_label: str
) -> list[str]:
    """``"name <expected> (<actual_label>: <actual>)"`` for each setting that differs,
    in the order of ``expected``."""
    return [
        f"{name} {_shown(value)} ({actual_label}: {_shown(actual.get(name))})"
        for name, value in expected.items()
        if actual.get(name) != value
    ]


@dataclass(frozen=True)
class ModelTask:
    """What a model was trained on: an env id and env kwargs (as its record gives them)."""

    env_id: str
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    #: The model's name in messages, e.g. ``ppo_generalist``.
    model: str = "model"
    #: Where the task was read (named in messages), e.g. ``ppo_generalist.json``.
    source: str = ""
    #: The model's policy is one of :data:`SLOT_FREE_POLICIES`: an env with more
    #: ``max_landmarks`` slots than the recorded ones is still its task.
    slot_free: bool = False

    @classmethod
    def from_record(cls, record: Mapping[str, Any], model: str, source: str) -> ModelTask:
        """The task of a training record (``env_id``, ``env_kwargs``).

        Raises:
            ValueError: the record names no env id, or its env kwargs are not a mapping.
        """
        env_id, env_kwargs = record.get("env_id"), record.get("env_kwargs", {})
        if not isinstance(env_id, str) or not env_id:
            raise ValueError(f"{source} names no env_id, so the model's task is unknown")
        if not isinstance(env_kwargs, Mapping):
            raise ValueError(f"{source}: env_kwargs must be a mapping, got {env_kwargs!r}")
        hyperparams = record.get("hyperparams", {})
        policy = hyperparams.get("policy") if isinstance(hyperparams, Mapping) else None
        return cls(
            env_id=env_id,
            env_kwargs=dict(env_kwargs),
            model=model,
            source=source,
            slot_free=policy in SLOT_FREE_POLICIES,
        )

    @property
    def discrete(self) -> bool:
        """Whether the env id's env takes discrete actions."""
        import bearing_env  # noqa: F401  (registers the ids)

        entry_point = gym.spec(self.env_id).entry_point
        # Typed as object: a registered entry point may be any callable, not only a class.
        creator: object = (
            gym.envs.registration.load_env_creator(entry_point)
            if isinstance(entry_point, str)
            else entry_point
        )
        return inspect.isclass(creator) and issubclass(creator, BearingSLAMDiscreteEnv)

    @property
    def config(self) -> EnvConfig:
        """The settings of the env the model was trained on (the id's registered kwargs,
        then the record's)."""
        import bearing_env  # noqa: F401  (registers the ids)

        kwargs = {**gym.spec(self.env_id).kwargs, **self.env_kwargs}
        kwargs.pop("render_mode", None)
        return EnvConfig.create(**kwargs)

    def settings(self) -> dict[str, Any]:
        """The task-making settings (:func:`task_settings`) of the model's env."""
        return task_settings(self.config, self.discrete)

    def describe(self) -> str:
        """``<env id> with k=v, ...``: the env the model was trained on, as recorded."""
        kwargs = ", ".join(f"{key}={value!r}" for key, value in sorted(self.env_kwargs.items()))
        return f"{self.env_id} with {kwargs}" if kwargs else self.env_id

    def differences(self, env: gym.Env) -> list[str]:
        """The task settings in which ``env`` differs from the model's (see
        :func:`setting_differences`); none for an env that is not a BearingSLAM env."""
        try:
            base = bearing_env_of(env)
        except TypeError:
            return []  # a foreign env: only its spaces can be checked
        actual = task_settings(base.config, isinstance(base, BearingSLAMDiscreteEnv))
        expected = self.settings()
        if self.slot_free and actual["max_landmarks"] >= expected["max_landmarks"]:
            expected["max_landmarks"] = actual["max_landmarks"]  # more slots: still its task
        return setting_differences(expected, actual, "env")

    def mismatch_message(self, differences: list[str], where: str = "this env") -> str:
        """One line: what differs, and the model's own task."""
        return (
            f"model {self.model!r} was trained on another task than {where}: "
            f"{', '.join(differences)}; its task ({self.source}): {self.describe()}"
        )

    def check(self, env: gym.Env) -> None:
        """Raise :class:`TaskMismatchError` if ``env`` is another task than the model's."""
        differences = self.differences(env)
        if differences:
            raise TaskMismatchError(self.mismatch_message(differences))

    def make_env(self, **overrides: Any) -> gym.Env:
        """``gym.make`` of the model's env id with its env kwargs, ``overrides`` on top
        (``render_mode="human"``, ``n_landmarks=12``, ...).

        Raises:
            TaskMismatchError: an override changes the task (:data:`TASK_SETTINGS`).
        """
        import bearing_env  # noqa: F401  (registers the ids)

        env = gym.make(self.env_id, **{**self.env_kwargs, **overrides})
        differences = self.differences(env)
        if differences:
            env.close()
            raise TaskMismatchError(
                self.mismatch_message(differences, "the env these overrides make")
            )
        return env


def task_record_of(model_path: Path) -> ModelTask | None:
    """The task recorded beside a model, ``<stem>.json`` (``bearing-env train
    --export``'s layout), or None when there is no such record naming an env id."""
    record_path = model_path.with_suffix(".json")
    if not record_path.is_file():
        return None
    try:
        record = json.loads(record_path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(record, dict) or "env_id" not in record:
        return None
    return ModelTask.from_record(record, model_path.stem, record_path.name)
