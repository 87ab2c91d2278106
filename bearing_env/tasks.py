"""The named, versioned tasks: settings people compare on, each registered as its own id.

This table is the one home of the tasks: :mod:`bearing_env.registration` registers them,
``bearing-env suite`` (:mod:`bearing_env.train.compare.suite`) runs the baselines on them
and writes their cards in ``docs/tasks/``.

The ids follow :data:`NAMING_RULE`.

A task's settings are ``gym.make`` keyword arguments on top of the env's defaults;
``gym.make(task_id, **more)`` overrides them as for any id. Importing this module is
cheap (no native core, no env modules).
"""

from __future__ import annotations

import copy
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

#: How the task ids are formed (Markdown; the task index quotes it).
NAMING_RULE = """\
`<kind>-<setting>[-<sensor>][-<fault>][-<observation>]-v<version>`:

- `kind` is the base id's name: `BearingSLAM` (continuous actions) or
  `BearingSLAMDiscrete` (the discrete action grid);
- `setting` names the layout: `Khepera` (the paper's real arena, fixed landmarks),
  `Random<N>` (a new random layout of N landmarks every episode, on the Khepera field;
  `Random<A>to<B>`: a count drawn from A to B every episode, `max_landmarks` = B)
  or `FurnishedRoom` (a room whose furniture blocks motion and sight, fixed landmarks);
- `sensor` names a camera narrower than the paper's panoramic one: `Camera<D>` (a
  forward field of view of D degrees about the move's direction);
- `fault` names a sensor that breaks the paper's assumptions, mapped with the relaxed
  fusion (`fusion="relaxed"`, which tolerates `max_outliers` contradicting readings):
  `Outliers` (some bearings replaced by random angles) or `Missed` (some landmarks not
  detected in a reading);
- `observation` names an observation other than the flat vector: `Entities` (the landmark
  table, `observation="entities"`) or `Shapes` (the table with each region's shape,
  `observation="shapes"`); such an id is what an rl-zoo3 hyperparameter file is keyed by,
  so that its training and evaluation envs have the same observation space;
- `version` starts at 0 and goes up whenever a change alters what an agent faces (the
  task's settings, an env default it relies on, the dynamics or the reward), so scores
  reported under one id stay comparable.
"""

#: The base ids a task builds on, by action kind.
BASE_IDS: dict[str, str] = {
    "continuous": "BearingSLAM-v0",
    "discrete": "BearingSLAMDiscrete-v0",
}

#: The sensor of the ``Outliers`` tasks: 5% of bearings replaced by a random angle (the
#: rate the README's robustness comparison uses).
OUTLIER_NOISE: dict[str, Any] = {"kind": "uniform", "outlier_rate": 0.05}
#: The sensor of the ``Missed`` tasks: each landmark seen in 80% of readings.
MISSED_NOISE: dict[str, Any] = {"kind": "uniform", "detection_rate": 0.8}


@dataclass(frozen=True)
class Task:
    """One registered task.

    Attributes:
        id: the registered id (see the module doc for the naming rule).
        base_id: the base id whose env (and vector env) it makes: ``BearingSLAM-v0`` or
            ``BearingSLAMDiscrete-v0``.
        settings: the ``gym.make`` keyword arguments that define it (read-only).
        description: one line for tables.
    """

    id: str
    base_id: str
    # Hashed by the rest (a mapping has no hash); compared all the same.
    settings: Mapping[str, Any] = field(hash=False)
    description: str = ""
    #: What each version changed, one line each, oldest first (the cards' "Version
    #: history").
    history: tuple[str, ...] = ("v0: the first version (bearing_env 0.1.0).",)

    def __post_init__(self) -> None:
        if self.base_id not in BASE_IDS.values():
            raise ValueError(
                f"task {self.id!r}: base_id must be one of {sorted(BASE_IDS.values())}, "
                f"got {self.base_id!r}"
            )
        # Held read-only, so the table cannot be changed through a task.
        object.__setattr__(self, "settings", MappingProxyType(copy.deepcopy(dict(self.settings))))

    @property
    def action_kind(self) -> str:
        """``"continuous"`` or ``"discrete"``."""
        return next(kind for kind, base in BASE_IDS.items() if base == self.base_id)

    def kwargs(self) -> dict[str, Any]:
        """The settings as a new ``dict`` (nested values copied), for ``gym.make``."""
        return copy.deepcopy(dict(self.settings))

    def settings_text(self) -> str:
        """The settings as ``key=value`` pairs (values as JSON), for tables."""
        return ", ".join(f"{key}={json.dumps(value)}" for key, value in self.settings.items())


def _khepera(kind: str) -> Task:
    name = "BearingSLAM" if kind == "continuous" else "BearingSLAMDiscrete"
    actions = "continuous turn and move length" if kind == "continuous" else "a grid of moves"
    return Task(
        id=f"{name}-Khepera-v0",
        base_id=BASE_IDS[kind],
        settings={"scenario": "khepera"},
        description=f"the paper's Khepera arena (4 fixed landmarks), {actions}",
    )


def _random(n_landmarks: int) -> Task:
    return Task(
        id=f"BearingSLAM-Random{n_landmarks}-v0",
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "random", "n_landmarks": n_landmarks},
        description=f"a new random layout of {n_landmarks} landmarks every episode, Khepera field",
    )


def _camera(degrees: int) -> Task:
    return Task(
        id=f"BearingSLAM-Khepera-Camera{degrees}-v0",
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "khepera", "field_of_view_deg": degrees},
        description=f"Khepera arena, a forward camera of {degrees} deg: landmarks outside it "
        "are missed (`bearing-env observability` shows what it can map at all)",
    )


#: Every task, in the order of the tables.
TASKS: tuple[Task, ...] = (
    _khepera("continuous"),
    _khepera("discrete"),
    _random(4),
    _random(8),
    _random(16),
    Task(
        id="BearingSLAM-Khepera-Outliers-v0",
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "khepera", "noise": OUTLIER_NOISE, "fusion": "relaxed"},
        description="Khepera arena, 5% of bearings replaced by random angles, relaxed fusion",
    ),
    Task(
        id="BearingSLAM-Khepera-Missed-v0",
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "khepera", "noise": MISSED_NOISE, "fusion": "relaxed"},
        description="Khepera arena, each landmark missed in 20% of readings, relaxed fusion",
    ),
    _camera(90),
    _camera(180),
    Task(
        id="BearingSLAM-FurnishedRoom-v0",
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "furnished_room"},
        description="a furnished room of 2 x 1.5 m (5 landmarks): furniture blocks moves "
        "and hides landmarks",
    ),
)

#: The tasks by id.
TASKS_BY_ID: dict[str, Task] = {task.id: task for task in TASKS}


def _random_table(observation: str) -> Task:
    return Task(
        id=f"BearingSLAM-Random3to16-{observation.capitalize()}-v0",
        base_id=BASE_IDS["continuous"],
        settings={
            "scenario": "random",
            "n_landmarks": [3, 16],
            "max_landmarks": 16,
            "observation": observation,
        },
        description=f"a new random layout of 3 to 16 landmarks every episode, the "
        f'`"{observation}"` observation (a landmark table, for set and attention policies)',
    )


#: The training tasks: registered like :data:`TASKS`, the ids the shipped rl-zoo3 files
#: are keyed by when their observation is not the flat vector (rl-zoo3 builds its
#: evaluation env from the id alone); the suite does not card them.
TRAINING_TASKS: tuple[Task, ...] = (_random_table("entities"), _random_table("shapes"))

#: Every registered task by id: :data:`TASKS` and :data:`TRAINING_TASKS`.
REGISTERED_TASKS_BY_ID: dict[str, Task] = {
    task.id: task for task in (*TASKS, *TRAINING_TASKS)
}


def task_named(task_id: str) -> Task:
    """The task of an id (``"NAME-vN"`` or ``"bearing_env:NAME-vN"``); ValueError naming
    the id and listing the tasks otherwise."""
    name = task_id.rpartition(":")[2]
    if name not in TASKS_BY_ID:
        raise ValueError(f"unknown task {task_id!r}; the tasks are {', '.join(TASKS_BY_ID)}")
    return TASKS_BY_ID[name]
