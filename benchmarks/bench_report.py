"""The report of ``bearing-env bench``: the targets each figure is held to (met / not
met), the JSON results file and the terminal table.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import platform
import sys
from collections.abc import Collection, Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import bearing_env
from bearing_env.benchmarks.bench_readings import RECORDED_TASKS, SYNTHETIC_LABEL
from bearing_env.benchmarks.bench_slam import row_case
from bearing_env.benchmarks.bench_timing import (
    SINGLE_ACTION_BLOCK,
    ppo_label,
    vector_label,
)
from bearing_env.extras import available
from bearing_env.train.common.files import atomic_write_text
from bearing_env.train.common.provenance import (
    short_commit,
    source_commit,
    uncommitted_files,
    uncommitted_text,
)

#: Relative to the working directory, so an installed package never writes into itself.
DEFAULT_JSON = Path("outputs") / "bench_env.json"
#: 2: no ``fallback`` fields (targets, vector and PPO rows), no ``measured_with`` (PPO
#: rows) and no ``settings.vector_entry_point``: the batched env always exists, so nothing
#: falls back. (The format-1 files under ``benchmarks/results/`` carry them, all false.)
#: 3: the startup section times whole fresh processes of BearingSLAM-Khepera-v1 against
#: the same script on CartPole-v1 (:func:`~bearing_env.benchmarks.bench_timing.bench_startup`:
#: ``ratio_to_cartpole``, ``numba_imported``, ...); formats 1 and 2 timed the first step
#: alone (``warm_first_step_s``, ``cold_first_step_s``), which :func:`startup_section`
#: reports as an older format. No target ``j`` (a compile time) any more.
#: 4: the slam rows replay readings recorded from env episodes (``readings``, ``label``,
#: ``primary``; the synthetic ones are secondary) and give the median, min and max over
#: runs (``steps_per_s_min``, ``ratio_to_cartpole_max``, ...); target ``e`` reads the
#: recorded Khepera-v1 row. Formats 1 to 3 timed the synthetic readings alone.
JSON_FORMAT = 4
TARGETS: dict[str, str] = {
    "a": "single env, Khepera: env.step >= 20% of CartPole-v1",
    "b": "batched env, 64 envs x 4 landmarks: total steps/s >= 50% of CartPole-v1",
    "i": "batched env, 256 envs x 4 landmarks: total steps/s >= 60% of CartPole-v1",
    "c": "single env, 64 landmarks >= 1/16 of the 4-landmark rate",
    "d": "PPO on the batched env >= 2x PPO on SubprocVecEnv (same n_envs)",
    "e": "PolygonSLAM.update on recorded Khepera-v1 readings (4 landmarks), conservative: "
    ">= 60% of CartPole-v1",
    "f": "a fresh process that imports bearing_env, makes BearingSLAM-Khepera-v1 and steps "
    "once: <= 1.5x the same script with CartPole-v1 (no bearing_env import), side by side",
    "g": "GreedyOneStep planning per move (median): <= 0.5 ms",
    "h": "PPO on 16 batched envs >= 0.7x the same SB3 PPO on CartPole-v1 "
    "(same hyperparameters and n_envs)",
}
TARGET_THRESHOLDS: dict[str, float] = {
    "a": 0.20,
    "b": 0.50,
    "i": 0.60,
    "c": 1.0 / 16.0,
    "d": 2.0,
    "e": 0.60,
    "f": 1.5,
    "g": 0.5e-3,
    "h": 0.7,
}
#: Targets that are upper bounds (f a ratio of process times, g seconds); the others are
#: lower bounds (ratios).
UPPER_BOUND_TARGETS = frozenset({"f", "g"})


# --------------------------------------------------------------------------------------
# Targets
# --------------------------------------------------------------------------------------


def _target(key: str, value: float | None, note: str | None = None) -> dict[str, Any]:
    threshold = TARGET_THRESHOLDS[key]
    if value is None:
        met = None
    elif key in UPPER_BOUND_TARGETS:
        met = bool(value <= threshold)
    else:
        met = bool(value >= threshold)
    return {
        "id": key,
        "description": TARGETS[key],
        "value": value,
        "threshold": threshold,
        "met": met,
        "note": note,
    }


def startup_section(results: dict[str, Any]) -> tuple[dict[str, Any] | None, str | None]:
    """(the startup section, None), or (None, why not): no startup section, or one of an
    older results file (formats 1 and 2: the first step timed alone, in seconds, not a
    fresh process against CartPole-v1)."""
    startup = results.get("startup")
    if startup is None:
        return None, "needs the startup section"
    if "ratio_to_cartpole" not in startup:
        return None, (
            f"older results file (format {results.get('format', '1 or 2')}): its start-up "
            "was not measured against CartPole-v1"
        )
    return startup, None


def khepera_update_row(results: dict[str, Any]) -> tuple[dict[str, Any] | None, str | None]:
    """(the slam section's conservative row on recorded Khepera-v1 readings, None), or
    (None, why not): no slam section, or one of an older results file (formats 1 to 3:
    synthetic readings only)."""
    rows = results.get("slam")
    if not rows:
        return None, "needs the slam section"
    for row in rows:
        if row.get("readings") == "khepera" and row["transfer"] == "conservative":
            return row, None
    return None, (
        f"older results file (format {results.get('format', '1 to 3')}): its update() rows "
        "replayed synthetic readings, not recorded Khepera-v1 ones"
    )


def evaluate_targets(results: dict[str, Any]) -> list[dict[str, Any]]:
    single = {row["name"]: row for row in results.get("single", [])}
    vector = results.get("vector", [])
    ppo = {row["kind"]: row for row in results.get("ppo", [])}
    targets = []

    khepera = single.get("khepera")
    if khepera is None:
        targets.append(_target("a", None, "needs the single-env Khepera row"))
    else:
        targets.append(_target("a", khepera["ratio_to_cartpole"]))

    batched_64 = next(
        (row for row in vector if row["kind"] == "batched" and row["num_envs"] == 64), None
    )
    if batched_64 is None:
        targets.append(_target("b", None, "no batched row with 64 envs measured"))
    else:
        targets.append(_target("b", batched_64["ratio_to_cartpole"]))
    batched_256 = next(
        (row for row in vector if row["kind"] == "batched" and row["num_envs"] == 256), None
    )
    if batched_256 is None:
        targets.append(_target("i", None, "no batched row with 256 envs measured"))
    else:
        targets.append(_target("i", batched_256["ratio_to_cartpole"]))

    many = single.get("random_64")
    few = single.get("random_4")
    if many is None or few is None:
        targets.append(_target("c", None, "needs the 4- and 64-landmark single-env rows"))
    else:
        targets.append(_target("c", many["steps_per_s"] / few["steps_per_s"]))

    update_khepera, why_not = khepera_update_row(results)
    if update_khepera is None:
        targets.append(_target("e", None, why_not))
    else:
        targets.append(_target("e", update_khepera["ratio_to_cartpole"]))
    startup, why_not = startup_section(results)
    if startup is None:
        targets.append(_target("f", None, why_not))
    else:
        targets.append(_target("f", startup["ratio_to_cartpole"]))

    planning = results.get("planning")
    if planning is None:
        targets.append(_target("g", None, "needs the planning section"))
    else:
        targets.append(_target("g", planning["median_s"]))

    batched, subproc = ppo.get("batched"), ppo.get("subproc")
    if batched is None or subproc is None:
        targets.append(_target("d", None, "needs the batched and subproc PPO rows"))
    else:
        # The median of the per-round ratios (rounds are interleaved), as in the table.
        ratio = batched.get("ratio_to_subproc") or batched["steps_per_s"] / subproc["steps_per_s"]
        targets.append(_target("d", ratio))

    throughput_ppo = (results.get("throughput") or {}).get("ppo")
    if throughput_ppo is None:
        targets.append(_target("h", None, "needs the throughput section's PPO pair"))
    else:
        targets.append(_target("h", throughput_ppo["ratio_to_cartpole_ppo"]))
    return targets


# --------------------------------------------------------------------------------------
# Output
# --------------------------------------------------------------------------------------


def machine_info() -> dict[str, Any]:
    info: dict[str, Any] = {
        "platform": platform.platform(),
        "processor": platform.processor() or platform.machine(),
        "python": sys.version.split()[0],
        "cpu_count": os.cpu_count(),
        "numpy": np.__version__,
        "gymnasium": gym.__version__,
        "bearing_env": bearing_env.__version__,
    }
    with contextlib.suppress(AttributeError):
        info["usable_cpus"] = len(os.sched_getaffinity(0))
    for module in ("torch", "stable_baselines3"):
        if module in sys.modules:
            info[module] = getattr(sys.modules[module], "__version__", None)
    info["commit"] = source_commit()
    info["uncommitted"] = uncommitted_files()
    with contextlib.suppress(OSError, AttributeError):
        # Other jobs on the machine move every figure: the 1-minute load average at the
        # time the JSON is written, for the reader of the results.
        info["load_average_1min"] = round(os.getloadavg()[0], 2)
    return info


def _finite(value: Any) -> Any:
    """JSON without NaN/inf: non-finite floats become null."""
    if isinstance(value, dict):
        return {str(key): _finite(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(item) for item in value]
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, np.generic):
        return _finite(value.item())
    return value


def write_json(path: Path, results: dict[str, Any]) -> None:
    """Write ``results`` to ``path`` atomically (``files.atomic_write_text``: an OSError
    names ``path``)."""
    atomic_write_text(path, json.dumps(_finite(results), indent=2, allow_nan=False) + "\n")


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{value:.2%}"


def _times(value: float | None) -> str:
    return "-" if value is None else f"{value:.2f}x"


def _relative(ratio: float | None, reference: str) -> str:
    """``"1.5x sync"``, or empty where the reference row was not measured."""
    return "" if ratio is None else f"{_times(ratio)} {reference}"


#: The limited-sensor rows of the single section: (case, the reference of its step cost).
SENSOR_ROW_CASES: dict[str, tuple[str, str]] = {
    "furnished_room": ("furnished room, 4 obstacles", "without them"),
    "furnished_room_empty": ("furnished room, no obstacles", ""),
    "khepera_camera90": ("khepera, 90 deg camera", "panoramic"),
}


def slam_spread(row: dict[str, Any]) -> str:
    """A slam row's min and max over its runs (the row's figures are the medians); empty
    for a row of an older results file (one run)."""
    if "ratio_to_cartpole_min" not in row:
        return ""
    return (
        f"{row['runs']} runs: {row['steps_per_s_min']:,.0f} to {row['steps_per_s_max']:,.0f} /s, "
        f"{_pct(row['ratio_to_cartpole_min'])} to {_pct(row['ratio_to_cartpole_max'])}"
    )


def table_rows(results: dict[str, Any]) -> list[tuple[str, ...]]:
    """(section, case, steps/s, % nearest ref, ref, % start ref, relative) rows."""
    rows: list[tuple[str, ...]] = []

    def add(section: str, case: str, figure: dict[str, Any], relative: str) -> None:
        rows.append(
            (
                section,
                case,
                f"{figure['steps_per_s']:,.0f}",
                _pct(figure["ratio_to_cartpole"]),
                figure["cartpole_reference"],
                _pct(figure["ratio_to_cartpole_start"]),
                relative,
            )
        )

    for row in results.get("single", []):
        if row["name"] == "khepera":
            case = "khepera, 4 landmarks"
        elif row["name"] == "khepera_wrapped":
            case = "khepera, gym.make wrappers"
        elif row["name"] == "khepera_no_robot_map":
            case = "khepera, robot_map_info=False"
        elif row["name"] in SENSOR_ROW_CASES:
            case, reference = SENSOR_ROW_CASES[row["name"]]
            cost = row.get("step_cost_ratio")
            add("single", case, row, "" if cost is None else f"step {cost:.2f}x {reference}")
            continue
        else:
            case = f"random, {row['n_landmarks']} landmarks"
        add("single", case, row, _relative(row["ratio_to_4_landmarks"], "4-landmark rate"))
    for row in results.get("vector", []):
        case = f"{vector_label(row)}, {row['num_envs']} envs"
        add("vector", case, row, _relative(row["ratio_to_sync"], "sync"))
    for row in results.get("slam", []):
        add("slam", row_case(row), row, slam_spread(row))
    for row in results.get("ppo", []):
        case = f"PPO {ppo_label(row)}, {row['n_envs']} envs"
        add("ppo", case, row, _relative(row["ratio_to_subproc"], "subproc"))
    return rows


TABLE_HEADER: tuple[str, ...] = (
    "section",
    "case",
    "steps/s",
    "% CartPole",
    "(ref)",
    "% CartPole@start",
    "relative",
)
NUMERIC_COLUMNS = frozenset({2, 3, 5})


def references_line(results: dict[str, Any]) -> str:
    references = ", ".join(
        f"{ref['label']} {ref['steps_per_s']:,.0f}" for ref in results["cartpole_references"]
    )
    return f"CartPole-v1 env.step references (steps/s, same run): {references}"


def column_widths(rows: Sequence[Sequence[str]]) -> list[int]:
    return [max(len(text) for text in column) for column in zip(*rows, strict=True)]


def table_notes(results: dict[str, Any]) -> list[str]:
    """The targets and what the columns mean, printed under the table."""
    lines = []
    if "startup" in results:
        lines += ["", startup_text(results)]
    planning = results.get("planning")
    if planning is not None:
        lines += [
            "",
            f"Planning: GreedyOneStep.act {planning['median_s'] * 1e3:.3f} ms per move "
            f"(median of {planning['moves']} moves; mean {planning['mean_s'] * 1e3:.3f} ms, "
            f"p90 {planning['p90_s'] * 1e3:.3f} ms).",
        ]
    lines += ["", *figure_notes(results), "", "Targets:"]
    lines.extend("  " + format_target(target) for target in results["targets"])
    lines.append("")
    lines.append(
        f"{results['settings']['seconds']:g} s per measurement; % CartPole uses the reference "
        "measured closest in time ((ref)), % CartPole@start the first one."
    )
    if "ppo" in results:
        lines.append(
            "PPO: env steps per wall-second of model.learn() after a warm-up learn() "
            "(process start-up and torch init excluded); the median of "
            f"{results['settings'].get('ppo_rounds', 1)} interleaved rounds per kind."
        )
    return lines


def figure_notes(results: dict[str, Any]) -> list[str]:
    """What the single and slam rows time."""
    lines = []
    if "single" in results:
        lines.append(
            f"single: seeded random actions sampled ahead of the timed loop (a block of "
            f"{SINGLE_ACTION_BLOCK:,}, cycled): env.step and resets alone are timed."
        )
    if "slam" in results and any("readings" in row for row in results["slam"]):
        lines.append(
            "slam: update() on the readings of the random polygonal trajectory recorded from "
            f"seeded {' and '.join(RECORDED_TASKS)} episodes (a fresh map per episode); "
            f"[secondary]: {SYNTHETIC_LABEL}. Medians over runs, each against its run's "
            "CartPole-v1; relative: min to max."
        )
    return lines


def format_table(results: dict[str, Any]) -> str:
    """The results as a plain-text table, the CartPole references and the targets."""
    rows = table_rows(results)
    header, rule, *texts = plain_table(TABLE_HEADER, rows, NUMERIC_COLUMNS)
    lines = [references_line(results), header, rule]
    previous = None
    for row, text in zip(rows, texts, strict=True):
        if previous is not None and row[0] != previous:
            lines.append("")
        lines.append(text)
        previous = row[0]
    lines += table_notes(results)
    if "throughput" in results:
        section = results["throughput"]
        rows = throughput_rows(section)
        lines += ["", throughput_title(section)]
        lines += plain_table(THROUGHPUT_HEADER, rows, THROUGHPUT_NUMERIC)
        lines += throughput_notes(section)
    return "\n".join(lines)


def plain_table(
    header: Sequence[str], rows: Sequence[Sequence[str]], numeric: Collection[int]
) -> list[str]:
    """``header``, a rule and ``rows`` as lines of plain text, the ``numeric`` columns
    right-justified."""
    widths = column_widths([header, *rows])

    def line(cells: Sequence[str]) -> str:
        return "  ".join(
            cell.rjust(width) if index in numeric else cell.ljust(width)
            for index, (cell, width) in enumerate(zip(cells, widths, strict=True))
        ).rstrip()

    return [line(header), line(["-" * width for width in widths]), *map(line, rows)]


# --------------------------------------------------------------------------------------
# The throughput section's table (EnvPool's and gymnax's format)
# --------------------------------------------------------------------------------------

THROUGHPUT_HEADER: tuple[str, ...] = (
    "sub-envs",
    "CartPole-v1 steps/s",
    "BearingSLAM-v1 steps/s",
    "ratio",
)
THROUGHPUT_NUMERIC = frozenset({1, 2, 3})


def throughput_rows(section: dict[str, Any]) -> list[tuple[str, ...]]:
    """One row per number of sub-envs (random actions), then PPO training."""
    rows: list[tuple[str, ...]] = [
        (
            f"{row['num_envs']:,}",
            f"{row['cartpole']['steps_per_s']:,.0f}",
            f"{row['bearing_slam']['steps_per_s']:,.0f}",
            f"{row['ratio_to_cartpole_vector']:.3f}",
        )
        for row in section["env_steps"]
    ]
    ppo = section["ppo"]
    if ppo is not None:
        rows.append(
            (
                f"PPO, {ppo['n_envs']} envs",
                f"{ppo['cartpole']['steps_per_s']:,.0f}",
                f"{ppo['bearing_slam']['steps_per_s']:,.0f}",
                f"{ppo['ratio_to_cartpole_ppo']:.3f}",
            )
        )
    return rows


def throughput_title(section: dict[str, Any]) -> str:
    return (
        "Throughput, same run: env steps/s with random actions, and PPO training env steps/s "
        f"(CartPole-v1 vectorization_mode={section['cartpole_vectorization_mode']})"
    )


def throughput_notes(section: dict[str, Any]) -> list[str]:
    """What the throughput table's ratio and PPO row mean."""
    lines = [
        "",
        "ratio: BearingSLAM-v1 (batched BearingSLAMVectorEnv, vector_entry_point) / CartPole-v1 "
        "with the same number of sub-envs, measured back to back; actions sampled up front.",
    ]
    ppo = section["ppo"]
    if ppo is None:
        lines.append(section["ppo_note"])
    else:
        lines.append(
            f"PPO: SB3 PPO, ppo.yml's BearingSLAM-v1 settings on {ppo['n_envs']} batched envs and "
            f"on CartPole-v1 ({ppo['cartpole']['kind']} vec env, the same hyperparameters); "
            f"the median of {len(ppo['bearing_slam']['rounds'])} interleaved rounds, the ratio "
            f"the median of the per-round ratios (target >= {TARGET_THRESHOLDS['h']:g})."
        )
    return lines


def format_target(target: dict[str, Any]) -> str:
    if target["met"] is None:
        status = "NOT MEASURED"
    else:
        status = "MET" if target["met"] else "NOT MET"
    value = target["value"]
    if value is None:
        shown = "-"
    elif target["id"] in ("a", "b", "e", "i"):
        shown = f"{value:.2%} (need {target['threshold']:.0%})"
    elif target["id"] == "c":
        shown = f"{value:.3f} (need {target['threshold']:.4f})"
    elif target["id"] == "f":
        shown = f"{value:.2f}x (need <= {target['threshold']:g}x)"
    elif target["id"] == "g":
        shown = f"{value * 1e3:.3f} ms (need <= {target['threshold'] * 1e3:g} ms)"
    else:
        shown = f"{value:.2f}x (need {target['threshold']:g}x)"
    note = f"  [{target['note']}]" if target["note"] else ""
    return f"({target['id']}) {target['description']}: {shown} -> {status}{note}"


def print_table(results: dict[str, Any]) -> None:
    """A rich table on a terminal (its last columns left out when it is too narrow for
    them, numbers never split), else plain text."""
    if sys.stdout.isatty() and available("rich"):
        from rich.console import Console

        from bearing_env.train.common.tables import print_table as print_rich_table

        console = Console()
        title = references_line(results)
        print_rich_table(title, TABLE_HEADER, table_rows(results), console, NUMERIC_COLUMNS)
        for text in table_notes(results):
            console.print(text, markup=False, highlight=False)
        if "throughput" in results:
            section = results["throughput"]
            console.print()
            print_rich_table(
                throughput_title(section),
                THROUGHPUT_HEADER,
                throughput_rows(section),
                console,
                THROUGHPUT_NUMERIC,
            )
            for text in throughput_notes(section):
                console.print(text, markup=False, highlight=False)
        return
    print(format_table(results))




# --------------------------------------------------------------------------------------
# Markdown for the docs (``bearing-env docs-tables`` writes the performance page's tables
# from the results file with these)
# --------------------------------------------------------------------------------------

#: What each goal is about, in the docs' words (the goals' ids stay internal).
GOAL_NAMES: dict[str, str] = {
    "a": "single env, Khepera, `env.step`",
    "b": "batched vector env, 64 Khepera sub-envs",
    "i": "batched vector env, 256 Khepera sub-envs",
    "c": "single env, 64 landmarks ÷ 4 landmarks",
    "d": "PPO on the batched env ÷ PPO on `SubprocVecEnv` (16 envs)",
    "e": "`PolygonSLAM.update` on recorded Khepera-v1 readings, conservative",
    "f": "fresh process: import, make `BearingSLAM-Khepera-v1`, one step ÷ the same with "
    "CartPole-v1",
    "g": "`GreedyOneStep` planning per move (median)",
    "h": "PPO on the batched env ÷ PPO on CartPole-v1 (16 envs)",
}


def _goal_figures(target: dict[str, Any]) -> tuple[str, str]:
    """The measured value and the goal of a target, as the docs write them."""
    key, value, threshold = target["id"], target["value"], target["threshold"]
    if key in ("a", "b", "e", "i"):
        shown = "-" if value is None else f"{value:.1%} of CartPole-v1"
        goal = f"≥ {threshold:.0%}"
    elif key == "c":
        shown, goal = ("-" if value is None else f"{value:.3f}"), f"≥ {threshold:.4f} (1/16)"
    elif key == "f":
        shown, goal = ("-" if value is None else f"{value:.2f}x"), f"≤ {threshold:g}x"
    elif key == "g":
        shown = "-" if value is None else f"{value * 1e3:.2f} ms"
        goal = f"≤ {threshold * 1e3:g} ms"
    else:
        shown, goal = ("-" if value is None else f"{value:.2f}x"), f"≥ {threshold:g}x"
    return shown, goal


def markdown_machine(results: dict[str, Any]) -> str:
    """Where, when and on what code the results were measured, and the command."""
    machine = results["machine"]
    commit = machine.get("commit")
    code = (
        short_commit(commit) + uncommitted_text(machine.get("uncommitted", []))
        if commit
        else f"bearing_env {machine['bearing_env']}"
    )
    from bearing_env.benchmarks.bench_timing import SECTIONS

    sections = list(results["settings"]["sections"])
    command = (
        "bearing-env bench"
        if sorted(sections) == sorted(SECTIONS)
        else f"bearing-env bench --sections {','.join(sections)}"
    )
    return (
        f"Measured by `{command}` "
        f"({results['settings']['seconds']:g} s per figure) on {results['started'][:10]}, "
        f"{code}, on a {machine['cpu_count']}-core {machine['processor']} machine "
        f"(`{machine['platform']}`, Python {machine['python']}, numpy {machine['numpy']}, "
        f"Gymnasium {machine['gymnasium']}"
        + (
            f"; load average {machine['load_average_1min']:g} as the run ended"
            if "load_average_1min" in machine
            else ""
        )
        + "); file `benchmarks/results/bench_env.json`. "
        + (f"{machine['provenance']} " if machine.get("provenance") else "")
        + "CartPole-v1's `env.step` measured in the same run: "
        + ", ".join(
            f"{ref['steps_per_s']:,.0f}" for ref in results["cartpole_references"]
        )
        + " steps/s."
    )


def markdown_goals(results: dict[str, Any]) -> str:
    """The goals each figure is held to, with what the results file measured."""
    order = ("a", "b", "i", "c", "e", "f", "g", "d", "h")
    by_id = {target["id"]: target for target in evaluate_targets(results)}
    rows = []
    for key in order:
        target = by_id[key]
        shown, goal = _goal_figures(target)
        if target["value"] is None and target["note"]:
            shown = f"- ({target['note']})"
        met = "-" if target["met"] is None else ("yes" if target["met"] else "**no**")
        rows.append((GOAL_NAMES[key], shown, goal, met))
    return _markdown(("what", "measured", "goal", "met"), rows)


def markdown_env_table(results: dict[str, Any]) -> str:
    """Every env, vector env and world-model figure of the results file. The PPO rows
    stay out: PPO on the batched env has one home on a page, the throughput table's row
    (:func:`markdown_throughput`), and its ratio to ``SubprocVecEnv`` is goal d's."""
    rows = [
        (section, case, steps, share, relative)
        for section, case, steps, share, _, _, relative in table_rows(results)
        if section != "ppo"
    ]
    return _markdown(("section", "case", "steps/s", "% of CartPole-v1", "relative"), rows)


def markdown_startup(results: dict[str, Any]) -> str:
    """The start-up and planning figures."""
    lines = []
    if "startup" in results:
        lines.append("- " + startup_text(results, markdown=True))
    planning = results.get("planning")
    if planning is not None:
        lines.append(
            f"- `GreedyOneStep.act`: {planning['median_s'] * 1e3:.2f} ms per move (median of "
            f"{planning['moves']} moves; mean {planning['mean_s'] * 1e3:.2f} ms, "
            f"90th percentile {planning['p90_s'] * 1e3:.2f} ms)."
        )
    return "\n".join(lines)


def startup_text(results: dict[str, Any], markdown: bool = False) -> str:
    """The startup section in a sentence or two (the terminal's notes, the docs' list),
    or what an older results file measured, said to be older."""
    startup, why_not = startup_section(results)
    if startup is None:
        old = results.get("startup") or {}
        measured = (
            f" (the first env step alone: {old['warm_first_step_s']:.2f} s with a warm cache)"
            if "warm_first_step_s" in old
            else ""
        )
        return f"Start-up: {why_not}{measured}; rerun `bearing-env bench --sections startup`."
    env_id = f"`{startup['env_id']}`" if markdown else startup["env_id"]
    separator = " / " if markdown else ", "
    bearing = separator.join(f"{t:.2f}" for t in startup["bearing_env_runs_s"])
    cartpole = separator.join(f"{t:.2f}" for t in startup["cartpole_runs_s"])
    numba = ("**yes**" if markdown else "yes") if startup["numba_imported"] else "no"
    return (
        f"Start-up, a fresh process from start to exit (import bearing_env, make {env_id}, "
        f"reset, one step): {startup['bearing_env_median_s']:.2f} s, "
        f"{startup['ratio_to_cartpole']:.2f}x CartPole-v1 "
        f"({startup['cartpole_median_s']:.2f} s for the same script without bearing_env); "
        f"medians of {startup['runs']} side-by-side pairs ({bearing} s; CartPole-v1 "
        f"{cartpole} s). The first process, with empty HOME and cache folders: "
        f"{startup['cold_bearing_env_s']:.2f} s. numba imported: {numba}."
    )


def markdown_throughput(results: dict[str, Any]) -> str:
    """The throughput section in EnvPool's and gymnax's format."""
    section = results["throughput"]
    header = ("sub-envs", "CartPole-v1 steps/s", "BearingSLAM-v1 steps/s", "ratio")
    return _markdown(header, throughput_rows(section))


def _markdown(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)
