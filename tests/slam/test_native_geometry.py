"""The native polygon and frame kernels against the numba ones, bit for bit.

Every function bound by ``csrc/bindings/bind_slam_geometry.cpp`` is called with the same
arguments as its numba reference (``bearing_env.slam.kernels``): the return values must be
equal, floats and complex numbers by their bits, and the arrays the kernels write (``out``
arrays, polygons simplified in place) must hold the same bytes. Inputs are seeded random
batches and hypothesis examples, degenerate ones included: repeated and collinear points,
grids, tiny and huge coordinates, near-parallel cones, epsilon from 0.5 to 10 degrees,
1 to 8 samples per edge.

Where numba raises ZeroDivisionError (a complex division by 0: repeated vertices given to
offset_outward, coincident samples in sample_hypotheses) the native kernels return NaNs
instead; those calls are not compared.

Bad arguments raise TypeError or ValueError naming the argument, and inputs beyond a
kernel's fixed capacity raise CapacityError, never a crash.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env.numerics import wrap as numba_wrap
from bearing_env.slam import kernels
from bearing_env.slam.kernels.polygons import small_hull_indices as numba_small_hull_indices

ComplexArray = NDArray[np.complex128]

SETTINGS = settings(deadline=None, max_examples=150, derandomize=True)
MAX_HULL_POINTS = kernels.MAX_CLOUD + kernels.SCRATCH

# --------------------------------------------------------------------------------------
# comparing the two cores
# --------------------------------------------------------------------------------------


def bits(value: Any) -> Any:
    """A value in a form compared bit for bit (NaNs by payload, signed zeros apart)."""
    if isinstance(value, np.ndarray):
        return (value.dtype.str, value.shape, value.tobytes())
    if isinstance(value, tuple):
        return tuple(bits(v) for v in value)
    if isinstance(value, (bool, np.bool_)):
        return ("bool", bool(value))
    if isinstance(value, (int, np.integer)):
        return ("int", int(value))
    if isinstance(value, (float, np.floating)):
        return ("float", struct.pack("<d", float(value)))
    if isinstance(value, (complex, np.complexfloating)):
        return ("complex", struct.pack("<dd", value.real, value.imag))
    raise TypeError(f"cannot compare {type(value).__name__}")


def copied(args: tuple[Any, ...]) -> list[Any]:
    return [a.copy() if isinstance(a, np.ndarray) else a for a in args]


def agree(name: str, *args: Any, reference: Callable[..., Any] | None = None) -> Any:
    """Call ``name`` in both cores on copies of ``args``; assert the same result and the
    same bytes in every array argument afterwards. Returns the result (None where numba
    raised ZeroDivisionError)."""
    numba_function = reference if reference is not None else getattr(kernels, name)
    native_function = getattr(_core, name)
    numba_args, native_args = copied(args), copied(args)
    try:
        expected = numba_function(*numba_args)
    except ZeroDivisionError:
        native_function(*native_args)  # must not crash
        return None
    got = native_function(*native_args)
    assert bits(got) == bits(expected), (name, got, expected)
    for i, (a, b) in enumerate(zip(numba_args, native_args, strict=True)):
        if isinstance(a, np.ndarray):
            assert bits(a) == bits(b), (name, f"argument {i} differs after the call")
    return expected


def filled(n: int, dtype: Any = np.complex128) -> NDArray[Any]:
    """An output array with a recognisable content (the same for both cores)."""
    if dtype == np.int64:
        return np.full(n, -7, dtype=np.int64)
    return np.full(n, complex(-3.25, 7.5), dtype=np.complex128)


def agree_small_hulls(points: ComplexArray, n: int, tol: float) -> None:
    """small_convex_hull and small_hull_indices in both cores.

    On nearly collinear points rounding can make the monotone chain's lower and upper
    halves both keep a point, and numba's kernels then write past the n + 1 slots of
    their index buffer (corrupting the heap: they are not called then). Given room, the
    numba chain shows what the kernels compute; the native kernels compute it in a
    buffer of their own and must return the same hull, or raise CapacityError when it
    has more than n + 1 vertices (it would overflow ``out``).
    """
    room = np.full(2 * n + 2, -7, dtype=np.int64)
    k = int(numba_small_hull_indices(points, n, room, tol))
    if bool(np.any(room[n + 1 :] != -7)):
        if k > n + 1:
            with pytest.raises(_core.CapacityError):
                _core.small_convex_hull(points, n, filled(n + 1), tol)
            return
        out = filled(n + 1)
        assert _core.small_convex_hull(points, n, out, tol) == k
        assert bits(out[:k]) == bits(points[room[:k]])
        indices = filled(n + 1, np.int64)
        assert _core.small_hull_indices(points, n, indices, tol) == k
        assert bits(indices[:k]) == bits(room[:k])
        return
    agree("small_convex_hull", points, n, filled(n + 1), tol)
    indices = filled(n + 1, np.int64)
    assert _core.small_hull_indices(points, n, indices, tol) == k
    assert bits(indices[:k]) == bits(room[:k])  # (numba also leaves its chain's tail there)


# --------------------------------------------------------------------------------------
# inputs
# --------------------------------------------------------------------------------------

KINDS = ("normal", "grid", "line", "circle", "repeated", "cluster", "square")


def cloud(rng: np.random.Generator, n: int, kind: str) -> ComplexArray:
    """``n`` points of a kind that stresses the hulls and tolerances."""
    if kind == "normal":
        z = rng.normal(size=n) + 1j * rng.normal(size=n)
    elif kind == "grid":  # many ties, repeats and exactly collinear triples
        z = rng.integers(-3, 4, size=n) + 1j * rng.integers(-3, 4, size=n)
    elif kind == "line":  # collinear up to rounding (and a hair off it)
        t = rng.uniform(-1, 1, size=n)
        noise = rng.choice([0.0, 1e-15, 1e-9]) * rng.normal(size=n)
        z = (0.3 + 0.8j) + t * np.exp(1j * rng.uniform(0, np.pi)) + 1j * noise
    elif kind == "circle":
        z = np.exp(1j * rng.uniform(0, 2 * np.pi, size=n))
    elif kind == "repeated":
        base = rng.normal(size=3) + 1j * rng.normal(size=3)
        z = base[rng.integers(0, 3, size=n)]
    elif kind == "cluster":  # tiny spread far from the origin
        z = (1e6 + 3e5j) + 1e-7 * (rng.normal(size=n) + 1j * rng.normal(size=n))
    else:  # square corners and edge points
        corners = np.array([0, 1, 1 + 1j, 1j])
        z = corners[rng.integers(0, 4, size=n)] + rng.choice([0.0, 0.5], size=n) * rng.choice(
            [1, 1j], size=n
        )
    scale = 10.0 ** rng.choice([0.0, 0.0, -12.0, -6.0, 6.0, 12.0, 150.0])
    return np.ascontiguousarray(np.asarray(z, dtype=np.complex128) * scale)


def hull_of(points: ComplexArray) -> ComplexArray:
    """A convex polygon (CCW), from the numba hull."""
    out = np.empty(points.size + 1, dtype=np.complex128)
    n = int(kernels.convex_hull(points, points.size, out))
    hull: ComplexArray = out[:n].copy()
    return hull


def polygon(rng: np.random.Generator, n: int, kind: str | None = None) -> ComplexArray:
    return hull_of(cloud(rng, n, kind if kind is not None else str(rng.choice(KINDS))))


def angles(rng: np.random.Generator) -> Iterator[tuple[float, float, float]]:
    """(a, b, epsilon) triples: random, near-parallel cones, apexes on the other cone."""
    while True:
        epsilon = math.radians(float(rng.uniform(0.5, 10.0)))
        a = float(rng.uniform(-math.pi, math.pi))
        kind = int(rng.integers(0, 6))
        if kind == 0:
            b = float(rng.uniform(-math.pi, math.pi))
        elif kind == 1:  # the cones' direction ranges nearly touch
            b = a + 2.0 * epsilon * (1.0 + float(rng.choice([-1e-12, 0.0, 1e-12, 1e-6, 1e-3])))
        elif kind == 2:  # nearly parallel the other way (the region is long and thin)
            b = a + math.pi + float(rng.normal()) * epsilon
        elif kind == 3:  # R2 near the cone at R1's edge
            a = float(rng.choice([-1.0, 1.0])) * epsilon * (1.0 + float(rng.normal()) * 1e-9)
            b = float(rng.uniform(-math.pi, math.pi))
        elif kind == 4:  # R1 near the cone at R2's edge
            b = math.pi + float(rng.choice([-1.0, 1.0])) * epsilon
        else:  # bearings beyond [-pi, pi)
            b = a + float(rng.uniform(-20.0, 20.0))
        yield a, b, epsilon


def fr_region(a: float, b: float, epsilon: float) -> ComplexArray:
    out = np.empty(kernels.FR_VERTICES, dtype=np.complex128)
    n, _ = kernels.cone_region(a, b, epsilon, out)
    region: ComplexArray = out[: int(n)].copy()
    return region


def small_polygon(rng: np.random.Generator) -> ComplexArray:
    """A region of L1 or L2: a cone region (as the update makes them) or 1..4 points."""
    for a, b, epsilon in angles(rng):
        if rng.uniform() < 0.8:
            region = fr_region(a, b, epsilon)
        else:
            region = polygon(rng, int(rng.integers(1, 5)), "normal") * 0.1 + complex(
                float(rng.normal()), float(rng.normal())
            )
        if 1 <= region.size <= kernels.FR_VERTICES:
            return region
    raise AssertionError("unreachable")


# --------------------------------------------------------------------------------------
# common.py and the scalar helpers
# --------------------------------------------------------------------------------------


def test_scalar_helpers() -> None:
    rng = np.random.default_rng(1)
    values = np.concatenate(
        [
            rng.normal(size=200) * 10.0 ** rng.integers(-12, 12, size=200),
            [0.0, -0.0, math.pi, -math.pi, 2 * math.pi, 1e300, -1e300, math.inf, math.nan],
            np.arange(-20, 21) * math.pi,
        ]
    )
    for x in values:
        assert bits(_core.wrap(float(x))) == bits(numba_wrap(float(x)))
    for _ in range(200):
        a = complex(*(rng.normal(size=2) * 10.0 ** rng.integers(-8, 8, size=2)))
        b = complex(*(rng.normal(size=2) * 10.0 ** rng.integers(-8, 8, size=2)))
        assert bits(_core.cross(a, b)) == bits(kernels.cross(a, b))
        assert bits(_core.dot(a, b)) == bits(kernels.dot(a, b))
        size, magnitude = abs(a.real), abs(b.imag)
        assert bits(_core.tolerance_of(size, magnitude)) == bits(
            kernels.tolerance_of(size, magnitude)
        )


def test_scale_of() -> None:
    rng = np.random.default_rng(2)
    for trial in range(300):
        points = cloud(rng, int(rng.integers(1, 40)), KINDS[trial % len(KINDS)])
        agree("scale_of", points, int(rng.integers(0, points.size + 1)))


# --------------------------------------------------------------------------------------
# hulls
# --------------------------------------------------------------------------------------


def test_convex_hulls_on_random_clouds() -> None:
    rng = np.random.default_rng(3)
    for trial in range(700):
        kind = KINDS[trial % len(KINDS)]
        n = int(rng.choice([1, 2, 3, 4, 5, 8, 20, 60, 300]))
        points = cloud(rng, n, kind)
        agree("convex_hull", points, n, filled(n + 1))
        tol = float(rng.choice([0.0, 1e-12, 1e-3, 0.1]))
        agree_small_hulls(points, n, tol)


def test_convex_hull_of_a_full_cloud() -> None:
    """As many points as the native hull takes (a transfer's largest cloud)."""
    rng = np.random.default_rng(4)
    for kind in ("normal", "circle", "grid", "line"):
        points = cloud(rng, MAX_HULL_POINTS, kind)
        agree("convex_hull", points, MAX_HULL_POINTS, filled(MAX_HULL_POINTS + 1))


# Nearly collinear triples on which the chains disagree (numba writes a 5th index into
# its 4 slots); found by a seeded search.
DISAGREEING = [
    [
        ("-0x1.112adabfa3e70p-5", "0x1.2745d7d1c92f5p+0"),
        ("0x1.c35e899bedd00p-1", "0x1.77a1fbec7c05dp-3"),
        ("-0x1.c8bb0d4e2e596p-3", "0x1.5ac00a77eeeddp+0"),
    ],
    [
        ("-0x1.a69ac7569fd4fp-2", "0x1.131e087e4f4b5p-2"),
        ("-0x1.b0736ba3833bcp-4", "0x1.fd93a76ab0c07p-2"),
        ("0x1.ac1b7cd6f0b48p-1", "0x1.332008cded573p+0"),
    ],
]


def test_small_hulls_where_the_chains_disagree() -> None:
    for case in DISAGREEING:
        points = np.array(
            [complex(float.fromhex(x), float.fromhex(y)) for x, y in case], dtype=np.complex128
        )
        room = np.full(8, -7, dtype=np.int64)
        assert numba_small_hull_indices(points, 3, room, 0.0) == 4
        assert room[4] != -7  # past the 4 slots numba's kernels allocate
        agree_small_hulls(points, 3, 0.0)
        # the native convex_hull (whose tolerance settles them) on the same points
        agree("convex_hull", points, 3, filled(4))


def test_non_finite_points_do_not_crash() -> None:
    """NaN and infinite coordinates (numba's hulls may write out of bounds on them: not
    compared): each native kernel returns or raises CapacityError."""
    rng = np.random.default_rng(17)
    for trial in range(200):
        n = int(rng.integers(1, 40))
        points = cloud(rng, n, KINDS[trial % len(KINDS)])
        with np.errstate(over="ignore"):
            points[rng.integers(0, n, size=n // 3)] *= 1e300  # overflows to inf
        points[rng.integers(0, n, size=n // 4)] = complex(math.nan, float(rng.normal()))
        for call in native_calls(points, n):
            try:
                call()
            except _core.CapacityError:
                pass


def native_calls(points: ComplexArray, n: int) -> list[Callable[[], Any]]:
    big = filled(2 * kernels.SCRATCH)
    m = min(n, kernels.CAPACITY)
    return [
        lambda: _core.convex_hull(points, n, filled(n + 1)),
        lambda: _core.small_convex_hull(points, n, filled(n + 1), 0.0),
        lambda: _core.small_hull_indices(points, n, filled(n + 1, np.int64), 1e-9),
        lambda: _core.simplify(points.copy(), n, 1e-9),
        lambda: _core.drop_edges_outward(points.copy(), n, 3),
        lambda: _core.area_centroid(points, n),
        lambda: _core.contains_point(points, n, 0.5 + 0.5j, 1e-12),
        lambda: _core.polygon_distance(points, n, points[::-1].copy(), n),
        lambda: _core.clip_convex(points, m, points, m, big, big.copy()),
        lambda: _core.offset_outward(points, n, 0.5, filled(n + 3)),
    ]


FINITE = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_subnormal=True)
POINTS = st.lists(st.tuples(FINITE, FINITE), min_size=1, max_size=40)
GRID = st.lists(st.tuples(st.integers(-3, 3), st.integers(-3, 3)), min_size=1, max_size=40)


def as_points(pairs: list[tuple[float, float]], scale: float = 1.0) -> ComplexArray:
    return np.array([complex(x, y) * scale for x, y in pairs], dtype=np.complex128)


@SETTINGS
@given(POINTS, st.sampled_from([0.0, 1e-12, 1e-4]))
def test_convex_hulls_hypothesis(pairs: list[tuple[float, float]], tol: float) -> None:
    points = as_points(pairs)
    n = points.size
    agree("convex_hull", points, n, filled(n + 1))
    agree_small_hulls(points, n, tol)


@SETTINGS
@given(GRID, st.sampled_from([1.0, 1e-300, 1e-9, 1e9, 1e150]))
def test_convex_hulls_on_grids_hypothesis(pairs: list[tuple[int, int]], scale: float) -> None:
    points = as_points([(float(x), float(y)) for x, y in pairs], scale)
    n = points.size
    agree("convex_hull", points, n, filled(n + 1))
    agree_small_hulls(points, n, 0.0)


# --------------------------------------------------------------------------------------
# area, containment, distances
# --------------------------------------------------------------------------------------


def test_area_containment_and_edges() -> None:
    rng = np.random.default_rng(5)
    for trial in range(400):
        kind = KINDS[trial % len(KINDS)]
        raw = cloud(rng, int(rng.integers(1, 12)), kind)
        for poly in (raw, hull_of(raw)):
            n = poly.size
            agree("area_centroid", poly, n)
            agree("longest_edge", poly, n)
            scale = float(np.max(np.abs(poly))) or 1.0
            probes = [
                poly[0],
                poly[-1],
                0.5 * (poly[0] + poly[-1]),
                complex(np.mean(poly)),
                poly[0] + scale * 1e-13 * complex(*rng.normal(size=2)),
                # within rounding of the boundary, where the tolerance's magnitude term decides
                poly[0] + scale * 1e-16 * complex(*rng.normal(size=2)),
                0.5 * (poly[0] + poly[-1]) + scale * 4e-16 * complex(*rng.normal(size=2)),
                complex(*rng.normal(size=2)) * scale,
            ]
            for point in probes:
                relative = float(rng.choice([0.0, 1e-12, 1e-6]))
                agree("contains_point", poly, n, point, relative)


def test_polygon_distance() -> None:
    rng = np.random.default_rng(6)
    for trial in range(500):
        p = polygon(rng, int(rng.integers(1, 7)), "normal")
        mode = trial % 4
        if mode == 0:  # apart or overlapping
            q = polygon(rng, int(rng.integers(1, 7)), "normal") + complex(*rng.normal(size=2)) * 3
        elif mode == 1:  # sharing a vertex
            q = polygon(rng, int(rng.integers(1, 7)), "normal")
            q = q - q[0] + p[int(rng.integers(0, p.size))]
        elif mode == 2:  # the same polygon, slightly moved
            q = p + complex(*rng.normal(size=2)) * 10.0 ** float(rng.integers(-15, 0))
        else:  # cone regions, as the frame plan sees them
            p, q = small_polygon(rng), small_polygon(rng)
        agree("polygon_distance", p, p.size, q, q.size)


# --------------------------------------------------------------------------------------
# simplify, drop_edges_outward, clip_convex, offset_outward
# --------------------------------------------------------------------------------------


def with_extra_vertices(rng: np.random.Generator, poly: ComplexArray) -> ComplexArray:
    """A polygon with repeated vertices and points on (or a hair off) its edges."""
    out: list[complex] = []
    for i in range(poly.size):
        out.append(complex(poly[i]))
        r = rng.uniform()
        if r < 0.2:
            out.append(complex(poly[i]))
        elif r < 0.5:
            t = float(rng.uniform())
            nxt = poly[(i + 1) % poly.size]
            wobble = float(rng.choice([0.0, 1e-14, 1e-10])) * complex(*rng.normal(size=2))
            out.append(complex(poly[i] + t * (nxt - poly[i]) + wobble))
    return np.array(out, dtype=np.complex128)


def test_simplify() -> None:
    rng = np.random.default_rng(7)
    for trial in range(500):
        kind = KINDS[trial % len(KINDS)]
        raw = cloud(rng, int(rng.integers(1, 20)), kind)
        for poly in (raw, with_extra_vertices(rng, hull_of(raw))):
            size, magnitude = kernels.scale_of(poly, poly.size)
            for tol in (0.0, kernels.tolerance_of(size, magnitude), 1e-6 * size):
                agree("simplify", poly, poly.size, float(tol))


def test_drop_edges_outward() -> None:
    rng = np.random.default_rng(8)
    # a symmetric octagon and grid polygons: edges whose removals add equal areas (ties)
    octagon = np.array([1, 2, 3 + 1j, 3 + 2j, 2 + 3j, 1 + 3j, 2j, 1j], dtype=np.complex128)
    polygons = [octagon, octagon * 1e-7 + 5.0]
    polygons += [polygon(rng, 60, "grid") * 2.0 ** int(rng.integers(-3, 4)) for _ in range(30)]
    for trial in range(200):
        polygons.append(polygon(rng, int(rng.integers(3, 400)), ("circle", "normal")[trial % 2]))
    for poly in polygons:
        for capacity in (3, 4, max(3, poly.size // 2), poly.size - 1, poly.size, -1):
            agree("drop_edges_outward", poly, poly.size, capacity)


def test_clip_convex() -> None:
    rng = np.random.default_rng(9)
    for trial in range(400):
        mode = trial % 5
        p = polygon(rng, int(rng.integers(3, 200)), ("normal", "circle", "grid")[trial % 3])
        if p.size > kernels.CAPACITY:
            p = p[: kernels.CAPACITY].copy()  # still convex: a sub-sequence of the hull
        if mode == 0:
            q = polygon(rng, int(rng.integers(1, 200)), "normal") + complex(*rng.normal(size=2))
        elif mode == 1:  # the same polygon
            q = p.copy()
        elif mode == 2:  # rotated about a vertex: shared vertex and crossing edges
            turn = np.exp(1j * rng.uniform(-0.3, 0.3))
            q = p[0] + turn * (p - p[0])
        elif mode == 3:  # one inside the other
            q = complex(np.mean(p)) + rng.uniform(0.1, 1.5) * (p - complex(np.mean(p)))
        else:  # sharing an edge's line (a hair apart)
            q = p + (p[1] - p[0]) * float(rng.choice([0.0, 1e-14, 1e-8]))
        if q.size > kernels.CAPACITY:
            q = q[: kernels.CAPACITY].copy()
        for subject, clipper in ((p, q), (q, p)):
            agree(
                "clip_convex",
                subject,
                subject.size,
                clipper,
                clipper.size,
                filled(kernels.SCRATCH),
                filled(kernels.SCRATCH),
            )


def test_offset_outward() -> None:
    rng = np.random.default_rng(10)
    for trial in range(500):
        n = int(rng.choice([1, 2, 3, 4, 6, 30]))
        poly = polygon(rng, n, KINDS[trial % len(KINDS)]) if n > 2 else cloud(rng, n, "normal")
        for radius in (0.0, 1e-9, float(rng.uniform(0.01, 2.0)), 1e3):
            agree("offset_outward", poly, poly.size, radius, filled(poly.size + 3))
    # repeated vertices: numba divides by 0 (ZeroDivisionError), the native core must not crash
    square = np.array([0, 1, 1, 1 + 1j, 1j], dtype=np.complex128)
    assert agree("offset_outward", square, 5, 0.5, filled(8)) is None


# --------------------------------------------------------------------------------------
# frames.py
# --------------------------------------------------------------------------------------


def test_cone_region() -> None:
    rng = np.random.default_rng(11)
    statuses: set[int] = set()
    for _, (a, b, epsilon) in zip(range(3000), angles(rng), strict=False):
        result = agree("cone_region", a, b, epsilon, filled(kernels.FR_VERTICES))
        statuses.add(int(result[1]))
    assert statuses == {kernels.FR_BOUNDED, kernels.FR_UNBOUNDED, kernels.FR_EMPTY}


@SETTINGS
@given(
    st.floats(-10.0, 10.0),
    st.floats(-10.0, 10.0),
    st.floats(math.radians(0.5), math.radians(10.0)),
)
def test_cone_region_hypothesis(a: float, b: float, epsilon: float) -> None:
    agree("cone_region", a, b, epsilon, filled(kernels.FR_VERTICES))


def test_boundary_samples() -> None:
    rng = np.random.default_rng(12)
    for _ in range(300):
        poly = small_polygon(rng)
        per_edge = int(rng.integers(1, kernels.MAX_EDGE_SAMPLES + 1))
        agree("boundary_samples", poly, poly.size, per_edge, filled(poly.size * per_edge))


def frames(rng: np.random.Generator, count: int) -> Iterator[tuple[Any, ...]]:
    """(a1, a2, conservative, edge_samples) for ``count`` movements."""
    for i in range(count):
        yield small_polygon(rng), small_polygon(rng), i % 3 != 0, int(rng.integers(1, 9))


def test_frame_plan_hypotheses_and_transfer() -> None:
    rng = np.random.default_rng(13)
    counts = {"planned": 0, "ok": 0, "transferred": 0}
    for a1, a2, conservative, edge_samples in frames(rng, 400):
        plan = agree("frame_plan", a1, a1.size, a2, a2.size, conservative, edge_samples)
        counts["planned"] += 1
        status, per_edge, distance, delta1, delta2 = plan
        if status != kernels.FRAME_OK:
            continue
        counts["ok"] += 1
        h1, inv_d = filled(kernels.MAX_PAIRS), filled(kernels.MAX_PAIRS)
        n_pairs = agree("sample_hypotheses", a1, a1.size, a2, a2.size, per_edge, h1, inv_d)
        if n_pairs is None:
            continue
        kernels.sample_hypotheses(a1, a1.size, a2, a2.size, per_edge, h1, inv_d)
        frame = kernels.FrameChange(
            a1, a1.size, a2, a2.size, h1, inv_d, n_pairs, conservative, distance, delta1, delta2
        )
        for target in (small_polygon(rng), small_polygon(rng)[:1].copy(), np.array([1 + 0j])):
            check_transfer(target, frame)
            counts["transferred"] += 1
    assert counts["ok"] > 100 and counts["transferred"] > 300, counts


def check_transfer(target: ComplexArray, frame: Any) -> None:
    """transfer_region in both cores: the same count and region (the buffers' tails may
    differ: the native paper transfer reduces its hull before copying it to out)."""
    k = target.size * frame.n_pairs
    results = []
    for function in (kernels.transfer_region, _core.transfer_region):
        cloud_, hull, out = (
            filled(kernels.MAX_CLOUD),
            filled(kernels.MAX_CLOUD + 1),
            filled(kernels.MAX_CLOUD + 1),
        )
        n = function(target, target.size, frame, cloud_, hull, out)
        results.append((bits(n), bits(out[:n]), bits(cloud_[:k])))
    assert results[0] == results[1]


@SETTINGS
@given(st.integers(0, 2**32 - 1))
def test_frames_hypothesis(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for a1, a2, conservative, edge_samples in frames(rng, 3):
        plan = agree("frame_plan", a1, a1.size, a2, a2.size, conservative, edge_samples)
        if plan[0] != kernels.FRAME_OK:
            continue
        h1, inv_d = filled(kernels.MAX_PAIRS), filled(kernels.MAX_PAIRS)
        n_pairs = agree("sample_hypotheses", a1, a1.size, a2, a2.size, plan[1], h1, inv_d)
        if n_pairs is None:
            continue
        kernels.sample_hypotheses(a1, a1.size, a2, a2.size, plan[1], h1, inv_d)
        frame = kernels.FrameChange(
            a1, a1.size, a2, a2.size, h1, inv_d, n_pairs, conservative, *plan[2:]
        )
        check_transfer(small_polygon(rng), frame)


def test_frame_plan_extremes() -> None:
    """Subnormal distances (ceil(inf) converted to an int, per_edge 0, 0 / 0) and huge
    coordinates (infinite distances and edges)."""
    cases = [
        ([0, 1e308, -1e308 + 1e308j], [5e307]),
        ([-1.7e308, 1.7e308], [1e300j]),
        ([0, 1e-300], [1e-310j + 5e-311]),
        ([0, 1], [1e-320j]),
        ([0, 1, 1j], [1e-320j - 1e-320]),
    ]
    for p1, p2 in cases:
        a1, a2 = np.array(p1, dtype=np.complex128), np.array(p2, dtype=np.complex128)
        for conservative in (True, False):
            for edge_samples in (-1, 0, 1, 3, 8):
                agree("frame_plan", a1, a1.size, a2, a2.size, conservative, edge_samples)
                agree("frame_plan", a2, a2.size, a1, a1.size, conservative, edge_samples)


def test_sample_hypotheses_per_edge() -> None:
    """Every per_edge 1..8 on regions of 1..4 vertices (within MAX_SAMPLES)."""
    rng = np.random.default_rng(14)
    for per_edge in range(1, kernels.MAX_EDGE_SAMPLES + 1):
        done = 0
        while done < 20:
            a1, a2 = small_polygon(rng), small_polygon(rng)
            if kernels.polygon_distance(a1, a1.size, a2, a2.size) <= 0.0:
                continue
            h1, inv_d = filled(kernels.MAX_PAIRS), filled(kernels.MAX_PAIRS)
            agree("sample_hypotheses", a1, a1.size, a2, a2.size, per_edge, h1, inv_d)
            done += 1


@pytest.mark.slow
def test_many_frames() -> None:
    rng = np.random.default_rng(15)
    for a1, a2, conservative, edge_samples in frames(rng, 5000):
        plan = agree("frame_plan", a1, a1.size, a2, a2.size, conservative, edge_samples)
        if plan[0] != kernels.FRAME_OK:
            continue
        h1, inv_d = filled(kernels.MAX_PAIRS), filled(kernels.MAX_PAIRS)
        n_pairs = agree("sample_hypotheses", a1, a1.size, a2, a2.size, plan[1], h1, inv_d)
        if n_pairs is None:
            continue
        kernels.sample_hypotheses(a1, a1.size, a2, a2.size, plan[1], h1, inv_d)
        frame = kernels.FrameChange(
            a1, a1.size, a2, a2.size, h1, inv_d, n_pairs, conservative, *plan[2:]
        )
        check_transfer(small_polygon(rng), frame)


# --------------------------------------------------------------------------------------
# bad arguments and capacities
# --------------------------------------------------------------------------------------


def test_bad_arrays_raise() -> None:
    points = np.array([0, 1, 1j, 1 + 1j], dtype=np.complex128)
    out = np.empty(8, dtype=np.complex128)
    core: Any = _core  # the wrong types below are the point
    with pytest.raises(TypeError, match="points"):
        _core.convex_hull(points.real.copy(), 4, out)
    with pytest.raises(TypeError, match="points"):
        core.convex_hull(list(points), 4, out)
    with pytest.raises(TypeError, match="out"):
        _core.convex_hull(points, 4, np.empty(8, dtype=np.complex64))
    with pytest.raises(ValueError, match="points"):
        _core.convex_hull(np.repeat(points, 2)[::2], 4, out)
    with pytest.raises(ValueError, match="points"):
        _core.convex_hull(points.reshape(2, 2), 4, out)
    with pytest.raises(ValueError, match="n_points"):
        _core.convex_hull(points, 5, out)
    with pytest.raises(ValueError, match="n_points"):
        _core.convex_hull(points, -1, out)
    with pytest.raises(ValueError, match="out"):
        _core.convex_hull(points, 4, np.empty(4, dtype=np.complex128))
    read_only = out.copy()
    read_only.flags.writeable = False
    with pytest.raises(ValueError, match="out"):
        _core.convex_hull(points, 4, read_only)
    with pytest.raises(ValueError, match="poly"):
        _core.simplify(read_only, 4, 0.0)
    with pytest.raises(TypeError, match="out"):
        core.small_hull_indices(points, 4, out, 0.0)
    with pytest.raises(ValueError, match="poly"):
        _core.area_centroid(np.empty(0, dtype=np.complex128), 0)
    with pytest.raises(ValueError, match="n_q"):
        _core.polygon_distance(points, 4, points, 9)
    with pytest.raises(TypeError, match="point"):
        core.contains_point(points, 4, "a point", 0.0)
    with pytest.raises(ValueError, match="work"):
        _core.clip_convex(points, 4, points, 4, np.empty(kernels.SCRATCH, complex), out)
    with pytest.raises(ValueError, match="n"):
        _core.offset_outward(points, 0, 1.0, out)
    with pytest.raises(ValueError, match="out"):
        _core.offset_outward(points, 4, 1.0, np.empty(6, dtype=np.complex128))
    with pytest.raises(ValueError, match="out"):
        _core.cone_region(0.0, 1.0, 0.1, np.empty(3, dtype=np.complex128))
    with pytest.raises(ValueError, match="out"):
        _core.boundary_samples(points, 4, 3, np.empty(11, dtype=np.complex128))
    with pytest.raises(TypeError, match="conservative"):
        core.frame_plan(points, 4, points + 5, 4, "yes", 3)
    with pytest.raises(ValueError, match="h1"):
        _core.sample_hypotheses(points, 4, points + 5, 4, 2, np.empty(63, complex), out)


def valid_frame() -> tuple[ComplexArray, Any]:
    a1 = fr_region(0.5, 1.5, 0.05)
    a2 = fr_region(-0.5, -1.5, 0.05)
    plan = kernels.frame_plan(a1, a1.size, a2, a2.size, True, 3)
    assert plan[0] == kernels.FRAME_OK
    h1, inv_d = np.empty(kernels.MAX_PAIRS, complex), np.empty(kernels.MAX_PAIRS, complex)
    n_pairs = kernels.sample_hypotheses(a1, a1.size, a2, a2.size, plan[1], h1, inv_d)
    frame = kernels.FrameChange(a1, a1.size, a2, a2.size, h1, inv_d, n_pairs, True, *plan[2:])
    return a1, frame


def test_bad_frames_raise() -> None:
    target, frame = valid_frame()
    buffers = [np.empty(kernels.MAX_CLOUD + 1, dtype=np.complex128) for _ in range(3)]
    assert _core.transfer_region(target, target.size, frame, *buffers) > 0
    core: Any = _core  # the wrong types below are the point
    with pytest.raises(TypeError, match="frame"):
        core.transfer_region(target, target.size, list(frame), *buffers)
    with pytest.raises(TypeError, match="frame"):
        _core.transfer_region(target, target.size, tuple(frame)[:10], *buffers)
    with pytest.raises(ValueError, match=r"frame\.n_pairs"):
        _core.transfer_region(target, target.size, frame._replace(n_pairs=10**6), *buffers)
    with pytest.raises(ValueError, match=r"frame\.n1"):
        _core.transfer_region(target, target.size, frame._replace(n1=9), *buffers)
    with pytest.raises(TypeError, match=r"frame\.h1"):
        _core.transfer_region(target, target.size, frame._replace(h1=frame.h1.real), *buffers)
    with pytest.raises(TypeError, match="frame"):
        _core.transfer_region(target, target.size, frame._replace(n1="4"), *buffers)
    with pytest.raises(ValueError, match="n_target"):
        _core.transfer_region(target, target.size + 1, frame, *buffers)
    # no target: an empty hull, which the conservative bound cannot grow (numba would read
    # the hull buffer's last slot); the paper transfer gives an empty region
    with pytest.raises(ValueError, match="offset_outward"):
        _core.transfer_region(target, 0, frame, *buffers)
    assert _core.transfer_region(target, 0, frame._replace(conservative=False), *buffers) == 0
    with pytest.raises(ValueError, match="hull"):
        small = np.empty(target.size * frame.n_pairs, dtype=np.complex128)
        _core.transfer_region(target, target.size, frame, buffers[0], small, buffers[2])


def test_over_capacity_raises_capacity_error() -> None:
    rng = np.random.default_rng(16)
    points = cloud(rng, MAX_HULL_POINTS + 1, "normal")
    out = np.empty(points.size + 1, dtype=np.complex128)
    with pytest.raises(_core.CapacityError):
        _core.convex_hull(points, points.size, out)
    with pytest.raises(_core.CapacityError):
        _core.small_convex_hull(points, points.size, out, 0.0)
    big = polygon(rng, 400, "circle")
    assert big.size > kernels.SCRATCH
    scratch = np.empty(big.size + 8, dtype=np.complex128)
    with pytest.raises(_core.CapacityError):
        _core.clip_convex(big, big.size, big, big.size, scratch, scratch.copy())
    square = np.array([0, 1, 1 + 1j, 1j], dtype=np.complex128) + 5
    h1, inv_d = np.empty(4096, complex), np.empty(4096, complex)
    with pytest.raises(_core.CapacityError):  # 4 edges x 9 samples > MAX_SAMPLES
        _core.sample_hypotheses(square, 4, square + 5, 4, 9, h1, inv_d)
    target, frame = valid_frame()
    many = np.repeat(target, kernels.MAX_CLOUD // frame.n_pairs + 1)
    buffers = [np.empty(many.size * frame.n_pairs + 1, dtype=np.complex128) for _ in range(3)]
    with pytest.raises(_core.CapacityError):
        _core.transfer_region(many, many.size, frame, *buffers)
    assert issubclass(_core.CapacityError, RuntimeError)
