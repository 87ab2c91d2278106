"""The task cards ``bearing-env suite`` writes: ``<task id>.md`` per task (what the agent
sees, does and is rewarded for, the settings, the baseline tables with bootstrap CIs, a
rendered frame and the area plot as PNGs beside it) and ``index.md``, the task table.

Plain MyST-compatible Markdown with relative links. A card quotes only reproducible
numbers (no timings), so regenerating it with the same command gives the same text.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from bearing_env.envs.candidates import CANDIDATE_FEATURES, candidate_count
from bearing_env.tasks import Task
from bearing_env.train.common.errors import available
from bearing_env.train.common.files import atomic_path, atomic_write_text
from bearing_env.train.common.provenance import measured_record, measured_sentence
from bearing_env.train.compare.comparison import CompareResult
from bearing_env.train.compare.config import CompareConfig
from bearing_env.train.compare.report import (
    area_mean_rows,
    area_median_rows,
    markdown_table,
    outcome_table_rows,
)
from bearing_env.train.compare.runner import make_env

INDEX_NAME = "index.md"
#: The folder (under the cards' folder) of the results the cards are written from: one
#: ``<task id>.json`` per card, the comparison's summary and the command that ran it.
RESULTS_DIR = "results"
#: The environment page, relative to the cards.
ENV_PAGE = "../environment.md"
#: The world model page, relative to the cards.
WORLD_MODEL_PAGE = "../world_model.md"
#: The heading of the index's overview table (:func:`overview_markdown`).
OVERVIEW_HEADING = "## Baselines at a glance"
#: Moves of the greedy policy before the card's frame is rendered.
FRAME_MOVES = 5


def card_name(task: Task) -> str:
    return f"{task.id}.md"


def area_plot_name(task: Task) -> str:
    return f"{task.id}_area.png"


def frame_name(task: Task) -> str:
    return f"{task.id}_frame.png"


# ----------------------------------------------------------------------------------------
# What the agent faces, from the resolved settings
# ----------------------------------------------------------------------------------------


def _number(value: float) -> str:
    return f"{value:g}"


def _field_of_view(degrees: float) -> str:
    if degrees >= 360:
        return "360°: the paper's panoramic camera"
    return (
        f"{_number(degrees)}° about the heading (the move's direction): a landmark outside "
        "it is missed"
    )


def _obstacles(obstacles: Sequence[Sequence[Sequence[float]]]) -> str:
    """The obstacles in a few words: none, or each polygon (a box by its extent)."""
    if not obstacles:
        return "none"
    shapes = []
    for polygon in obstacles:
        xs = sorted({float(x) for x, _ in polygon})
        ys = sorted({float(y) for _, y in polygon})
        if len(polygon) == 4 and len(xs) == 2 and len(ys) == 2:
            shapes.append(
                f"x {_number(xs[0])} to {_number(xs[1])}, y {_number(ys[0])} to {_number(ys[1])}"
            )
        else:
            shapes.append(f"a polygon of {len(polygon)} vertices")
    return f"{len(obstacles)} polygons that block moves and sight, in metres: " + "; ".join(shapes)


def settings_rows(config: Any, task: Task) -> list[list[str]]:
    """Every setting of the task, resolved (``EnvConfig``), as table rows: those that
    define the task (its registered settings) first, then the rest at their values."""
    noise = config.noise
    if noise.kind == "uniform":
        bound = "ε" if noise.bound_deg is None else f"{_number(noise.bound_deg)}°"
        sensor = f"uniform within ±{bound}"
    elif noise.kind == "gaussian":
        sigma = "ε/2" if noise.sigma_deg is None else f"{_number(noise.sigma_deg)}°"
        sensor = f"Gaussian, sigma = {sigma}"
    else:
        sensor = "none"
    lo, hi = config.landmark_counts
    if config.landmarks is not None:
        positions = ", ".join(f"({_number(x)}, {_number(y)})" for x, y in config.landmarks)
        layout = f"{lo} fixed landmarks at {positions} m (L1, L2, ...)"
    else:
        count = f"{lo}" if lo == hi else f"{lo} to {hi}"
        layout = f"a new random layout of {count} landmarks every episode"
    rows = [
        ["layout (`scenario`, `n_landmarks`)", f"`{config.scenario}`: {layout}"],
        ["arena (`arena`)", f"{_number(config.arena.width)} x {_number(config.arena.height)} m"],
        ["bearing error bound ε (`epsilon_deg`)", f"{_number(config.epsilon_deg)}°"],
        ["true sensor noise (`noise`)", sensor],
        ["field of view (`field_of_view_deg`)", _field_of_view(config.field_of_view_deg)],
        [
            "range (`max_range`)",
            "unlimited" if np.isinf(config.max_range) else f"{_number(config.max_range)} m",
        ],
        ["obstacles (`obstacles`)", _obstacles(config.obstacles)],
        ["outliers (`noise.outlier_rate`)", f"{100 * noise.outlier_rate:g}% of bearings"],
        ["detection (`noise.detection_rate`)", f"{100 * noise.detection_rate:g}% of readings"],
        ["`fusion`", f"`{config.fusion}`"],
    ]
    if config.fusion == "relaxed":
        rows.append(["`max_outliers`", str(config.max_outliers)])
    if config.fusion == "robust":
        rows += [
            ["`risk`", _number(config.risk)],
            ["`robust_set`", f"`{config.robust_set}`"],
            ["`noise_bound`", f"`{config.noise_bound}`"],
        ]
    rows += [
        ["`transfer`", f"`{config.transfer}`"],
        ["`on_inconsistency`", f"`{config.on_inconsistency}`"],
        [
            "`move_length`",
            f"{_number(config.move_length[0])} to {_number(config.move_length[1])} m",
        ],
        ["`max_moves`", str(config.max_moves)],
        ["reward (`reward`)", f"`{config.reward}`"],
        [
            "costs (`path_cost`, `move_cost`)",
            f"{_number(config.path_cost)} per metre, {_number(config.move_cost)} per move",
        ],
        ["`target_area`", f"{_number(config.target_area)} FL units²"],
        ["`area_cap`", f"{_number(config.area_cap)} FL units²"],
        ["`observation`, `max_landmarks`", f"`{config.observation}`, {config.max_landmarks} slots"],
        [
            "`planner_features`",
            "on: the observation ends with 5 predictions per candidate move"
            if config.planner_features
            else "off",
        ],
        [
            "info (`robot_map_info`, `sensor_info`)",
            f"`robot_map` {'on' if config.robot_map_info else 'off'}, "
            f"`seen` and `blocked` {'on' if config.sensor_info else 'off'}",
        ],
    ]
    if task.action_kind == "discrete":
        rows.append(
            [
                "action grid (`n_turns`, `n_move_lengths`)",
                f"{config.n_turns} turns x {config.n_move_lengths} lengths",
            ]
        )
    return [[_registered(label, task), value] for label, value in rows]


def _registered(label: str, task: Task) -> str:
    """A settings row's label, in bold with "(registered)" when it holds one of the
    settings the task's id registers."""
    if any(re.search(f"`{re.escape(key)}[`.]", label) for key in task.settings):
        return f"**{label}** (registered)"
    return label


def space_text(space: Any) -> str:
    """A space in a few words: ``Box(-1.0, 1.0, (2,), float32)`` for a Box with one
    bound for every column, ``Box((63,), float32)`` otherwise (:func:`bounds_text` gives
    those bounds), ``Discrete(24)``, ``Dict(...)``."""
    from gymnasium import spaces

    if isinstance(space, spaces.Box):
        low, high = np.unique(space.low), np.unique(space.high)
        if low.size == 1 and high.size == 1:
            return f"Box({float(low[0])}, {float(high[0])}, {space.shape}, {space.dtype})"
        return f"Box({space.shape}, {space.dtype})"
    if isinstance(space, spaces.Dict):
        items = ", ".join(f"{key}: {space_text(sub)}" for key, sub in space.spaces.items())
        return f"Dict({items})"
    return str(space)


def _bound(value: float) -> str:
    """A Box bound as the card shows it: 4 significant digits (a bound is the float32
    just outside the value it stands for), 0 for a subnormal."""
    return "0" if abs(value) < 1e-30 else f"{float(value):.4g}"


def column_names(config: Any, key: str | None = None) -> list[str]:
    """The name of each column of the flat observation (``key`` None) or of a Dict
    observation's ``"robot"`` or ``"landmarks"`` Box, as the env lays them out."""
    from bearing_env.envs.observations import (
        BEARING_FEATURES,
        ENTITY_FEATURES,
        LANDMARK_FEATURES,
        ROBOT_FEATURES,
        SHAPE_ENTITY_FEATURES,
    )

    m = config.max_landmarks
    candidates = list(CANDIDATE_FEATURES) * candidate_count(config)
    if key == "robot":
        return list(ROBOT_FEATURES)
    if key == "landmarks":
        columns = ENTITY_FEATURES if config.observation == "entities" else SHAPE_ENTITY_FEATURES
        return list(columns) * m
    if key == "candidates":
        return candidates
    return [
        *ROBOT_FEATURES,
        *(list(LANDMARK_FEATURES) * (m - 2)),
        *(list(BEARING_FEATURES) * m),
        *(candidates if config.planner_features else []),
    ]


def bounds_text(space: Any, config: Any) -> str:
    """A Box's bounds by column, grouped: ``[-50, 50]`` robot_x, robot_y, x, y; ...
    (a Dict's per key); empty for a Box with one bound for every column."""
    from gymnasium import spaces

    if isinstance(space, spaces.Dict):
        parts = [
            f"`{key}` {text}"
            for key, sub in space.spaces.items()
            if (text := _box_bounds(sub, column_names(config, key)))
        ]
        return "; ".join(parts)
    if isinstance(space, spaces.Box):
        return _box_bounds(space, column_names(config))
    return ""


def _box_bounds(space: Any, names: Sequence[str]) -> str:
    if np.unique(space.low).size == 1 and np.unique(space.high).size == 1:
        return ""
    if len(names) != space.low.size:
        names = [f"column {i}" for i in range(space.low.size)]
    groups: dict[tuple[str, str], list[str]] = {}
    for name, low, high in zip(names, space.low.ravel(), space.high.ravel(), strict=True):
        columns = groups.setdefault((_bound(low), _bound(high)), [])
        if name not in columns:
            columns.append(name)
    return "; ".join(
        f"[{low}, {high}]: {', '.join(columns)}" for (low, high), columns in groups.items()
    )


def observation_text(config: Any, space: Any) -> str:
    from bearing_env.envs.observations import (
        BEARING_FEATURES,
        ENTITY_FEATURES,
        LANDMARK_FEATURES,
        ROBOT_FEATURES,
        SHAPE_ENTITY_FEATURES,
    )

    m = config.max_landmarks
    robot = (
        f"the robot block ({len(ROBOT_FEATURES)} numbers: its position estimate, region "
        "log-area and heading in the landmark frame FL, where L1 = (0, 0) and L2 = (1, 0), "
        "the progress through the episode and flags of the last move)"
    )
    if config.observation in ("entities", "shapes"):
        columns = ENTITY_FEATURES if config.observation == "entities" else SHAPE_ENTITY_FEATURES
        layout = (
            f'a `Dict` of {robot} under `"robot"` and a landmark table under '
            f'`"landmarks"`, {m} rows of {len(columns)} columns '
            f"({', '.join(columns)}), flattened"
        )
    else:
        layout = (
            f"{robot}, then {m - 2} blocks of {len(LANDMARK_FEATURES)} for the mapped "
            f"landmarks L3 .. L{m} ({', '.join(LANDMARK_FEATURES)}), then {m} blocks of "
            f"{len(BEARING_FEATURES)} for the latest bearings of L1 .. L{m} "
            f"({', '.join(BEARING_FEATURES)})"
        )
    if config.planner_features:
        where = '`"candidates"`' if config.observation in ("entities", "shapes") else "the end"
        layout += (
            f"; at {where}, {candidate_count(config)} blocks of {len(CANDIDATE_FEATURES)}, "
            f"one per candidate move (action `k`): {', '.join(CANDIDATE_FEATURES)}, what a "
            "one-step planner predicts from the robot's map and believed pose "
            f"([the planner features]({ENV_PAGE}#planner-features))"
        )
    return (
        f"`{space_text(space)}`: {layout}. Only what the robot can know, never ground truth; slots "
        "beyond the episode's landmarks are zeros. Every column is in "
        f"[the environment's observation tables]({ENV_PAGE}#observation)."
    )


def action_text(config: Any, space: Any, task: Task) -> str:
    lo, hi = (_number(v) for v in config.move_length)
    if task.action_kind == "discrete":
        step = 360.0 / config.n_turns
        return (
            f"`{space_text(space)}`: action `a` turns on the spot by "
            f"`turns[a // {config.n_move_lengths}]` ({config.n_turns} relative headings, "
            f"every {_number(step)}°), then moves straight by "
            f"`lengths[a % {config.n_move_lengths}]` ({config.n_move_lengths} lengths "
            f"evenly spaced over {lo} to {hi} m), stopped at the wall."
        )
    return (
        f"`{space_text(space)}` in [-1, 1]: turn on the spot by `π · a[0]` radians, then "
        f"move straight by `{lo} + (a[1] + 1) / 2 · ({hi} - {lo})` metres, stopped at the "
        "wall. A reading is taken before and after the move, and the map updated."
    )


def reward_text(config: Any) -> str:
    cap = _number(config.area_cap)
    if config.reward == "log_area":
        text = (
            "The decrease of the potential Φ = Σ over landmarks L3, L4, ... of "
            f"log(min(area, {cap})), an uninitialised landmark counting at {cap} FL units²; "
            "an episode's return is Φ(start) - Φ(end)."
        )
    else:
        text = (
            "The decrease of the potential Φ = Σ over landmarks L3, L4, ... of "
            f"min(area, {cap}), an uninitialised landmark counting at {cap} FL units²."
        )
    costs = []
    if config.path_cost:
        costs.append(f"{_number(config.path_cost)} per metre travelled")
    if config.move_cost:
        costs.append(f"{_number(config.move_cost)} per move")
    if costs:
        text += " Less " + " and ".join(costs) + "."
    return text


def starting_state_text(config: Any, task: Task) -> str:
    """Where an episode starts (the environment page's "Starting state", for this task)."""
    if config.landmarks is not None:
        fixed = len(config.landmarks)
        layout = f"The {fixed} landmarks are the scenario's, the same every episode."
    else:
        lo, hi = config.landmark_counts
        drawn = f"{lo}" if lo == hi else f"a count drawn from {lo} to {hi}"
        layout = f"A new layout of {drawn} landmarks is drawn every episode from the reset's seed."
    obstacles = " outside the obstacles," if config.obstacles else ""
    return (
        f"{layout} The robot starts at a uniformly random position inside the wall "
        f"margin,{obstacles} away from the landmarks, with a uniformly random heading, "
        "takes one reading and has an empty map: no landmark is initialised, so each of "
        f"L3, L4, ... counts at `area_cap` = {_number(config.area_cap)} FL units². "
        "`reset(seed=s)` makes the same start for the same `s`; `reset` takes no options. "
        f"See [the environment's starting state]({ENV_PAGE}#starting-state)."
    )


def return_text(config: Any) -> str:
    """How an episode's return relates to the total area the tables report."""
    cap = _number(config.area_cap)
    if config.reward != "log_area":
        return (
            f"The return is Φ(start) - Φ(end) = (n - 2) · {cap} - Σ min(area, {cap}): "
            "the total area removed, capped areas counted."
        )
    lo, hi = config.landmark_counts
    mapped = f"{lo - 2}" if lo == hi else f"{lo - 2} to {hi - 2}"
    text = (
        f"The return (costs aside) is R = Φ(start) - Φ(end) = Σ log({cap} / min(area, {cap})) "
        f"over the {mapped} landmarks L3, L4, ...: the geometric mean of their final areas "
        f"is {cap} · exp(-R / (n - 2)) FL units², n the episode's landmark count."
    )
    if lo == hi:
        example = config.area_cap * np.exp(-10.0 / (lo - 2))
        text += (
            f" Here n = {lo}: a return of 10 means a geometric mean area of {example:.3g}, "
            "and the total area is at least n - 2 times it."
        )
    return text


def info_keys(env: Any, seed: int) -> list[str]:
    """The keys of the info a reset of ``env`` gives (a step gives the same), in the
    order the env writes them: what the card's Info section lists."""
    _, info = env.reset(seed=seed)
    return list(info)


def info_text(keys: Sequence[str]) -> str:
    return (
        ", ".join(f"`{key}`" for key in keys)
        + ": the same keys from `reset` and `step`. `robot_map` is the robot's own map and "
        "`outliers` its fusion's count of left-out regions; the others are ground truth, "
        "for evaluation. Their meanings are in "
        f"[the environment's info table]({ENV_PAGE}#info)."
    )


def summary_box(task: Task, config: Any, observation_space: Any, action_space: Any) -> str:
    """The card's top table, as Gymnasium's env pages have it, with the Box bounds."""
    observation = f"`{space_text(observation_space)}`"
    bounds = bounds_text(observation_space, config)
    if bounds:
        observation += f", bounds by column: {bounds}"
    rows = [
        ["Action space", f"`{space_text(action_space)}`"],
        ["Observation space", observation],
        ["Episode cap", f"`max_moves` = {config.max_moves} moves"],
        ["Success", f"every region of L3, L4, ... ≤ {_number(config.target_area)} FL units²"],
        ["Registered settings", f"`{task.settings_text()}` on `{task.base_id}`"],
        ["Import", f'`gym.make("bearing_env:{task.id}")`'],
    ]
    return markdown_table(rows[0], rows[1:])


def description_section(task: Task) -> list[str]:
    """The card's Description: the one-line summary, what the task is for and what makes
    it hard (from :mod:`bearing_env.tasks`, their one home), the paper, how to make it."""
    from bearing_env.tasks import PAPER

    return [
        "## Description",
        "",
        f"{task.description[0].upper()}{task.description[1:]}.",
        "",
        task.purpose,
        "",
        task.challenge,
        "",
        "The world model is the polygon SLAM of the paper below, with a conservative "
        f"transfer ([the world model]({WORLD_MODEL_PAGE}#two-transfers)); "
        "the agent chooses the moves and is rewarded for shrinking the regions.",
        "",
        f"Reference: {PAPER}.",
        "",
        "```python",
        "import gymnasium as gym",
        "",
        f'env = gym.make("bearing_env:{task.id}")',
        f'envs = gym.make_vec("bearing_env:{task.id}", num_envs=8)  # the batched vector env',
        "```",
        "",
    ]


def arguments_section(task: Task) -> list[str]:
    """The card's Arguments: what ``gym.make(ID, **kwargs)`` may override, and how."""
    from bearing_env.tasks import VERSIONS, versioned_id

    defining = ", ".join(f"`{key}`" for key in task.settings)
    older = [versioned_id(task.name, v) for v in VERSIONS if v != task.version]
    return [
        "## Arguments",
        "",
        f'`gym.make("bearing_env:{task.id}", **kwargs)` (and `gym.make_vec`) takes every '
        f"keyword of its base env `{task.base_id}` ([the environment's settings table]"
        f'({ENV_PAGE}#settings)) and `render_mode` (`"human"` or `"rgb_array"`). The id '
        f"registers {defining} (the Registered settings above) as its kwargs: a keyword "
        "given to `gym.make` replaces the registered one of that name, and every other "
        "setting keeps the value in the Settings table. For example:",
        "",
        "```python",
        f'env = gym.make("bearing_env:{task.id}", max_moves=40, render_mode="rgb_array")',
        "```",
        "",
        f"The scores below hold for the id as registered. Changing {defining} makes "
        "another task; changing any other setting (the episode cap, the noise, the "
        "transfer, ...) changes the scores too, so a result under overrides names them. "
        + (
            f"`{', '.join(older)}` "
            + ("is" if len(older) == 1 else "are")
            + " the same task in "
            + ("an older version" if len(older) == 1 else "older versions")
            + " (the Version history), registered so that scores published under "
            + ("it" if len(older) == 1 else "them")
            + " reproduce."
            if older
            else ""
        ),
        "",
    ]


def version_history(task: Task, config: CompareConfig | None = None) -> list[str]:
    """The task's versions, then a line for each shipped model on the card that was
    trained on another version of the task and not retrained on this one."""
    from bearing_env.tasks import split_id

    lines = [f"- {entry}" for entry in task.history]
    for label, record in shipped_records(config).items() if config else ():
        env_id = str(record.get("env_id", "")).rpartition(":")[2]
        with contextlib.suppress(ValueError):
            version = split_id(env_id)[1]
            if version != task.version:
                lines.append(
                    f"- `{label}` stays the model trained on `{env_id}`: it was not retrained "
                    f"on v{task.version}, and its rows above run it on `{task.id}`."
                )
    return lines


def shipped_records(config: CompareConfig) -> dict[str, dict[str, Any]]:
    """The records of the card's shipped models (its ``pretrained:NAME`` policies), by
    label."""
    from bearing_env.agents import pretrained_record
    from bearing_env.agents.registry import parse_policy_spec

    records = {}
    for label, spec in config.policies.items():
        parsed = parse_policy_spec(spec)
        if parsed.kind == "pretrained":
            records[label] = pretrained_record(str(parsed.options["name"]))
    return records


def seeds_path(docs: Path, model: str) -> Path:
    """``bearing-env evaluate``'s results over a shipped model's training seeds."""
    return docs.parent / "compare" / "results" / f"seeds_{model}.json"


def training_seeds_section(docs: Path, config: CompareConfig) -> list[str]:
    """For each shipped model with a seeds file (:func:`seeds_path`): the IQM over its
    training seeds beside the shipped seed's own figure and the baselines'."""
    from bearing_env.train.compare.evaluation_report import seeds_markdown

    lines: list[str] = []
    for label in shipped_records(config):
        path = seeds_path(docs, label)
        if not path.is_file():
            continue
        results = json.loads(path.read_text(encoding="utf-8"))
        runs = results["model"]["runs"]
        lines += [
            "## Training seeds",
            "",
            f"`{label}` is one of {len(runs)} training seeds of the same recipe: the one whose "
            "IQM is the closest to the IQM over the seeds. Over the seeds, on the same "
            f"{results['episodes']} evaluation episodes (`bearing-env evaluate`: IQM of the "
            "total area with stratified bootstrap 95% CIs over episodes and seeds, and the "
            "probability of a smaller area than each baseline on an episode; "
            "[evaluating a trained model](../evaluation.md)):",
            "",
            seeds_markdown(results),
            "",
            measured_sentence(results["measured"], f"docs/compare/results/{path.name}"),
            "",
        ]
    return lines


def termination_text(config: Any) -> str:
    return (
        "Terminated (success) when every landmark L3, L4, ... is initialised and its "
        f"region's area is at most `target_area` = {_number(config.target_area)} FL units². "
        f"Truncated after `max_moves` = {config.max_moves} moves, the one episode cap (the id "
        "registers no `TimeLimit`; `env.spec.max_episode_steps` reads `max_moves`)."
    )


# ----------------------------------------------------------------------------------------
# Pictures
# ----------------------------------------------------------------------------------------


def render_frame(config: CompareConfig, seed: int, path: Path) -> bool:
    """Render the first evaluation episode after :data:`FRAME_MOVES` moves of the greedy
    policy to ``path`` (PNG); False, writing nothing, without pygame or Pillow."""
    if not available("pygame", "PIL"):
        return False
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    from PIL import Image

    from bearing_env.agents.registry import make_policy

    env = make_env(config.env_id, {**config.env_kwargs, "render_mode": "rgb_array"})
    with contextlib.closing(env):
        policy = make_policy("greedy", env)
        observation, info = env.reset(seed=seed)
        policy.reset(seed=seed)
        for _ in range(FRAME_MOVES):
            observation, _, terminated, truncated, info = env.step(policy.act(observation, info))
            if terminated or truncated:
                break
        frame = env.render()
    if not isinstance(frame, np.ndarray):
        raise TypeError(f"expected an rgb_array frame from render(), got {type(frame).__name__}")
    with atomic_path(path, suffix=".png") as temporary:
        Image.fromarray(frame).save(temporary, format="PNG")
    return True


# ----------------------------------------------------------------------------------------
# The card and the index
# ----------------------------------------------------------------------------------------


def task_card(
    task: Task,
    config: CompareConfig,
    summary: Mapping[str, Any],
    measured: Mapping[str, Any] | None,
    frame: bool,
    plot: bool,
    docs: Path | None = None,
) -> str:
    """The Markdown of a task's card; ``measured`` is its results file's record of the
    run (:func:`~bearing_env.train.common.provenance.measured_record`), or None."""
    from bearing_env.envs.config import EnvConfig

    resolved = EnvConfig.create(**{**task.kwargs(), **config.env_kwargs})
    env = make_env(config.env_id, config.env_kwargs)
    with contextlib.closing(env):
        observation_space, action_space = env.observation_space, env.action_space
        keys = info_keys(env, config.seeds[0])
    seeds = config.seeds
    parts = [
        f"# {task.id}",
        "",
        summary_box(task, resolved, observation_space, action_space),
        "",
        *description_section(task),
        *task_sections(task, resolved, observation_space, action_space, keys),
        *arguments_section(task),
        *baselines_section(task, config, summary),
        *(training_seeds_section(docs, config) if docs is not None else []),
    ]
    if plot:
        parts += [f"![total area versus moves, {task.id}]({area_plot_name(task)})", ""]
    if frame:
        parts += [
            f"![a rendered frame of {task.id}]({frame_name(task)})",
            "",
            f"The first evaluation episode (seed {seeds[0]}) after {FRAME_MOVES} moves of "
            "`greedy`: the true landmarks (stars), their uncertainty regions and centroids, the "
            "latest bearing cones (±ε), the robot and its path.",
            "",
        ]
    if measured:
        parts += [
            measured_sentence(measured, f"docs/tasks/{RESULTS_DIR}/{task.id}.json")
            + " `bearing-env docs-tables` writes this card from that file.",
            "",
        ]
    parts += ["## Version history", "", *version_history(task, config), ""]
    return "\n".join(parts)


def task_sections(
    task: Task, resolved: Any, observation_space: Any, action_space: Any, keys: Sequence[str]
) -> list[str]:
    """The card's sections on what the agent faces: observation, action, reward,
    starting state, episode end, info (``keys``) and settings."""
    return [
        "## Observation",
        "",
        observation_text(resolved, observation_space),
        "",
        "## Action",
        "",
        action_text(resolved, action_space, task),
        "",
        "## Reward",
        "",
        reward_text(resolved),
        "",
        return_text(resolved),
        "",
        "## Starting state",
        "",
        starting_state_text(resolved, task),
        "",
        "## Episode end",
        "",
        termination_text(resolved),
        "",
        "## Info",
        "",
        info_text(keys),
        "",
        "## Settings",
        "",
        "Every setting of the task as its id makes it: in bold, the settings the id "
        "registers; the others at the env's defaults.",
        "",
        markdown_table(["setting", "value"], settings_rows(resolved, task)),
        "",
        f"Each setting is described in [the environment's settings table]({ENV_PAGE}#settings).",
        "",
    ]


def shipped_models_text(task: Task, config: CompareConfig) -> str:
    """`` Shipped models: `NAME` was trained on `ID` with `k=v, ...`.`` for the
    ``pretrained:NAME`` policies of a comparison (from their records), saying when that
    id is another version of the task's; empty without such a policy."""
    from bearing_env.tasks import split_id

    parts = []
    for label, record in shipped_records(config).items():
        env_id = str(record.get("env_id", "")).rpartition(":")[2]
        kwargs = ", ".join(
            f"{key}={json.dumps(value)}" for key, value in record.get("env_kwargs", {}).items()
        )
        text = f"`{label}` was trained on `{env_id}`" + (f" with `{kwargs}`" if kwargs else "")
        with contextlib.suppress(ValueError):
            version = split_id(env_id)[1]
            if version != task.version:
                text += (
                    f" (a `-v{version}` id, evaluated here on `-v{task.version}`: see the "
                    "version history)"
                )
        parts.append(text)
    return f" Shipped models: {'; '.join(parts)}." if parts else ""


def baselines_section(task: Task, config: CompareConfig, summary: Mapping[str, Any]) -> list[str]:
    """The card's lines on the baselines: how they ran, their area and outcome tables."""
    seeds = config.seeds
    policies = ", ".join(f"`{label}` = `{spec}`" for label, spec in config.policies.items())
    overrides = (
        f" with `{', '.join(f'{k}={v!r}' for k, v in config.env_kwargs.items())}`"
        if config.env_kwargs
        else ""
    )
    return [
        "## Baselines",
        "",
        f"{config.episodes} evaluation episodes per policy on `{task.id}`{overrides}, "
        f"the same for every policy: episode i resets the env with seed {seeds[0]} + i "
        f"(seeds {seeds[0]}..{seeds[-1]}), and each policy's own randomness is seeded from "
        "the episode's seed. Policies: "
        f"{policies}. Total area: the sum of the region areas of L3, L4, ... (FL units², "
        "|L1 - L2| = 1), each capped at `area_cap`, which also counts for a landmark not "
        "yet initialised; lower is better. Confidence intervals: 95% percentile bootstrap "
        f"of the mean ({config.bootstrap} resamples, seed {config.bootstrap_seed})."
        + shipped_models_text(task, config),
        "",
        "Mean total area [95% bootstrap CI] after n moves:",
        "",
        markdown_table(*area_mean_rows(summary, config)),
        "",
        "Median total area after n moves:",
        "",
        markdown_table(*area_median_rows(summary, config)),
        "",
        "Outcomes:",
        "",
        markdown_table(*outcome_table_rows(summary, config)),
        "",
    ]


def write_task_card(
    task: Task,
    config: CompareConfig,
    result: CompareResult,
    folder: Path,
    docs: Path,
    command: str | None,
) -> Path:
    """Write the card of a finished task, its frame and its area plot (from the
    comparison in ``folder``) into ``docs``; the card's path."""
    from bearing_env.train.compare.suite import copy_file

    plot_source = folder / "area_vs_moves.png"
    plot = plot_source.is_file()
    if plot:
        copy_file(plot_source, docs / area_plot_name(task))
    frame = render_frame(config, config.seeds[0], docs / frame_name(task))
    measured = measured_record(command) if command else None
    results = {"task": task.id, "measured": measured, "summary": result.summary}
    atomic_write_text(results_path(docs, task), json.dumps(results, indent=1) + "\n")
    path = docs / card_name(task)
    atomic_write_text(path, task_card(task, config, result.summary, measured, frame, plot, docs))
    return path


def results_path(docs: Path, task: Task) -> Path:
    return docs / RESULTS_DIR / f"{task.id}.json"


def read_results(docs: Path, task: Task) -> dict[str, Any] | None:
    """The results file a card is written from, or None."""
    path = results_path(docs, task)
    if not path.is_file():
        return None
    data: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    return data


def config_of(summary: Mapping[str, Any]) -> CompareConfig:
    """The comparison a summary ran (its ``config``)."""
    saved = {k: v for k, v in summary["config"].items() if k != "format_version"}
    return CompareConfig(**saved)


def published_cards(docs: Path) -> dict[Path, str]:
    """Every card (and the index) as its results files in ``docs`` write it: the text
    ``bearing-env docs-tables`` writes and its check compares."""
    from bearing_env.tasks import TASKS

    cards: dict[Path, str] = {}
    for task in TASKS:
        data = read_results(docs, task)
        if data is None:
            continue
        summary = data["summary"]
        frame = (docs / frame_name(task)).is_file()
        plot = (docs / area_plot_name(task)).is_file()
        text = task_card(task, config_of(summary), summary, data.get("measured"), frame, plot, docs)
        cards[docs / card_name(task)] = text
    if cards:
        cards[docs / INDEX_NAME] = index_page(TASKS, docs)
    return cards


def markdown_medians(data: Mapping[str, Any]) -> str:
    """The README's table: each policy's median total area after 10 and 20 moves, from
    a card's results file (the cards are the canonical evaluation)."""
    summary = data["summary"]
    config = config_of(summary)
    header, rows = area_median_rows(summary, config)
    wanted = [i for i, name in enumerate(header) if name in ("policy", "after 10", "after 20")]
    rates = {stats.get("containment_rate") for stats in summary["policies"].values()} - {None}
    containment = (
        f"\n\nContainment (the final region holds the true landmark): "
        f"{100 * rates.pop():.1f}% for every policy."
        if len(rates) == 1
        else ""
    )
    return (
        f"Median total area of L3 and L4 (FL units², 20 = nothing mapped), {config.episodes} "
        f"evaluation episodes per policy, from [the `{data['task']}` card]"
        f"(docs/tasks/{data['task']}.md):\n\n"
        + markdown_table([header[i] for i in wanted], [[row[i] for i in wanted] for row in rows])
        + containment
    )


def final_area_cell(stats: Mapping[str, Any], move: str) -> str:
    entry = stats["area_after"].get(move)
    if entry is None or entry["mean"] is None:
        return "-"
    return f"{entry['mean']:.3g} [{entry['ci_low']:.3g}, {entry['ci_high']:.3g}]"


def overview_cells(
    results: Sequence[tuple[Task, Mapping[str, Any]]],
) -> dict[str, dict[str, str]]:
    """Per task id, its overview row as cells by column (``moves``, ``episodes`` and one
    per policy label): each policy's mean total area [95% CI] after the last reported
    move count."""
    cells: dict[str, dict[str, str]] = {}
    for task, summary in results:
        policies = summary["policies"]
        moves = sorted({int(k) for p in policies.values() for k in p["area_after"]})
        last = str(moves[-1]) if moves else ""
        episodes = sorted({int(p["episodes"]) for p in policies.values()})
        row = {"moves": last, "episodes": "/".join(str(n) for n in episodes)}
        for label, stats in policies.items():
            row[label] = final_area_cell(stats, last)
        cells[task.id] = row
    return cells


def overview_markdown(cells: Mapping[str, Mapping[str, str]]) -> str:
    """The overview table of ``cells`` (:func:`overview_cells`), in their order, with its
    title: one column per policy any task ran (``-`` where a task's did not)."""
    labels: list[str] = []
    for row in cells.values():
        labels += [c for c in row if c not in ("moves", "episodes") and c not in labels]
    header = ["task", "moves", "episodes", *labels]
    rows = [[task, *(row.get(column, "-") for column in header[1:])] for task, row in cells.items()]
    return (
        "Mean total area [95% bootstrap CI] after the last move (FL units², lower is "
        "better):\n\n" + markdown_table(header, rows)
    )


def overview_table(results: Sequence[tuple[Task, Mapping[str, Any]]]) -> str:
    """The overview of finished comparisons as a Markdown table with its title."""
    return overview_markdown(overview_cells(results))


def published_overview(index: Path) -> dict[str, dict[str, str]]:
    """The rows of an existing ``index.md``'s overview table (:func:`overview_markdown`),
    as cells by column per task id; empty when there is no such file or table."""
    if not index.is_file():
        return {}
    lines = index.read_text(encoding="utf-8").splitlines()
    try:
        start = lines.index(OVERVIEW_HEADING)
    except ValueError:
        return {}
    header: list[str] | None = None
    cells: dict[str, dict[str, str]] = {}
    for line in lines[start + 1 :]:
        if line.startswith("#"):
            break
        if not line.startswith("|"):
            if header is not None:
                break
            continue
        row = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if header is None:
            header = row
        elif not all(set(cell) <= {"-"} for cell in row):
            cells[row[0]] = dict(zip(header[1:], row[1:], strict=False))
    return cells


def finished_summary(folder: Path) -> dict[str, Any] | None:
    """The summary of a task folder whose comparison is complete (every policy has every
    episode of its config), or None."""
    from bearing_env.train.compare.suite import read_summary

    summary = read_summary(folder)
    if summary is None:
        return None
    episodes = int(summary["config"]["episodes"])
    wanted = set(summary["config"]["policies"])
    policies = summary["policies"]
    if set(policies) != wanted or any(int(p["episodes"]) != episodes for p in policies.values()):
        return None
    return summary


def index_page(tasks: Sequence[Task], docs: Path) -> str:
    """The Markdown of ``index.md``: the task table (linking the cards that exist in
    ``docs``), the training ids, and the baselines at a glance: from the cards' results
    files, and for a card without one, its row of the index already in ``docs``."""
    from bearing_env.tasks import NAMING_RULE, TRAINING_TASKS

    rows = []
    for task in tasks:
        card = docs / card_name(task)
        link = f"[card]({card_name(task)})" if card.is_file() else "no card yet"
        rows.append(
            [f"`{task.id}`", task.action_kind, task.description, f"`{task.settings_text()}`", link]
        )
    carded = [task for task in tasks if (docs / card_name(task)).is_file()]
    fresh = overview_cells(
        [(t, data["summary"]) for t in carded if (data := read_results(docs, t)) is not None]
    )
    published = published_overview(docs / INDEX_NAME)
    overview = {
        t.id: fresh[t.id] if t.id in fresh else published[t.id]
        for t in carded
        if t.id in fresh or t.id in published
    }
    parts = [
        "# Tasks",
        "",
        "Named, versioned tasks to compare on. Each id is registered with Gymnasium "
        '(`gym.make("bearing_env:ID")`, `gym.make_vec("bearing_env:ID", num_envs=N)`) '
        "as its base id with the settings below; `gym.make(ID, **more)` overrides them. "
        "Each card gives the observation, action, reward, episode end, every setting, "
        "and the baselines' scores with 95% bootstrap confidence intervals "
        "(`bearing-env suite`).",
        "",
        markdown_table(["id", "actions", "description", "settings", "card"], rows),
        "",
        "Naming rule: " + NAMING_RULE,
        "Training ids: registered the same way, without a card; the shipped rl-zoo3 files "
        "whose observation is a landmark table are keyed by them.",
        "",
        markdown_table(
            ["id", "description", "settings"],
            [[f"`{t.id}`", t.description, f"`{t.settings_text()}`"] for t in TRAINING_TASKS],
        ),
        "",
    ]
    parts += registered_ids_section()
    if overview:
        parts += [OVERVIEW_HEADING, "", overview_markdown(overview), ""]
    # The docs site lists the cards under this page (a hidden toctree: the table links them).
    cards = [
        card_name(task).removesuffix(".md") for task in tasks if (docs / card_name(task)).is_file()
    ]
    if cards:
        parts += ["```{toctree}", ":hidden:", "", *cards, "```", ""]
    return "\n".join(parts)


#: The heading of the index's list of every registered id (:func:`registered_ids_section`).
REGISTERED_IDS_HEADING = "## Every registered id"


def registered_ids() -> list[tuple[str, str, str]]:
    """Every id ``import bearing_env`` registers, as (id, what it is, its kwargs), from
    :mod:`bearing_env.tasks`: the base ids, the tasks and the training tasks, each in
    every version, the current version first."""
    from bearing_env.registration import ENV_IDS
    from bearing_env.tasks import (
        BASE_ID_KINDS,
        REGISTERED_TASKS_BY_ID,
        TASKS,
        VERSIONS,
        split_id,
    )

    carded = {task.name for task in TASKS}
    rows: list[tuple[int, int, str, str, str]] = []
    for env_id in ENV_IDS:
        version = split_id(env_id)[1]
        kwargs = ", ".join(f"{k}={json.dumps(v)}" for k, v in VERSIONS[version].items())
        rows.append((-version, 0, env_id, f"base id, {BASE_ID_KINDS[env_id]} actions", kwargs))
    for task in REGISTERED_TASKS_BY_ID.values():
        kind = "task" if task.name in carded else "training task"
        rows.append(
            (
                -task.version,
                1 if kind == "task" else 2,
                task.id,
                f"{kind} on `{task.base_id}`",
                task.settings_text(),
            )
        )
    rows.sort(key=lambda row: row[:2])
    return [(env_id, what, kwargs) for _, _, env_id, what, kwargs in rows]


def registered_ids_section() -> list[str]:
    """The index's list of every registered id, with their count."""
    from bearing_env.tasks import BASE_ID_KINDS, TASKS, TRAINING_TASKS, VERSIONS

    ids = registered_ids()
    per_version = len(BASE_ID_KINDS) // len(VERSIONS)
    return [
        REGISTERED_IDS_HEADING,
        "",
        f"`import bearing_env` registers {len(ids)} ids with Gymnasium: {per_version} base "
        f"ids, {len(TASKS)} tasks and {len(TRAINING_TASKS)} training tasks, each in "
        f"{len(VERSIONS)} versions ({', '.join(f'`-v{v}`' for v in VERSIONS)}). An older "
        "version registers the settings its version kept (its kwargs below), so that "
        "scores published under it reproduce; Gymnasium warns that it is out of date.",
        "",
        markdown_table(
            ["id", "what", "registered kwargs"],
            [[f"`{i}`", what, f"`{kw}`" if kw else "-"] for i, what, kw in ids],
        ),
        "",
    ]


def write_index(tasks: Sequence[Task], docs: Path) -> Path:
    path = docs / INDEX_NAME
    atomic_write_text(path, index_page(tasks, docs))
    return path
