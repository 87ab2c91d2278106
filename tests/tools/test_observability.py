"""``bearing-env observability``: the movements a sensor lets map a layout, from truth."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from shapely.geometry import Point, Polygon

from bearing_env.train.studies import observability
from tests.extras import needs

KHEPERA = "bearing_env:BearingSLAM-Khepera-v1"
#: A small grid: (starts per side, headings, lengths).
SMALL = (8, 12, 2)


def _outcomes(fov: float) -> tuple[observability.Movements, observability.Outcomes]:
    layout = observability.layout_of(KHEPERA, {"field_of_view_deg": fov})
    movements = observability.candidate_movements(layout, *SMALL)
    return movements, observability.movement_outcomes(layout, movements)


def test_a_narrower_view_only_loses_updates() -> None:
    """The same movements, the same true bearings: a forward camera only turns readings
    into misses, so every update it allows the panoramic camera makes too, alike."""
    wide_moves, wide = _outcomes(360.0)
    narrow_moves, narrow = _outcomes(90.0)
    np.testing.assert_array_equal(wide_moves.headings, narrow_moves.headings)
    assert wide.updated.sum() > 0
    assert np.all(wide.updated[narrow.updated])
    np.testing.assert_allclose(narrow.areas[narrow.updated], wide.areas[narrow.updated])
    assert np.all(wide.frame_changed[narrow.frame_changed])
    assert narrow.updated.sum() < wide.updated.sum()


def test_readings_miss_exactly_what_lies_outside_the_view() -> None:
    layout = observability.layout_of(KHEPERA, {"field_of_view_deg": 90.0})
    rng = np.random.default_rng(7)
    positions = rng.uniform((0.05, 0.05), (1.0, 0.63), size=(200, 2))
    headings = rng.uniform(-math.pi, math.pi, size=200)
    readings = observability._readings(layout, positions, headings)
    offsets = layout.landmarks[None] - positions[:, None]
    expected = np.angle(
        np.exp(1j * (np.arctan2(offsets[..., 1], offsets[..., 0]) - headings[:, None]))
    )
    outside = np.abs(expected) > math.radians(45.0)
    np.testing.assert_array_equal(np.isnan(readings), outside)
    np.testing.assert_allclose(readings[~outside], expected[~outside], atol=1e-12)


def test_starts_keep_clear_of_walls_obstacles_and_landmarks() -> None:
    layout = observability.layout_of("bearing_env:BearingSLAM-FurnishedRoom-v1", {})
    movements = observability.candidate_movements(layout, 20, 4, 1)
    arena = layout.config.layout.arena
    margin = arena.wall_margin
    starts = movements.starts
    assert len(starts) > 50
    assert np.all(
        (starts >= margin - 1e-9)
        & (starts <= (arena.width - margin + 1e-9, arena.height - margin + 1e-9))
    )
    for polygon in layout.config.layout.obstacles:
        shape = Polygon(polygon)
        assert all(shape.distance(Point(x, y)) > margin for x, y in starts)
    gaps = np.linalg.norm(starts[:, None] - layout.landmarks[None], axis=2)
    assert gaps.min() > margin
    assert len(movements.headings) == len(starts) * 4
    assert np.all(movements.lengths == layout.config.actions.move_length[0])


def test_summary_shares_and_best_movement_per_start() -> None:
    movements = observability.Movements(
        starts=np.zeros((2, 2)),
        start_index=np.array([0, 0, 1, 1]),
        headings=np.zeros(4),
        lengths=np.full(4, 0.1),
    )
    areas = np.array([[0.5, np.inf], [np.inf, 3.0], [50.0, np.inf], [np.inf, np.inf]])
    outcomes = observability.Outcomes(
        frame_changed=np.array([True, True, True, False]),
        updated=np.isfinite(areas),
        areas=areas,
    )
    summary = observability.summarise(movements, outcomes, area_cap=10.0)
    assert summary["frame_changes"] == 0.75
    assert summary["updates"] == [0.5, 0.25]
    assert summary["within_cap"] == [0.25, 0.25]
    assert summary["median_area"] == 3.0
    assert summary["starts_mapping_any"] == 0.5
    assert summary["best_by_start"].tolist() == [2, 0]


@needs("train")
def test_the_command_prints_the_table_and_draws_the_arenas(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path, figures = tmp_path / "observability.png", tmp_path / "observability.json"
    observability.main(
        ["--env", "BearingSLAM-Khepera-v1", "--fov", "360", "90", "--per-side", "6",
         "--headings", "8", "--lengths", "2", "--plot", str(path), "--json", str(figures),
         "--no-progress"]
    )  # fmt: skip
    out = capsys.readouterr().out
    assert "BearingSLAM-Khepera-v1: one movement" in out
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    written = json.loads(figures.read_text())
    assert written["env"] == "BearingSLAM-Khepera-v1"
    wide, narrow = written["fovs"]["360"], written["fovs"]["90"]
    assert wide["movements"] == narrow["movements"] == wide["starts"] * 8 * 2
    assert len(wide["updates"]) == 2  # L3 and L4
    assert wide["frame_changes"] > narrow["frame_changes"]
    assert wide["starts_mapping_any"] > 0.5
    measured = written["measured"]
    assert measured["command"].startswith("bearing-env observability --env BearingSLAM-Khepera-v1")
    assert {"commit", "date", "machine"} <= measured.keys()
    # The environment page's table reads the file as it is written.
    table = observability.markdown_observability({"observability_khepera": written})
    assert "| `BearingSLAM-Khepera-v1` (" in table and "| 360° |" in table and "| 90° |" in table
    assert f"Measured by `{measured['command']}`" in table


def test_the_page_table_rounds_shares_and_areas_as_the_page_shows_them() -> None:
    assert [observability._percent(s) for s in (1.0, 0.46947, 0.005878, 0.000494, 0.0)] == [
        "100%", "46.9%", "0.59%", "0.05%", "0%",
    ]  # fmt: skip
    assert [observability._area(a) for a in (6.247, 102.74, 1992.5, 22122.5, math.inf)] == [
        "6.25", "103", "1,990", "22,100", "-",
    ]  # fmt: skip


def test_a_bad_field_of_view_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as raised:
        observability.main(["--fov", "0", "--per-side", "4", "--headings", "4", "--no-progress"])
    assert raised.value.code == 2
    assert "field_of_view_deg" in capsys.readouterr().err


def test_the_omniscient_planner_maps_with_a_panoramic_camera_and_not_with_90_degrees() -> None:
    wide = observability.omniscient_final_areas(KHEPERA, {"max_moves": 4}, episodes=1)
    narrow = observability.omniscient_final_areas(
        KHEPERA, {"max_moves": 4, "field_of_view_deg": 90.0}, episodes=1
    )
    assert len(wide) == len(narrow) == 1
    assert 0.0 < wide[0] < 1.0  # both landmarks mapped well within 4 moves
    assert narrow[0] == 20.0  # both still at the cap of 10
