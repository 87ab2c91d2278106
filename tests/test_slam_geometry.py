"""Unit tests of the world model's geometry: cones in FR, support K-gons, frame changes.

Every expected value is computed independently here (shapely's exact polygon operations,
closed forms, or the exact line intersections of ``tests/slam_sim.py``), never copied
from the implementation's output.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from bearing_env.slam import (
    fl_to_world,
    fr_region,
    transfer_point,
    transfer_polygon,
    world_to_fl,
)
from bearing_env.slam.geometry import (
    FR_BOUNDED,
    FR_EMPTY,
    FR_UNBOUNDED,
    KGon,
    cone_intersections,
)
from tests.slam_sim import cone_region_vertices, to_xy, wrap

SETTINGS = settings(deadline=None, max_examples=60, derandomize=True)
SEEDS = st.integers(min_value=0, max_value=2**32 - 1)

# --------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------


def shp(verts) -> shapely.Polygon:
    """Convex hull of complex vertices as a shapely geometry."""
    v = np.asarray(verts, dtype=complex).reshape(-1)
    return shapely.convex_hull(shapely.multipoints(to_xy(v)))


def kgon_polygon(kgon: KGon, h: np.ndarray) -> shapely.Polygon:
    return shp(kgon.vertices(h))


def random_convex_cloud(rng: np.random.Generator, centre: complex, radius: float) -> np.ndarray:
    n = int(rng.integers(3, 12))
    r = radius * np.sqrt(rng.uniform(0.05, 1.0, n))
    return centre + r * np.exp(1j * rng.uniform(0, 2 * np.pi, n))


def hausdorff(a, b) -> float:
    return float(shapely.hausdorff_distance(a, b))


# --------------------------------------------------------------------------------------
# KGon
# --------------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [0, 6, 7, 9, 33])
def test_kgon_rejects_bad_directions_and_names_the_value(bad):
    with pytest.raises(ValueError, match=rf"directions.*{bad}"):
        KGon(bad)


@pytest.mark.parametrize("k", [8, 16, 32, 64])
def test_kgon_of_the_unit_circle_is_the_circumscribed_regular_polygon(k):
    kgon = KGon(k)
    circle = np.exp(1j * np.linspace(0, 2 * np.pi, 20001))
    h = kgon.support_of_points(circle)
    np.testing.assert_allclose(h, 1.0, atol=1e-7)
    area, centroid = kgon.area_centroid(h)
    # Circumscribed regular K-gon of the unit circle: area K tan(pi / K).
    assert area == pytest.approx(k * np.tan(np.pi / k), rel=1e-6)
    assert abs(centroid) < 1e-7


@settings(deadline=None, max_examples=40, derandomize=True)
@given(seed=SEEDS, k=st.sampled_from([8, 16, 32, 64]))
def test_kgon_support_vertices_round_trip(seed, k):
    rng = np.random.default_rng(seed)
    kgon = KGon(k)
    pts = random_convex_cloud(rng, complex(*rng.normal(size=2)), rng.uniform(0.1, 3))
    h = kgon.support_of_points(pts)
    # Independent support values.
    u = np.exp(2j * np.pi * np.arange(k) / k)
    expected = np.max((np.conj(u)[:, None] * pts[None, :]).real, axis=1)
    np.testing.assert_allclose(h, expected, rtol=0, atol=1e-12)
    # The K-gon contains the cloud, and its vertices give back the same (tight) supports.
    verts = kgon.vertices(h)
    np.testing.assert_allclose(kgon.support_of_points(verts), h, atol=1e-9)
    poly = kgon_polygon(kgon, h)
    assert poly.buffer(1e-9).contains(shapely.multipoints(to_xy(pts)))
    area, centroid = kgon.area_centroid(h)
    assert area == pytest.approx(poly.area, rel=1e-9, abs=1e-12)
    assert abs(centroid - complex(poly.centroid.x, poly.centroid.y)) < 1e-9


@SETTINGS
@given(seed=SEEDS, k=st.sampled_from([8, 16, 32, 64]))
def test_kgon_intersect_matches_shapely(seed, k):
    rng = np.random.default_rng(seed)
    kgon = KGon(k)
    scale = 10.0 ** rng.uniform(-3, 2)
    c1 = scale * complex(*rng.normal(size=2))
    c2 = c1 + scale * rng.uniform(0, 2.5) * np.exp(1j * rng.uniform(0, 2 * np.pi))
    hp = kgon.support_of_points(random_convex_cloud(rng, c1, scale * rng.uniform(0.2, 1.5)))
    hc = kgon.support_of_points(random_convex_cloud(rng, c2, scale * rng.uniform(0.2, 1.5)))
    p, q = kgon_polygon(kgon, hp), kgon_polygon(kgon, hc)
    exact = p.intersection(q)
    h, empty = kgon.intersect(hp, hc)
    if exact.area > 1e-6 * scale**2:
        assert not empty
        area, centroid = kgon.area_centroid(h)
        assert area == pytest.approx(exact.area, rel=1e-9, abs=1e-12 * scale**2)
        assert abs(centroid - complex(exact.centroid.x, exact.centroid.y)) <= 1e-9 * scale
        got = kgon_polygon(kgon, h)
        assert got.symmetric_difference(exact).area <= 1e-9 * exact.area + 1e-14 * scale**2
        # Tight: every returned support is attained by the result's own vertices.
        np.testing.assert_allclose(
            kgon.support_of_points(kgon.vertices(h)), h, atol=1e-9 * (scale + abs(c1))
        )
    elif p.distance(q) > 1e-6 * scale:
        assert empty


def test_kgon_intersect_batched_and_special_cases():
    kgon = KGon(16)
    square = np.array([0, 1, 1 + 1j, 1j])
    h_sq = kgon.support_of_points(square)
    h_small = kgon.support_of_points(0.25 + 0.25j + 0.5 * square)  # inside the square
    h_far = kgon.support_of_points(square + 5.0)  # disjoint
    h_gap = kgon.support_of_points(square + 1.001)  # disjoint by a small gap along x
    h_shift = kgon.support_of_points(square + 0.5)  # overlaps half
    hp = np.stack([h_sq, h_sq, h_sq, h_sq, h_sq])
    hc = np.stack([h_sq, h_small, h_far, h_gap, h_shift])
    h, empty = kgon.intersect(hp, hc)
    assert h.shape == (5, 16)
    np.testing.assert_array_equal(empty, [False, False, True, True, False])
    area, _ = kgon.area_centroid(h[[0, 1, 4]])
    ref = [kgon_polygon(kgon, h_sq).area, kgon_polygon(kgon, h_small).area]
    ref.append(kgon_polygon(kgon, h_sq).intersection(kgon_polygon(kgon, h_shift)).area)
    np.testing.assert_allclose(area, ref, rtol=1e-9)
    # Intersection is symmetric.
    h2, empty2 = kgon.intersect(hc, hp)
    np.testing.assert_array_equal(empty2, empty)
    np.testing.assert_allclose(h2[~empty], h[~empty], atol=1e-12)
    # Each pair's result is the one it gets alone, bit for bit, whatever else is batched.
    for i in range(5):
        alone, alone_empty = kgon.intersect(hp[i : i + 1], hc[i : i + 1])
        assert alone_empty[0] == empty[i]
        if not empty[i]:
            np.testing.assert_array_equal(alone[0], h[i])


@SETTINGS
@given(seed=SEEDS)
def test_kgon_contains_matches_shapely(seed):
    rng = np.random.default_rng(seed)
    kgon = KGon(int(rng.choice([8, 16, 32, 64])))
    h = kgon.support_of_points(random_convex_cloud(rng, complex(*rng.normal(size=2)), 1.0))
    poly = kgon_polygon(kgon, h)
    pts = complex(poly.centroid.x, poly.centroid.y) + 1.5 * (
        rng.uniform(-1, 1, 200) + 1j * rng.uniform(-1, 1, 200)
    )
    got = kgon.contains(np.broadcast_to(h, (200, kgon.k)), pts)
    geoms = shapely.points(to_xy(pts))
    margin = shapely.distance(geoms, poly.exterior)
    clear = margin > 1e-7
    inside = shapely.contains(poly, geoms)
    np.testing.assert_array_equal(got[clear], inside[clear])
    # Vertices (on the boundary) count as inside.
    assert np.all(kgon.contains(np.broadcast_to(h, (kgon.k, kgon.k)), kgon.vertices(h)))


# --------------------------------------------------------------------------------------
# Cones in FR
# --------------------------------------------------------------------------------------


def random_fr_landmarks(rng: np.random.Generator, n: int) -> np.ndarray:
    """FR landmark positions (R1 = 0, R2 = 1), kept off the apexes."""
    r = rng.uniform(0.05, 4.0, n)
    z = 0.5 + r * np.exp(1j * rng.uniform(-np.pi, np.pi, n))
    return np.where((np.abs(z) < 0.02) | (np.abs(z - 1) < 0.02), z + 0.1j, z)


@SETTINGS
@given(seed=SEEDS, eps_deg=st.floats(0.1, 15.0), noise=st.sampled_from(["uniform", "extreme"]))
def test_cone_intersections_contain_the_truth_and_match_exact_geometry(seed, eps_deg, noise):
    rng = np.random.default_rng(seed)
    eps = np.deg2rad(eps_deg)
    n = 40
    truth = random_fr_landmarks(rng, n)
    if noise == "uniform":
        u1, u2 = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    else:
        u1, u2 = rng.choice([-1.0, 1.0], n), rng.choice([-1.0, 1.0], n)
    b1 = wrap(np.angle(truth) + eps * u1)
    b2 = wrap(np.angle(truth - 1) + eps * u2)
    verts, status = cone_intersections(b1, b2, eps)
    assert verts.shape[0] == n and status.shape == (n,)
    # The truth is in both cones, so the intersection is never empty.
    assert not np.any(status == FR_EMPTY)
    for i in range(n):
        mine = cone_region_vertices(b1[i], b2[i], eps)
        if status[i] != FR_BOUNDED:
            # Unbounded: the direction ranges overlap, or the region is numerically huge.
            assert mine is None or np.max(np.abs(mine)) > 1e3
            continue
        assert mine is not None, "bounded region where the cones' directions overlap"
        v = verts[i]
        assert np.all(np.isfinite(v))
        got, ref = shp(v), shp(mine)
        size = 1.0 + np.max(np.abs(mine))
        assert hausdorff(got, ref) <= 1e-9 * size
        assert got.buffer(1e-9 * size).contains(shapely.Point(truth[i].real, truth[i].imag))
        # fr_region agrees with the batched kernel.
        one = fr_region(b1[i], b2[i], eps)
        assert one is not None and hausdorff(one, ref) <= 1e-9 * size


def test_cone_intersections_classify_constructed_cases():
    eps = np.deg2rad(2.0)
    b1 = np.array(
        [
            np.pi / 4,  # bounded: landmark above, in front
            0.0,  # on the line of motion ahead of R2: parallel cones
            np.pi,  # on the line of motion behind R1
            np.pi / 2,  # up from R1 ...
            np.pi - 0.3,  # up-left from R1 ...
            0.0,  # between R1 and R2: bounded diamond
        ]
    )
    b2 = np.array([3 * np.pi / 4, 0.0, np.pi, -np.pi / 2, 0.3, np.pi])
    _, status = cone_intersections(b1, b2, eps)
    assert status.tolist() == [
        FR_BOUNDED,
        FR_UNBOUNDED,
        FR_UNBOUNDED,
        FR_EMPTY,  # ... and down from R2: the cones miss each other
        FR_EMPTY,  # ... and up-right from R2: diverging cones
        FR_BOUNDED,
    ]
    assert fr_region(np.pi / 2, -np.pi / 2, eps) is None
    assert fr_region(0.0, 0.0, eps) is None
    diamond = fr_region(0.0, np.pi, eps)
    # Diamond between R1 and R2 with half-angles eps: area tan(eps) / 2 exactly.
    assert diamond.area == pytest.approx(0.5 * np.tan(eps), rel=1e-9)


def test_cone_intersections_are_batched_over_leading_axes():
    rng = np.random.default_rng(7)
    eps = np.deg2rad(3.0)
    truth = random_fr_landmarks(rng, 15).reshape(3, 5)
    b1, b2 = np.angle(truth), np.angle(truth - 1)
    verts, status = cone_intersections(b1, b2, eps)
    assert status.shape == (3, 5) and verts.shape[:2] == (3, 5)
    flat_v, flat_s = cone_intersections(b1.reshape(-1), b2.reshape(-1), eps)
    np.testing.assert_array_equal(status.reshape(-1), flat_s)
    ok = flat_s == FR_BOUNDED
    np.testing.assert_allclose(verts.reshape(15, -1)[ok], flat_v[ok], atol=1e-12)


@pytest.mark.parametrize("turns", [1, -3, 1000])
def test_cone_intersections_wrap_bearings(turns):
    eps = np.deg2rad(2.0)
    b1, b2 = np.array([0.7, -2.0, np.pi]), np.array([1.9, -0.4, np.pi / 2])
    v0, s0 = cone_intersections(b1, b2, eps)
    v1, s1 = cone_intersections(b1 + 2 * np.pi * turns, b2 - 2 * np.pi * turns, eps)
    np.testing.assert_array_equal(s0, s1)
    for a, b in zip(v0[s0 == FR_BOUNDED], v1[s1 == FR_BOUNDED], strict=True):
        assert hausdorff(shp(a), shp(b)) < 1e-9


# --------------------------------------------------------------------------------------
# Frame conversions and the one-movement transfer
# --------------------------------------------------------------------------------------


@SETTINGS
@given(seed=SEEDS)
def test_world_fl_round_trip(seed):
    rng = np.random.default_rng(seed)
    l1, l2 = rng.normal(size=2) * 10, rng.normal(size=2) * 10
    pts = rng.normal(size=(7, 3, 2)) * 10
    fl = world_to_fl(pts, l1, l2)
    assert fl.shape == pts.shape
    np.testing.assert_allclose(fl_to_world(fl, l1, l2), pts, atol=1e-9 * (1 + np.abs(pts).max()))
    np.testing.assert_allclose(world_to_fl(l1, l1, l2), [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(world_to_fl(l2, l1, l2), [1.0, 0.0], atol=1e-12)
    # A similarity: distances scale by 1 / |L2 - L1| and orientation is kept.
    d_world = np.linalg.norm(pts[0, 0] - pts[1, 1])
    d_fl = np.linalg.norm(fl[0, 0] - fl[1, 1])
    assert d_fl == pytest.approx(d_world / np.linalg.norm(l2 - l1), rel=1e-9)
    a, b, c = (fl[0, 0], fl[1, 1], fl[2, 2])
    wa, wb, wc = (pts[0, 0], pts[1, 1], pts[2, 2])
    def cross(p, q):
        return p[0] * q[1] - p[1] * q[0]

    assert np.sign(cross(b - a, c - a)) == np.sign(cross(wb - wa, wc - wa))


def test_world_to_fl_rejects_bad_shapes():
    with pytest.raises(ValueError, match="2"):
        world_to_fl(np.zeros((4, 3)), [0, 0], [1, 0])
    with pytest.raises(ValueError, match="2"):
        fl_to_world(np.zeros((4, 2)), [0, 0, 0], [1, 0])


def test_transfer_with_exact_frame_landmarks_is_the_change_of_basis():
    """Paper Fig. 3: with L1 and L2 known exactly, the transfer is one similarity."""
    l1, l2 = 0.3 - 0.8j, 1.4 - 0.5j
    region = np.array([2.0 + 1.0j, 2.5 + 1.1j, 2.4 + 1.6j])
    expected = shp((region - l1) / (l2 - l1))
    for transfer in ("paper", "conservative"):
        got = transfer_polygon(to_xy(region), to_xy([l1]), to_xy([l2]), transfer=transfer)
        assert got is not None, f"{transfer}: exact L1 != L2 were reported as overlapping"
        # Paper: exact. Conservative: may add its safety margin (~1e-9 relative), no more.
        tol = 1e-9 if transfer == "paper" else 1e-6
        assert hausdorff(got, expected) < tol
        assert got.buffer(1e-12).contains(expected)
        pt = transfer_point([1.0, 0.0], to_xy([l1]), to_xy([l2]), transfer=transfer)
        assert pt is not None
        assert hausdorff(pt, shapely.Point(to_xy((1.0 - l1) / (l2 - l1)))) < tol


def test_transfer_accepts_fr_regions_with_different_vertex_counts():
    """fr_region can return a triangle (an apex inside the other cone); transfer_polygon
    must accept it next to a quadrangle, as L1, L2 or the target."""
    eps = np.deg2rad(2.0)
    tri = fr_region(0.005, np.pi / 2, eps)  # just above R2: R2 is a vertex
    quad = fr_region(np.pi / 4, 3 * np.pi / 4, eps)
    low = fr_region(-np.pi / 4, -3 * np.pi / 4, eps)
    assert len(tri.exterior.coords) - 1 == 3 and len(quad.exterior.coords) - 1 == 4
    for target, a1, a2 in [(quad, tri, low), (tri, quad, low), (quad, low, tri)]:
        ring1 = np.asarray(a1.exterior.coords)[:-1]
        ring2 = np.asarray(a2.exterior.coords)[:-1]
        ringt = np.asarray(target.exterior.coords)[:-1]
        v1, v2 = ring1 @ [1, 1j], ring2 @ [1, 1j]
        vt = ringt @ [1, 1j]
        images = (vt[:, None, None] - v1[None, :, None]) / (v2[None, None, :] - v1[None, :, None])
        expected = shp(images)
        got = transfer_polygon(target, a1, a2, transfer="paper")
        assert got is not None
        assert hausdorff(got, expected) < 1e-9
        cons = transfer_polygon(target, a1, a2, transfer="conservative")
        assert cons is not None and cons.buffer(1e-9).contains(expected)


def test_transfer_returns_none_when_l1_and_l2_overlap():
    a1 = fr_region(np.pi / 3, 2 * np.pi / 3, np.deg2rad(5))
    for transfer in ("paper", "conservative"):
        assert transfer_polygon(a1, a1, a1, transfer=transfer) is None
        shifted = shapely.affinity.translate(a1, 0.01, 0.0)
        assert transfer_polygon(a1, a1, shifted, transfer=transfer) is None


@SETTINGS
@given(seed=SEEDS, eps_deg=st.floats(0.5, 6.0))
def test_transfer_of_fr_regions_contains_the_true_images(seed, eps_deg):
    """Any hypotheses (h1, h2) in A_L1 x A_L2 and any z in A_Li map into the conservative
    region; the true configuration does too. Regions of any vertex count are accepted."""
    rng = np.random.default_rng(seed)
    eps = np.deg2rad(eps_deg)
    for _ in range(500):
        truth = random_fr_landmarks(rng, 3)
        b1 = np.angle(truth) + eps * rng.uniform(-1, 1, 3)
        b2 = np.angle(truth - 1) + eps * rng.uniform(-1, 1, 3)
        regions = [fr_region(b1[i], b2[i], eps) for i in range(3)]
        if all(r is not None for r in regions) and regions[0].distance(regions[1]) > 1e-3:
            break
    else:
        pytest.fail("no usable movement drawn")
    a1, a2, a3 = regions
    cons = transfer_polygon(a3, a1, a2, transfer="conservative")
    paper = transfer_polygon(a3, a1, a2, transfer="paper")
    assert paper is not None  # A_L1 and A_L2 are disjoint
    if cons is None:
        # The conservative bound may refuse L1 and L2 that are close for their size (the
        # map reports "l1_l2_too_close"); only then.
        longest = max(edge_lengths(a1).max(), edge_lengths(a2).max())
        assert a1.distance(a2) < longest
        return
    assert cons.buffer(1e-9).contains(paper)
    # Dense hypotheses, boundary and interior, and the target's vertices and interior.
    h1 = sample_polygon(rng, a1, 300)
    h2 = sample_polygon(rng, a2, 300)
    z = sample_polygon(rng, a3, 300)
    images = (z - h1) / (h2 - h1)
    size = 1.0 + np.abs(images).max()
    assert cons.buffer(1e-9 * size).contains(shapely.multipoints(to_xy(images)))
    true_img = (truth[2] - truth[0]) / (truth[1] - truth[0])
    assert cons.buffer(1e-9 * size).contains(shapely.Point(true_img.real, true_img.imag))
    r2 = transfer_point([1.0, 0.0], a1, a2, transfer="conservative")
    r2_true = (1.0 - truth[0]) / (truth[1] - truth[0])
    assert r2.buffer(1e-9 * size).contains(shapely.Point(r2_true.real, r2_true.imag))


def edge_lengths(poly: shapely.Polygon) -> np.ndarray:
    ring = np.asarray(poly.exterior.coords)
    return np.hypot(*np.diff(ring, axis=0).T)


def sample_polygon(rng: np.random.Generator, poly: shapely.Polygon, n: int) -> np.ndarray:
    """n points of a convex polygon: half on its boundary (vertices included), half inside."""
    ring = np.asarray(poly.exterior.coords)[:-1]
    v = ring[:, 0] + 1j * ring[:, 1]
    m = v.size
    k = rng.integers(0, m, n)
    t = rng.uniform(0, 1, n)
    t[: n // 10] = 0.0
    boundary = v[k] + t * (v[(k + 1) % m] - v[k])
    w = rng.dirichlet(np.ones(m), n)
    inside = w @ v
    pick = rng.uniform(size=n) < 0.5
    return np.where(pick, boundary, inside)
