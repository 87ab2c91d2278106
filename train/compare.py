"""``bearing-env compare``: run exploration policies on the same evaluation episodes.

Every policy plays the same episodes: episode ``i`` resets the env with seed
``seed_start + i`` (default ``EVAL_SEED_START = 1_000_000``). Training code keeps its
seeds below that (``TRAINING_SEED_LIMIT``), so evaluation episodes are never trained on.
The policy's own randomness is seeded from the same episode seed through a separate
stream (``bearing_env.agents.base.policy_rng``).

Outputs (in ``--out``):

- ``config.json``: what was run (env id and kwargs, policy specs, seeds);
- ``episodes.jsonl``: one JSON line per finished episode, appended and fsynced as soon as
  the episode ends, so an interrupted run loses no finished episode; ``--resume`` runs
  only the missing ones and gives the same summary as an uninterrupted run;
- ``episodes.csv``, ``summary.json``, ``summary.csv``, ``report.md``: written atomically
  (temporary file + ``os.replace``) from the log;
- ``area_vs_moves.png``, ``error_vs_moves.png``;
- ``timing.json``: policy time per decision (the only output that is not reproducible).

With ``--executor ray`` (the ``ray`` extra) the episodes run as Ray tasks, on a local Ray
instance or, with ``--ray-address ADDRESS``, on a running cluster, with the same seeds,
log, ``--resume`` and summary (``bearing_env.train.ray_executor``).

With ``--workers N`` the episodes run in a pool of spawned processes that exit with the
command: if it is killed (SIGKILL, out of memory), the kernel ends them on Linux
(``prctl(PR_SET_PDEATHSIG)``) and elsewhere they notice their parent is gone within half
a second; multiprocessing's resource tracker then exits too, so nothing is left holding
the caller's stdout or stderr open.

An ``OSError`` while writing (disk full, no permission) ends the command with a one-line
message naming the file and exit status 2. A line of ``episodes.jsonl`` that is not a
valid record, other than a torn last line, is a :class:`CorruptLogError` naming its line
number: delete that line and rerun with ``--resume``, or start again with ``--overwrite``.

Metrics per policy. **Total area** is the sum over landmarks L3, L4, ... of the region
areas (FL units squared), each capped at the env's ``area_cap`` (default 10), which is
also the value of a landmark not yet initialised, exactly as in the reward. An episode
that succeeds early keeps its final map, so its area is carried forward to later move
counts. Reported after 1, 3, 5, 10 and 20 moves (those <= max_moves): the median, and the
mean with a 95% percentile-bootstrap CI (2000 resamples, seeded). Also: success rate
(the env's termination: every region below ``target_area``), moves to success (median
over successful episodes), final landmark error (per episode the mean distance from
centroid to truth over initialised landmarks, FL units; median over episodes),
containment (the fraction of initialised landmarks whose final region holds the truth),
and path length (metres per episode, mean).

    bearing-env compare --env-kwargs scenario=khepera --episodes 200 --workers 2
    bearing-env compare --quick                   # 20 short episodes of the heuristics
    bearing-env compare --episodes 2000 --executor ray --ray-address HEAD_IP:6379
"""

from __future__ import annotations

import argparse
import ast
import contextlib
import csv
import io
import json
import math
import multiprocessing
import os
import signal
import sys
import threading
import time
import zlib
from collections.abc import Iterable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from bearing_env.train.errors import (
    MissingExtraError,
    available,
    fail,
    missing_extra,
    require,
    with_path,
    write_error_message,
)
from numpy.typing import NDArray

from bearing_env.extras import DISTRIBUTIONS, install_command

#: Evaluation episodes use seeds from here up; training seeds stay below it.
EVAL_SEED_START = 1_000_000
#: Training code must keep its env seeds below this (disjoint from evaluation).
TRAINING_SEED_LIMIT = EVAL_SEED_START
#: Move counts at which the total area is reported.
REPORTED_MOVES: tuple[int, ...] = (1, 3, 5, 10, 20)
DEFAULT_POLICIES: tuple[str, ...] = ("random", "parallax", "greedy", "oracle")
QUICK_POLICIES: tuple[str, ...] = ("random", "parallax", "greedy")
DEFAULT_ENV_ID = "bearing_env:BearingSLAM-v0"
DEFAULT_ENV_KWARGS: dict[str, Any] = {"scenario": "khepera"}
QUICK_EPISODES = 20
QUICK_MAX_MOVES = 10
DEFAULT_BOOTSTRAP = 2000
DEFAULT_BOOTSTRAP_SEED = 20050101
LOG_NAME = "episodes.jsonl"
CONFIG_NAME = "config.json"
FORMAT_VERSION = 1
#: Where the episodes run: ``local`` (this process or ``--workers`` processes), ``ray``.
EXECUTORS = ("local", "ray")


# --------------------------------------------------------------------------------------
# Configuration
# --------------------------------------------------------------------------------------


def _json_normalised(value: Any) -> Any:
    """The value as it reads back from JSON (tuples become lists), for comparisons."""
    return json.loads(json.dumps(value))


@dataclass(frozen=True)
class CompareConfig:
    """One comparison: which policies, which env, which episodes.

    ``policies`` maps each report label to its policy spec string (``bearing_env.agents.registry``).
    """

    policies: dict[str, str]
    env_id: str = DEFAULT_ENV_ID
    env_kwargs: dict[str, Any] = field(default_factory=lambda: dict(DEFAULT_ENV_KWARGS))
    episodes: int = 200
    seed_start: int = EVAL_SEED_START
    bootstrap: int = DEFAULT_BOOTSTRAP
    bootstrap_seed: int = DEFAULT_BOOTSTRAP_SEED

    @property
    def seeds(self) -> list[int]:
        return [self.seed_start + index for index in range(self.episodes)]

    def to_json(self) -> dict[str, Any]:
        return {
            "format_version": FORMAT_VERSION,
            "env_id": self.env_id,
            "env_kwargs": _json_normalised(self.env_kwargs),
            "policies": dict(self.policies),
            "episodes": self.episodes,
            "seed_start": self.seed_start,
            "bootstrap": self.bootstrap,
            "bootstrap_seed": self.bootstrap_seed,
        }


def policies_from_specs(specs: Sequence[str]) -> dict[str, str]:
    """Report labels for policy spec strings (unique; duplicates get ``#2``, ``#3``...)."""
    from bearing_env.agents.registry import parse_policy_spec

    labelled: dict[str, str] = {}
    for spec in specs:
        parsed = parse_policy_spec(spec)
        label = parsed.display_name()
        candidate, count = label, 1
        while candidate in labelled:
            count += 1
            candidate = f"{label}#{count}"
        labelled[candidate] = parsed.to_string()
    return labelled


def parse_env_kwargs(items: Sequence[str]) -> dict[str, Any]:
    """``["scenario=khepera", "move_length=0.25"]`` -> kwargs (values as Python literals
    when they parse as one: ``0.25``, ``0.05,0.3`` (a tuple), ``None``; else strings)."""
    kwargs: dict[str, Any] = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise ValueError(f"env kwarg {item!r} is not KEY=VALUE")
        try:
            value: Any = ast.literal_eval(text)
        except (ValueError, SyntaxError):
            value = text
        kwargs[key.strip()] = value
    return kwargs


def make_env(env_id: str, env_kwargs: Mapping[str, Any]) -> gym.Env:
    """``gym.make`` with the TimeLimit matched to ``max_moves`` (see the README)."""
    import bearing_env  # noqa: F401  (registers the ids in spawned workers)

    kwargs = dict(env_kwargs)
    if "max_moves" in kwargs and "max_episode_steps" not in kwargs:
        kwargs["max_episode_steps"] = kwargs["max_moves"]
    return gym.make(env_id, **kwargs)


# --------------------------------------------------------------------------------------
# One episode
# --------------------------------------------------------------------------------------


def _finite_or_none(value: float) -> float | None:
    return float(value) if math.isfinite(value) else None


def run_episode(policy: Any, env: gym.Env, seed: int) -> dict[str, Any]:
    """Play one episode; the per-move record the harness logs (JSON-safe, no timing
    except ``policy_seconds``).

    Per move ``k = 0..n`` (0 = after reset): ``area`` (capped total area),
    ``uninitialised`` (landmarks without a region), ``error`` (mean error over
    initialised landmarks, or None), ``contained`` (initialised landmarks whose region
    holds the truth).
    """
    base = env.unwrapped
    area_cap = float(base.area_cap)
    observation, info = env.reset(seed=seed)
    policy.reset(seed=seed)
    series: dict[str, list[Any]] = {"area": [], "uninitialised": [], "error": [], "contained": []}

    def record(step_info: dict[str, Any]) -> None:
        areas = np.asarray(step_info["landmark_area"], dtype=np.float64)
        initialised = np.isfinite(areas)
        errors = np.asarray(step_info["landmark_error"], dtype=np.float64)[initialised]
        contains = np.asarray(step_info["landmark_contains_truth"], dtype=bool)[initialised]
        series["area"].append(float(np.sum(np.minimum(areas, area_cap))))
        series["uninitialised"].append(int(np.count_nonzero(~initialised)))
        series["error"].append(_finite_or_none(float(np.mean(errors))) if errors.size else None)
        series["contained"].append(int(np.count_nonzero(contains)))

    record(info)
    path_length, frame_changes, inconsistent, policy_seconds = 0.0, 0, 0, 0.0
    terminated = truncated = False
    moves = 0
    while not (terminated or truncated):
        started = time.perf_counter()
        action = policy.act(observation, info)
        policy_seconds += time.perf_counter() - started
        observation, _, terminated, truncated, info = env.step(action)
        moves += 1
        path_length += float(info["path_length"])
        frame_changes += int(bool(info["frame_changed"]))
        inconsistent += int(info["inconsistent"])
        record(info)
    return {
        "seed": int(seed),
        "moves": moves,
        "max_moves": int(base.max_moves),
        "n_mapped": int(base.n_landmarks) - 2,
        "success": bool(terminated),
        "moves_to_success": moves if terminated else None,
        "path_length": path_length,
        "frame_changes": frame_changes,
        "inconsistent": inconsistent,
        **series,
        "policy_seconds": policy_seconds,
    }


# Per-process caches: a worker builds each env and policy once and reuses them (reset
# re-seeds both, so reuse does not change results).
_ENVS: dict[str, gym.Env] = {}
_POLICIES: dict[tuple[str, str, str], Any] = {}


@dataclass(frozen=True)
class EpisodeTask:
    label: str
    spec: str
    env_id: str
    env_kwargs_json: str
    seed: int


def run_task(task: EpisodeTask) -> dict[str, Any]:
    """Run one (policy, seed) episode in this process; the logged record."""
    from bearing_env.agents.registry import make_policy

    env_key = f"{task.env_id}|{task.env_kwargs_json}"
    env = _ENVS.get(env_key)
    if env is None:
        env = _ENVS[env_key] = make_env(task.env_id, json.loads(task.env_kwargs_json))
    policy_key = (task.label, task.spec, env_key)
    policy = _POLICIES.get(policy_key)
    if policy is None:
        policy = _POLICIES[policy_key] = make_policy(task.spec, env)
    return {"policy": task.label, **run_episode(policy, env, task.seed)}


# --------------------------------------------------------------------------------------
# Files
# --------------------------------------------------------------------------------------


def atomic_write_text(path: Path, text: str, newline: str | None = None) -> None:
    """Write ``text`` to ``path`` so readers see the old or the new file, never a part.
    ``newline`` is :func:`open`'s (``""`` for CSV: no line-end translation)."""
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(temporary, "w", encoding="utf-8", newline=newline) as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(temporary, path)
    except OSError as error:
        with contextlib.suppress(OSError):
            temporary.unlink(missing_ok=True)
        raise with_path(error, path) from None


def atomic_save_figure(figure: Any, path: Path, **kwargs: Any) -> None:
    temporary = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(temporary, **kwargs)
        os.replace(temporary, path)
    except OSError as error:
        with contextlib.suppress(OSError):
            temporary.unlink(missing_ok=True)
        if error.filename is None or str(error.filename) == str(temporary):
            error.filename = str(path)
        raise error from None


#: What every record of the episode log must hold (``run_task``'s record).
RECORD_KEYS = ("policy", "seed", "moves", "max_moves", "area", "error", "contained")


class CorruptLogError(ValueError):
    """A line of ``episodes.jsonl`` other than the last is not a valid episode record."""

    def __init__(self, path: Path, line: int, problem: str) -> None:
        self.path, self.line = path, line
        super().__init__(
            f"{path}, line {line}: {problem}. To recover, delete that line (its episode "
            "runs again with --resume), or rerun with --overwrite instead of --resume to "
            "start the comparison again"
        )


class EpisodeLog:
    """The append-only JSON-lines log of finished episodes."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def load(self) -> list[dict[str, Any]]:
        """All complete records. A torn last line (the run was killed mid-write) is
        dropped and the file repaired; any other unreadable line is a
        :class:`CorruptLogError` naming its line number."""
        if not self.path.exists():
            return []
        text = self.path.read_text(encoding="utf-8")
        lines = text.split("\n")
        records, torn = [], False
        for index, line in enumerate(lines):
            if not line.strip():
                continue
            try:
                record = json.loads(line)
            except json.JSONDecodeError as error:
                if index == len(lines) - 1:
                    torn = True  # no newline after it: the write was cut short
                    break
                raise CorruptLogError(self.path, index + 1, f"not valid JSON ({error})") from None
            if not isinstance(record, dict) or any(key not in record for key in RECORD_KEYS):
                needed = ", ".join(RECORD_KEYS)
                raise CorruptLogError(
                    self.path, index + 1, f"not an episode record (it needs {needed})"
                )
            records.append(record)
        if torn:
            atomic_write_text(
                self.path, "".join(json.dumps(r, allow_nan=False) + "\n" for r in records)
            )
        return records

    def append(self, record: dict[str, Any]) -> None:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with open(self.path, "a", encoding="utf-8") as handle:
                handle.write(json.dumps(record, allow_nan=False) + "\n")
                handle.flush()
                os.fsync(handle.fileno())
        except OSError as error:
            raise with_path(error, self.path) from None

    def clear(self) -> None:
        if self.path.exists():
            self.path.unlink()


# --------------------------------------------------------------------------------------
# Statistics
# --------------------------------------------------------------------------------------


def bootstrap_mean_ci(
    values: NDArray[np.float64], rng: np.random.Generator, resamples: int, level: float = 0.95
) -> tuple[float, float]:
    """Percentile bootstrap CI of the mean."""
    n = values.size
    if n == 0:
        return (math.nan, math.nan)
    if n == 1:
        return (float(values[0]), float(values[0]))
    means = values[rng.integers(0, n, size=(resamples, n))].mean(axis=1)
    tail = 100.0 * (1.0 - level) / 2.0
    low, high = np.percentile(means, [tail, 100.0 - tail])
    return (float(low), float(high))


def _stat_rng(bootstrap_seed: int, label: str, metric: str, move: int) -> np.random.Generator:
    # Keyed by the label (not the policy's position), so adding a policy to a comparison
    # does not change the others' intervals.
    key = zlib.crc32(f"{label}|{metric}".encode())
    return np.random.default_rng([bootstrap_seed, key, move])


def _series_matrix(
    records: Sequence[Mapping[str, Any]], key: str, length: int
) -> NDArray[np.float64]:
    """(episodes, length) values per move; None -> NaN; carried forward after the end."""
    matrix = np.full((len(records), length), np.nan)
    for row, record in enumerate(records):
        values = [np.nan if v is None else float(v) for v in record[key]]
        values = values[:length] + [values[-1]] * max(0, length - len(values))
        matrix[row] = values
    return matrix


def _nan_to_none(value: float) -> float | None:
    return None if value is None or not math.isfinite(value) else float(value)


def _distribution(
    values: NDArray[np.float64], rng: np.random.Generator, resamples: int
) -> dict[str, Any]:
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return {"n": 0, "median": None, "mean": None, "ci_low": None, "ci_high": None}
    low, high = bootstrap_mean_ci(finite, rng, resamples)
    return {
        "n": int(finite.size),
        "median": float(np.median(finite)),
        "mean": float(np.mean(finite)),
        "ci_low": _nan_to_none(low),
        "ci_high": _nan_to_none(high),
    }


def summarise_policy(
    label: str, records: Sequence[Mapping[str, Any]], config: CompareConfig
) -> dict[str, Any]:
    """Every reported number for one policy (deterministic given the records)."""
    records = sorted(records, key=lambda r: r["seed"])
    max_moves = max(int(r["max_moves"]) for r in records)
    length = max_moves + 1
    areas = _series_matrix(records, "area", length)
    errors = _series_matrix(records, "error", length)
    resamples = config.bootstrap

    area_after = {
        str(k): _distribution(
            areas[:, k], _stat_rng(config.bootstrap_seed, label, "area", k), resamples
        )
        for k in REPORTED_MOVES
        if k <= max_moves
    }
    curves: dict[str, list[float | None]] = {
        key: []
        for key in (
            "area_median",
            "area_mean",
            "area_ci_low",
            "area_ci_high",
            "error_median",
            "error_mean",
            "error_ci_low",
            "error_ci_high",
        )
    }
    for k in range(length):
        for metric, matrix in (("area", areas), ("error", errors)):
            stats = _distribution(
                matrix[:, k],
                _stat_rng(config.bootstrap_seed, label, f"{metric}_curve", k),
                resamples,
            )
            for name in ("median", "mean", "ci_low", "ci_high"):
                curves[f"{metric}_{name}"].append(stats[name])

    success = np.array([bool(r["success"]) for r in records])
    moves_to_success = np.array(
        [r["moves_to_success"] for r in records if r["moves_to_success"] is not None], float
    )
    final_errors = errors[:, -1]
    n_mapped = np.array([int(r["n_mapped"]) for r in records])
    final_initialised = n_mapped - np.array([int(r["uninitialised"][-1]) for r in records])
    contained = np.array([int(r["contained"][-1]) for r in records])
    path_lengths = np.array([float(r["path_length"]) for r in records])
    moves = np.array([int(r["moves"]) for r in records])
    return {
        "label": label,
        "spec": config.policies[label],
        "episodes": len(records),
        "max_moves": max_moves,
        "area_after": area_after,
        "success_rate": float(success.mean()),
        "moves_to_success_median": _nan_to_none(
            float(np.median(moves_to_success)) if moves_to_success.size else math.nan
        ),
        "moves_to_success_mean": _nan_to_none(
            float(np.mean(moves_to_success)) if moves_to_success.size else math.nan
        ),
        "final_error": _distribution(
            final_errors, _stat_rng(config.bootstrap_seed, label, "final_error", 0), resamples
        ),
        "containment_rate": (
            float(contained.sum() / final_initialised.sum()) if final_initialised.sum() else None
        ),
        "uninitialised_rate": float(1.0 - final_initialised.sum() / n_mapped.sum()),
        "path_length_mean": float(path_lengths.mean()),
        "frame_change_rate": float(sum(int(r["frame_changes"]) for r in records) / moves.sum()),
        "inconsistent_per_episode": float(np.mean([int(r["inconsistent"]) for r in records])),
        "curves": curves,
    }


def summarise(records: Sequence[Mapping[str, Any]], config: CompareConfig) -> dict[str, Any]:
    """The summary of a comparison: the config and one entry per policy, in config order."""
    wanted = set(config.seeds)
    by_label: dict[str, list[Mapping[str, Any]]] = {label: [] for label in config.policies}
    for record in records:
        if record["policy"] in by_label and record["seed"] in wanted:
            by_label[record["policy"]].append(record)
    return {
        "config": config.to_json(),
        "policies": {
            label: summarise_policy(label, rows, config) for label, rows in by_label.items() if rows
        },
    }


# --------------------------------------------------------------------------------------
# Reports
# --------------------------------------------------------------------------------------


def _fmt(value: float | None, digits: int = 3) -> str:
    return "-" if value is None else f"{value:.{digits}g}"


def _display_label(label: str, config: CompareConfig) -> str:
    from bearing_env.agents.registry import POLICY_CLASSES, parse_policy_spec

    cls = POLICY_CLASSES[parse_policy_spec(config.policies[label]).kind]
    return f"{label} (privileged)" if getattr(cls, "privileged", False) else label


def _reference_label(config: CompareConfig) -> str | None:
    """The random polygonal policy the others are compared with, if it was run."""
    from bearing_env.agents.registry import parse_policy_spec

    for label, spec in config.policies.items():
        if parse_policy_spec(spec).kind == "random":
            return label
    return None


def _reported_moves(summary: Mapping[str, Any]) -> list[int]:
    return sorted({int(k) for p in summary["policies"].values() for k in p["area_after"]})


def area_median_rows(
    summary: Mapping[str, Any], config: CompareConfig
) -> tuple[list[str], list[list[str]]]:
    """Median total area after each reported move count, and the ratio to random
    polygonal at 10 moves (or the last reported count)."""
    policies = summary["policies"]
    moves = _reported_moves(summary)
    header = ["policy", *[f"after {k}" for k in moves]]
    reference = _reference_label(config)
    ratio_at = 10 if 10 in moves else (moves[-1] if moves else None)
    reference_median = None
    if reference in policies and ratio_at is not None:
        reference_median = policies[reference]["area_after"][str(ratio_at)]["median"]
        header.append(f"random ÷ policy (median, {ratio_at} moves)")
    rows = []
    for label, stats in policies.items():
        cells = [_display_label(label, config)]
        for k in moves:
            entry = stats["area_after"].get(str(k))
            cells.append("-" if entry is None else _fmt(entry["median"]))
        if reference_median is not None:
            median = stats["area_after"][str(ratio_at)]["median"]
            cells.append("-" if not median else f"{reference_median / median:.1f}x")
        rows.append(cells)
    return header, rows


def area_mean_rows(
    summary: Mapping[str, Any], config: CompareConfig
) -> tuple[list[str], list[list[str]]]:
    """Mean total area [95% bootstrap CI] after each reported move count."""
    moves = _reported_moves(summary)
    header = ["policy", *[f"after {k}" for k in moves]]
    rows = []
    for label, stats in summary["policies"].items():
        cells = [_display_label(label, config)]
        for k in moves:
            entry = stats["area_after"].get(str(k))
            if entry is None or entry["mean"] is None:
                cells.append("-")
            else:
                cells.append(
                    f"{_fmt(entry['mean'])} [{_fmt(entry['ci_low'])}, {_fmt(entry['ci_high'])}]"
                )
        rows.append(cells)
    return header, rows


def outcome_table_rows(
    summary: Mapping[str, Any], config: CompareConfig, timing: Mapping[str, float] | None = None
) -> tuple[list[str], list[list[str]]]:
    header = [
        "policy",
        "episodes",
        "success",
        "moves to success (median)",
        "final error (median, FL units)",
        "containment",
        "path length (m, mean)",
        "moves that changed frames",
    ]
    if timing is not None:
        header.append("policy ms/move")
    rows = []
    for label, stats in summary["policies"].items():
        cells = [
            _display_label(label, config),
            str(stats["episodes"]),
            f"{100.0 * stats['success_rate']:.1f}%",
            _fmt(stats["moves_to_success_median"]),
            _fmt(stats["final_error"]["median"]),
            _percent(stats["containment_rate"]),
            f"{stats['path_length_mean']:.2f}",
            f"{100.0 * stats['frame_change_rate']:.0f}%",
        ]
        if timing is not None:
            cells.append(_fmt(timing.get(label), 2))
        rows.append(cells)
    return header, rows


def _percent(fraction: float | None) -> str:
    return "-" if fraction is None else f"{100.0 * fraction:.1f}%"


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def print_tables(
    summary: Mapping[str, Any], config: CompareConfig, timing: Mapping[str, float]
) -> None:
    env_text = " ".join(f"{k}={v}" for k, v in config.env_kwargs.items())
    tables = (
        (
            f"Median total area (FL units²) — {config.env_id} {env_text}, "
            f"{config.episodes} episodes",
            area_median_rows(summary, config),
        ),
        ("Mean total area [95% bootstrap CI]", area_mean_rows(summary, config)),
        ("Outcomes", outcome_table_rows(summary, config, timing)),
    )
    if not available("rich"):  # a plain install: the same tables as markdown
        for title, (header, rows) in tables:
            print(f"\n{title}\n\n{markdown_table(header, rows)}")
        return
    from rich.console import Console
    from rich.table import Table

    console = Console()
    if not console.is_terminal:
        console = Console(width=160)  # a log file: no need to fold the tables
    for title, (header, rows) in tables:
        table = Table(title=title, show_lines=False)
        for index, column in enumerate(header):
            table.add_column(column, no_wrap=index == 0, overflow="fold")
        for row in rows:
            table.add_row(*row)
        console.print(table)


def report_markdown(
    summary: Mapping[str, Any], config: CompareConfig, command: str | None, plots: bool = True
) -> str:
    env_text = ", ".join(f"`{k}={v!r}`" for k, v in config.env_kwargs.items()) or "defaults"
    seeds = config.seeds
    parts = [
        "# Exploration policies compared",
        "",
        f"Env `{config.env_id}` ({env_text}); {config.episodes} evaluation episodes per "
        f"policy, seeds {seeds[0]}..{seeds[-1]}.",
        "",
        "Total area: the sum of the landmark region areas (FL units², |L1 - L2| = 1), each "
        "capped at `area_cap`, which also counts for a landmark not yet initialised.",
        "",
        "Median total area after n moves:",
        "",
        markdown_table(*area_median_rows(summary, config)),
        "",
        "Mean total area [95% bootstrap CI]:",
        "",
        markdown_table(*area_mean_rows(summary, config)),
        "",
        markdown_table(*outcome_table_rows(summary, config)),
        "",
    ]
    if plots:
        parts += [
            "![total area versus moves](area_vs_moves.png)",
            "",
            "![landmark error versus moves](error_vs_moves.png)",
            "",
        ]
    if command:
        parts += ["Regenerate with:", "", "```bash", command, "```", ""]
    return "\n".join(parts)


def summary_csv(summary: Mapping[str, Any]) -> str:
    header = ["policy", "spec", "episodes"]
    moves = sorted({int(k) for p in summary["policies"].values() for k in p["area_after"]})
    for k in moves:
        header += [f"area{k}_median", f"area{k}_mean", f"area{k}_ci_low", f"area{k}_ci_high"]
    header += [
        "success_rate",
        "moves_to_success_median",
        "final_error_median",
        "final_error_mean",
        "containment_rate",
        "uninitialised_rate",
        "path_length_mean",
        "frame_change_rate",
        "inconsistent_per_episode",
    ]
    rows: list[list[Any]] = []
    for label, stats in summary["policies"].items():
        row: list[Any] = [label, stats["spec"], stats["episodes"]]
        for k in moves:
            entry = stats["area_after"].get(str(k), {})
            row += [entry.get(name) for name in ("median", "mean", "ci_low", "ci_high")]
        row += [
            stats["success_rate"],
            stats["moves_to_success_median"],
            stats["final_error"]["median"],
            stats["final_error"]["mean"],
            stats["containment_rate"],
            stats["uninitialised_rate"],
            stats["path_length_mean"],
            stats["frame_change_rate"],
            stats["inconsistent_per_episode"],
        ]
        rows.append(row)
    return csv_text(header, rows)


def _csv_cell(value: Any) -> str:
    """A cell's text: empty for a missing value, the shortest exact repr for a float."""
    if value is None:
        return ""
    return repr(value) if isinstance(value, float) else str(value)


def csv_text(header: Sequence[str], rows: Iterable[Sequence[Any]]) -> str:
    """CSV (RFC 4180 quoting by the stdlib ``csv`` module, ``\\n`` line ends) of a header
    and rows. Write it with ``newline=""`` so quoted line breaks stay as they are."""
    buffer = io.StringIO(newline="")
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(header)
    writer.writerows([_csv_cell(value) for value in row] for row in rows)
    return buffer.getvalue()


def episodes_csv(records: Sequence[Mapping[str, Any]], config: CompareConfig) -> str:
    order = {label: index for index, label in enumerate(config.policies)}
    rows = sorted(
        (r for r in records if r["policy"] in order),
        key=lambda r: (order[r["policy"]], r["seed"]),
    )
    max_moves = max((int(r["max_moves"]) for r in rows), default=0)
    header = [
        "policy",
        "seed",
        "moves",
        "success",
        "moves_to_success",
        "path_length",
        "frame_changes",
        "inconsistent",
        "final_error",
        "final_contained",
        *[f"area{k}" for k in range(max_moves + 1)],
    ]
    table: list[list[Any]] = []
    for r in rows:
        area = list(r["area"]) + [r["area"][-1]] * (max_moves + 1 - len(r["area"]))
        cells = [
            r["policy"],
            r["seed"],
            r["moves"],
            r["success"],
            r["moves_to_success"],
            r["path_length"],
            r["frame_changes"],
            r["inconsistent"],
            r["error"][-1],
            r["contained"][-1],
            *area,
        ]
        table.append(cells)
    return csv_text(header, table)


def plot_curves(summary: Mapping[str, Any], config: CompareConfig, out: Path) -> list[Path]:
    """Total area (log) and landmark error versus moves, mean with 95% CI band, median dashed."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    written = []
    colours = plt.get_cmap("tab10").colors
    env_text = ", ".join(f"{k}={v}" for k, v in config.env_kwargs.items())
    for metric, ylabel, filename in (
        ("area", "total area (FL units², log)", "area_vs_moves.png"),
        ("error", "mean error of initialised landmarks (FL units, log)", "error_vs_moves.png"),
    ):
        figure, axes = plt.subplots(figsize=(7.0, 4.3), dpi=110)
        for index, (label, stats) in enumerate(summary["policies"].items()):
            curves = stats["curves"]
            x = np.arange(len(curves[f"{metric}_mean"]))

            def array(key: str, curves: Mapping[str, Any] = curves) -> NDArray[np.float64]:
                return np.array([np.nan if v is None else v for v in curves[key]], float)

            colour = colours[index % len(colours)]
            display = _display_label(label, config)
            axes.plot(x, array(f"{metric}_mean"), color=colour, lw=2, label=f"{display}: mean")
            axes.fill_between(
                x,
                array(f"{metric}_ci_low"),
                array(f"{metric}_ci_high"),
                color=colour,
                alpha=0.2,
                lw=0,
            )
            axes.plot(x, array(f"{metric}_median"), color=colour, lw=1.2, ls="--")
        axes.set_yscale("log")
        axes.xaxis.set_major_locator(MaxNLocator(integer=True))
        axes.set_xlabel("moves")
        axes.set_ylabel(ylabel)
        axes.set_title(
            f"{config.env_id.split(':')[-1]} ({env_text}), {config.episodes} episodes\n"
            "solid: mean with 95% bootstrap CI; dashed: median",
            fontsize=9,
        )
        axes.grid(True, which="both", alpha=0.3)
        axes.legend(fontsize=8)
        figure.tight_layout()
        path = out / filename
        atomic_save_figure(figure, path)
        plt.close(figure)
        written.append(path)
    return written


# --------------------------------------------------------------------------------------
# The run
# --------------------------------------------------------------------------------------


class RunMismatchError(ValueError):
    """``--resume`` on an output folder that holds a different comparison."""


def _check_resumable(existing: Mapping[str, Any], config: CompareConfig) -> None:
    wanted = config.to_json()
    for key in ("env_id", "env_kwargs"):
        if existing.get(key) != wanted[key]:
            raise RunMismatchError(
                f"cannot resume: the output folder ran {key}={existing.get(key)!r}, "
                f"this run asks for {wanted[key]!r}; use another --out"
            )
    for label, spec in wanted["policies"].items():
        old = existing.get("policies", {}).get(label)
        if old is not None and old != spec:
            raise RunMismatchError(
                f"cannot resume: policy {label!r} was {old!r} and is now {spec!r}; "
                "give it another label (spec option label=...) or use another --out"
            )


class _NoProgress:
    """Stands in for a tqdm bar when tqdm is not installed."""

    def __enter__(self) -> _NoProgress:
        return self

    def __exit__(self, *exc_info: object) -> None:
        return None

    def update(self, n: int = 1) -> None:
        pass


def _progress(total: int, initial: int, enabled: bool) -> Any:
    if not available("tqdm"):
        return _NoProgress()
    from tqdm.auto import tqdm

    return tqdm(
        total=total,
        initial=initial,
        disable=not enabled,
        unit="episode",
        dynamic_ncols=True,
        desc="compare",
    )


def _pending_tasks(config: CompareConfig, done: set[tuple[str, int]]) -> list[EpisodeTask]:
    kwargs_json = json.dumps(_json_normalised(config.env_kwargs), sort_keys=True)
    # Seed-major order: an interrupted run has every policy on the same first seeds.
    return [
        EpisodeTask(label, spec, config.env_id, kwargs_json, seed)
        for seed in config.seeds
        for label, spec in config.policies.items()
        if (label, seed) not in done
    ]


#: How often a worker checks that its parent is alive (where ``PR_SET_PDEATHSIG`` is missing).
PARENT_POLL_SECONDS = 0.5
_PR_SET_PDEATHSIG = 1


def _exit_with_parent(parent_pid: int) -> None:
    """Worker initializer: end this worker when the ``compare`` process that started it dies.

    A ``ProcessPoolExecutor`` worker waits on its task queue, which never reports EOF when
    the parent is SIGKILLed (the workers hold both ends of it): it would live on, holding
    the caller's stdout and stderr open, and so would multiprocessing's resource tracker,
    which exits once every process that shares its pipe has gone. On Linux the kernel
    sends the worker SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``); elsewhere,
    and as a fallback, a daemon thread sees ``os.getppid()`` change within
    :data:`PARENT_POLL_SECONDS` and exits.
    """
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent_pid:  # the parent died before the prctl
        os._exit(1)

    def watch() -> None:
        while os.getppid() == parent_pid:
            time.sleep(PARENT_POLL_SECONDS)
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def _run_pending(
    tasks: Sequence[EpisodeTask],
    workers: int,
    log: EpisodeLog,
    bar: Any,
    executor: str = "local",
    ray_address: str | None = None,
) -> Iterator[dict[str, Any]]:
    if executor == "ray":  # Ray tasks on this machine or a cluster (train/ray_executor.py)
        from bearing_env.train.ray_executor import run_on_ray

        for record in run_on_ray(tasks, address=ray_address):
            log.append(record)
            bar.update()
            yield record
        return
    if workers <= 1:
        for task in tasks:
            record = run_task(task)
            log.append(record)
            bar.update()
            yield record
        return
    # spawn: torch and pygame state must not be forked; each worker imports afresh.
    context = multiprocessing.get_context("spawn")
    executor = ProcessPoolExecutor(
        max_workers=workers,
        mp_context=context,
        initializer=_exit_with_parent,
        initargs=(os.getpid(),),
    )
    try:
        futures = [executor.submit(run_task, task) for task in tasks]
        for future in as_completed(futures):
            record = future.result()
            log.append(record)
            bar.update()
            yield record
    finally:
        executor.shutdown(wait=True, cancel_futures=True)


@dataclass
class CompareResult:
    summary: dict[str, Any]
    records: list[dict[str, Any]]
    complete: bool
    out: Path
    timing: dict[str, float]


def run_comparison(
    config: CompareConfig,
    out: Path,
    workers: int = 1,
    resume: bool = False,
    overwrite: bool = False,
    stop_after: int | None = None,
    progress: bool = True,
    plots: bool = True,
    command: str | None = None,
    executor: str = "local",
    ray_address: str | None = None,
) -> CompareResult:
    """Run (or finish) a comparison and write every output file.

    Args:
        config: what to run.
        out: the output folder.
        workers: processes for the episodes (1: in this process).
        resume: keep the finished episodes of a previous run in ``out`` and run the rest.
        overwrite: discard a previous run in ``out``.
        stop_after: run at most this many new episodes, then write the outputs of what is
            done (``complete`` is False if episodes remain; ``resume`` finishes them).
        progress: show a progress bar.
        plots: write the PNG plots.
        command: the command line to quote in the report.
        executor: ``"local"`` (``workers`` processes) or ``"ray"`` (Ray tasks, see
            ``bearing_env.train.ray_executor``; ``workers`` is not used).
        ray_address: with ``executor="ray"``, the cluster to join (default: this
            process's Ray instance, or a new local one).
    """
    if executor not in EXECUTORS:
        raise ValueError(f"executor must be one of {EXECUTORS}, got {executor!r}")
    out = Path(out)
    log = EpisodeLog(out / LOG_NAME)
    config_path = out / CONFIG_NAME
    if log.path.exists() and not (resume or overwrite):
        raise FileExistsError(
            f"{out} already holds a comparison ({LOG_NAME}); pass --resume to finish it "
            "or --overwrite to start again"
        )
    if overwrite and not resume:
        log.clear()
    if resume and config_path.exists():
        try:
            existing = json.loads(config_path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as error:
            raise RunMismatchError(
                f"cannot resume: {config_path} is not valid JSON ({error}); rerun with "
                "--overwrite instead of --resume to start the comparison again"
            ) from None
        _check_resumable(existing, config)
    atomic_write_text(config_path, json.dumps(config.to_json(), indent=2) + "\n")

    records = log.load()
    done = {(r["policy"], int(r["seed"])) for r in records}
    tasks = _pending_tasks(config, done)
    if stop_after is not None:
        tasks = tasks[: max(0, stop_after)]
    n_total = len(config.seeds) * len(config.policies)
    with _progress(n_total, n_total - len(_pending_tasks(config, done)), progress) as bar:
        for record in _run_pending(tasks, workers, log, bar, executor, ray_address):
            records.append(record)

    summary = summarise(records, config)
    wanted = {(label, seed) for label in config.policies for seed in config.seeds}
    finished = {(r["policy"], int(r["seed"])) for r in records} & wanted
    timing = _timing(records, config)
    _write_outputs(summary, records, config, out, timing, plots, command)
    return CompareResult(summary, records, finished == wanted, out, timing)


def _timing(records: Sequence[Mapping[str, Any]], config: CompareConfig) -> dict[str, float]:
    """Milliseconds of policy time per move, per policy (machine-dependent)."""
    timing = {}
    for label in config.policies:
        rows = [r for r in records if r["policy"] == label]
        moves = sum(int(r["moves"]) for r in rows)
        if moves:
            timing[label] = 1000.0 * sum(float(r["policy_seconds"]) for r in rows) / moves
    return timing


def _write_outputs(
    summary: dict[str, Any],
    records: Sequence[Mapping[str, Any]],
    config: CompareConfig,
    out: Path,
    timing: Mapping[str, float],
    plots: bool,
    command: str | None,
) -> None:
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=1, allow_nan=False) + "\n")
    atomic_write_text(out / "timing.json", json.dumps({"ms_per_move": timing}, indent=1) + "\n")
    if not summary["policies"]:
        return
    atomic_write_text(out / "summary.csv", summary_csv(summary), newline="")
    atomic_write_text(out / "episodes.csv", episodes_csv(records, config), newline="")
    if plots and not available("matplotlib"):
        print(f"note: no plots: {MissingExtraError('matplotlib', 'plotting')}", file=sys.stderr)
        plots = False
    atomic_write_text(out / "report.md", report_markdown(summary, config, command, plots))
    if plots:
        plot_curves(summary, config, out)


# --------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="bearing-env compare",
        description="Compare exploration policies on the same evaluation episodes.",
        epilog=(
            "Policy specs: random, parallax, greedy, oracle, sb3:path=MODEL.zip, with options "
            "as NAME:key=value,... (e.g. random:length=0.25, greedy:n_turns=16). "
            f"Evaluation seeds start at {EVAL_SEED_START:,}; training seeds stay below."
        ),
    )
    parser.add_argument(
        "--policies",
        nargs="+",
        default=None,
        metavar="SPEC",
        help=f"policy specs (default: {' '.join(DEFAULT_POLICIES)}, and every model shipped "
        "in agents/pretrained/ that was trained on this env id and env kwargs)",
    )
    parser.add_argument("--env", default=DEFAULT_ENV_ID, help="env id (default %(default)s)")
    parser.add_argument(
        "--env-kwargs",
        nargs="*",
        default=None,
        metavar="KEY=VALUE",
        help="env kwargs (default: scenario=khepera)",
    )
    parser.add_argument(
        "--episodes",
        type=int,
        default=None,
        help="evaluation episodes per policy (default 200; --quick 20)",
    )
    parser.add_argument(
        "--seed-start",
        type=int,
        default=EVAL_SEED_START,
        help="seed of the first evaluation episode (default %(default)s)",
    )
    parser.add_argument(
        "--workers", type=int, default=1, help="processes to run episodes in (default %(default)s)"
    )
    parser.add_argument(
        "--executor",
        choices=EXECUTORS,
        default="local",
        help="local: this process, or --workers processes (default); ray: Ray tasks on a "
        "local Ray instance or the cluster of --ray-address (the ray extra)",
    )
    parser.add_argument(
        "--ray-address",
        default=None,
        metavar="ADDRESS",
        help="with --executor ray: the running cluster to join (HOST:PORT, or auto)",
    )
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output folder (default outputs/compare; with --quick outputs/compare_quick)",
    )
    parser.add_argument(
        "--resume", action="store_true", help="finish the comparison already in --out"
    )
    parser.add_argument(
        "--overwrite", action="store_true", help="discard the comparison already in --out"
    )
    parser.add_argument(
        "--stop-after",
        type=int,
        default=None,
        metavar="N",
        help="run at most N new episodes, then write the outputs (resume later)",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help=f"a short run: {QUICK_EPISODES} episodes of {QUICK_MAX_MOVES} moves, "
        f"policies {' '.join(QUICK_POLICIES)}, Khepera; overwrites its output",
    )
    parser.add_argument(
        "--bootstrap",
        type=int,
        default=DEFAULT_BOOTSTRAP,
        help="bootstrap resamples for the CIs (default %(default)s)",
    )
    parser.add_argument("--bootstrap-seed", type=int, default=DEFAULT_BOOTSTRAP_SEED)
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    parser.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    return parser


def matching_pretrained(env_id: str, env_kwargs: dict[str, Any]) -> list[str]:
    """Specs of the shipped models trained on this env id and these env kwargs.

    ``max_moves`` is ignored: it only sets how long an episode runs.
    """
    from bearing_env.agents import pretrained_names, pretrained_record

    def plain(kwargs: dict[str, Any]) -> dict[str, Any]:
        # Through JSON, as the record was written: tuples and lists compare equal.
        kept = {key: value for key, value in kwargs.items() if key != "max_moves"}
        return dict(json.loads(json.dumps(kept)))

    wanted = env_id.split(":")[-1]
    specs = []
    for name in pretrained_names():
        record = pretrained_record(name)
        trained_on = str(record.get("env_id", "")).split(":")[-1]
        if trained_on == wanted and plain(dict(record.get("env_kwargs", {}))) == plain(env_kwargs):
            specs.append(f"pretrained:{name}")
    return specs


def shipped_policies(env_id: str, env_kwargs: dict[str, Any]) -> list[str]:
    """The shipped models to compare by default: :func:`matching_pretrained`, or none,
    with a note on stderr, when stable-baselines3 (the ``train`` extra) is missing."""
    specs = matching_pretrained(env_id, env_kwargs)
    if specs and not available("stable_baselines3", "torch"):
        missing = "stable_baselines3" if not available("stable_baselines3") else "torch"
        names = ", ".join(spec.split(":", 1)[1] for spec in specs)
        package = DISTRIBUTIONS.get(missing, missing)
        print(
            f"note: skipped the shipped models ({names}): they need the package "
            f"'{package}', which is not installed; install the train extra: "
            f"{install_command('train')}",
            file=sys.stderr,
        )
        return []
    return specs


def config_from_args(args: argparse.Namespace) -> tuple[CompareConfig, Path]:
    env_kwargs = dict(DEFAULT_ENV_KWARGS)
    if args.env_kwargs is not None:
        env_kwargs = parse_env_kwargs(args.env_kwargs)
    if args.quick:
        env_kwargs.setdefault("max_moves", QUICK_MAX_MOVES)
    policies = args.policies or [
        *(QUICK_POLICIES if args.quick else DEFAULT_POLICIES),
        *shipped_policies(args.env, env_kwargs),
    ]
    episodes = args.episodes or (QUICK_EPISODES if args.quick else 200)
    if episodes < 1:
        raise ValueError(f"--episodes must be >= 1, got {episodes}")
    out = args.out or Path("outputs/compare_quick" if args.quick else "outputs/compare")
    config = CompareConfig(
        policies=policies_from_specs(policies),
        env_id=args.env,
        env_kwargs=env_kwargs,
        episodes=episodes,
        seed_start=args.seed_start,
        bootstrap=args.bootstrap,
        bootstrap_seed=args.bootstrap_seed,
    )
    return config, out


#: Options that change how a run proceeds but not its results: left out of the command
#: the report quotes (a resumed run regenerates with the plain command).
_PROCESS_ONLY_FLAGS = ("--resume", "--overwrite", "--no-progress")
_PROCESS_ONLY_OPTIONS = ("--stop-after", "--executor", "--ray-address")


def reproducing_command(argv: Sequence[str]) -> str:
    """``bearing-env compare ...`` with the arguments that determine the results."""
    kept: list[str] = []
    skip_value = False
    for arg in argv:
        if skip_value:
            skip_value = False
        elif arg in _PROCESS_ONLY_FLAGS:
            pass
        elif arg in _PROCESS_ONLY_OPTIONS:
            skip_value = True
        elif not arg.startswith(tuple(f"{option}=" for option in _PROCESS_ONLY_OPTIONS)):
            kept.append(arg)
    return " ".join(["bearing-env compare", *kept])


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if args.executor != "ray" and args.ray_address is not None:
        parser.error("--ray-address needs --executor ray")
    if args.executor == "ray" and args.workers != 1:
        parser.error("--workers is for --executor local; Ray runs as many episodes as the "
                     "cluster has CPUs")
    try:
        if args.executor == "ray":
            require("ray", "--executor ray", extra="ray")
        config, out = config_from_args(args)
        # Fail fast on a bad env or policy spec, before any worker starts.
        from bearing_env.agents.registry import make_policy

        with contextlib.closing(make_env(config.env_id, config.env_kwargs)) as env:
            for spec in config.policies.values():
                make_policy(spec, env)
    except (ValueError, TypeError, FileNotFoundError) as error:
        parser.error(str(error))
    except ImportError as error:  # an sb3: policy without stable-baselines3, ...
        clear = missing_extra(error, "this comparison")
        if clear is None:
            raise
        fail(parser.prog, str(clear))
    command = reproducing_command(sys.argv[1:] if argv is None else list(argv))
    started = time.perf_counter()
    try:
        result = run_comparison(
            config,
            out,
            workers=args.workers,
            resume=args.resume,
            overwrite=args.overwrite or args.quick,
            stop_after=args.stop_after,
            progress=not args.no_progress,
            plots=not args.no_plots,
            command=command,
            executor=args.executor,
            ray_address=args.ray_address,
        )
    except FileExistsError as error:
        if error.errno is None:  # raised above: the folder holds a comparison already
            parser.error(str(error))
        fail(parser.prog, write_error_message(error, out, "--out"))
    except (RunMismatchError, CorruptLogError) as error:
        fail(parser.prog, str(error))
    except OSError as error:
        fail(parser.prog, write_error_message(error, out, "--out"))
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: finished episodes are saved in {out / LOG_NAME}; "
            "rerun the same command with --resume to finish",
            file=sys.stderr,
        )
        raise SystemExit(130) from None
    print_tables(result.summary, config, result.timing)
    status = "complete" if result.complete else "INCOMPLETE (rerun with --resume)"
    print(
        f"{status}: {len(result.records)} episodes in {out} "
        f"({time.perf_counter() - started:.0f} s); report: {out / 'report.md'}"
    )


if __name__ == "__main__":
    main()
