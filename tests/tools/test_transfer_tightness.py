"""``bearing-env transfer-tightness``: the exact transferred set's membership test against
brute force and shapely, today's regions against the exact set, and the command end to
end."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from bearing_env.benchmarks import transfer_tightness as tightness

ComplexArray = tightness.ComplexArray

#: Angles (radians) of a polygon's vertices on its circle: 3 to 5, at least 0.3 apart so
#: that no edge is too short to matter.
ANGLES = st.lists(st.floats(0.0, 2.0 * math.pi), min_size=3, max_size=5).filter(
    lambda angles: np.diff(sorted([*angles, min(angles) + 2.0 * math.pi])).min() > 0.3
)
UNIT = st.floats(0.05, 1.0)


def on_circle(angles: list[float], centre: complex, radius: float) -> ComplexArray:
    """A convex CCW polygon with its vertices on a circle."""
    return np.ascontiguousarray(centre + radius * np.exp(1j * np.sort(np.array(angles))))


def shapely_polygon(vertices: ComplexArray) -> shapely.Polygon:
    return shapely.Polygon(np.stack([vertices.real, vertices.imag], axis=-1))


@st.composite
def regions(draw: st.DrawFn) -> tuple[ComplexArray, ComplexArray, ComplexArray]:
    """A target region A and disjoint regions of L1 and L2 (radius < 1, centres 3 apart
    at a random angle), as a movement's FR regions are."""
    target = on_circle(draw(ANGLES), complex(draw(UNIT), draw(UNIT)) * 2.0, draw(UNIT))
    turn = np.exp(1j * draw(st.floats(-math.pi, math.pi)))
    a1 = on_circle(draw(ANGLES), -1.5 * turn, 0.9 * draw(UNIT))
    a2 = on_circle(draw(ANGLES), 1.5 * turn, 0.9 * draw(UNIT))
    return target, a1, a2


def inside_point(polygon: ComplexArray, weights: list[float]) -> complex:
    """A convex combination of the polygon's vertices (weights cycled to its size)."""
    w = np.resize(np.array(weights), polygon.size)
    return complex((w * polygon).sum() / w.sum())


WEIGHTS = st.lists(st.floats(0.01, 1.0), min_size=5, max_size=5)


@settings(max_examples=60, deadline=None)
@given(regions(), WEIGHTS, WEIGHTS, WEIGHTS)
def test_every_image_of_a_hypothesis_pair_is_a_member(
    polygons: tuple[ComplexArray, ComplexArray, ComplexArray],
    p_weights: list[float],
    h1_weights: list[float],
    h2_weights: list[float],
) -> None:
    target, a1, a2 = polygons
    p, h1, h2 = (
        inside_point(target, p_weights),
        inside_point(a1, h1_weights),
        inside_point(a2, h2_weights),
    )
    assert tightness.exact_member(np.array([(p - h1) / (h2 - h1)]), target, a1, a2)[0]


@settings(max_examples=60, deadline=None)
@given(regions(), st.floats(-3.0, 3.0), st.floats(-3.0, 3.0))
def test_the_axis_test_agrees_with_shapely_on_the_minkowski_sum(
    polygons: tuple[ComplexArray, ComplexArray, ComplexArray], x: float, y: float
) -> None:
    target, a1, a2 = polygons
    w = complex(x, y)
    summed = shapely_polygon(tightness.minkowski_sum((1.0 - w) * a1, w * a2))
    gap = shapely.distance(shapely_polygon(target), summed)
    overlap = shapely.intersection(shapely_polygon(target), summed).area
    assume(gap > 1e-9 or overlap > 1e-9)  # touching is a measure-zero tie
    assert bool(tightness.exact_member(np.array([w]), target, a1, a2)[0]) == (gap == 0.0)


@settings(max_examples=25, deadline=None)
@given(regions(), st.floats(-3.0, 3.0), st.floats(-3.0, 3.0))
def test_no_image_comes_nearer_a_non_member_than_its_gap_allows(
    polygons: tuple[ComplexArray, ComplexArray, ComplexArray], x: float, y: float
) -> None:
    # (p - h1)/(h2 - h1) - w = (p - (1 - w) h1 - w h2)/(h2 - h1), so every image lies at
    # least gap / max|h2 - h1| from w, gap the distance from A to (1 - w) A_L1 + w A_L2.
    target, a1, a2 = polygons
    w = complex(x, y)
    assume(not tightness.exact_member(np.array([w]), target, a1, a2)[0])
    summed = shapely_polygon(tightness.minkowski_sum((1.0 - w) * a1, w * a2))
    gap = shapely.distance(shapely_polygon(target), summed)
    rng = np.random.default_rng(0)

    def samples(polygon: ComplexArray, count: int) -> ComplexArray:
        weights = rng.exponential(size=(count, polygon.size))
        inner = (weights @ polygon) / weights.sum(axis=1)
        return np.concatenate([inner, tightness.boundary_points(polygon, 10)])

    p, h1, h2 = samples(target, 40), samples(a1, 40), samples(a2, 40)
    spans = h2[None, :] - h1[:, None]
    images = (p[:, None, None] - h1[None, :, None]) / spans[None]
    assert np.abs(images - w).min() >= gap / np.abs(spans).max() * (1.0 - 1e-9)


def test_with_exact_l1_and_l2_the_exact_set_is_the_region_itself() -> None:
    # L1 = 0 and L2 = 1 exactly make T the identity, so E = A: the grid's area must be
    # A's within its error bound, and A must hold itself.
    target = on_circle([0.1, 1.7, 3.0, 4.6], 0.4 + 0.8j, 0.3)
    movement = tightness.Movement(
        layout="test", epsilon=0.01, landmark=2, target_fr=target,
        l1_fr=np.array([0j]), l2_fr=np.array([1 + 0j]), truth_fl=complex(target.mean()),
        region=target,
    )  # fmt: skip
    reference = tightness.reference_hull(target, movement.l1_fr, movement.l2_fr)
    found = tightness.measure(movement, reference, 200)
    area = shapely_polygon(target).area
    assert found.reference_area == pytest.approx(area, rel=1e-12)
    assert abs(found.exact_area / area - 1.0) <= found.grid_error_bound
    assert abs(found.exact_area / area - 1.0) < 0.01
    assert found.contained and found.truth_in_e and found.box_growths == 0


def draw_movements(count: int, seed: int) -> list[tightness.Movement]:
    rng = np.random.default_rng(seed)
    drawn: list[tightness.Movement] = []
    while len(drawn) < count:
        movement = tightness.draw_movement(rng)
        if not isinstance(movement, str):
            drawn.append(movement)
    return drawn


def test_todays_regions_hold_the_exact_set_and_are_no_smaller() -> None:
    movements = draw_movements(20, seed=11)
    assert {m.layout for m in movements} == set(tightness.LAYOUTS)
    for movement in movements:
        # A coarser reference and grid than the command's keep the test quick.
        reference = tightness.reference_hull(
            movement.target_fr, movement.l1_fr, movement.l2_fr, per_edge=30
        )
        found = tightness.measure(movement, reference, 80)
        assert found.holds_grid and found.holds_reference, found
        assert found.truth_in_e, found
        assert found.region_area >= found.reference_area
        assert found.ratio >= 1.0 - found.grid_error_bound, found


def test_the_command_runs_end_to_end_and_writes_the_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "results" / "tightness.json"
    argv = ["--movements", "8", "--resolution", "60", "--json", str(path), "--no-progress"]
    tightness.main(argv)
    out = capsys.readouterr().out
    assert "region area / exact area: median" in out and f"wrote {path}" in out
    written = json.loads(path.read_text())
    measured = written["measured"]
    assert measured["command"] == "bearing-env transfer-tightness " + " ".join(argv)
    assert {"commit", "date", "machine"} <= set(measured)
    figures = written["summary"]
    assert figures["regions"] == len(written["regions"]) == 8
    assert figures["contains_grid"] == figures["contains_reference"] == 1.0
    assert figures["truth_in_exact_set"] == 1.0
    assert figures["ratio_median"] >= 1.0 and figures["ratio_to_reference_median"] >= 1.0
    assert len(written["resolution_checks"]) == 8


def shrink_every_region(monkeypatch: pytest.MonkeyPatch, factor: float) -> None:
    """Make every drawn region ``factor`` times its size about its vertices' mean."""
    draw = tightness.draw_movement

    def shrunk(
        rng: np.random.Generator, mapping: tightness.Mapping | None = None
    ) -> tightness.Movement | str:
        movement = draw(rng, mapping)
        if isinstance(movement, str):
            return movement
        centre = movement.region.mean()
        return replace(movement, region=centre + factor * (movement.region - centre))

    monkeypatch.setattr(tightness, "draw_movement", shrunk)


def test_a_region_that_misses_the_exact_set_is_reported_and_exits_1(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    shrink_every_region(monkeypatch, 0.5)
    with pytest.raises(SystemExit) as stopped:
        tightness.main(["--movements", "2", "--resolution", "40", "--no-progress"])
    assert stopped.value.code == 1
    out = capsys.readouterr().out
    assert "every grid point of E: 0.0%" in out and "not contained:" in out


# ----------------------------------------------------------------------------------------
# --containment-only
# ----------------------------------------------------------------------------------------


def test_the_fast_containment_test_agrees_with_region_holds_to_one_image() -> None:
    # The region is the reference hull itself: it holds every image, and shrunk by 1e-7
    # (a hundred times the tolerance) it misses a few hull vertices only, which the patch
    # shortcut must still find; likewise today's region, and it shrunk by half.
    for movement in draw_movements(2, seed=5):
        images = tightness.reference_images(
            movement.target_fr, movement.l1_fr, movement.l2_fr, per_edge=20
        )
        hull = tightness.reference_hull(
            movement.target_fr, movement.l1_fr, movement.l2_fr, per_edge=20
        )
        centre = hull.mean()
        for region, holds in [
            (hull, True),
            (centre + (1.0 - 1e-7) * (hull - centre), False),
            (movement.region, True),
            (centre + 0.5 * (movement.region - centre), False),
        ]:
            assert tightness.region_holds(region, images.ravel()) is holds
            assert tightness.region_holds_all(region, images) is holds
            outside, worst = tightness.worst_excess(region, images)
            assert (outside > 0) is not holds and (worst > 1e-9) is not holds


def run_containment_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], *extra: str, movements: int = 3
) -> tuple[int | str | None, str, dict[str, Any]]:
    path = tmp_path / "containment.json"
    argv = ["--containment-only", "--movements", str(movements), "--json", str(path)]
    argv.append("--no-progress")
    code: int | str | None = 0
    try:
        tightness.main([*argv, *extra])
    except SystemExit as stopped:
        code = stopped.code
    return code, capsys.readouterr().out, json.loads(path.read_text())


def test_containment_only_checks_todays_regions_and_writes_the_counts(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out, written = run_containment_command(tmp_path, capsys, "--seed", "3")
    assert code == 0 and "misses: 0 regions" in out
    assert written["measured"]["command"].startswith(
        "bearing-env transfer-tightness --containment-only"
    )
    figures = written["summary"]
    assert figures["regions"] == 3 and figures["movements_drawn"] >= 3
    assert figures["misses"] == 0 and written["misses"] == [] and not figures["interrupted"]
    assert figures["reference_images_checked"] >= 3 * 3 * 300 * 300  # >= 3 edges a region
    assert figures["grid_points_in_e_checked"] > 0
    assert written["settings"]["transfer"] == "conservative"
    assert written["settings"]["resolution"] == tightness.CONTAINMENT_RESOLUTION


def test_containment_only_reports_a_shrunk_region_as_a_miss_and_exits_1(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    shrink_every_region(monkeypatch, 0.9)
    code, out, written = run_containment_command(tmp_path, capsys, movements=1)
    assert code == 1 and "misses: 1 regions" in out and "not contained: {" in out
    assert written["summary"]["reference_misses"] == 1
    miss = written["misses"][0]
    assert miss["seed"] == 0 and miss["draw"] >= 1 and not miss["holds_reference"]
    assert miss["reference_images_outside"] > 0 and miss["reference_worst_outside"] > 1e-9
    assert len(miss["region"]) >= 3 and len(miss["target_fr"]) >= 3


def test_containment_only_keeps_its_counts_on_ctrl_c(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    check = tightness.check_containment
    calls = []

    def interrupted(*args: Any) -> tightness.ContainmentCheck:
        calls.append(1)
        if len(calls) == 2:
            raise KeyboardInterrupt
        return check(*args)

    monkeypatch.setattr(tightness, "check_containment", interrupted)
    code, out, written = run_containment_command(tmp_path, capsys)
    assert code == 0 and "(interrupted)" in out
    assert written["summary"]["interrupted"] and written["summary"]["regions"] == 1


def test_merge_sums_runs_and_refuses_a_repeated_seed() -> None:
    def payload(seed: int, regions: int, misses: list[dict[str, Any]]) -> dict[str, Any]:
        found = tightness.ContainmentRun(
            movements_drawn=2 * regions, regions=regions, reference_images_checked=10 * regions,
            grid_points_in_e_checked=3 * regions, box_growths_max=seed, misses=len(misses),
            reference_misses=len(misses), no_region={"no_move": seed + 1}, seconds=1.0,
        )  # fmt: skip
        settings = {
            "transfer": "conservative", "edge_samples": 3, "resolution": 24,
            "reference_samples_per_edge": 100, "seed": seed,
        }  # fmt: skip
        summary = tightness.containment_summary(found)
        return {"settings": settings, "summary": summary, "misses": misses}

    merged = tightness.merge_containment([payload(0, 5, []), payload(1, 7, [{"draw": 4}])])
    figures = merged["summary"]
    assert figures["regions"] == 12 and figures["movements_drawn"] == 24
    assert figures["reference_images_checked"] == 120 and figures["misses"] == 1
    assert figures["no_region"] == {"no_move": 3} and figures["box_growths_max"] == 1
    assert merged["misses"] == [{"draw": 4}] and merged["settings"]["seeds"] == [0, 1]
    with pytest.raises(ValueError, match="same seed"):
        tightness.merge_containment([payload(0, 5, []), payload(0, 7, [])])


def test_the_circumscribed_polygon_of_fixed_directions_has_the_known_area() -> None:
    square = np.array([1 + 1j, -1 + 1j, -1 - 1j, 1 - 1j])
    assert tightness.circumscribed_area(square, 4) == pytest.approx(4.0)
    # A square turned by 0.3 rad, boxed by the axes' directions.
    turned = square * np.exp(0.3j)
    box = 2.0 * (np.cos(0.3) + np.sin(0.3))
    assert tightness.circumscribed_area(turned, 4) == pytest.approx(box**2)
    # A fine polygon of the unit circle: the regular K-gon around it, K tan(pi / K).
    circle = np.exp(2j * np.pi * np.arange(720) / 720)
    for k in tightness.FIXED_DIRECTIONS:
        assert tightness.circumscribed_area(circle, k) == pytest.approx(
            k * np.tan(np.pi / k), rel=1e-4
        )
