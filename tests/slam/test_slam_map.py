"""The map (PolygonSLAM) as users see it: construction, input validation, UpdateResult
semantics, degenerate input, inconsistency handling, the paper's Fig. 11, and the
promise that the world model imports neither gymnasium nor pygame.
"""

from __future__ import annotations

import pickle
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import shapely

import bearing_env.slam
from bearing_env.slam import (
    FRAME_L1_L2_OVERLAP,
    FRAME_L1_L2_TOO_CLOSE,
    FRAME_L1_UNBOUNDED,
    FRAME_L2_UNBOUNDED,
    FRAME_OK,
    INCONSISTENCY_POLICIES,
    LANDMARK_INCONSISTENT,
    LANDMARK_SKIPPED,
    LANDMARK_UNBOUNDED,
    LANDMARK_UPDATED,
    BatchedPolygonSLAM,
    PolygonSLAM,
    UpdateResult,
    kernels,
    world_to_fl,
)
from bearing_env.slam.batch import STATE_ARRAYS
from tests.slam_sim import Episode, fl, random_episode, run, to_xy, true_bearings

EPS = np.deg2rad(2.0)
FRAME_STATUSES = {
    FRAME_OK,
    FRAME_L1_UNBOUNDED,
    FRAME_L2_UNBOUNDED,
    FRAME_L1_L2_OVERLAP,
    FRAME_L1_L2_TOO_CLOSE,
}
LANDMARK_STATUSES = {
    LANDMARK_UPDATED,
    LANDMARK_UNBOUNDED,
    LANDMARK_INCONSISTENT,
    LANDMARK_SKIPPED,
}


def readings(landmarks, r1: complex, r2: complex) -> tuple[np.ndarray, np.ndarray]:
    """Exact bearings of world landmarks (complex) for a move from r1 to r2."""
    heading = float(np.angle(r2 - r1))
    lm = np.asarray(landmarks, dtype=complex)
    return true_bearings(lm, r1, heading), true_bearings(lm, r2, heading)


def state(slam: PolygonSLAM) -> dict:
    return {
        "vertices": slam_vertices(slam),
        "counts": slam.batch.counts[slam.index].copy(),
        "areas": slam.areas,
        "estimates": slam.estimates,
        "initialised": slam.initialised,
        "robot": slam.robot_estimate,
        "n_inconsistent": slam.n_inconsistent,
    }


def slam_vertices(slam: PolygonSLAM) -> np.ndarray:
    """Each region's vertex array (zeros beyond its count), as a copy."""
    vertices = slam.batch.vertices[slam.index].copy()
    for j, n in enumerate(slam.batch.counts[slam.index]):
        vertices[j, n:] = 0.0
    return vertices


def assert_same_state(a: dict, b: dict) -> None:
    for key in a:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)


def assert_no_nan(slam: PolygonSLAM) -> None:
    ok = slam.initialised
    assert not np.any(np.isnan(slam.areas)), slam.areas
    assert np.all(np.isfinite(slam.areas[ok])), slam.areas
    assert np.all(np.isinf(slam.areas[~ok]))
    assert np.all(np.isfinite(slam.estimates[ok])), slam.estimates
    # (Both coordinates of uninitialised estimates being nan is checked once, in
    # test_frame_failure_on_a_fresh_map_leaves_it_empty.)


# A reference world: the move R1 = 0 -> R2 = 1 along +x, L1 and L2 well above it.
L1, L2 = 0.3 + 1.0j, 0.9 + 1.2j
L3, L4 = 0.4 - 0.8j, 1.6 + 0.7j
GOOD = np.array([L1, L2, L3, L4])
R1, R2 = 0.0 + 0.0j, 1.0 + 0.0j


# --------------------------------------------------------------------------------------
# Construction and input validation
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"n_landmarks": 2}, r"n_landmarks.*2"),
        ({"n_landmarks": 0}, r"n_landmarks.*0"),
        ({"n_landmarks": -4}, r"n_landmarks.*-4"),
        ({"epsilon": 0.0}, r"epsilon.*0\.0"),
        ({"epsilon": -0.01}, r"epsilon.*-0\.01"),
        ({"epsilon": 1.6}, r"epsilon.*1\.6"),
        ({"epsilon": float("nan")}, r"epsilon.*nan"),
        ({"epsilon": float("inf")}, r"epsilon.*inf"),
        ({"transfer": "vertices"}, r"transfer.*vertices"),
        ({"transfer": "Paper"}, r"transfer.*Paper"),
        ({"edge_samples": 9}, r"edge_samples.*9"),
        ({"edge_samples": 10**6}, r"edge_samples.*1000000"),
        ({"on_inconsistency": "vote"}, r"on_inconsistency.*vote"),
        ({"edge_samples": 0}, r"edge_samples.*0"),
    ],
)
def test_constructor_rejects_bad_values_and_names_them(kwargs, pattern):
    args = {"n_landmarks": 4, "epsilon": EPS} | kwargs
    with pytest.raises(ValueError, match=pattern):
        PolygonSLAM(**args)


def test_constructor_accepts_the_documented_choices():
    for transfer in ("paper", "conservative"):
        for policy in INCONSISTENCY_POLICIES:
            slam = PolygonSLAM(3, 1e-3, transfer=transfer, on_inconsistency=policy)
            assert slam.polygons == [None]
    # Default: the conservative transfer (docs/design.md section 2.6: the env's default).
    assert PolygonSLAM(4, EPS).transfer == "conservative"


@pytest.mark.parametrize("which", ["bearings_start", "bearings_end"])
@pytest.mark.parametrize(
    "bad",
    [
        [0.1, 0.2, float("inf"), 0.4],
        [-float("inf"), 0.2, 0.3, 0.4],
        [0.1, 0.2, 0.3],  # too short
        [0.1, 0.2, 0.3, 0.4, 0.5],  # too long
        [[0.1, 0.2, 0.3, 0.4]],  # (1, 4)
        [[0.1], [0.2], [0.3], [0.4]],  # (4, 1)
        0.5,  # scalar
    ],
)
def test_bad_bearings_raise_a_value_error_naming_the_argument(which, bad):
    slam = PolygonSLAM(4, EPS)
    b1, b2 = readings(GOOD, R1, R2)
    slam.update(b1, b2)
    before = state(slam)
    n_updates = slam.n_updates
    args = {"bearings_start": b1, "bearings_end": b2, which: bad}
    with pytest.raises(ValueError, match=which):
        slam.update(**args)
    # A rejected update leaves the map alone.
    assert_same_state(before, state(slam))
    assert slam.n_updates == n_updates


# --------------------------------------------------------------------------------------
# UpdateResult semantics
# --------------------------------------------------------------------------------------


def test_a_good_move_updates_every_landmark():
    slam = PolygonSLAM(4, EPS)
    res = slam.update(*readings(GOOD, R1, R2))
    assert isinstance(res, UpdateResult)
    assert res.frame_changed and res.frame_status == FRAME_OK
    assert res.landmark_status.tolist() == [LANDMARK_UPDATED, LANDMARK_UPDATED]
    assert res.n_inconsistent == 0
    assert slam.initialised.all()
    assert slam.n_updates == 1 and slam.n_frame_changes == 1
    truth = to_xy(fl(GOOD[2:], L1, L2))
    assert slam.contains(truth).all()
    assert slam.robot_contains(to_xy(fl(R2, L1, L2)))
    # Public views agree with each other.
    for region, poly, area, est in zip(
        slam.regions, slam.polygons, slam.areas, slam.estimates, strict=True
    ):
        assert isinstance(region, shapely.Polygon) and region.is_valid
        assert region.area == pytest.approx(area, rel=1e-9)
        np.testing.assert_allclose([region.centroid.x, region.centroid.y], est, atol=1e-9)
        assert shapely.Polygon(poly).equals_exact(region, 1e-12)
    assert slam.robot_region.area > 0
    np.testing.assert_allclose(
        [slam.robot_region.centroid.x, slam.robot_region.centroid.y], slam.robot_estimate,
        atol=1e-9,
    )


@pytest.mark.parametrize(
    ("landmarks", "expected"),
    [
        # L1 on the line of motion, ahead: its cones are parallel.
        ([3.0 + 0.0j, L2, L3, L4], FRAME_L1_UNBOUNDED),
        # L1 fine, L2 on the line of motion behind R1.
        ([L1, -2.0 + 0.0j, L3, L4], FRAME_L2_UNBOUNDED),
        # L1 == L2: coincident, the regions overlap.
        ([L1, L1, L3, L4], FRAME_L1_L2_OVERLAP),
        # L1 and L2 1 mm apart at ~1 unit: the regions overlap for epsilon = 2 degrees.
        ([L1, L1 + 0.001, L3, L4], FRAME_L1_L2_OVERLAP),
    ],
)
def test_moves_that_cannot_change_frames_say_why_and_change_nothing(landmarks, expected):
    slam = PolygonSLAM(4, EPS)
    slam.update(*readings(GOOD, -0.5 + 0.5j, 0.5 - 0.3j))  # an earlier good move
    before = state(slam)
    heading_before = slam.robot_heading
    res = slam.update(*readings(landmarks, R1, R2))
    assert not res.frame_changed
    assert res.frame_status == expected
    assert res.landmark_status.tolist() == [LANDMARK_SKIPPED, LANDMARK_SKIPPED]
    assert res.n_inconsistent == 0
    assert_same_state(before, state(slam))
    assert slam.robot_heading == heading_before
    assert slam.n_updates == 2 and slam.n_frame_changes == 1


def test_frame_failure_on_a_fresh_map_leaves_it_empty():
    slam = PolygonSLAM(4, EPS)
    res = slam.update(*readings([L1, L1, L3, L4], R1, R2))
    assert not res.frame_changed and res.frame_status == FRAME_L1_L2_OVERLAP
    assert not slam.initialised.any()
    assert np.all(np.isinf(slam.areas))
    # Documented: estimates are nan (both coordinates) if not initialised.
    assert np.all(np.isnan(slam.estimates)), slam.estimates
    assert np.all(np.isnan(slam.robot_estimate))
    assert slam.robot_region is None and slam.regions == [None, None]
    assert not slam.contains(np.zeros((2, 2))).any()


@pytest.mark.parametrize("where", [2.5 + 0.0j, -1.5 + 0.0j])  # ahead of R2, behind R1
def test_a_landmark_on_the_line_of_motion_is_left_alone(where):
    slam = PolygonSLAM(4, EPS)
    slam.update(*readings(GOOD, -0.5 + 0.5j, 0.5 - 0.3j))
    before = slam_vertices(slam)[1].copy()
    b1, b2 = readings([L1, L2, L3, where], R1, R2)
    assert abs(abs(b1[3]) - abs(b2[3])) < 1e-12 and abs(b1[3]) in (0.0, np.pi)
    res = slam.update(b1, b2)
    assert res.frame_changed
    assert res.landmark_status.tolist() == [LANDMARK_UPDATED, LANDMARK_UNBOUNDED]
    np.testing.assert_array_equal(slam_vertices(slam)[1], before)
    # On a fresh map, the same move leaves that landmark uninitialised.
    fresh = PolygonSLAM(4, EPS)
    fresh.update(b1, b2)
    assert fresh.initialised.tolist() == [True, False]
    assert_no_nan(fresh)


def test_cones_that_miss_each_other_are_counted_as_inconsistent():
    slam = PolygonSLAM(5, EPS)
    world = np.array([L1, L2, L3, L4, 0.5 + 2.0j])
    slam.update(*readings(world, -0.5 + 0.5j, 0.5 - 0.3j))
    before = slam_vertices(slam)
    b1, b2 = readings(world, R1, R2)
    b1[4], b2[4] = np.pi / 2, -np.pi / 2  # up from R1, down from R2: no intersection
    res = slam.update(b1, b2)
    assert res.frame_changed
    assert res.landmark_status.tolist() == [
        LANDMARK_UPDATED,
        LANDMARK_UPDATED,
        LANDMARK_INCONSISTENT,
    ]
    assert res.n_inconsistent == 1 and slam.n_inconsistent == 1
    # That landmark's region is untouched (its movement region does not exist).
    np.testing.assert_array_equal(slam_vertices(slam)[2], before[2])
    assert_no_nan(slam)


EPS_FINE = np.deg2rad(0.5)


def contradicting_moves(transfer: str):
    """Two good moves; in the second, L3 is reported 0.6 units away from where it is.

    Precondition checked here: the two single-move regions of L3 are far apart, while
    those of L4 overlap.
    """
    move1 = readings(GOOD, -0.5 + 0.5j, 0.5 - 0.3j)
    b1, b2 = readings(GOOD, R1, R2)
    f1, f2 = readings([L1, L2, L3 + 0.6, L4], R1, R2)
    b1[2], b2[2] = f1[2], f2[2]
    one = PolygonSLAM(4, EPS_FINE, transfer=transfer)
    two = PolygonSLAM(4, EPS_FINE, transfer=transfer)
    assert one.update(*move1).frame_changed and two.update(b1, b2).frame_changed
    assert one.regions[0].distance(two.regions[0]) > 0.1
    assert one.regions[1].intersects(two.regions[1])
    return move1, (b1, b2)


@pytest.mark.parametrize("transfer", ["conservative", "paper"])
def test_on_inconsistency_keep_leaves_the_old_region(transfer):
    (a1, a2), (b1, b2) = contradicting_moves(transfer)
    slam = PolygonSLAM(4, EPS_FINE, transfer=transfer, on_inconsistency="keep")
    slam.update(a1, a2)
    old = slam_vertices(slam)
    old_area, old_est = slam.areas, slam.estimates
    res = slam.update(b1, b2)
    assert res.landmark_status.tolist() == [LANDMARK_INCONSISTENT, LANDMARK_UPDATED]
    assert res.n_inconsistent == 1 and slam.n_inconsistent == 1
    np.testing.assert_array_equal(slam_vertices(slam)[0], old[0])
    assert slam.areas[0] == old_area[0]
    np.testing.assert_array_equal(slam.estimates[0], old_est[0])
    # The consistent landmark was still fused (it can only shrink).
    assert slam.areas[1] <= old_area[1] * (1 + 1e-12)
    assert_no_nan(slam)


@pytest.mark.parametrize("transfer", ["conservative", "paper"])
def test_on_inconsistency_restart_takes_the_new_region(transfer):
    (a1, a2), (b1, b2) = contradicting_moves(transfer)
    slam = PolygonSLAM(4, EPS_FINE, transfer=transfer, on_inconsistency="restart")
    slam.update(a1, a2)
    res = slam.update(b1, b2)
    assert res.landmark_status.tolist() == [LANDMARK_INCONSISTENT, LANDMARK_UPDATED]
    assert res.n_inconsistent == 1 and slam.n_inconsistent == 1
    only_new = PolygonSLAM(4, EPS_FINE, transfer=transfer)
    only_new.update(b1, b2)
    np.testing.assert_allclose(
        slam_vertices(slam)[0], slam_vertices(only_new)[0], rtol=1e-12, atol=1e-12
    )
    assert slam.areas[0] == pytest.approx(only_new.areas[0], rel=1e-12)
    # The new region holds the (fake) reported position; L4 is fused as usual.
    fake = to_xy(fl(L3 + 0.6, L1, L2))
    assert slam.contains(np.stack([fake, to_xy(fl(L4, L1, L2))])).all() or transfer == "paper"
    assert slam.areas[1] <= only_new.areas[1] * (1 + 1e-12)
    assert_no_nan(slam)


@pytest.mark.parametrize("policy", INCONSISTENCY_POLICIES)
@pytest.mark.parametrize("transfer", ["conservative", "paper"])
def test_noise_beyond_epsilon_is_counted_and_the_map_stays_finite(policy, transfer):
    """Noise up to 8 epsilon over 10 moves: inconsistencies happen, are counted exactly,
    and every mapped region keeps a finite, positive area and a finite estimate."""
    total, statuses = 0, 0
    for seed in range(25):
        rng = np.random.default_rng(500 + seed)
        episode = random_episode(rng, 6, 10)
        slam = PolygonSLAM(6, EPS, transfer=transfer, on_inconsistency=policy)
        for b1, b2 in episode.readings(8 * EPS):
            res = slam.update(b1, b2)
            assert res.n_inconsistent == int(np.sum(res.landmark_status == LANDMARK_INCONSISTENT))
            statuses += res.n_inconsistent
            assert_no_nan(slam)
            ok = slam.initialised
            assert np.all(slam.areas[ok] >= 0)
        total += slam.n_inconsistent
    assert total == statuses
    assert total > 0


# --------------------------------------------------------------------------------------
# Degenerate input
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("transfer", ["conservative", "paper"])
def test_coincident_landmarks(transfer):
    slam = PolygonSLAM(5, EPS, transfer=transfer)
    world = np.array([L1, L2, L3, L3, L4])  # L3 == L4
    for r1, r2 in [(R1, R2), (-0.5 + 0.5j, 0.5 - 0.3j), (1.2 + 0.2j, 0.2 + 0.6j)]:
        slam.update(*readings(world, r1, r2))
        assert_no_nan(slam)
    np.testing.assert_array_equal(slam_vertices(slam)[0], slam_vertices(slam)[1])
    assert slam.initialised.all()
    if transfer == "conservative":
        assert slam.contains(to_xy(fl(world[2:], L1, L2))).all()


@pytest.mark.parametrize("bearing_at_landmark", [0.0, 1.0, np.pi, -np.pi])
@pytest.mark.parametrize("where", ["start_on_L3", "end_on_L4", "start_on_L1", "end_on_L2"])
def test_robot_on_a_landmark(where, bearing_at_landmark):
    """A landmark at the robot has no bearing; whatever the sensor reports, nothing may
    crash or turn NaN, and (the landmark being at the apex of its cone) the conservative
    regions still contain the truth."""
    targets = {"start_on_L3": (L3, 2, 0), "end_on_L4": (L4, 3, 1)}
    targets |= {"start_on_L1": (L1, 0, 0), "end_on_L2": (L2, 1, 1)}
    at, index, end = targets[where]
    r1, r2 = (at, at + 0.8 - 0.3j) if end == 0 else (at - 0.8 + 0.3j, at)
    slam = PolygonSLAM(4, EPS)
    slam.update(*readings(GOOD, -0.5 + 0.5j, 0.5 - 0.3j))
    b = list(readings(GOOD, r1, r2))
    b[end][index] = bearing_at_landmark
    res = slam.update(*b)
    assert_no_nan(slam)
    assert slam.contains(to_xy(fl(GOOD[2:], L1, L2)))[slam.initialised].all()
    if res.frame_changed:
        assert slam.robot_contains(to_xy(fl(r2, L1, L2)))


@pytest.mark.parametrize("transfer", ["conservative", "paper"])
def test_bearings_of_plus_and_minus_pi_are_the_same_direction(transfer):
    # L3 exactly behind R1 on the line of motion extended, L4 exactly behind at R2 only:
    # place L4 between R1 and R2 so that the reading at R2 is pi.
    world = np.array([L1, L2, -0.7 + 0.0j, 0.5 + 0.0j])
    b1, b2 = readings(world, R1, R2)
    assert abs(b1[2]) == np.pi and abs(b2[2]) == np.pi and abs(b2[3]) == np.pi
    results = []
    for sign in (1.0, -1.0):
        c1, c2 = b1.copy(), b2.copy()
        c1[2], c2[2], c2[3] = sign * np.pi, sign * np.pi, sign * np.pi
        slam = PolygonSLAM(4, EPS, transfer=transfer)
        slam.update(*readings(world, -0.5 + 0.5j, 0.5 - 0.3j))
        res = slam.update(c1, c2)
        assert_no_nan(slam)
        results.append((res.landmark_status.tolist(), slam_vertices(slam)))
    assert results[0][0] == results[1][0]
    # L3 behind on the line: unbounded; L4 between R1 and R2: a bounded diamond.
    assert results[0][0] == [LANDMARK_UNBOUNDED, LANDMARK_UPDATED]
    np.testing.assert_allclose(results[0][1], results[1][1], rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("transfer", ["conservative", "paper"])
def test_huge_bearings_are_wrapped(transfer):
    rng = np.random.default_rng(3)
    episode = random_episode(rng, 5, 4)
    turns = rng.integers(100_000, 200_000, size=(4, 2, 5)) * rng.choice([-1, 1], (4, 2, 5))
    plain = PolygonSLAM(5, EPS, transfer=transfer)
    huge = PolygonSLAM(5, EPS, transfer=transfer)
    for m, (b1, b2) in enumerate(episode.readings(EPS)):
        r_plain = plain.update(b1, b2)
        # |bearing| ~ 1e6 rad; rounding of the shifted value is ~1e-10 rad.
        r_huge = huge.update(b1 + 2 * np.pi * turns[m, 0], b2 + 2 * np.pi * turns[m, 1])
        assert r_plain.frame_status == r_huge.frame_status
        assert r_plain.landmark_status.tolist() == r_huge.landmark_status.tolist()
        assert_no_nan(huge)
        ok = plain.initialised
        np.testing.assert_allclose(huge.areas[ok], plain.areas[ok], rtol=1e-6)
        np.testing.assert_allclose(huge.estimates[ok], plain.estimates[ok], atol=1e-6)
    # Arbitrary huge values (not multiples of 2 pi away from anything) do not crash.
    wild = PolygonSLAM(5, EPS, transfer=transfer)
    for _ in range(5):
        wild.update(rng.uniform(-1e6, 1e6, 5), rng.uniform(-1e6, 1e6, 5))
        assert_no_nan(wild)
    wild.update(np.full(5, 1e6), np.full(5, -1e6))
    assert_no_nan(wild)


@pytest.mark.parametrize("transfer", ["conservative", "paper"])
def test_random_garbage_bearings_never_crash_or_nan(transfer):
    rng = np.random.default_rng(11)
    specials = np.array([0.0, np.pi, -np.pi, np.pi / 2, -np.pi / 2, 2 * np.pi, 1e-300])
    slam = PolygonSLAM(6, EPS, transfer=transfer)
    for _ in range(60):
        b1 = np.where(rng.uniform(size=6) < 0.5, rng.choice(specials, 6), rng.normal(0, 3, 6))
        b2 = np.where(rng.uniform(size=6) < 0.5, rng.choice(specials, 6), rng.normal(0, 3, 6))
        res = slam.update(b1, b2)
        assert res.landmark_status.shape == (4,)
        assert res.frame_status in FRAME_STATUSES
        assert bool(res.frame_changed) == (res.frame_status == FRAME_OK)
        assert set(res.landmark_status.tolist()) <= LANDMARK_STATUSES
        if not res.frame_changed:
            assert res.landmark_status.tolist() == [LANDMARK_SKIPPED] * 4
        else:
            assert LANDMARK_SKIPPED not in res.landmark_status.tolist()
        assert res.n_inconsistent == int(np.sum(res.landmark_status == LANDMARK_INCONSISTENT))
        assert_no_nan(slam)
    assert np.all(np.isfinite(slam.robot_estimate)) or slam.n_frame_changes == 0


# --------------------------------------------------------------------------------------
# Copies, reset, heading
# --------------------------------------------------------------------------------------


def test_copy_is_independent():
    episode = random_episode(np.random.default_rng(5), 5, 6)
    moves = episode.readings(EPS)
    slam = PolygonSLAM(5, EPS)
    for b1, b2 in moves[:3]:
        slam.update(b1, b2)
    snapshot = state(slam)
    clone = slam.copy()
    assert clone is not slam
    for b1, b2 in moves[3:]:
        clone.update(b1, b2)
    assert_same_state(snapshot, state(slam))  # the original did not move
    assert slam.n_updates == 3 and clone.n_updates == 6
    # Replaying the same moves on the original gives the clone's map, bit for bit.
    for b1, b2 in moves[3:]:
        slam.update(b1, b2)
    assert_same_state(state(clone), state(slam))
    # Mutating returned arrays does not reach into the map.
    slam.polygons[0][:] = 0.0
    slam.areas[:] = 0.0
    assert_same_state(state(clone), state(slam))


def test_reset_forgets_everything():
    slam = PolygonSLAM(4, EPS)
    slam.update(*readings(GOOD, R1, R2))
    slam.reset()
    fresh = PolygonSLAM(4, EPS)
    assert_same_state(state(fresh), state(slam))
    assert slam.n_updates == slam.n_frame_changes == slam.n_inconsistent == 0
    assert slam.robot_region is None


def test_robot_heading_in_fl_matches_the_true_heading():
    rng = np.random.default_rng(21)
    for _ in range(20):
        episode = random_episode(rng, 4, 3, noise="uniform")
        eps = 1e-4
        slam = PolygonSLAM(4, eps)
        for (_, _, heading), (b1, b2) in zip(
            episode.poses(), episode.readings(eps), strict=True
        ):
            if slam.update(b1, b2).frame_changed:
                l1, l2 = episode.landmarks[:2]
                expected = heading - np.angle(l2 - l1)
                assert abs(np.angle(np.exp(1j * (slam.robot_heading - expected)))) < 1e-2


# --------------------------------------------------------------------------------------
# Fig. 11 of the paper: area against epsilon
# --------------------------------------------------------------------------------------

# The paper's simulation world (Sec. 3.2, Fig. 7): four landmarks around the centre of a
# 2 m square, L1-L2 = 0.5 m = 1 FL unit; the robot wanders around the centre.
PAPER_SIM = np.array([0.75 + 0.60j, 1.25 + 0.60j, 1.35 + 1.30j, 0.65 + 1.40j])


def paper_sim_episode(seed: int, n_moves: int = 10) -> Episode:
    rng = np.random.default_rng(seed)
    centre = 1.0 + 1.0j

    def ok(z: complex) -> bool:
        d = z - centre
        return max(abs(d.real), abs(d.imag)) <= 0.6 and np.min(np.abs(PAPER_SIM - z)) > 0.1

    start = centre
    while True:
        start = complex(*rng.uniform(0.4, 1.6, 2))
        if ok(start):
            break
    moves, pos = [], start
    while len(moves) < n_moves:
        heading, length = rng.uniform(-np.pi, np.pi), rng.uniform(0.2, 0.6)
        end = pos + length * np.exp(1j * heading)
        if ok(end):
            moves.append((heading, length))
            pos = end
    shape = (n_moves, PAPER_SIM.size)
    return Episode(PAPER_SIM, start, moves, rng.uniform(-1, 1, shape), rng.uniform(-1, 1, shape))


FIG11_DEGREES = np.arange(2.0, 8.0)  # 2, 3, ..., 7


def final_areas(transfer: str, eps: float, n_episodes: int = 30) -> np.ndarray:
    """Areas of A_L3 and A_L4 after 10 moves over the fixed suite (inf: never bounded)."""
    areas = []
    for seed in range(n_episodes):
        episode = paper_sim_episode(100 + seed)
        slam = PolygonSLAM(4, eps, transfer=transfer)
        run(slam, episode, eps)  # the same u in every run, scaled by this epsilon
        areas.extend(slam.areas)
    return np.array(areas)


@pytest.mark.parametrize("transfer", ["paper", "conservative"])
def test_fig11_area_after_ten_moves_grows_as_a_power_of_epsilon(transfer: str) -> None:
    """Paper Fig. 11: the same 30 trajectories and the same normalised noise u in [-1, 1],
    scaled by epsilon, for epsilon = 2..7 degrees; areas of A_L3 and A_L4 after 10 moves.

    Issue 2 asks for the *mean* area to be linear in epsilon (R^2 >= 0.98), as the paper
    states. That does not hold for this model and cannot: every region's width scales
    with epsilon in both directions, so areas scale at least like epsilon**2 (the
    epsilon -> 0 property test sees 100x per decade), and an exact epsilon**2 law fits a
    line over these six points with R^2 = 0.974 at best. Measured on this suite with the
    paper transfer: means 0.103 0.260 0.487 0.872 863 3.09 (one huge region at 6
    degrees), linear R^2 = 0.16; medians 0.066 0.187 0.368 0.581 0.850 1.678, linear
    R^2 = 0.87. What does hold, and is tested here: the median area grows with epsilon
    as a power law, log-log R^2 >= 0.98, with an exponent of at least 2 (measured: 2.46
    paper, 3.05 conservative, whose frame changes also degrade as epsilon grows).
    """
    per_eps = [final_areas(transfer, e) for e in np.deg2rad(FIG11_DEGREES)]
    bounded = np.array([np.isfinite(a).mean() for a in per_eps])
    assert np.all(bounded >= 0.95), bounded
    medians = np.array([np.median(a) for a in per_eps])
    assert np.all(np.diff(medians) > 0), medians
    x, y = np.log(FIG11_DEGREES), np.log(medians)
    exponent, offset = np.polyfit(x, y, 1)
    fitted = exponent * x + offset
    r2 = 1.0 - np.sum((y - fitted) ** 2) / np.sum((y - y.mean()) ** 2)
    assert r2 >= 0.98, f"log-log R^2 = {r2:.4f}; medians {np.round(medians, 4).tolist()}"
    assert 1.8 <= exponent <= 3.5, f"exponent {exponent:.2f}; medians {medians.tolist()}"


# --------------------------------------------------------------------------------------
# Dependencies
# --------------------------------------------------------------------------------------

ROOT = Path(__file__).resolve().parents[2]
#: The package as imported: the checkout's, or an installed one (tests/tools/test_install.py).
PACKAGE = Path(bearing_env.__file__).resolve().parent


def _modules_after(code: str) -> set[str]:
    out = subprocess.run(
        [sys.executable, "-c", code + "\nimport sys\nprint(' '.join(sorted(sys.modules)))"],
        capture_output=True,
        text=True,
        cwd=ROOT,
        check=True,
    )
    return set(out.stdout.split())


def test_the_world_model_runs_with_gymnasium_and_pygame_unavailable() -> None:
    """Issue 2: the world model imports neither gymnasium nor pygame, so it runs on logged
    robot bearings without them. ``import bearing_env`` registers the Gymnasium ids when
    gymnasium is installed (issue 3 asks for that), so here both are made unimportable
    and the world model must still import and update."""
    code = textwrap.dedent(
        """
        import sys
        sys.modules["gymnasium"] = None  # any import of it now raises ImportError
        sys.modules["pygame"] = None
        import numpy as np
        from bearing_env.slam import PolygonSLAM
        fr = np.array([2 + 2j, 3 + 2j, 1 + 3j, -1 - 2j])
        slam = PolygonSLAM(4, np.deg2rad(2.0))
        assert slam.update(np.angle(fr), np.angle(fr - 1)).frame_changed
        assert np.isfinite(slam.areas).all()
        """
    )
    loaded = _modules_after(code)
    assert "bearing_env.slam" in loaded
    assert "bearing_env.registration" not in loaded


def test_the_slam_subpackage_itself_imports_neither_gymnasium_nor_pygame():
    """The subpackage alone (bearing_env/__init__ bypassed by a bare namespace parent)."""
    code = textwrap.dedent(
        f"""
        import sys, types
        pkg = types.ModuleType("bearing_env")
        pkg.__path__ = [{str(PACKAGE)!r}]
        sys.modules["bearing_env"] = pkg
        import bearing_env.slam
        s = bearing_env.slam.PolygonSLAM(3, 0.01)
        """
    )
    loaded = _modules_after(code)
    assert "bearing_env.slam" in loaded
    assert "gymnasium" not in loaded and "pygame" not in loaded


def test_world_to_fl_is_exported_and_agrees_with_the_simulator():
    rng = np.random.default_rng(2)
    pts = rng.normal(size=(6, 2))
    got = world_to_fl(pts, pts[0], pts[1])
    z = pts[:, 0] + 1j * pts[:, 1]
    np.testing.assert_allclose(got, to_xy(fl(z, z[0], z[1])), atol=1e-12)


# --------------------------------------------------------------------------------------
# Input types, map indices, and pickles with read-only buffers
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("epsilon", ["0.1", None, True, 1j, [0.1]])
def test_epsilon_must_be_a_number(epsilon):
    with pytest.raises(TypeError, match=rf"epsilon.*{re.escape(repr(epsilon))}"):
        PolygonSLAM(4, epsilon)


@pytest.mark.parametrize("bearings", [["0.1", "0.2", "0.3", "0.4"], np.array(["1"] * 4), [1j] * 4])
def test_bearings_must_be_numbers(bearings):
    slam = PolygonSLAM(4, EPS)
    good = readings(GOOD, R1, R2)[0]
    with pytest.raises(TypeError, match="bearings_start must be numbers"):
        slam.update(bearings, good)


@pytest.mark.parametrize(
    ("maps", "error", "pattern"),
    [
        ([-1, 0], ValueError, r"\[-1, 0\]"),
        ([0, 3], ValueError, r"\[0, 3\]"),
        ([1, 1], ValueError, r"repeat.*\[1, 1\]"),
        ([1.7, 0.0], TypeError, r"1\.7"),
        ([True, False], TypeError, r"True"),
    ],
)
def test_batched_update_rejects_bad_map_indices(maps, error, pattern):
    batch = BatchedPolygonSLAM(3, 4, EPS)
    b1, b2 = readings(GOOD, R1, R2)
    with pytest.raises(error, match=pattern):
        batch.update(np.stack([b1, b1]), np.stack([b2, b2]), maps=maps)
    assert batch.n_updates.tolist() == [0, 0, 0]  # nothing was half-done


def read_only_round_trip(obj):
    """Pickle out of band, as Ray's object store does, and hand back read-only buffers."""
    buffers: list[pickle.PickleBuffer] = []
    data = pickle.dumps(obj, protocol=5, buffer_callback=buffers.append)
    return pickle.loads(data, buffers=[memoryview(b).toreadonly() for b in buffers])


def test_a_map_from_read_only_buffers_still_updates_and_matches_the_original():
    moves = random_episode(np.random.default_rng(3), 5, 6).readings(EPS)
    slam = PolygonSLAM(5, EPS)
    for b1, b2 in moves[:3]:
        slam.update(b1, b2)
    copy = read_only_round_trip(slam)
    for b1, b2 in moves[3:]:
        slam.update(b1, b2)
        copy.update(b1, b2)
    assert_same_state(state(slam), state(copy))


def test_an_update_without_the_robot_maps_the_same_landmarks_and_keeps_the_old_robot():
    moves = random_episode(np.random.default_rng(11), 6, 8).readings(EPS)
    full, lean = BatchedPolygonSLAM(1, 6, EPS), BatchedPolygonSLAM(1, 6, EPS)
    for b1, b2 in moves:
        robot_before = (lean.robot_counts.copy(), lean.robot_area.copy())
        a = full.update(b1[None], b2[None])
        b = lean.update(b1[None], b2[None], robot=False)
        np.testing.assert_array_equal(a.landmark_status, b.landmark_status)
        np.testing.assert_array_equal(full.areas, lean.areas)
        np.testing.assert_array_equal(full.vertices, lean.vertices)
        np.testing.assert_array_equal(lean.robot_counts, robot_before[0])
        np.testing.assert_array_equal(lean.robot_area, robot_before[1])
    assert full.robot_counts[0] > 0 and lean.robot_counts[0] == 0


@pytest.mark.parametrize(
    ("transfer", "fusion"),
    [("conservative", "intersect"), ("paper", "intersect"), ("conservative", "relaxed")],
)
def test_the_threaded_kernel_gives_the_serial_kernels_maps_bit_for_bit(transfer, fusion):
    episodes = [random_episode(np.random.default_rng(40 + i), 5, 8) for i in range(16)]
    # Noise beyond epsilon, so that the relaxed fusion has regions to leave out.
    readings = [episode.readings(2.5 * EPS) for episode in episodes]
    settings = {"transfer": transfer, "fusion": fusion, "window": 4}
    serial = BatchedPolygonSLAM(16, 5, EPS, **settings)
    threaded = BatchedPolygonSLAM(16, 5, EPS, **settings)
    rows = np.arange(16)
    for move in range(8):
        b1 = np.array([r[move][0] for r in readings])
        b2 = np.array([r[move][1] for r in readings])
        outputs = []
        for batch, threads in ((serial, 0), (threaded, 4)):
            out = kernels.Outputs(
                np.empty(16, dtype=np.int8),
                np.empty((16, 3), dtype=np.int8),
                np.empty(16, dtype=np.int64),
            )
            arguments = (b1, b2, rows, batch._kernel_params(True), batch._kernel_state(), out)
            kernels.update_maps(*arguments, max(threads, 1))  # 4 blocks on threads, any cores
            frame, landmark, bad = out
            outputs.append((frame, landmark, bad))
        for mine, theirs in zip(*outputs, strict=True):
            np.testing.assert_array_equal(mine, theirs)
    for name in STATE_ARRAYS:
        np.testing.assert_array_equal(getattr(serial, name), getattr(threaded, name), name)
    assert serial.n_frame_changes.sum() > 16  # real fusions were compared
    if fusion == "relaxed":
        assert serial.outliers.sum() > 0  # and regions were left out


def test_take_copies_maps_by_index_with_repeats() -> None:
    batch = BatchedPolygonSLAM(3, 4, EPS)
    rng = np.random.default_rng(0)
    batch.update(rng.uniform(-3, 3, (3, 4)), rng.uniform(-3, 3, (3, 4)))
    copies = batch.take(np.array([2, 0, 2]))
    assert copies.num_maps == 3
    for i, source in enumerate((2, 0, 2)):
        for name in STATE_ARRAYS:
            mine, theirs = getattr(copies, name)[i], getattr(batch, name)[source]
            assert np.array_equal(mine, theirs, equal_nan=True), name
    copies.reset([0])  # independent copies
    assert np.array_equal(batch.counts[2], copies.counts[2])
    with pytest.raises(ValueError, match="indices"):
        batch.take(np.array([3]))


def test_status_names_are_indexed_by_contiguous_kernel_codes() -> None:
    from bearing_env.slam.batch import _names_by_code

    assert _names_by_code({1: "b", 0: "a"}) == ("a", "b")
    with pytest.raises(ValueError, match=r"0\.\.1, got \[0, 2\]"):
        _names_by_code({0: "a", 2: "c"})


@pytest.mark.parametrize(
    ("fusion", "counter", "value"),
    [
        ("intersect", "n_updates", 2**63 - 1),
        ("intersect", "n_frame_changes", 2**62 + 1),
        ("intersect", "n_inconsistent", -1),
        ("relaxed", "n_dropped", 2**63 - 1),
        ("robust", "n_regions", 2**63 - 1),
        ("robust", "bound_events", 2**63 - 1),
    ],
)
def test_a_counter_that_would_overflow_is_refused_and_the_map_left_alone(
    fusion: str, counter: str, value: int
) -> None:
    # A user can write the state's arrays; the update refuses a counter it would carry
    # past int64's end (or a negative one) instead of overflowing it.
    maps = BatchedPolygonSLAM(2, 4, np.deg2rad(3.0), fusion=fusion)
    getattr(maps, counter).reshape(2, -1)[1, 0] = value
    before = {name: getattr(maps, name).copy() for name in STATE_ARRAYS}
    episode = random_episode(np.random.default_rng(4), 4, 1)
    b1, b2 = episode.readings(np.deg2rad(1.0))[0]
    with pytest.raises(ValueError, match=f"map 1 has a corrupt state: {counter} out of range"):
        maps.update(b1[None], b2[None], maps=[1])
    for name in STATE_ARRAYS:
        np.testing.assert_array_equal(getattr(maps, name), before[name], err_msg=name)
    # At the limit, the update runs.
    getattr(maps, counter).reshape(2, -1)[1, 0] = 2**62
    maps.update(np.stack([b1, b1]), np.stack([b2, b2]))
