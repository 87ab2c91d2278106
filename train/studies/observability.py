"""``bearing-env observability``: can a sensor map a layout at all, whatever the policy?

A movement updates landmark ``Li`` (i >= 3) only when the sensor sees L1, L2 and ``Li`` at
both ends and the movement gives each of them enough parallax: its two bearing cones must
cross in a bounded region, and L1's and L2's regions must be apart. A forward camera
turns with the move, so every landmark it sees lies within half its field of view of the
line of motion, where the parallax is smallest. This study measures what that leaves,
from ground truth and noise-free bearings, independently of any policy.

For every start on a grid over the free arena, every heading (``--headings``) and every
move length (``--lengths``, over the env's range), it makes the env's own move (walls
and obstacles stop it) and readings (field of view, range, line of sight), and fuses
that one movement into an empty map with the env's own world model. Per field of view
it reports the share of these movements that change frames, the share that update each
landmark, the median area of the one-movement regions they give, the share that give a
region no larger than ``area_cap`` (the only ones the reward can see: a larger one is
capped), and the share of start positions from which some movement does. The plot
colours each start by how many landmarks its best movement maps within ``area_cap``.

    bearing-env observability --env BearingSLAM-Khepera-v1 --fov 360 180 90
    bearing-env observability --env BearingSLAM-FurnishedRoom-v1 --fov 360 90 --plot out.png

``--json`` writes the figures with the command, commit, date and machine that measured
them; the environment page's table is written from ``docs/figures/observability_*.json``
by ``bearing-env docs-tables`` (:func:`markdown_observability`).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env.envs.config import EnvConfig
from bearing_env.sensing import clearance, landmarks_seen
from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM
from bearing_env.slam.batch import LANDMARK_CODE
from bearing_env.train.common.cli_parser import add_no_progress, command_parser, doc_summary
from bearing_env.train.common.cli_values import COUNT, NON_NEGATIVE
from bearing_env.train.common.doc_tables import markdown_table
from bearing_env.train.common.files import write_json_atomically
from bearing_env.train.common.progress import progress_bar
from bearing_env.train.common.provenance import measured_here, measured_sentence
from bearing_env.train.common.seeds import EVAL_SEED_START
from bearing_env.train.common.tables import print_table
from bearing_env.world import obstructed_moves, true_bearings

FloatArray = NDArray[np.float64]

#: Movements fused per world-model call (bounds the memory of the batch of maps).
CHUNK = 4096
#: The results files of the environment page's table, one per layout (``--json``).
RESULTS_FILES = "docs/figures/observability_*.json"
#: The omniscient planner's headings (evenly over the circle), each with 3 lengths.
ORACLE_HEADINGS = 24


@dataclass(frozen=True)
class Layout:
    """What the study reads of an env: its settings and the episode's true landmarks."""

    config: EnvConfig
    landmarks: FloatArray  # (n, 2), metres; L1 and L2 first


@dataclass(frozen=True)
class Movements:
    """The candidate movements: a start index into ``starts`` per movement, its heading
    (radians) and requested length (metres)."""

    starts: FloatArray  # (S, 2) grid points in the free arena
    start_index: NDArray[np.int64]  # (N,)
    headings: FloatArray  # (N,)
    lengths: FloatArray  # (N,)


@dataclass(frozen=True)
class Outcomes:
    """What each movement did to an empty map."""

    frame_changed: NDArray[np.bool_]  # (N,)
    updated: NDArray[np.bool_]  # (N, n - 2): the landmark got a bounded region
    areas: FloatArray  # (N, n - 2): its area (FL units²); inf where not updated


def layout_of(env_id: str, env_kwargs: dict[str, Any], seed: int = EVAL_SEED_START) -> Layout:
    """The env's settings and the landmarks of its episode at ``seed`` (the first
    evaluation seed by default: a random scenario's layout is that episode's)."""
    import gymnasium as gym

    from bearing_env.agents.env_access import bearing_env_of, world_of

    env = gym.make(env_id, **env_kwargs)
    try:
        env.reset(seed=seed)
        return Layout(bearing_env_of(env).config, np.array(world_of(env).landmarks))
    finally:
        env.close()


def candidate_movements(layout: Layout, per_side: int, headings: int, lengths: int) -> Movements:
    """Every (start, heading, length): starts on a grid of ``per_side`` points along the
    arena's longer side (the same spacing along the other), inside the wall margin and
    clear of the obstacles and the landmarks by the margin; ``headings`` evenly over the
    circle; ``lengths`` evenly over the env's move-length range (its one value if fixed)."""
    arena = layout.config.layout.arena
    margin = arena.wall_margin
    spacing = (max(arena.width, arena.height) - 2 * margin) / max(per_side - 1, 1)
    xs = np.arange(margin, arena.width - margin + 1e-9, spacing)
    ys = np.arange(margin, arena.height - margin + 1e-9, spacing)
    grid = np.array([(x, y) for x in xs for y in ys])
    vertices, starts_of = layout.config.layout.packed_obstacles
    free = np.array([clearance(x, y, vertices, starts_of) > margin for x, y in grid], dtype=bool)
    gaps = np.linalg.norm(grid[:, None, :] - layout.landmarks[None], axis=2).min(axis=1)
    grid = grid[free & (gaps > margin)]
    low, high = layout.config.actions.move_length
    length_values = np.linspace(low, high, lengths) if high > low else np.array([low])
    heading_values = 2 * math.pi * np.arange(headings) / headings
    index, heading, length = np.meshgrid(
        np.arange(len(grid)), heading_values, length_values, indexing="ij"
    )
    return Movements(grid, index.ravel(), heading.ravel(), length.ravel())


def _readings(layout: Layout, positions: FloatArray, headings: FloatArray) -> FloatArray:
    """Noise-free bearings (N, n) from poses, NaN where the env's sensor misses."""
    count = len(positions)
    landmarks = np.broadcast_to(layout.landmarks, (count, *layout.landmarks.shape))
    bearings = true_bearings(landmarks, positions, headings)
    sensor = layout.config.sensor
    seen = landmarks_seen(
        layout.landmarks, positions, headings, sensor.half_fov, sensor.max_range,
        layout.config.layout.packed_obstacles,
    )  # fmt: skip
    return np.where(seen, bearings, np.nan)


def _moved(
    layout: Layout, begin: FloatArray, headings: FloatArray, lengths: FloatArray
) -> FloatArray:
    """Where the env's moves from ``begin`` (N, 2) end: walls and obstacles stop them."""
    config = layout.config.layout
    return obstructed_moves(config.arena, begin, headings, lengths, config.packed_obstacles)[2]


def movement_outcomes(layout: Layout, movements: Movements) -> Outcomes:
    """Move and read as the env does, then fuse each movement into an empty map."""
    begin = movements.starts[movements.start_index]
    end = _moved(layout, begin, movements.headings, movements.lengths)
    first = _readings(layout, begin, movements.headings)
    second = _readings(layout, end, movements.headings)
    n = len(layout.landmarks)
    count = len(begin)
    frame_changed = np.zeros(count, dtype=bool)
    updated = np.zeros((count, n - 2), dtype=bool)
    areas = np.full((count, n - 2), np.inf)
    for low in range(0, count, CHUNK):
        high = min(low + CHUNK, count)
        maps = BatchedPolygonSLAM.from_settings(high - low, n, layout.config.map_settings)
        result = maps.update(first[low:high], second[low:high])
        updated[low:high] = result.landmark_status == LANDMARK_CODE["updated"]
        frame_changed[low:high] = maps.n_frame_changes > 0
        areas[low:high] = np.where(updated[low:high], maps.areas, np.inf)
    return Outcomes(frame_changed, updated, areas)


def summarise(movements: Movements, outcomes: Outcomes, area_cap: float) -> dict[str, Any]:
    """The shares and areas of one field of view (see the module doc)."""
    useful = outcomes.areas <= area_cap
    by_start = np.zeros((len(movements.starts), useful.shape[1]), dtype=bool)
    np.logical_or.at(by_start, movements.start_index, useful)
    updated_areas = outcomes.areas[np.isfinite(outcomes.areas)]
    return {
        "movements": len(movements.headings),
        "starts": len(movements.starts),
        "frame_changes": float(outcomes.frame_changed.mean()),
        "updates": [float(share) for share in outcomes.updated.mean(axis=0)],
        "median_area": float(np.median(updated_areas)) if updated_areas.size else math.inf,
        "within_cap": [float(share) for share in useful.mean(axis=0)],
        "starts_mapping_any": float(by_start.any(axis=1).mean()),
        "best_by_start": by_start.sum(axis=1),
    }


def study(
    env_id: str, fovs: Sequence[float], grid: tuple[int, int, int], progress: bool = False
) -> dict[float, dict[str, Any]]:
    """:func:`summarise` per field of view (degrees); ``grid`` is (points per side,
    headings, lengths)."""
    results: dict[float, dict[str, Any]] = {}
    with progress_bar(len(fovs), desc="observability", unit="fov", enabled=progress) as bar:
        for fov in fovs:
            layout = layout_of(env_id, {"field_of_view_deg": float(fov)})
            movements = candidate_movements(layout, *grid)
            outcomes = movement_outcomes(layout, movements)
            summary = summarise(movements, outcomes, layout.config.task.area_cap)
            results[float(fov)] = {**summary, "layout": layout, "grid_starts": movements.starts}
            bar.update()
    return results


@dataclass(frozen=True)
class MoveGrid:
    """The omniscient planner's candidate moves: absolute headings and lengths (K,)."""

    headings: FloatArray
    lengths: FloatArray


def _potentials(maps: BatchedPolygonSLAM, config: EnvConfig) -> FloatArray:
    """The env's uncertainty potential of each map of a batch."""
    from bearing_env.agents.planning import uncertainty_potential

    task = config.task
    return uncertainty_potential(maps.areas, task.area_cap, task.reward == "log_area")


def _omniscient_choice(
    layout: Layout, slam: PolygonSLAM, position: FloatArray, grid: MoveGrid, last: bool
) -> int:
    """The index of the move whose best follow-up (none on the ``last`` move) leaves the
    lowest potential, simulated from the true ``position`` with noise-free readings."""
    count = grid.headings.size
    start = np.repeat(position[None], count, axis=0)
    ends = _moved(layout, start, grid.headings, grid.lengths)
    first = slam.replicate(count)
    first.update(
        _readings(layout, start, grid.headings), _readings(layout, ends, grid.headings), robot=False
    )
    scores = _potentials(first, layout.config)
    if not last:
        pairs = np.repeat(np.arange(count), count)
        headings, lengths = np.tile(grid.headings, count), np.tile(grid.lengths, count)
        after = _moved(layout, ends[pairs], headings, lengths)
        second = first.take(pairs)
        second.update(
            _readings(layout, ends[pairs], headings),
            _readings(layout, after, headings),
            robot=False,
        )
        best_next = _potentials(second, layout.config).reshape(count, count).min(axis=1)
        scores = best_next + 1e-3 * scores  # ties: the better first move
    return int(np.argmin(scores))


def omniscient_final_areas(
    env_id: str, env_kwargs: dict[str, Any], episodes: int, progress: bool = False
) -> list[float]:
    """The final total area (each landmark capped at ``area_cap``) of each of
    ``episodes`` evaluation episodes played by an omniscient two-move planner: it knows
    the true pose and landmarks, simulates the env's moves and sensor with noise-free
    readings, scores every pair of moves (:data:`ORACLE_HEADINGS` headings x 3 lengths
    over the env's range, twice) on copies of the robot's own map with the env's
    potential, and makes the first move of the best pair. It reads ground truth: an upper
    reference of what a policy could reach, not a robot policy."""
    import gymnasium as gym

    from bearing_env.agents.base import ActionCodec
    from bearing_env.agents.env_access import MapReader, bearing_env_of, world_of

    env = gym.make(env_id, **{**env_kwargs, "target_area": 1e-12})  # play every move
    codec, maps = ActionCodec(env), MapReader(env)
    headings, lengths = np.meshgrid(
        2 * math.pi * np.arange(ORACLE_HEADINGS) / ORACLE_HEADINGS,
        np.linspace(*codec.length_range, 3),
        indexing="ij",
    )
    grid = MoveGrid(headings.ravel(), lengths.ravel())
    finals = []
    with progress_bar(episodes, desc="omniscient", unit="episode", enabled=progress) as bar:
        for episode in range(episodes):
            _, info = env.reset(seed=EVAL_SEED_START + episode)
            world, config = world_of(env), bearing_env_of(env).config
            layout = Layout(config, np.array(world.landmarks))
            for move in range(config.task.max_moves):
                slam = maps.read(info, len(layout.landmarks))
                last = move + 1 == config.task.max_moves
                k = _omniscient_choice(layout, slam, np.array(world.position), grid, last)
                turn = math.remainder(grid.headings[k] - world.heading, 2 * math.pi)
                action = codec.movement(turn, float(grid.lengths[k])).action
                _, _, terminated, truncated, info = env.step(action)
                if terminated or truncated:
                    break
            cap = config.task.area_cap
            areas = np.minimum(np.nan_to_num(info["landmark_area"], posinf=cap), cap)
            finals.append(float(areas.sum()))
            bar.update()
    env.close()
    return finals


def as_json(results: dict[float, dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """The figures of :func:`study` without its arrays and layouts, by field of view."""
    skipped = ("layout", "grid_starts", "best_by_start")
    return {
        f"{fov:g}": {key: value for key, value in row.items() if key not in skipped}
        for fov, row in results.items()
    }


def _percent(share: float) -> str:
    """A share as the page shows it: 3 significant figures, at most 2 decimals."""
    value = 100 * share
    if value == 0:
        return "0%"
    decimals = min(2, max(0, 2 - math.floor(math.log10(value))))
    return f"{value:.{decimals}f}%"


def _area(value: float | None) -> str:
    """An area to 3 significant figures, with a thousands comma; "-" if none updated."""
    if value is None or not math.isfinite(value):
        return "-"
    rounded = float(f"{value:.3g}")
    return f"{rounded:,.0f}" if rounded >= 100 else f"{rounded:.3g}"


def _task_order(env_id: str) -> tuple[int, str]:
    """The registry's order of the tasks (the Khepera arena first), other ids after."""
    from bearing_env.tasks import TASKS

    ids = [task.id for task in TASKS]
    return (ids.index(env_id), env_id) if env_id in ids else (len(ids), env_id)


def markdown_observability(runs: Mapping[str, Mapping[str, Any]]) -> str:
    """The environment page's table from the ``--json`` files of several layouts
    (``docs/figures/observability_*.json``, by file name): per layout and field of view
    (widest first), the shares of movements that change frames, that update L3 and that
    map it within ``area_cap``, the median area of an update and the share of starts
    from which some movement maps a landmark within ``area_cap``; then each file's
    command, commit and machine."""
    header = (
        "layout", "field of view", "movements that change frames", "that update L3",
        "median area of an update (FL units²)", "that map L3 within `area_cap`",
        "starts from which some movement maps a landmark within `area_cap`",
    )  # fmt: skip
    ordered = sorted(runs.items(), key=lambda item: _task_order(item[1]["env"]))
    rows = []
    for _, run in ordered:
        fovs = sorted(run["fovs"].items(), key=lambda item: -float(item[0]))
        for position, (fov, row) in enumerate(fovs):
            layout = f"`{run['env']}` ({row['movements']:,} movements)" if position == 0 else ""
            rows.append(
                (
                    layout, f"{float(fov):g}°", _percent(row["frame_changes"]),
                    _percent(row["updates"][0]), _area(row["median_area"]),
                    _percent(row["within_cap"][0]), _percent(row["starts_mapping_any"]),
                )
            )  # fmt: skip
    folder = RESULTS_FILES.rpartition("/")[0]
    sources = [measured_sentence(run["measured"], f"{folder}/{name}.json") for name, run in ordered]
    return markdown_table(header, rows) + "\n\n" + "\n".join(f"- {line}" for line in sources)


def print_results(env_id: str, results: dict[float, dict[str, Any]]) -> None:
    n_mapped = len(next(iter(results.values()))["updates"])
    names = [f"L{i + 3}" for i in range(n_mapped)]
    rows = []
    for fov, row in results.items():
        rows.append(
            [
                f"{fov:g}",
                f"{100 * row['frame_changes']:.2f}%",
                *(f"{100 * share:.2f}%" for share in row["updates"]),
                f"{row['median_area']:.3g}",
                *(f"{100 * share:.2f}%" for share in row["within_cap"]),
                f"{100 * row['starts_mapping_any']:.1f}%",
            ]
        )
    first = next(iter(results.values()))
    print_table(
        f"{env_id}: one movement from an empty map, noise-free ({first['movements']:,} "
        f"movements from {first['starts']} starts)",
        [
            "view (deg)",
            "frames changed",
            *(f"{name} updated" for name in names),
            "median area",
            *(f"{name} <= cap" for name in names),
            "starts mapping",
        ],
        rows,
    )


def plot(env_id: str, results: dict[float, dict[str, Any]], path: Path) -> Path:
    """One arena panel per field of view: each start coloured by how many landmarks its
    best movement maps within ``area_cap``; landmarks and obstacles drawn."""
    from bearing_env.train.studies.figures import _plt, save_and_close

    plt = _plt()
    figure, panels = plt.subplots(1, len(results), figsize=(4.5 * len(results), 3.8))
    panels = np.atleast_1d(panels)
    n_mapped = len(next(iter(results.values()))["updates"])
    for axes, (fov, row) in zip(panels, results.items(), strict=True):
        layout: Layout = row["layout"]
        arena = layout.config.layout.arena
        axes.scatter(
            row["grid_starts"][:, 0], row["grid_starts"][:, 1], c=row["best_by_start"],
            cmap="viridis", vmin=0, vmax=n_mapped, s=14, marker="s",
        )  # fmt: skip
        for polygon in layout.config.layout.obstacles:
            axes.fill(*np.array((*polygon, polygon[0])).T, color="0.55")
        axes.plot(*layout.landmarks[:2].T, "r^", markersize=8, label="L1, L2")
        axes.plot(*layout.landmarks[2:].T, "k*", markersize=9, label="L3, L4, ...")
        if layout.config.layout.obstacles:
            axes.fill([], [], color="0.55", label="obstacles")
        axes.set_xlim(0, arena.width)
        axes.set_ylim(0, arena.height)
        axes.set_aspect("equal")
        axes.set_title(f"field of view {fov:g}°: {100 * row['starts_mapping_any']:.0f}% of starts")
    colours = plt.get_cmap("viridis")(np.linspace(0, 1, n_mapped + 1))
    for count, colour in enumerate(colours):  # a discrete legend for the colours
        panels[-1].scatter([], [], color=colour, marker="s", s=14, label=f"{count} mapped")
    panels[-1].legend(fontsize=7, loc="center left", bbox_to_anchor=(1.02, 0.5))
    figure.suptitle(
        f"{env_id}: how many landmarks one movement from each start maps within area_cap"
    )
    return save_and_close(figure, path, rect=(0, 0, 1, 0.93))


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser("bearing-env observability", doc_summary(__doc__))
    parser.add_argument("--env", default="BearingSLAM-Khepera-v1", help="a registered task id")
    parser.add_argument(
        "--fov", type=float, nargs="+", default=[360.0, 180.0, 90.0], metavar="DEG",
        help="fields of view to compare, degrees in (0, 360]",
    )  # fmt: skip
    parser.add_argument(
        "--per-side", type=COUNT, default=24, help="grid starts along the long side"
    )
    parser.add_argument("--headings", type=COUNT, default=36, help="headings per start")
    parser.add_argument("--lengths", type=COUNT, default=3, help="move lengths per heading")
    parser.add_argument(
        "--plot", type=Path, default=None, help="also draw the arenas here (PNG; default: none)"
    )
    parser.add_argument(
        "--json", type=Path, default=None, help="also write the figures here (default: none)"
    )
    parser.add_argument(
        "--oracle-episodes",
        type=NON_NEGATIVE,
        default=0,
        help="also play this many evaluation episodes per field of view with the omniscient "
        "two-move planner (ground truth; slow: about a second per move) and report its final "
        "total areas",
    )
    add_no_progress(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    import gymnasium as gym

    parser = build_parser()
    arguments = list(sys.argv[1:] if argv is None else argv)
    args = parser.parse_args(arguments)
    env_id = args.env if ":" in args.env else f"bearing_env:{args.env}"
    grid = (args.per_side, args.headings, args.lengths)
    try:
        results = study(env_id, args.fov, grid, progress=not args.no_progress)
    except (ValueError, TypeError, gym.error.Error) as error:  # a bad id or field of view
        parser.error(str(error))
    print_results(args.env, results)
    if args.oracle_episodes:
        for fov, row in results.items():
            finals = omniscient_final_areas(
                env_id, {"field_of_view_deg": fov}, args.oracle_episodes, not args.no_progress
            )
            row["omniscient_final_areas"] = finals
            low, median, high = np.percentile(finals, [10, 50, 90])
            print(
                f"field of view {fov:g} deg: the omniscient planner's final total area over "
                f"{len(finals)} episodes: median {median:.3g} (10th-90th percentile "
                f"{low:.3g}-{high:.3g})"
            )
    if args.json is not None:
        measured = measured_here(parser.prog, arguments)
        write_json_atomically(
            args.json, {"env": args.env, "fovs": as_json(results), "measured": measured}
        )
        print(f"wrote {args.json}")
    if args.plot is not None:
        print(f"wrote {plot(args.env, results, args.plot)}")


if __name__ == "__main__":
    main()
