"""Property tests of the world model against the paper's method (docs/design.md section 2).

* similarity invariance of every FL result;
* the conservative transfer contains the truth whenever the noise is within +-epsilon,
  on a large seeded suite of single moves and 10-move sequences;
* the paper transfer equals a direct vertex-hull computation, in the one-movement API
  and in the map's regions;
* epsilon -> 0 drives areas to 0 and estimates to the truth.

The simulator (tests/slam_sim.py) and every reference computation are independent of
bearing_env.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from bearing_env.slam import (
    FRAME_L1_L2_TOO_CLOSE,
    LANDMARK_UNBOUNDED,
    LANDMARK_UPDATED,
    PolygonSLAM,
    fr_region,
    transfer_point,
    transfer_polygon,
)
from tests.slam_sim import (
    cone_region_vertices,
    random_episode,
    run,
    to_xy,
)

SEEDS = st.integers(min_value=0, max_value=2**32 - 1)
TRANSFERS = st.sampled_from(["conservative", "paper"])


def shp(verts) -> shapely.Polygon:
    v = np.asarray(verts, dtype=complex).reshape(-1)
    return shapely.convex_hull(shapely.multipoints(to_xy(v)))


def hull_xy(verts) -> np.ndarray:
    """Distinct vertices (V, 2) of the convex hull, counter-clockwise."""
    return np.asarray(shp(verts).exterior.coords)[:-1]


# --------------------------------------------------------------------------------------
# Similarity invariance
# --------------------------------------------------------------------------------------


def snapshot(slam: PolygonSLAM) -> dict:
    return {
        "initialised": slam.initialised,
        "areas": slam.areas,
        "estimates": slam.estimates,
        "regions": slam.regions,
        "robot": slam.robot_estimate,
        "heading": slam.robot_heading,
    }


@settings(deadline=None, max_examples=25, derandomize=True)
@given(
    seed=SEEDS,
    transfer=TRANSFERS,
    log_scale=st.floats(-3.0, 3.0),
    angle=st.floats(-np.pi, np.pi),
    shift=st.tuples(st.floats(-50.0, 50.0), st.floats(-50.0, 50.0)),
)
def test_similarity_of_the_world_leaves_every_fl_result_unchanged(
    seed, transfer, log_scale, angle, shift
):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 9))
    eps = np.deg2rad(rng.uniform(1.0, 5.0))
    episode = random_episode(rng, n, 6)
    scale = 10.0**log_scale
    # Translation in units of the world's size, so the rounding of the bearings stays at
    # the 1e-13 level and differences are the model's, not the input's.
    moved = episode.transformed(scale, angle, scale * complex(*shift))
    np.testing.assert_allclose(moved.truth_fl(), episode.truth_fl(), atol=1e-9)

    a = PolygonSLAM(n, eps, transfer=transfer)
    b = PolygonSLAM(n, eps, transfer=transfer)
    for (a1, a2), (b1, b2) in zip(episode.readings(eps), moved.readings(eps), strict=True):
        ra, rb = a.update(a1, a2), b.update(b1, b2)
        assert ra.frame_changed == rb.frame_changed
        assert ra.frame_status == rb.frame_status
        assert ra.landmark_status.tolist() == rb.landmark_status.tolist()
        assert ra.n_inconsistent == rb.n_inconsistent
        sa, sb = snapshot(a), snapshot(b)
        np.testing.assert_array_equal(sa["initialised"], sb["initialised"])
        ok = sa["initialised"]
        np.testing.assert_array_equal(np.isinf(sb["areas"]), ~ok)
        np.testing.assert_allclose(sb["areas"][ok], sa["areas"][ok], rtol=1e-9, atol=1e-15)
        polygons = [p for p in sa["regions"] if p is not None]
        size = 1.0 + max((np.abs(np.asarray(p.exterior.coords)).max() for p in polygons), default=0)
        tol = 1e-9 * size
        np.testing.assert_allclose(sb["estimates"][ok], sa["estimates"][ok], rtol=0, atol=tol)
        for pa, pb in zip(sa["regions"], sb["regions"], strict=True):
            assert (pa is None) == (pb is None)
            if pa is not None:
                assert shapely.hausdorff_distance(pa, pb) < tol
        if np.all(np.isfinite(sa["robot"])):
            np.testing.assert_allclose(sb["robot"], sa["robot"], atol=1e-9 * size)
            turn = np.angle(np.exp(1j * (sb["heading"] - sa["heading"])))
            assert abs(turn) < 1e-9
        else:
            assert not np.any(np.isfinite(sb["robot"]))


# --------------------------------------------------------------------------------------
# Containment: the conservative transfer never loses the truth
# --------------------------------------------------------------------------------------

N_SUITE = 300  # episodes; each gives 10 single moves and one 10-move sequence


def containment_suite(transfer: str, n_episodes: int = N_SUITE, edge_samples: int = 3):
    """Count truth-in-region checks and misses over the seeded suite.

    Episodes alternate uniform noise and worst-case noise (+-epsilon exactly), with
    epsilon between 0.5 and 5 degrees and 4 to 8 landmarks.
    """
    counts = dict(single=0, single_miss=0, seq=0, seq_miss=0, robot=0, robot_miss=0)
    counts["inconsistent"] = 0
    for seed in range(n_episodes):
        rng = np.random.default_rng(10_000 + seed)
        n = int(rng.integers(4, 9))
        eps = np.deg2rad(rng.uniform(0.5, 5.0))
        noise = "extreme" if seed % 2 else "uniform"
        episode = random_episode(rng, n, 10, noise=noise)
        truth = episode.truth_fl()
        readings = episode.readings(eps)
        seq = PolygonSLAM(n, eps, transfer=transfer, edge_samples=edge_samples)
        last_frame_move = None
        for m, (b1, b2) in enumerate(readings):
            single = PolygonSLAM(n, eps, transfer=transfer, edge_samples=edge_samples)
            single.update(b1, b2)
            ok = single.initialised
            counts["single"] += int(ok.sum())
            counts["single_miss"] += int((~single.contains(truth)[ok]).sum())

            res = seq.update(b1, b2)
            counts["inconsistent"] += res.n_inconsistent
            ok = seq.initialised
            counts["seq"] += int(ok.sum())
            counts["seq_miss"] += int((~seq.contains(truth)[ok]).sum())
            if res.frame_changed:
                last_frame_move = m
            if last_frame_move is not None:
                counts["robot"] += 1
                r2 = episode.robot_truth_fl(last_frame_move)
                counts["robot_miss"] += int(not seq.robot_contains(r2))
    return counts


@pytest.mark.parametrize("transfer", ["conservative", "conservative_global"])
def test_conservative_regions_contain_the_truth_in_every_case(transfer: str) -> None:
    # Measured on this suite (300 episodes), the same for "conservative" and
    # "conservative_global" (the growth does not change which regions are bounded): 7526
    # single-move landmark regions, 10752 (landmark, move) checks along the sequences,
    # 2771 robot regions; 0 misses and 0 inconsistencies. The paper transfer on the same
    # suite misses 68 of 7913 single-move regions, 330 of 10957 sequence checks and 122 of
    # 2845 robot regions, with 44 inconsistencies. (The conservative map refuses some
    # moves whose A_L1 and A_L2 are close for their size: "l1_l2_too_close"; hence its
    # smaller counts.)
    c = containment_suite(transfer)
    # The suite is not vacuous: most landmarks of most moves give a bounded region.
    assert c["single"] > 15 * N_SUITE and c["seq"] > 25 * N_SUITE, c
    assert c["robot"] > 8 * N_SUITE, c
    assert c["single_miss"] == 0, c
    assert c["seq_miss"] == 0, c
    assert c["robot_miss"] == 0, c
    assert c["inconsistent"] == 0, c


def test_containment_holds_with_the_coarsest_edge_sampling():
    # One sample per edge: the bound alone (no extra sampling) keeps the truth inside.
    c = containment_suite("conservative", n_episodes=40, edge_samples=1)
    assert c["single_miss"] == c["seq_miss"] == c["robot_miss"] == c["inconsistent"] == 0, c


def test_the_suite_is_sharp_enough_to_catch_the_paper_transfer():
    """The same suite with the paper's vertex hull does lose the truth (about 3% of single
    moves on random layouts, docs/design.md section 4): the containment test above can fail."""
    c = containment_suite("paper", n_episodes=60)
    assert c["single_miss"] + c["seq_miss"] > 0, c


# --------------------------------------------------------------------------------------
# The paper transfer is the vertex hull, exactly
# --------------------------------------------------------------------------------------


def usable_move(rng: np.random.Generator, eps: float):
    """Draw single-move episodes until A_L1 and A_L2 are bounded and apart."""
    for _ in range(200):
        n = int(rng.integers(4, 9))
        episode = random_episode(rng, n, 1, noise="uniform")
        b1, b2 = episode.readings(eps)[0]
        regions = [cone_region_vertices(b1[i], b2[i], eps) for i in range(n)]
        if regions[0] is None or regions[1] is None:
            continue
        if max(np.abs(regions[0]).max(), np.abs(regions[1]).max()) > 1e3:
            continue  # numerically unbounded: the implementation may refuse it
        if shp(regions[0]).distance(shp(regions[1])) < 1e-6:
            continue
        return n, b1, b2, regions
    pytest.fail("no usable move drawn")


@settings(deadline=None, max_examples=40, derandomize=True)
@given(seed=SEEDS, eps_deg=st.floats(0.5, 7.0))
def test_paper_transfer_is_the_convex_hull_of_vertex_hypotheses(seed, eps_deg):
    rng = np.random.default_rng(seed)
    eps = np.deg2rad(eps_deg)
    n, b1, b2, regions = usable_move(rng, eps)
    a1, a2 = regions[0], regions[1]
    h1, h2 = a1[:, None], a2[None, :]

    slam = PolygonSLAM(n, eps, transfer="paper")
    res = slam.update(b1, b2)
    assert res.frame_changed
    mapped = slam.regions
    for i in range(2, n):
        status = res.landmark_status[i - 2]
        if regions[i] is None:  # the cones' direction ranges overlap
            assert status == LANDMARK_UNBOUNDED
            assert not slam.initialised[i - 2]
            continue
        if np.abs(regions[i]).max() > 1e3:
            continue  # numerically unbounded: either answer is acceptable
        assert status == LANDMARK_UPDATED
        images = (regions[i][:, None, None] - h1[None]) / (h2 - h1)[None]
        hull = shp(images)
        size = 1.0 + np.abs(images).max()
        # One-movement API, fed with the implementation's FR regions and with ours.
        for got in (
            transfer_polygon(fr_region(b1[i], b2[i], eps), fr_region(b1[0], b2[0], eps),
                             fr_region(b1[1], b2[1], eps), transfer="paper"),
            transfer_polygon(hull_xy(regions[i]), hull_xy(a1), hull_xy(a2), transfer="paper"),
        ):
            assert got is not None
            assert shapely.hausdorff_distance(got, hull) < 1e-9 * size
            assert got.symmetric_difference(hull).area <= 1e-9 * hull.area + 1e-18
        # The map: exactly the same hull.
        poly = mapped[i - 2]
        assert shapely.hausdorff_distance(poly, hull) < 1e-9 * size
        assert slam.areas[i - 2] == pytest.approx(hull.area, rel=1e-9)
        np.testing.assert_allclose(
            slam.estimates[i - 2], [hull.centroid.x, hull.centroid.y], atol=1e-9 * size
        )
    # The robot: R2 = 1 in FR.
    r2_images = (1.0 - h1) / (h2 - h1)
    size = 1.0 + np.abs(r2_images).max()
    assert shapely.hausdorff_distance(slam.robot_region, shp(r2_images)) < 1e-9 * size
    got = transfer_point([1.0, 0.0], hull_xy(a1), hull_xy(a2), transfer="paper")
    assert shapely.hausdorff_distance(got, shp(r2_images)) < 1e-9 * size


@settings(deadline=None, max_examples=25, derandomize=True)
@given(seed=SEEDS, eps_deg=st.floats(0.5, 7.0))
def test_conservative_map_region_contains_the_paper_region(seed, eps_deg):
    rng = np.random.default_rng(seed)
    eps = np.deg2rad(eps_deg)
    n, b1, b2, _ = usable_move(rng, eps)
    paper = PolygonSLAM(n, eps, transfer="paper")
    cons = PolygonSLAM(n, eps, transfer="conservative")
    rp, rc = paper.update(b1, b2), cons.update(b1, b2)
    assert rp.frame_changed  # usable_move drew bounded, disjoint A_L1 and A_L2
    if not rc.frame_changed:
        # The conservative bound may refuse L1 and L2 that are too close for it; that must
        # be said, and nothing may be mapped.
        assert rc.frame_status == FRAME_L1_L2_TOO_CLOSE
        assert not cons.initialised.any()
        return
    assert rp.landmark_status.tolist() == rc.landmark_status.tolist()
    ok = paper.initialised
    for inner, outer in zip(paper.regions, cons.regions, strict=True):
        assert (inner is None) == (outer is None)
        if inner is not None:
            assert inner.difference(outer).area <= 1e-9 * inner.area
    assert np.all(cons.areas[ok] >= paper.areas[ok] * (1 - 1e-9))


# --------------------------------------------------------------------------------------
# epsilon -> 0
# --------------------------------------------------------------------------------------

EPSILONS = (1e-1, 1e-2, 1e-3, 1e-4)


@settings(deadline=None, max_examples=12, derandomize=True)
@given(seed=SEEDS, transfer=TRANSFERS, noisy=st.booleans())
def test_areas_vanish_and_estimates_converge_as_epsilon_goes_to_zero(seed, transfer, noisy):
    """Same trajectory, noise u * epsilon (or none), epsilon = 1e-1 .. 1e-4 rad.

    Regions scale linearly with epsilon once the geometry is linear, so areas shrink like
    epsilon**2 and errors like epsilon (or faster without noise). Measured over 100 seeds
    (random layouts, 6 landmarks, 10 moves): area(1e-4) / area(1e-2) <= 1.2e-4
    (conservative) and <= 1.1e-3 (paper, whose restarts after inconsistencies add jumps);
    error(1e-4) / error(1e-2) <= 0.1 (conservative) and 0.25 (paper); per decade the
    conservative area ratio stays within 0.0035 .. 0.012. The bounds below leave margin.
    """
    rng = np.random.default_rng(seed)
    episode = random_episode(rng, 6, 10, noise="uniform" if noisy else "none")
    truth = episode.truth_fl()
    areas, errors, robot_errors = [], [], []
    for eps in EPSILONS:
        slam = PolygonSLAM(6, eps, transfer=transfer)
        results = run(slam, episode, eps)
        ok = slam.initialised
        assert not np.any(np.isnan(slam.areas)), slam.areas
        assert np.all(np.isfinite(slam.estimates[ok]))
        if transfer == "conservative":
            assert np.all(slam.contains(truth)[ok])
        areas.append(slam.areas)
        errors.append(np.linalg.norm(slam.estimates - truth, axis=-1))
        moved = [m for m, r in enumerate(results) if r.frame_changed]
        if moved:
            truth_r2 = episode.robot_truth_fl(moved[-1])
            robot_errors.append(np.linalg.norm(slam.robot_estimate - truth_r2))
        else:  # possible at epsilon = 0.1 only: A_L1 and A_L2 overlap in every move
            assert eps > 0.05
            robot_errors.append(np.inf)
    areas, errors, robot_errors = np.array(areas), np.array(errors), np.array(robot_errors)
    # From 1e-2 down every landmark is mapped (a landmark within 1e-2 rad of the line of
    # motion in all ten moves does not occur in this arena).
    assert np.all(np.isfinite(areas[1:])), areas
    # Monotone decrease, and the two decades from 1e-2 to 1e-4 shrink areas >= 100x
    # (theory: 1e4x) and errors >= 2x (theory: >= 100x).
    assert np.all(areas[2:] < areas[1:-1]), areas
    assert np.all(areas[3] <= 1e-2 * areas[1]), areas
    assert np.all(errors[3] <= 0.5 * errors[1] + 1e-12), errors
    assert robot_errors[3] <= 0.1 * robot_errors[1] + 1e-12, robot_errors
    # Tiny in absolute terms at 1e-4 rad (FL units, |L1 L2| = 1; landmarks of this arena
    # lie up to ~7 units away): measured max area 4e-5 and max error 1.7e-3.
    assert np.all(areas[3] < 2e-4), areas[3]
    assert np.all(errors[3] < 1e-2), errors[3]
    if transfer == "conservative":
        # Clean epsilon**2 scaling per decade (theory 0.01), and no growth from 0.1.
        assert np.all(areas[2:] <= 0.05 * areas[1:-1]), areas
        init = np.isfinite(areas[0])
        assert np.all(areas[1][init] <= 0.05 * areas[0][init]), areas
