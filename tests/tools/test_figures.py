"""The paper's figures: they are written, and Fig. 11's protocol holds (same bearings)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from bearing_env.train import cli
from bearing_env.train.studies.figures import (
    FIG7_MOVEMENTS,
    figure7,
    figure10,
    figure11,
    linear_fit,
    power_fit,
    random_polygonal_trace,
    shows_shrinking,
)
from tests.extras import needs

KHEPERA_25 = {"scenario": "khepera", "move_length": 0.25, "transfer": "paper"}


def assert_png(path: Path) -> None:
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    assert 10_000 < len(data) < 300_000  # a real plot, small enough to commit


def test_fits() -> None:
    x = np.array([2.0, 3.0, 4.0, 5.0, 6.0, 7.0])
    line = linear_fit(x, 3.0 * x - 1.0)
    assert line["slope"] == pytest.approx(3.0) and line["intercept"] == pytest.approx(-1.0)
    assert line["r_squared"] == pytest.approx(1.0)
    # A parabola over 2..7 is visibly not a line: R^2 of its best line is about 0.974.
    assert linear_fit(x, x**2)["r_squared"] == pytest.approx(0.974, abs=1e-3)
    assert power_fit(x, 0.5 * x**2.5)["exponent"] == pytest.approx(2.5)


def test_same_bearing_set_for_every_epsilon() -> None:
    # Fig. 11's premise: only the SLAM's epsilon changes, not the trajectory or readings.
    noise = {"kind": "uniform", "bound_deg": 2.0}
    runs = [
        random_polygonal_trace({**KHEPERA_25, "epsilon_deg": eps, "noise": noise}, 1_000_003, 6)
        for eps in (2.0, 5.0)
    ]
    np.testing.assert_array_equal(runs[0].bearings, runs[1].bearings)
    np.testing.assert_array_equal(runs[0].trajectory_fl, runs[1].trajectory_fl)
    finite = np.isfinite(runs[0].areas) & np.isfinite(runs[1].areas)
    assert np.all(runs[1].areas[finite] >= runs[0].areas[finite])  # wider cones, larger regions
    # "scaled" noise: the same normalised draws, so the same path but scaled errors.
    scaled = [
        random_polygonal_trace({**KHEPERA_25, "epsilon_deg": eps}, 1_000_003, 6)
        for eps in (2.0, 4.0)
    ]
    np.testing.assert_array_equal(scaled[0].trajectory_fl, scaled[1].trajectory_fl)
    assert not np.array_equal(scaled[0].bearings[1:], scaled[1].bearings[1:])


@needs("train", "matplotlib")
def test_figure7_shows_a_shrinking_run(tmp_path: Path) -> None:
    path, data = figure7(tmp_path)
    assert_png(path)
    areas = np.array([data["areas"][str(m)] for m in FIG7_MOVEMENTS])
    assert shows_shrinking(areas, range(len(FIG7_MOVEMENTS)))
    assert data["runs_skipped"] == data["seed"]


@needs("train", "matplotlib")
def test_figures_10_and_11(tmp_path: Path) -> None:
    seeds = list(range(1_000_000, 1_000_004))
    path10, data10 = figure10(tmp_path, seeds)
    assert_png(path10)
    assert len(data10["area_L3_median"]) == 10
    path11, data11 = figure11(tmp_path, seeds, epsilons=(2.0, 4.0, 6.0), moves=5)
    assert_png(path11)
    assert data11["epsilons"] == [2.0, 4.0, 6.0]
    areas = [a for a in data11["final_area_median"] if a is not None]
    assert areas == sorted(areas)  # wider cones, larger regions
    assert 0.0 <= data11["linear_fit"]["r_squared"] <= 1.0
    with pytest.raises(ValueError, match="noise_mode"):
        figure11(tmp_path, seeds, noise_mode="loud")


@needs("train", "matplotlib")
def test_bearing_env_dispatches_figures(tmp_path: Path) -> None:
    cli.main(["figures", "--only", "11", "--seeds", "2", "--out", str(tmp_path)])
    assert_png(tmp_path / "fig11_epsilon.png")
    summary = json.loads((tmp_path / "figures.json").read_text())
    assert set(summary) == {"fig11"} and "r_squared" in summary["fig11"]["linear_fit"]


@needs("train", "matplotlib")
def test_robustness_figure_compares_the_fusions_on_the_same_seeds(tmp_path: Path) -> None:
    from bearing_env.train.studies.figures import (
        ROBUST_FUSIONS,
        ROBUST_NOISE_FACTORS,
        ROBUST_OUTLIER_RATES,
        figure_robustness,
    )

    path, data = figure_robustness(tmp_path, [1_000_000, 1_000_001], moves=8)
    assert_png(path)
    for sweep, values in (
        ("outlier_rate", ROBUST_OUTLIER_RATES),
        ("noise_factor", ROBUST_NOISE_FACTORS),
    ):
        assert data[sweep]["values"] == list(values)
        for label in ROBUST_FUSIONS:
            points = data[sweep][label]
            assert len(points) == len(values)
            assert all(0.0 <= p["containment"] <= 1.0 for p in points)
    # Without outliers and within epsilon, every fusion is the strict intersection.
    clean = [data["outlier_rate"][label][0] for label in ROBUST_FUSIONS]
    assert all(p == clean[0] for p in clean)
    assert clean[0]["containment"] == 1.0
