"""Unit tests of the world model's geometry: cones in FR, exact convex polygons, frame changes.

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
    kernels,
    transfer_point,
    transfer_polygon,
    world_to_fl,
)
from bearing_env.slam.geometry import (
    FR_BOUNDED,
    FR_EMPTY,
    FR_UNBOUNDED,
    area_centroid,
    cone_region,
    convex_hull,
    intersect,
    offset_outward,
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


def ring(verts) -> shapely.Polygon:
    """Complex vertices taken as they are (not re-hulled) as a shapely polygon."""
    return shapely.Polygon(to_xy(np.asarray(verts, dtype=complex)))


def random_convex_cloud(rng: np.random.Generator, centre: complex, radius: float) -> np.ndarray:
    n = int(rng.integers(3, 12))
    r = radius * np.sqrt(rng.uniform(0.05, 1.0, n))
    return centre + r * np.exp(1j * rng.uniform(0, 2 * np.pi, n))


def hausdorff(a, b) -> float:
    return float(shapely.hausdorff_distance(a, b))


def assert_strictly_convex_ccw(verts: np.ndarray) -> None:
    """Every turn is strictly to the left: counter-clockwise, no repeated or collinear vertex."""
    a, b, c = verts, np.roll(verts, -1), np.roll(verts, -2)
    turns = ((b - a).conjugate() * (c - b)).imag
    assert np.all(turns > 0.0), turns


def cone_intersections(b1, b2, eps):
    """cone_region over arrays: (list of vertex arrays, status array of b1's shape)."""
    b1, b2 = np.asarray(b1, dtype=float), np.asarray(b2, dtype=float)
    pairs = [cone_region(a, b, eps) for a, b in zip(b1.ravel(), b2.ravel(), strict=True)]
    return [v for v, _ in pairs], np.array([s for _, s in pairs]).reshape(b1.shape)


# --------------------------------------------------------------------------------------
# Convex polygons: hull, area, clipping, offset, capacity
# --------------------------------------------------------------------------------------


@SETTINGS
@given(seed=SEEDS, duplicates=st.booleans(), collinear=st.booleans())
def test_convex_hull_matches_shapely(seed, duplicates, collinear):
    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.uniform(-6, 3)
    centre = scale * 10.0 ** rng.uniform(-2, 3) * complex(*rng.normal(size=2))
    n = int(rng.integers(3, 300))
    pts = centre + scale * (rng.normal(size=n) + 1j * rng.normal(size=n))
    if duplicates:
        pts = np.concatenate([pts, pts[: pts.size // 2]])
    if collinear:  # points on the segment between two of them, exactly representable
        pts = np.concatenate([pts, pts[0] + np.array([0.25, 0.5, 0.75]) * (pts[1] - pts[0])])
    got = convex_hull(pts)
    ref = shp(pts)
    assert_strictly_convex_ccw(got)
    size = scale + abs(centre)
    assert hausdorff(ring(got), ref) <= 1e-12 * size
    assert len(ref.exterior.coords) - 1 >= got.size  # no vertex shapely would not keep
    area, centroid = area_centroid(got)
    assert area == pytest.approx(ref.area, rel=1e-9)
    assert abs(centroid - complex(ref.centroid.x, ref.centroid.y)) <= 1e-9 * size


def test_area_centroid_of_degenerate_polygons_is_zero_and_the_vertex_mean():
    assert area_centroid([1 + 1j]) == (0.0, 1 + 1j)
    area, centroid = area_centroid([0j, 2 + 0j])
    assert area == 0.0 and centroid == 1 + 0j


CASES = ("random", "shared_vertex", "shared_edge", "nested", "identical", "touching", "disjoint")


def clipping_pair(rng: np.random.Generator, case: str) -> tuple[np.ndarray, np.ndarray, float]:
    """Two convex polygons (CCW vertices) of a degenerate kind, and their scale."""
    scale = 10.0 ** rng.uniform(-6, 2)
    origin = scale * 10.0 ** rng.uniform(-1, 3) * complex(*rng.normal(size=2))
    p = convex_hull(random_convex_cloud(rng, origin, scale))
    while p.size < 3:
        p = convex_hull(random_convex_cloud(rng, origin, scale))
    k = int(rng.integers(p.size))
    v = p[k]
    if case == "random":
        q = convex_hull(random_convex_cloud(rng, origin + scale * rng.normal(), scale))
    elif case == "shared_vertex":
        # A rotated, scaled copy about one of p's vertices: that vertex is exactly shared.
        turn = np.exp(1j * rng.uniform(-np.pi, np.pi)) * rng.uniform(0.3, 2.0)
        q = convex_hull(v + turn * (p - v))
        q = np.concatenate([[v], q[q != v]])
        q = convex_hull(q)
    elif case == "shared_edge":
        # Both end points of one of p's edges, plus points on either side of it.
        w = p[(k + 1) % p.size]
        side = rng.choice([-1.0, 1.0])
        extra = v + (w - v) * (rng.uniform(-0.5, 1.5, 3) + 1j * side * rng.uniform(0.1, 1, 3))
        q = convex_hull(np.concatenate([[v, w], extra]))
    elif case == "nested":
        centre = p.mean()
        q = convex_hull(centre + rng.choice([0.4, 1.7]) * (p - centre))
    elif case == "identical":
        q = p.copy()
    elif case == "touching":
        # Point-reflected through one of p's vertices: they meet in that vertex only.
        q = convex_hull(2 * v - p)
    else:
        q = convex_hull(p + 3.0 * (np.abs(p - p.mean()).max() + scale))
    return p, q, scale + abs(origin)


@settings(deadline=None, max_examples=300, derandomize=True)
@given(seed=SEEDS, case=st.sampled_from(CASES), swap=st.booleans())
def test_intersection_matches_shapely_including_degenerate_pairs(seed, case, swap):
    rng = np.random.default_rng(seed)
    p, q, size = clipping_pair(rng, case)
    if q.size < 3:
        return  # the construction collapsed (rare): nothing to clip
    if swap:
        p, q = q, p
    exact = ring(p).intersection(ring(q))
    got = intersect(p, q)
    smaller = min(ring(p).area, ring(q).area)
    if got.size == 0:
        # Empty only when the exact intersection has no area to speak of.
        assert exact.area <= 1e-9 * smaller, (case, exact.area, smaller)
        assert case not in ("nested", "identical"), case
        return
    assert case not in ("touching", "disjoint"), got
    assert_strictly_convex_ccw(got)
    area, centroid = area_centroid(got)
    assert area == pytest.approx(exact.area, rel=1e-9)
    assert abs(centroid - complex(exact.centroid.x, exact.centroid.y)) <= 1e-9 * size
    assert hausdorff(ring(got), exact) <= 1e-9 * size
    if case in ("nested", "identical"):
        inner = p if ring(p).area <= ring(q).area else q
        assert area == pytest.approx(ring(inner).area, rel=1e-12)


def test_intersection_of_polygons_sharing_a_vertex_has_the_exact_area():
    """The case the K-gon engine got wrong (a negative area): two squares sharing a corner,
    one rotated by 45 degrees about it."""
    square = np.array([0, 1, 1 + 1j, 1j])
    diamond = np.exp(1j * np.pi / 4) * square
    got = intersect(square, diamond)
    exact = ring(square).intersection(ring(diamond))  # a triangle with the shared corner
    assert got.size >= 3
    assert area_centroid(got)[0] == pytest.approx(exact.area, rel=1e-12)
    assert area_centroid(got)[0] > 0.0


@settings(deadline=None, max_examples=60, derandomize=True)
@given(seed=SEEDS)
def test_offset_moves_every_edge_out_by_the_radius_and_covers_the_round_buffer(seed):
    rng = np.random.default_rng(seed)
    scale = 10.0 ** rng.uniform(-3, 1)
    p = convex_hull(random_convex_cloud(rng, scale * complex(*rng.normal(size=2)), scale))
    if p.size < 3:
        return
    radius = scale * 10.0 ** rng.uniform(-4, 0.5)
    grown = offset_outward(p, radius)
    assert_strictly_convex_ccw(grown)
    # Every supporting line of p (its edge normals) moved out by exactly the radius.
    normals = -1j * (np.roll(p, -1) - p) / np.abs(np.roll(p, -1) - p)
    support_p = np.max((normals.conj()[:, None] * p[None, :]).real, axis=1)
    support_g = np.max((normals.conj()[:, None] * grown[None, :]).real, axis=1)
    np.testing.assert_allclose(support_g - support_p, radius, rtol=1e-9, atol=1e-12 * scale)
    # It contains the true (round) offset: every point within the radius of p.
    round_offset = ring(p).buffer(radius, quad_segs=256)
    assert ring(grown).buffer(1e-9 * (scale + radius)).contains(round_offset)


def test_offset_cuts_sharp_corners_instead_of_a_long_mitre():
    # A needle: its mitres would reach ~r / sin(angle / 2) far out.
    needle = np.array([0, 1, 0.5 + 0.001j])
    needle = convex_hull(needle)
    grown = offset_outward(needle, 0.1)
    assert np.abs(grown - 0.5).max() < 0.5 + 0.1 * np.sqrt(2) + 1e-9
    assert ring(grown).buffer(1e-12).contains(ring(needle).buffer(0.1, quad_segs=256))


@settings(deadline=None, max_examples=40, derandomize=True)
@given(seed=SEEDS, capacity=st.integers(3, 40))
def test_dropping_edges_only_grows_the_polygon(seed, capacity):
    rng = np.random.default_rng(seed)
    circle = np.exp(1j * np.sort(rng.uniform(0, 2 * np.pi, 60)))
    p = convex_hull(circle * rng.uniform(0.8, 1.2, circle.size))
    reduced = p.copy()
    n = kernels.drop_edges_outward(reduced, reduced.size, capacity)
    reduced = reduced[:n]
    assert n <= max(capacity, 3)
    assert_strictly_convex_ccw(reduced)
    assert ring(reduced).buffer(1e-12).contains(ring(p))


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
    assert len(verts) == n and status.shape == (n,)
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
        # fr_region agrees with the kernel.
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


@pytest.mark.parametrize("turns", [1, -3, 1000])
def test_cone_intersections_wrap_bearings(turns):
    eps = np.deg2rad(2.0)
    b1, b2 = np.array([0.7, -2.0, np.pi]), np.array([1.9, -0.4, np.pi / 2])
    v0, s0 = cone_intersections(b1, b2, eps)
    v1, s1 = cone_intersections(b1 + 2 * np.pi * turns, b2 - 2 * np.pi * turns, eps)
    np.testing.assert_array_equal(s0, s1)
    for a, b, status in zip(v0, v1, s0, strict=True):
        if status == FR_BOUNDED:
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


@SETTINGS
@given(seed=SEEDS, n=st.integers(1, 40), duplicates=st.booleans())
def test_the_small_hull_equals_the_general_hull(seed, n, duplicates):
    rng = np.random.default_rng(seed)
    pts = rng.normal(size=n) + 1j * rng.normal(size=n)
    if duplicates:
        pts = np.concatenate([pts, pts[::2]])
    out = np.empty(pts.size + 1, dtype=complex)
    small = out[: kernels.small_convex_hull(pts, pts.size, out, 0.0)].copy()
    general = convex_hull(pts)
    # Both start at the leftmost (then lowest) point and go counter-clockwise.
    np.testing.assert_array_equal(small, general)


@SETTINGS
@given(seed=SEEDS, n_line=st.integers(3, 60), n_off=st.integers(1, 3))
def test_the_hull_of_nearly_collinear_points_is_a_simple_strictly_convex_polygon(
    seed, n_line, n_off
):
    """Points on one line, off it only by rounding, plus a few others: quickhull's rounded
    side tests once emitted the line's points in a zig-zag (turns of 0 and 180 degrees),
    a self-overlapping 'hull' whose outward offset was self-intersecting."""
    rng = np.random.default_rng(seed)
    a, b = 10.0 * complex(*rng.normal(size=2)), 10.0 * complex(*rng.normal(size=2))
    line = a + rng.uniform(size=n_line) * (b - a)
    centre = rng.uniform(0.0, 5.0) * complex(*rng.normal(size=2))
    pts = np.concatenate([line, centre + rng.normal(size=n_off) + 1j * rng.normal(size=n_off)])
    got = convex_hull(pts)
    ref = shp(pts)
    if ref.geom_type != "Polygon":  # every point on the line: a segment
        assert got.size <= 2
        return
    assert_strictly_convex_ccw(got)
    assert ring(got).is_valid
    assert ring(got).area == pytest.approx(ref.area, rel=1e-9)
