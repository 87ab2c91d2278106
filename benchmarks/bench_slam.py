"""Throughput of PolygonSLAM.update() on readings recorded from env episodes, against
CartPole-v1 steps, measured in the same runs.

The primary rows replay the readings of the random polygonal trajectory on
BearingSLAM-Khepera-v1 (4 landmarks) and BearingSLAM-Random8-v1 (8 landmarks), a few
seeded episodes each, recorded at the start (``bench_readings``); a map starts afresh
with each episode, as the env's does. The secondary rows replay the older synthetic
readings (one layout in a 100 x 100 arena, repeated) at 4 to 64 landmarks.

Absolute times drift on shared machines, so every figure is also given as a ratio to
Gymnasium's CartPole-v1 ``env.step`` rate. ``--seconds`` per figure is split over
``--runs`` runs; each run measures CartPole-v1 and then every figure once, each figure's
ratio is to its run's CartPole-v1 rate, and the rows give the median, min and max over
the runs.

    python benchmarks/bench_slam.py [--seconds 2] [--runs 5] [--json out.json]
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import gymnasium as gym
import numpy as np

from bearing_env.benchmarks.bench_readings import (
    RECORDED_TASKS,
    SYNTHETIC_LABEL,
    WORKLOAD_LABELS,
    Reading,
    record,
    synthetic_readings,
)
from bearing_env.slam import MapSettings, PolygonSLAM
from bearing_env.train.common.cli_parser import add_json_output, command_parser, doc_summary
from bearing_env.train.common.cli_values import at_least, seconds
from bearing_env.train.common.errors import exit_on_output_errors
from bearing_env.train.common.files import atomic_write_text


def cartpole_steps_per_second(seconds: float) -> float:
    env = gym.make("CartPole-v1")
    env.reset(seed=0)
    steps, action = 0, 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        for _ in range(500):
            _, _, terminated, truncated, _ = env.step(action)
            action ^= 1
            if terminated or truncated:
                env.reset()
        steps += 500
    return steps / (time.perf_counter() - start)


def make_readings(n_landmarks: int, n_moves: int, seed: int) -> list[Reading]:
    """The synthetic readings (:func:`.bench_readings.synthetic_readings`)."""
    return synthetic_readings(n_landmarks, n_moves, seed)


#: The transfers measured, in order.
MEASURED_TRANSFERS: tuple[str, ...] = ("conservative", "paper")
#: The landmark counts of the synthetic (secondary) rows; the first is their base rate.
LANDMARK_COUNTS: tuple[int, ...] = (4, 16, 64)
#: Movements of a synthetic pass (a map starts afresh with each).
SYNTHETIC_MOVES = 20
#: Runs per figure (``--runs``): the rows give the median, min and max over them.
DEFAULT_RUNS = 5
#: CartPole steps run before its rate is measured (its first steps build the env's wrappers).
CARTPOLE_WARM_UP_STEPS = 2_000


@dataclass(frozen=True)
class Workload:
    """Readings to replay: ``episodes`` of (start, end) pairs, each from a fresh map with
    ``settings`` (their transfer replaced by the one measured)."""

    key: str
    label: str
    #: Recorded from env episodes (the primary rows), or synthetic (secondary).
    primary: bool
    env_id: str | None
    n_landmarks: int
    settings: MapSettings
    episodes: tuple[tuple[Reading, ...], ...]

    @property
    def movements(self) -> int:
        return sum(len(episode) for episode in self.episodes)


def recorded_workload(env_id: str) -> Workload:
    recording = record(env_id)
    return Workload(
        key=env_id.removeprefix("BearingSLAM-").removesuffix("-v1").lower(),
        label=WORKLOAD_LABELS[env_id],
        primary=True,
        env_id=env_id,
        n_landmarks=recording.n_landmarks,
        settings=recording.settings,
        episodes=tuple(tuple(episode) for episode in recording.episode_readings()),
    )


def synthetic_workload(n_landmarks: int) -> Workload:
    readings = synthetic_readings(n_landmarks, SYNTHETIC_MOVES, seed=n_landmarks)
    return Workload(
        key=f"synthetic_{n_landmarks}",
        label=SYNTHETIC_LABEL,
        primary=False,
        env_id=None,
        n_landmarks=n_landmarks,
        settings=MapSettings(np.deg2rad(2.0)),
        episodes=(tuple(readings),),
    )


def workloads(synthetic_counts: Sequence[int] = LANDMARK_COUNTS) -> list[Workload]:
    """The recorded workloads (:data:`RECORDED_TASKS`), then the synthetic ones."""
    recorded = [recorded_workload(env_id) for env_id in RECORDED_TASKS]
    return recorded + [synthetic_workload(n) for n in synthetic_counts]


def make_map(workload: Workload, transfer: str) -> PolygonSLAM:
    settings = replace(workload.settings, transfer=transfer)
    return PolygonSLAM.from_settings(workload.n_landmarks, settings)


def replay(slam: PolygonSLAM, workload: Workload) -> int:
    """Every episode of ``workload`` once, each from a fresh map: the updates made."""
    for episode in workload.episodes:
        slam.reset()
        for b1, b2 in episode:
            slam.update(b1, b2)
    return workload.movements


def warm_up(transfers: Sequence[str], measured: Sequence[Workload]) -> None:
    """Run, untimed, everything that is timed next: some CartPole steps and one pass of
    each workload's readings, so that no first-call cost (a thread's buffers, CartPole's
    wrappers) falls inside a timed window."""
    env = gym.make("CartPole-v1")
    env.reset(seed=0)
    for step in range(CARTPOLE_WARM_UP_STEPS):
        _, _, terminated, truncated, _ = env.step(step % 2)
        if terminated or truncated:
            env.reset()
    env.close()
    for transfer in transfers:
        for workload in measured:
            replay(make_map(workload, transfer), workload)


def updates_per_second(workload: Workload, transfer: str, seconds: float) -> float:
    """Replay ``workload`` (whole passes, at least one) for about ``seconds``."""
    slam = make_map(workload, transfer)
    count = 0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        count += replay(slam, workload)
    return count / (time.perf_counter() - start)


def row_order(measured: Sequence[Workload], transfers: Sequence[str]) -> list[tuple[Workload, str]]:
    """The rows' order: the recorded readings first (per transfer), then the synthetic."""
    primary = [(w, t) for t in transfers for w in measured if w.primary]
    return primary + [(w, t) for t in transfers for w in measured if not w.primary]


def _spread(values: Sequence[float], name: str) -> dict[str, float]:
    return {
        name: float(np.median(values)),
        f"{name}_min": float(min(values)),
        f"{name}_max": float(max(values)),
    }


def measure_updates(
    measured: Sequence[Workload], transfers: Sequence[str], seconds: float, runs: int
) -> tuple[list[dict[str, Any]], list[float]]:
    """(rows in :func:`row_order`, CartPole-v1's rate in each run). ``seconds`` per figure
    are split over ``runs`` runs; each run times CartPole-v1, then every figure once."""
    per_run = seconds / runs
    order = row_order(measured, transfers)
    rates: dict[tuple[str, str], list[float]] = {(w.key, t): [] for w, t in order}
    cartpole: list[float] = []
    for _ in range(runs):
        cartpole.append(cartpole_steps_per_second(per_run))
        for workload, transfer in order:
            rates[workload.key, transfer].append(updates_per_second(workload, transfer, per_run))
    rows = []
    for workload, transfer in order:
        run_rates = rates[workload.key, transfer]
        ratios = [rate / reference for rate, reference in zip(run_rates, cartpole, strict=True)]
        rows.append(
            {
                "readings": workload.key,
                "label": workload.label,
                "primary": workload.primary,
                "env_id": workload.env_id,
                "transfer": transfer,
                "n_landmarks": workload.n_landmarks,
                "movements": workload.movements,
                "runs": runs,
                **_spread(run_rates, "steps_per_s"),
                **_spread(ratios, "ratio_to_cartpole"),
                "cartpole_steps_per_s": float(np.median(cartpole)),
                "run_steps_per_s": run_rates,
            }
        )
    return rows, cartpole


def row_case(row: dict[str, Any]) -> str:
    """How a row is named in the tables: its transfer, readings and landmarks; the
    synthetic rows say they are secondary."""
    if "readings" not in row:  # an older results file: synthetic readings only
        return f"update(), {row['transfer']}, {row['n_landmarks']} landmarks"
    case = f"update(), {row['transfer']}, {row['label']}, {row['n_landmarks']} landmarks"
    return case if row["primary"] else f"{case} [secondary]"


def print_rows(rows: Sequence[dict[str, Any]], cartpole: Sequence[float]) -> None:
    print(
        f"CartPole-v1 env.step: {np.median(cartpole):10.0f} steps/s, median of {len(cartpole)} "
        f"runs ({min(cartpole):,.0f} to {max(cartpole):,.0f}; reference, same runs)"
    )
    print("update(): median /s and % of CartPole over the runs (min to max)")
    for row in rows:
        print(
            f"{row_case(row)}: {row['steps_per_s']:8.0f} /s = {row['ratio_to_cartpole']:6.1%} "
            f"of CartPole ({row['ratio_to_cartpole_min']:.1%} to "
            f"{row['ratio_to_cartpole_max']:.1%})"
        )
    print(
        f"Recorded readings: the random polygonal trajectory, {', '.join(RECORDED_TASKS)}, "
        "seeded episodes; secondary: " + SYNTHETIC_LABEL + "."
    )


def main(argv: Sequence[str] | None = None) -> None:
    parser = command_parser("bearing-env bench-slam", doc_summary(__doc__))
    parser.add_argument(
        "--seconds",
        type=seconds,
        default=2.0,
        help="time per figure, split over the runs, finite and > 0 (default %(default)s)",
    )
    parser.add_argument(
        "--runs",
        type=at_least(1),
        default=DEFAULT_RUNS,
        help="runs per figure: median, min and max (default %(default)s)",
    )
    add_json_output(parser, "the rates")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)

    measured = workloads()
    warm_up(MEASURED_TRANSFERS, measured)
    rows, cartpole = measure_updates(measured, MEASURED_TRANSFERS, args.seconds, args.runs)
    print_rows(rows, cartpole)
    if args.json is not None:
        results = {"cartpole_steps_per_s": cartpole, "rows": rows}
        with exit_on_output_errors(parser, args.json, "--json", refusals=()):
            atomic_write_text(args.json, json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
