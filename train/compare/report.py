"""The reports of a comparison, from its summary and records: the terminal tables,
``report.md``, ``summary.csv`` and ``episodes.csv`` (stdlib ``csv``), the PNG plots,
``summary.json`` and ``timing.json``, each written atomically.
"""

from __future__ import annotations

import csv
import io
import json
import sys
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env.train.common.errors import (
    MissingExtraError,
    available,
)
from bearing_env.train.common.files import atomic_save_figure, atomic_write_text
from bearing_env.train.common.tables import print_table
from bearing_env.train.compare.config import CompareConfig


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


def _tail_moves(moves: Sequence[int]) -> list[int]:
    """The move counts the worst-case table reports: 10 and 20 where run, else the last."""
    wanted = [k for k in (10, 20) if k in moves]
    return wanted or list(moves[-1:])


def area_tail_rows(
    summary: Mapping[str, Any], config: CompareConfig
) -> tuple[list[str], list[list[str]]]:
    """The worst case beside the median: the 90th percentile of the total area and the
    mean of the worst 5% of the episodes, after 10 and 20 moves (or the last count)."""
    moves = _tail_moves(_reported_moves(summary))
    header = ["policy"]
    for k in moves:
        header += [f"median, {k}", f"90th pct, {k}", f"worst 5% mean, {k}"]
    rows = []
    for label, stats in summary["policies"].items():
        cells = [_display_label(label, config)]
        for k in moves:
            entry = stats["area_after"].get(str(k), {})
            cells += [_fmt(entry.get(name)) for name in ("median", "p90", "worst5_mean")]
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
        ("Worst case of the total area", area_tail_rows(summary, config)),
        ("Outcomes", outcome_table_rows(summary, config, timing)),
    )
    if not available("rich"):  # a plain install: the same tables as markdown
        for title, (header, rows) in tables:
            print(f"\n{title}\n\n{markdown_table(header, rows)}")
        return
    from rich.console import Console

    console = Console()
    if not console.is_terminal:
        console = Console(width=160)  # a log file: no need to fold the tables
    for title, (header, rows) in tables:
        print_table(title, header, rows, console)


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
        "Worst case of the total area: the 90th percentile and the mean of the worst 5% of "
        "the episodes, beside the median:",
        "",
        markdown_table(*area_tail_rows(summary, config)),
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


#: The total-area statistics the CSV gives per reported move count.
AREA_CSV_STATS = ("median", "mean", "ci_low", "ci_high", "p90", "worst5_mean")


def summary_csv(summary: Mapping[str, Any]) -> str:
    header = ["policy", "spec", "episodes"]
    moves = sorted({int(k) for p in summary["policies"].values() for k in p["area_after"]})
    for k in moves:
        header += [f"area{k}_{name}" for name in AREA_CSV_STATS]
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
            row += [entry.get(name) for name in AREA_CSV_STATS]
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
    colours = plt.get_cmap("tab10").colors  # type: ignore[attr-defined]  # a ListedColormap
    env_text = ", ".join(f"{k}={v}" for k, v in config.env_kwargs.items())
    for metric, ylabel, filename in (
        ("area", "total area (FL units², log)", "area_vs_moves.png"),
        ("error", "mean error of initialised landmarks (FL units, log)", "error_vs_moves.png"),
    ):
        figure, axes = plt.subplots(figsize=(7.0, 4.3), dpi=110)
        positive = False  # a log axis needs a positive value (none: no landmark mapped)
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
            means = array(f"{metric}_mean")
            positive = positive or bool(np.any(np.isfinite(means) & (means > 0)))
        if positive:
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


def write_outputs(
    summary: dict[str, Any],
    records: Sequence[Mapping[str, Any]],
    config: CompareConfig,
    out: Path,
    timing: Mapping[str, float],
    plots: bool,
    command: str | None,
) -> None:
    """Every report file of a comparison into ``out`` (the plots only with ``plots`` and
    matplotlib)."""
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
