"""``bearing-env robust-eval``: its table's ratios and a tiny real run."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from bearing_env.train.studies import robust_eval
from tests.extras import needs


def test_table_divides_areas_by_clean_strict_and_steps_by_strict() -> None:
    rows = [
        {
            "layout": "khepera",
            "policy": "random",
            "noise": noise,
            "fusion": fusion,
            "containment": containment,
            "median_area": area,
            "step_seconds": step,
        }
        for noise, fusion, containment, area, step in [
            ("clean", "strict", 1.0, 0.5, 0.002),
            ("clean", "robust", 1.0, 0.5, 0.003),
            ("outliers 5%", "strict", 0.8, 0.75, 0.002),
            ("outliers 5%", "robust", 0.975, 1.0, 0.004),
        ]
    ]
    lines = robust_eval.table(rows).splitlines()
    assert lines[0].split()[:4] == ["layout", "policy", "noise", "fusion"]
    assert lines[2].split()[-3:] == ["100.0%", "1.00", "1.50"]
    assert lines[4].split()[-3:] == ["97.5%", "2.00", "2.00"]


@needs("train")
def test_a_one_episode_run_scores_every_case(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(robust_eval, "LAYOUTS", {"khepera": {"scenario": "khepera"}})
    rows = robust_eval.evaluate(1, ["random"])
    assert [(r["noise"], r["fusion"]) for r in rows] == [
        (noise, fusion) for noise in robust_eval.NOISES for fusion in robust_eval.FUSIONS
    ]
    for row in rows:
        assert 0.0 <= row["containment"] <= 1.0
        assert row["median_area"] > 0.0 and row["step_seconds"] > 0.0
    clean = {r["fusion"]: r for r in rows if r["noise"] == "clean"}
    # Without the bound estimate, clean data give the strict intersection exactly.
    assert clean["robust, nominal bound"]["median_area"] == clean["strict"]["median_area"]
    assert robust_eval.step_ratio(rounds=1, steps=20) > 0.0


def test_the_page_table_bolds_the_robust_fusion_where_it_meets_its_target() -> None:
    times = robust_eval.TIMES
    cells = {
        ("outliers 5%", "robust", 0.98): f"**98.0%** (2.00{times})",
        ("outliers 5%", "robust, nominal bound", 0.993): f"99.3% (2.00{times})",
        ("bound 3 deg", "robust", 0.949): f"94.9% (2.00{times})",
        ("clean", "robust", 1.0): f"100% (2.00{times})",
    }
    for (noise, fusion, containment), expected in cells.items():
        row = {"noise": noise, "fusion": fusion, "containment": containment}
        assert robust_eval._cell({**row, "area_over_clean_strict": 2.0}) == expected
    assert robust_eval._cell({"noise": "bound 3 deg", "fusion": "strict", "containment": 0.5}) == (
        "50.0%"
    )


@needs("train")
def test_the_json_holds_what_the_results_page_table_is_written_from(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(robust_eval, "LAYOUTS", {"khepera": {"scenario": "khepera"}})
    monkeypatch.setattr(robust_eval, "step_ratio", lambda: 1.5)
    path = tmp_path / "robust_eval.json"
    robust_eval.main(["--episodes", "1", "--policies", "random", "--no-progress",
                      "--json", str(path)])  # fmt: skip
    results = json.loads(path.read_text(encoding="utf-8"))
    assert results["measured"]["command"] == (
        f"bearing-env robust-eval --episodes 1 --policies random --no-progress --json {path}"
    )
    assert results["robust_step_over_strict"] == 1.5
    clean_strict = next(
        r for r in results["rows"] if (r["noise"], r["fusion"]) == ("clean", "strict")
    )
    assert clean_strict["area_over_clean_strict"] == 1.0
    table = robust_eval.markdown_robust_eval(results).splitlines()
    assert table[0].startswith("| layout | policy | clean: robust | 5% outliers: strict |")
    assert table[2].startswith("| Khepera | RandomPolygonal | ") and len(table[2].split("|")) == 13
    assert f"A robust env step costs 1.50{robust_eval.TIMES} a strict one" in table[-1]
