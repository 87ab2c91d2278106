"""Tables on an 80-column terminal: no number is split across lines (rich used to narrow
the widest columns, so "0.192" printed as "0.19" over "2")."""

# ruff: noqa: E402  (imports of the extra follow its skip)
from __future__ import annotations

import io
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import pytest

from tests.extras import skip_module_without

skip_module_without("train", "rich")

from rich.console import Console

from bearing_env.train.common.tables import boxed_chrome, fit_widths, print_table

#: The outcome table of `bearing-env compare --quick`, as it printed (header and cells).
OUTCOME_HEADER = (
    "policy",
    "episodes",
    "success",
    "moves to success (median)",
    "final error (median, FL units)",
    "containment",
    "path length (m, mean)",
    "moves that changed frames",
    "policy ms/move",
)
OUTCOME_ROWS = (
    ("random_polygonal", "20", "0.0%", "-", "0.192", "100.0%", "1.19", "57%", "0.023"),
    ("parallax", "20", "0.0%", "-", "0.0679", "100.0%", "2.78", "92%", "1.2"),
    ("greedy_one_step", "20", "0.0%", "-", "0.0465", "100.0%", "2.79", "98%", "1.5e+02"),
    ("ppo_khepera", "20", "5.0%", "10", "0.049", "100.0%", "2.81", "100%", "1.5"),
)
#: Mean areas with their bootstrap CIs: cells of several numbers, which may wrap at spaces.
CI_HEADER = ("policy", "after 1", "after 3", "after 5", "after 10")
CI_ROWS = (
    ("random_polygonal", "15.2 [12, 18.1]", "11.2 [7.62, 14.8]", "10.7 [7.29, 14.3]",
     "6.44 [3.36, 9.87]"),
    ("greedy_one_step", "6.5 [3.72, 9.46]", "1.75 [0.928, 2.86]", "0.937 [0.379, 1.89]",
     "0.242 [0.204, 0.282]"),
)


def rendered(
    header: Sequence[str], rows: Sequence[Sequence[str]], width: int, **kwargs: Any
) -> list[str]:
    buffer = io.StringIO()
    console = Console(file=buffer, width=width, color_system=None, force_terminal=False)
    print_table("title", header, rows, console, **kwargs)
    return buffer.getvalue().splitlines()


def words_split(rows: Sequence[Sequence[str]], lines: Sequence[str]) -> list[str]:
    """The words of ``rows``' cells (numbers, CI bounds) that no printed line holds whole."""
    cells = [re.findall(r"[^\s|│]+", line) for line in lines]
    printed = {word for line in cells for word in line}
    return [word for row in rows for cell in row for word in cell.split() if word not in printed]


@pytest.mark.parametrize(("header", "rows"), [(OUTCOME_HEADER, OUTCOME_ROWS), (CI_HEADER, CI_ROWS)])
def test_no_number_is_split_at_80_columns(
    header: Sequence[str], rows: Sequence[Sequence[str]]
) -> None:
    lines = rendered(header, rows, 80)
    assert max(len(line) for line in lines) <= 80
    assert words_split(rows, lines) == []
    assert "left out" not in "\n".join(lines)


def test_what_does_not_fit_is_left_out_and_named() -> None:
    lines = rendered(OUTCOME_HEADER, OUTCOME_ROWS, 50)
    text = "\n".join(lines)
    assert max(len(line) for line in lines) <= 50
    assert "left out at 50 columns:" in text
    shown = [row[:3] for row in OUTCOME_ROWS]
    assert words_split(shown, lines) == []


def test_widths_are_natural_when_they_fit_and_never_below_the_longest_cell_word() -> None:
    natural = [max(len(r[i]) for r in (CI_HEADER, *CI_ROWS)) for i in range(5)]
    assert fit_widths(CI_HEADER, CI_ROWS, 200) == natural
    room = 80 - boxed_chrome(len(CI_HEADER))
    narrow = fit_widths(CI_HEADER, CI_ROWS, room)
    assert narrow is not None and sum(narrow) <= room
    assert narrow[0] == len("random_polygonal")
    assert all(width >= len("[0.204,") for width in narrow[1:])  # the longest CI word
    assert fit_widths(CI_HEADER, CI_ROWS, 30) is None


def test_compare_prints_its_tables_whole_at_80_columns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import rich.console

    from bearing_env.train.compare.comparison import run_comparison
    from bearing_env.train.compare.config import CompareConfig, policies_from_specs
    from bearing_env.train.compare.report import outcome_table_rows, print_tables

    config = CompareConfig(
        policies=policies_from_specs(["random", "greedy"]),
        env_id="BearingSLAM-v1",
        env_kwargs={"scenario": "khepera", "max_moves": 3},
        episodes=3,
        bootstrap=50,
    )
    result = run_comparison(config, tmp_path, progress=False, plots=False)
    buffer = io.StringIO()
    terminal = Console(file=buffer, width=80, color_system=None, force_terminal=True)
    monkeypatch.setattr(rich.console, "Console", lambda *args, **kwargs: terminal)
    timing = {"random_polygonal": 0.0123456, "greedy_one_step": 123.456}
    print_tables(result.summary, config, timing)
    lines = buffer.getvalue().splitlines()
    assert max(len(line) for line in lines) <= 80
    _, rows = outcome_table_rows(result.summary, config, timing)
    assert words_split(rows, lines) == []
    assert "Outcomes" in buffer.getvalue() and "left out" not in buffer.getvalue()
