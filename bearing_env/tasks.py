"""The named, versioned tasks: settings people compare on, each registered as its own id.

This table is the one home of the tasks and of their versions: :mod:`bearing_env.registration`
registers them, ``bearing-env suite`` (:mod:`bearing_env.train.compare.suite`) runs the
baselines on the current ones and writes their cards in ``docs/tasks/``.

The ids follow :data:`NAMING_RULE`. Every id exists in every version of :data:`VERSIONS`
(``BearingSLAM-Khepera-v0``, ``BearingSLAM-Khepera-v1``, and the base ids
``BearingSLAM-v0``, ``BearingSLAM-v1``, ...): the current version is on the env's defaults,
an older one registers the defaults it was measured with on top, so that its published
figures still reproduce bit for bit.

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
  `observation="shapes"`), or `Planner` (the flat vector followed by the planner
  features of 16 candidate moves, `planner_features=True`, on the discrete id with
  `n_turns=8, n_move_lengths=2`); such an id is what an rl-zoo3 hyperparameter file is
  keyed by, so that its training and evaluation envs have the same observation space;
- `version` starts at 0 and goes up whenever a change alters what an agent faces (the
  task's settings, an env default it relies on, the dynamics or the reward), so scores
  reported under one id stay comparable; every id stays registered in every version, an
  older one with the env defaults it was measured with (each card's version history says
  what changed).
"""

#: Every version of the ids, oldest first, and the settings it registers on top of its
#: ids' own: an older version keeps the env defaults that changed after it (the last, the
#: current version, adds nothing). A new version adds its entry here (and the settings
#: that change to every older entry) and its line to :data:`HISTORY`.
VERSIONS: dict[int, Mapping[str, Any]] = {
    0: MappingProxyType({"transfer": "conservative_global"}),
    1: MappingProxyType({}),
}
#: The current version: the tasks, the cards and the shipped hyperparameters use it.
VERSION: int = max(VERSIONS)
#: What each version changed, one line each, oldest first (the cards' "Version history").
HISTORY: tuple[str, ...] = (
    "v0: the first version (bearing_env 0.1.0).",
    "v1: the conservative transfer grows regions by a local bound instead of one global "
    "radius per movement (bearing_env 0.2.0): every transferred region is smaller or "
    "equal, so areas and rewards change; `-v0` keeps the old bound "
    '(`transfer="conservative_global"`).',
)

#: The base ids' names, by action kind (the id adds ``-v<version>``).
BASE_NAMES: dict[str, str] = {"continuous": "BearingSLAM", "discrete": "BearingSLAMDiscrete"}


def versioned_id(name: str, version: int = VERSION) -> str:
    """``<name>-v<version>``, by default the current version's id."""
    return f"{name}-v{version}"


def split_id(task_id: str) -> tuple[str, int]:
    """An id's name and version: ``"BearingSLAM-Khepera-v1"`` -> ``("BearingSLAM-Khepera",
    1)`` (a ``module:`` prefix is dropped); ValueError without a ``-v<N>`` suffix."""
    name, _, version = task_id.rpartition(":")[2].rpartition("-v")
    if not name or not version.isdigit():
        raise ValueError(f"{task_id!r} is not a versioned id (NAME-vN)")
    return name, int(version)


#: The current base ids a task builds on, by action kind.
BASE_IDS: dict[str, str] = {kind: versioned_id(name) for kind, name in BASE_NAMES.items()}
#: Every registered base id, all versions, and its action kind.
BASE_ID_KINDS: dict[str, str] = {
    versioned_id(name, version): kind for version in VERSIONS for kind, name in BASE_NAMES.items()
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
        base_id: the base id of the same version whose env (and vector env) it makes:
            ``BearingSLAM-v1`` or ``BearingSLAMDiscrete-v1`` (``-v0`` for a ``-v0`` task).
        settings: the ``gym.make`` keyword arguments that define it (read-only), those of
            its version (:data:`VERSIONS`) included.
        description: one line for tables.
        purpose: what the task is for, and its place against the paper (Markdown, a
            few sentences; the card's "Description").
        challenge: what makes the task hard, and whether it can be solved at all
            (Markdown; the card's "Description").
    """

    id: str
    base_id: str
    # Hashed by the rest (a mapping has no hash); compared all the same.
    settings: Mapping[str, Any] = field(hash=False)
    description: str = ""
    purpose: str = ""
    challenge: str = ""
    #: What each version changed, one line each, oldest first (the cards' "Version
    #: history").
    history: tuple[str, ...] = HISTORY

    def __post_init__(self) -> None:
        bases = [base for base in BASE_ID_KINDS if split_id(base)[1] == split_id(self.id)[1]]
        if self.base_id not in bases:
            raise ValueError(
                f"task {self.id!r}: base_id must be one of {bases}, got {self.base_id!r}"
            )
        # Held read-only, so the table cannot be changed through a task.
        object.__setattr__(self, "settings", MappingProxyType(copy.deepcopy(dict(self.settings))))

    @property
    def action_kind(self) -> str:
        """``"continuous"`` or ``"discrete"``."""
        return BASE_ID_KINDS[self.base_id]

    @property
    def name(self) -> str:
        """The id without its version: ``BearingSLAM-Khepera``."""
        return split_id(self.id)[0]

    @property
    def version(self) -> int:
        """The id's version."""
        return split_id(self.id)[1]

    def at_version(self, version: int) -> Task:
        """This task as ``version`` registers it: the same name with that version, on
        that version's base id, the version's settings (:data:`VERSIONS`) under the
        task's own, and the history up to it."""
        if version == self.version:
            return self
        return Task(
            id=versioned_id(self.name, version),
            base_id=versioned_id(BASE_NAMES[self.action_kind], version),
            settings={**self.settings, **_missing(VERSIONS[version], self.settings)},
            description=self.description,
            purpose=self.purpose,
            challenge=self.challenge,
            history=tuple(line for line in self.history if _line_version(line) <= version),
        )

    def kwargs(self) -> dict[str, Any]:
        """The settings as a new ``dict`` (nested values copied), for ``gym.make``."""
        return copy.deepcopy(dict(self.settings))

    def settings_text(self) -> str:
        """The settings as ``key=value`` pairs (values as JSON), for tables."""
        return ", ".join(f"{key}={json.dumps(value)}" for key, value in self.settings.items())


def _missing(added: Mapping[str, Any], settings: Mapping[str, Any]) -> dict[str, Any]:
    """The settings of ``added`` that ``settings`` does not set itself."""
    return {key: value for key, value in added.items() if key not in settings}


def _line_version(line: str) -> int:
    """The version a history line is about: ``"v1: ..."`` -> 1."""
    return int(line.partition(":")[0].removeprefix("v"))


#: The paper every task builds on, as the cards cite it.
PAPER = (
    "H. Huang, F. Maire and N. Keeratipranon, *Uncertainty Analysis of a Landmark "
    "Initialization Method for Simultaneous Localization and Mapping*, Australasian "
    "Conference on Robotics and Automation (ACRA), Sydney, 2005"
)

_KHEPERA_PURPOSE = (
    "The arena of the paper's real-robot experiment (Huang, Maire & Keeratipranon, "
    "ACRA 2005): a Khepera robot with a panoramic camera on a 1.05 x 0.68 m field with "
    "four landmarks, L1 and L2 20 cm apart. The paper moved its robot along random "
    "polygonal trajectories and showed that the uncertainty regions of L3 and L4 shrink "
    "as it moves; this task asks which moves shrink them fastest, the paper's own "
    "setting turned into an exploration problem."
)
_KHEPERA_CHALLENGE = (
    "A region shrinks only where the bearing cones of a movement cross at a wide angle, "
    "so a good move depends on where the robot believes it is and where the regions are "
    "long; with moves of 5 to 30 cm and a bearing error of ±2°, short or radial moves "
    "map little. Success asks both regions to fall below 0.05 FL units² within 20 moves, "
    "which the planners reach only in some episodes. The robot never sees ground truth: "
    "it plans on its own map."
)


def _khepera(kind: str) -> Task:
    actions = "continuous turn and move length" if kind == "continuous" else "a grid of moves"
    grid = (
        ""
        if kind == "continuous"
        else " The discrete id offers a grid of turns and lengths instead, for agents "
        "(DQN and the like) that need a finite action set."
    )
    return Task(
        id=versioned_id(f"{BASE_NAMES[kind]}-Khepera"),
        base_id=BASE_IDS[kind],
        settings={"scenario": "khepera"},
        description=f"the paper's Khepera arena (4 fixed landmarks), {actions}",
        purpose=_KHEPERA_PURPOSE + grid,
        challenge=_KHEPERA_CHALLENGE,
    )


def _random(n_landmarks: int) -> Task:
    return Task(
        id=versioned_id(f"BearingSLAM-Random{n_landmarks}"),
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "random", "n_landmarks": n_landmarks},
        description=f"a new random layout of {n_landmarks} landmarks every episode, Khepera field",
        purpose="The paper's sensor and world model on layouts it did not study: a new "
        f"layout of {n_landmarks} landmarks every episode on the Khepera field, so that a "
        "policy must generalise over layouts instead of learning one arena's moves.",
        challenge=f"Every episode places L1, L2 and the {n_landmarks - 2} landmarks to map "
        "anew, so no fixed sequence of moves works; "
        + (
            "with two landmarks to map the task is close to the Khepera one."
            if n_landmarks <= 4
            else f"with {n_landmarks - 2} landmarks to map within 20 moves, one move "
            "cannot serve them all, and the policy must choose which regions to shrink "
            "first (the observation has a slot per landmark, up to `max_landmarks`)."
        ),
    )


#: The environment page's section on what a limited sensor can map at all (from a card).
_OBSERVABILITY = (
    "[what a forward camera can map at all](../environment.md#what-a-forward-camera-can-map-at-all)"
)

#: What makes each camera task hard (the cards' "Description").
_CAMERA_CHALLENGE: dict[int, str] = {
    90: "**This task cannot be solved in practice: every baseline ends at the cap.** A "
    "movement maps a landmark only when the camera sees L1, L2 and that landmark at both "
    "ends, with enough parallax. A forward camera turns with the move, so every landmark "
    "it sees, L1 and L2 (20 cm apart) included, lies within 45° of the line of motion, "
    "where a move gives the least parallax: the few movements that update L3 or L4 at "
    "all give regions far wider than `area_cap`. From an empty map no "
    "single movement in this arena maps both within the cap, and the omniscient two-move "
    "planner of `bearing-env observability` (measured on the `-v0` id) ended every "
    "episode with both at the cap "
    f"({_OBSERVABILITY}). "
    "The task is kept as a reference for a sensor that cannot map this layout: an agent "
    "that scores below the cap here has found something the baselines have not.",
    180: "A movement maps a landmark only when the camera sees L1, L2 and that landmark "
    "at both ends, with enough parallax; with half the view, few movements do "
    f"({_OBSERVABILITY}). "
    "Before it has a map the robot must look around and keep L1 and L2 in view; the "
    "planners do better than random here but stay far from the panoramic camera's areas.",
}


def _camera(degrees: int) -> Task:
    return Task(
        id=versioned_id(f"BearingSLAM-Khepera-Camera{degrees}"),
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "khepera", "field_of_view_deg": degrees},
        description=f"Khepera arena, a forward camera of {degrees} deg: landmarks outside it "
        "are missed (`bearing-env observability` shows what it can map at all)",
        purpose="The paper's robot has a panoramic camera; most robots have a forward "
        f"one. This task keeps the Khepera arena and gives the robot a camera of {degrees}° "
        "about its heading (the move's direction), so a reading misses every landmark "
        "outside it, and the world model learns nothing from a movement that misses L1 or L2.",
        challenge=_CAMERA_CHALLENGE[degrees],
    )


def _random_table(observation: str) -> Task:
    return Task(
        id=versioned_id(f"BearingSLAM-Random3to16-{observation.capitalize()}"),
        base_id=BASE_IDS["continuous"],
        settings={
            "scenario": "random",
            "n_landmarks": [3, 16],
            "max_landmarks": 16,
            "observation": observation,
        },
        description=f"a new random layout of 3 to 16 landmarks every episode, the "
        f'`"{observation}"` observation (a landmark table, for set and attention policies)',
        purpose="The training task of the shipped generalist models: a policy for any "
        "landmark count from 3 to 16, on a landmark table that set and attention "
        "policies read.",
        challenge="The landmark count changes every episode, so a policy must work on a "
        "table of variable length.",
    )


#: The planner-features tasks' grid: GreedyOneStep's 8 turns x the shortest and longest
#: lengths, K = 16 candidates.
PLANNER_GRID: dict[str, Any] = {"n_turns": 8, "n_move_lengths": 2, "planner_features": True}
_PLANNER_PURPOSE = (
    " Here the actions are a grid of 16 candidate moves (8 turns, the shortest and the "
    "longest length) and the observation ends with what a one-step planner predicts of "
    "each, from the robot's own map and believed pose: the predicted decrease of the "
    "potential, whether L1 and L2 stay in view, whether the move is predicted blocked "
    "([the planner features](../environment.md#planner-features)). A policy chooses "
    "among the candidates with what GreedyOneStep knows, and more: the map, and what it "
    "learned over episodes."
)


def _planner(setting: str, settings: Mapping[str, Any], like: Task, description: str) -> Task:
    return Task(
        id=versioned_id(f"BearingSLAMDiscrete-{setting}-Planner"),
        base_id=BASE_IDS["discrete"],
        settings={**settings, **PLANNER_GRID},
        description=f"{description}; 16 candidate moves with the planner's predictions",
        purpose=like.purpose + _PLANNER_PURPOSE,
        challenge=like.challenge
        + " The predictions come from the robot's map and believed pose, so they are "
        "wrong where those are: a policy that follows them blindly does as well as "
        "GreedyOneStep, no better.",
    )


#: The planner-features tasks (the learned exploration's), carded with the rest.
PLANNER_TASKS: tuple[Task, ...] = (
    _planner(
        "Khepera", {"scenario": "khepera"}, _khepera("continuous"), "the paper's Khepera arena"
    ),
    _planner(
        "Random3to16",
        {"scenario": "random", "n_landmarks": [3, 16], "max_landmarks": 16},
        _random_table("entities"),
        "a new random layout of 3 to 16 landmarks every episode, Khepera field",
    ),
)
#: Every task, in the order of the tables.
TASKS: tuple[Task, ...] = (
    _khepera("continuous"),
    _khepera("discrete"),
    _random(4),
    _random(8),
    _random(16),
    Task(
        id=versioned_id("BearingSLAM-Khepera-Outliers"),
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "khepera", "noise": OUTLIER_NOISE, "fusion": "relaxed"},
        description="Khepera arena, 5% of bearings replaced by random angles, relaxed fusion",
        purpose="The paper assumes every bearing is within ±ε of the truth. Here 5% of "
        "the bearings are outliers, replaced by a uniformly random angle, as a "
        "misdetection would give, and the map uses the relaxed fusion, which may leave "
        "out up to `max_outliers` contradicting regions per landmark over its last 8 "
        "movements ([the world model](../world_model.md#robust-fusion-fusionrelaxed)).",
        challenge="An outlier gives a region that may not hold the landmark, and the "
        "strict intersection would then lose the truth or come out empty; the relaxed "
        "fusion holds the truth in most regions but not in all, so the regions are "
        "larger than on the clean task and `landmark_contains_truth` can be false.",
    ),
    Task(
        id=versioned_id("BearingSLAM-Khepera-Missed"),
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "khepera", "noise": MISSED_NOISE, "fusion": "relaxed"},
        description="Khepera arena, each landmark missed in 20% of readings, relaxed fusion",
        purpose="The paper's camera sees every landmark in every reading. Here each "
        "landmark is missed in 20% of the readings (its bearing is NaN for the world "
        "model), as a detector that fails now and then would, with the relaxed fusion.",
        challenge="A movement maps a landmark only when both readings see it, and maps "
        "nothing when either misses L1 or L2, so about half the movements are lost "
        "or partial; the policy cannot know in advance which ones.",
    ),
    _camera(90),
    _camera(180),
    Task(
        id=versioned_id("BearingSLAM-FurnishedRoom"),
        base_id=BASE_IDS["continuous"],
        settings={"scenario": "furnished_room"},
        description="a furnished room of 2 x 1.5 m (5 landmarks): furniture blocks moves "
        "and hides landmarks",
        purpose="The paper's arena is empty. This one is a room of 2 x 1.5 m with five "
        "landmarks and four pieces of furniture (a table, a sofa, a shelf and an "
        "armchair, the `obstacles` setting) that stop moves and block the line of sight, "
        "as a real room would; the camera is the paper's panoramic one.",
        challenge="A landmark behind furniture is missed, a move into it stops short, and "
        "the robot is not told where the furniture is: it learns that from where its "
        "moves were blocked. From many starts no single movement maps any landmark within "
        "`area_cap` "
        f"({_OBSERVABILITY}), "
        "so a policy must first move to where L1, L2 and the other landmarks are in sight; "
        "the map-based planners plan on a map they do not have yet, while a trained "
        "policy can learn where to go (the baselines below).",
    ),
    *PLANNER_TASKS,
)


#: The tasks by id.
TASKS_BY_ID: dict[str, Task] = {task.id: task for task in TASKS}


#: The training tasks: registered like :data:`TASKS`, the ids the shipped rl-zoo3 files
#: are keyed by when their observation is not the flat vector (rl-zoo3 builds its
#: evaluation env from the id alone); the suite does not card them.
TRAINING_TASKS: tuple[Task, ...] = (_random_table("entities"), _random_table("shapes"))

#: The older versions of every task and training task (:data:`VERSIONS`): registered, so
#: that their figures reproduce, and not carded.
OLDER_TASKS: tuple[Task, ...] = tuple(
    task.at_version(version)
    for version in VERSIONS
    if version != VERSION
    for task in (*TASKS, *TRAINING_TASKS)
)

#: Every registered task by id: :data:`TASKS`, :data:`TRAINING_TASKS` and
#: :data:`OLDER_TASKS`.
REGISTERED_TASKS_BY_ID: dict[str, Task] = {
    task.id: task for task in (*TASKS, *TRAINING_TASKS, *OLDER_TASKS)
}


def task_named(task_id: str) -> Task:
    """The current task of an id (``"NAME-vN"`` or ``"bearing_env:NAME-vN"``); ValueError
    naming the id and listing the tasks otherwise (and the current id of an older one)."""
    name = task_id.rpartition(":")[2]
    if name not in TASKS_BY_ID:
        older = REGISTERED_TASKS_BY_ID.get(name)
        newer = (
            f" ({name} is an older version of {versioned_id(older.name)})"
            if older is not None and older.version != VERSION
            else ""
        )
        raise ValueError(f"unknown task {task_id!r}{newer}; the tasks are {', '.join(TASKS_BY_ID)}")
    return TASKS_BY_ID[name]


def current_id(env_id: str) -> str:
    """The current version's id of a registered bearing_env id (``BearingSLAM-v0`` ->
    ``BearingSLAM-v1``, ``bearing_env:BearingSLAM-FurnishedRoom-v0`` ->
    ``bearing_env:BearingSLAM-FurnishedRoom-v1``); any other id as it is. A model trained
    on an older version is evaluated on its task's current version."""
    prefix, colon, name = env_id.rpartition(":")
    if name not in REGISTERED_TASKS_BY_ID and name not in BASE_ID_KINDS:
        return env_id
    return f"{prefix}{colon}{versioned_id(split_id(name)[0])}"
