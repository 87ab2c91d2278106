"""``bearing-env robust-eval``: its table's ratios and a tiny real run."""

from __future__ import annotations

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
