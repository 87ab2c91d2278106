"""Hard inputs never crash the interpreter: every entry point of the native core
(``bearing_env._core``), fuzzed.

Each entry point is driven by hypothesis with inputs built the way the Python side builds
them (``bearing_env.slam.kernels``, ``bearing_env.slam.batch``, ``bearing_env.envs.core``,
``bearing_env.world``, ``bearing_env.sensing``), then corrupted: special floats (NaN,
+-inf, 1e-300, 1e300, -0.0), degenerate polygons (every vertex equal, collinear, repeated
vertices, 0 to 2 of them), counts beyond their arrays, empty batches, repeated and
out-of-range rows, all-NaN bearings. A call must either return, with outputs of the
documented shape and dtype (and finite where its inputs were finite and the contract
says so), or refuse with ``TypeError``, ``ValueError`` or ``CapacityError``. A crash (a
segfault, an abort) kills the test process, which is how such a test fails; under the
sanitizer build (``tests/slam/test_native_sanitizers.py`` runs every test file of this
folder) an out-of-bounds access or undefined behaviour fails it too.

The map and env states' own integers (region counts, window and history cursors, noise
and trajectory cursors, counters), which the kernels keep and a user can write, are
corrupted too: negative, past a region's capacity, absurd. Not with values near int64's
end: the env's counters that count on from them would overflow only after 2**63 steps (the
map update refuses its own counters past ``MAX_COUNTER``, 2**62, rather than overflow
them: tests/slam/test_slam_map.py).

Bad arguments (wrong dtype, dimensions or shape, a strided view, a read-only output,
not an array) raise ``TypeError`` or ``ValueError`` naming the argument: the table
``BAD_ARGUMENTS`` covers the array arguments of each binding file.

:data:`FUZZED` lists the entry points covered; a test holds it equal to the module's, so a
new entry point without a fuzz test fails the suite. The examples are derandomized (the
same ones every run); the ``slow`` variant runs every fuzz test with a larger budget.
"""

from __future__ import annotations

import ast
import dataclasses
import enum
import functools
import importlib.resources
import math
import re
from collections import Counter
from collections.abc import Callable
from pathlib import Path
from types import SimpleNamespace
from typing import Any, Protocol, TypeVar

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env.envs import core
from bearing_env.envs.actions import CONTINUOUS
from bearing_env.envs.config import EnvConfig
from bearing_env.envs.core import MapBank
from bearing_env.envs.kernels import Report, Settings
from bearing_env.envs.state import STATE_ARRAYS, BatchState
from bearing_env.slam import kernels
from bearing_env.slam.batch import BatchedPolygonSLAM
from bearing_env.slam.settings import FUSIONS

T = TypeVar("T")
ComplexArray = NDArray[np.complex128]
FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: The stub as installed with the package (the source tree is absent when the installed
#: package's tests run, e.g. from the sdist).
STUB = importlib.resources.files("bearing_env") / "_core.pyi"


class Draw(Protocol):
    """A composite strategy's draw, or st.data()'s: a value of a strategy."""

    def __call__(self, strategy: st.SearchStrategy[T], /) -> T: ...


# ----------------------------------------------------------------------------------------
# The entry points covered, and how a call may end
# ----------------------------------------------------------------------------------------

#: Every entry point this module fuzzes (a test checks each is called here, and that the
#: set is the module's public callables plus the underscore functions of the stub).
FUZZED: frozenset[str] = frozenset(
    {
        # bind_slam_geometry.cpp
        "cross", "dot", "wrap", "scale_of", "tolerance_of", "convex_hull",
        "small_convex_hull", "small_hull_indices", "area_centroid", "contains_point",
        "polygon_distance", "longest_edge", "simplify", "drop_edges_outward", "clip_convex",
        "offset_outward", "cone_region", "boundary_samples", "frame_plan",
        "sample_hypotheses", "transfer_region", "transfer_polygon", "sub_square_growths",
        # bind_slam.cpp
        "MapState", "Params", "update_maps", "copy_maps", "check_indices", "none_infinite",
        "contains_points", "binomial_q", "relaxed_region", "update_levels",
        # bind_sim.cpp
        "_add_wrapped", "_add_wrapped_with_outliers", "bearing", "straight_move",
        "obstructed_move", "_true_bearings_into", "_edge_entry", "_disc_entry",
        "free_length", "_cross", "segments_cross", "_on_segment", "line_of_sight",
        "visible", "inside_polygon", "_segment_distance", "clearance", "visible_rows",
        # bind_env.cpp
        "EnvInputs", "StepOutputs", "step_rows", "new_report", "new_arrays",
        "report_rows_into", "potentials", "move_and_read", "append_positions", "capped",
        "potential_of", "_write_shape", "decode_continuous", "_known", "encode_map",
        "encode_map_into", "encode_window", "encode_levels", "_potentials_of_rows",
        "_move_ends", "_bearings_of", "_simulate_potentials", "_score_readings",
        "_score_rows",
    }
)  # fmt: skip

#: How a call may refuse its input; anything else (or a crash) fails the test.
REFUSALS: tuple[type[Exception], ...] = (TypeError, ValueError, _core.CapacityError)

#: Calls made and calls that returned, per entry point, over this session: the last test
#: checks that each fuzzed entry point got past its checks on some example.
CALLS: Counter[str] = Counter()
RETURNS: Counter[str] = Counter()


def result(entry: Callable[..., T], *args: Any, **kwargs: Any) -> T | None:
    """entry(*args, **kwargs), or None when it refuses the input (an entry point returning a
    value)."""
    CALLS[entry.__name__] += 1
    try:
        value = entry(*args, **kwargs)
    except REFUSALS:
        return None
    RETURNS[entry.__name__] += 1
    return value


def completes(entry: Callable[..., object], *args: Any) -> bool:
    """Whether entry(*args) returned (True) or refused its input (an entry point writing
    its outputs in place and returning None)."""
    CALLS[entry.__name__] += 1
    try:
        assert entry(*args) is None
    except REFUSALS:
        return False
    RETURNS[entry.__name__] += 1
    return True


#: Each fuzz test's body and strategies, for the slow variant's larger budget.
Body = Callable[..., None]
FUZZ_BODIES: dict[str, tuple[Body, dict[str, st.SearchStrategy[Any]]]] = {}
#: The normal suite's budget: the whole module runs in a few seconds.
FAST = settings(max_examples=40, deadline=None, derandomize=True, database=None)
SLOW = settings(max_examples=1500, deadline=None, derandomize=True, database=None)


def fuzz(**strategies: st.SearchStrategy[Any]) -> Callable[[Body], Callable[[], None]]:
    """A hypothesis test of the body over the strategies, with the normal budget."""

    def register(body: Body) -> Callable[[], None]:
        FUZZ_BODIES[body.__name__] = (body, strategies)
        test: Callable[[], None] = FAST(given(**strategies)(body))
        return test

    return register


# ----------------------------------------------------------------------------------------
# Hard values
# ----------------------------------------------------------------------------------------

SPECIAL_FLOATS = (math.nan, math.inf, -math.inf, 1e-300, -1e-300, 1e300, -1e300, -0.0, 0.0, 5e-324)
SPECIAL_INTS = (-1, 0, 1, 2**31, 2**62, -(2**63), 2**63 - 1)
SEEDS = st.integers(0, 2**32 - 1)
special_floats = st.sampled_from(SPECIAL_FLOATS)
moderate_floats = st.floats(-10.0, 10.0)
hard_floats = st.one_of(special_floats, moderate_floats, st.floats())
hard_complexes = st.builds(complex, hard_floats, hard_floats)
moderate_complexes = st.builds(complex, moderate_floats, moderate_floats)
hard_ints = st.one_of(st.integers(-3, 12), st.sampled_from(SPECIAL_INTS))

#: Hull inputs beyond this many points raise CapacityError (MAX_HULL_POINTS,
#: csrc/include/bearing_core/slam/polygons.hpp).
MAX_HULL_POINTS = kernels.MAX_CLOUD + kernels.SCRATCH

POLYGON_SHAPES = ("convex", "clockwise", "equal", "collinear", "repeated", "wild")


def special_value(draw: Draw, dtype: np.dtype[Any]) -> Any:
    """A special value of the dtype's kind: a special float (complex: in either part)."""
    if dtype.kind == "c":
        return complex(draw(special_floats), draw(hard_floats))
    return draw(special_floats)


#: Values a state's counts and cursors are overwritten with: negative, at and past a
#: region's capacity, absurd; not near int64's end, where counters that count on from
#: them (movements made, regions fused) would overflow after 2**63 movements.
COUNT_SPECIALS = (
    -5,
    -1,
    0,
    1,
    3,
    kernels.CAPACITY,
    kernels.CAPACITY + 1,
    kernels.SCRATCH + 1,
    2**40,
)


def corrupt_counts(draw: Draw, arrays: list[NDArray[Any]]) -> bool:
    """At times, overwrite an element of one or two of the int64 arrays (a state's counts,
    cursors and counters, which the kernels keep and a user can write) with a special
    count, in place; whether it did."""
    ints = [array for array in arrays if array.dtype == np.int64 and array.size > 0]
    if not ints or draw(st.integers(0, 2)) > 0:
        return False
    for k in draw(st.lists(st.integers(0, len(ints) - 1), min_size=1, max_size=2, unique=True)):
        flat = ints[k].reshape(-1)
        flat[draw(st.integers(0, flat.size - 1))] = draw(st.sampled_from(COUNT_SPECIALS))
    return True


def corrupt(draw: Draw, array: NDArray[Any]) -> bool:
    """Overwrite some elements of a float or complex array (or all) with special values,
    in place; whether it did."""
    if array.size == 0 or array.dtype.kind not in "fc":
        return False
    mode = draw(st.sampled_from(("keep", "some", "all")))
    if mode == "keep":
        return False
    flat = array.reshape(-1)
    if mode == "all":
        flat[:] = special_value(draw, array.dtype)
    else:
        for _ in range(draw(st.integers(1, 3))):
            flat[draw(st.integers(0, flat.size - 1))] = special_value(draw, array.dtype)
    return True


@st.composite
def polygons(draw: st.DrawFn, max_size: int = 9, clean: bool = False) -> ComplexArray:
    """Complex polygons as the kernels take them: convex (counter-clockwise), clockwise,
    every vertex equal, collinear, each vertex repeated, or wild points; at any scale and
    corrupted by special values, unless `clean` (then finite and moderate: a convex
    polygon's, or a degenerate one's, vertices)."""
    size = draw(st.integers(0, max_size))
    shape = draw(st.sampled_from(POLYGON_SHAPES[:-1] if clean else POLYGON_SHAPES))
    rng = np.random.default_rng(draw(SEEDS))
    scales = (1.0, 1e-3, 1e3) if clean else (1.0, 1e-300, 1e-9, 1e9, 1e300)
    scale = draw(st.sampled_from(scales))
    centre = complex(rng.uniform(-5.0, 5.0), rng.uniform(-5.0, 5.0))
    if shape in ("convex", "clockwise"):
        angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, size))
        poly = centre + scale * np.exp(1j * angles)
        if shape == "clockwise":
            poly = poly[::-1]
    elif shape == "equal":
        poly = np.full(size, centre)
    elif shape == "collinear":
        direction = np.exp(1j * rng.uniform(0.0, np.pi))
        poly = centre + scale * direction * np.sort(rng.uniform(-1.0, 1.0, size))
    elif shape == "repeated":
        angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, (size + 1) // 2))
        poly = np.repeat(centre + scale * np.exp(1j * angles), 2)[:size]
    else:
        poly = np.array(draw(st.lists(hard_complexes, min_size=size, max_size=size)))
    poly = np.ascontiguousarray(poly, dtype=np.complex128)
    if not clean:
        corrupt(draw, poly)
    return poly


def counts_for(size: int) -> st.SearchStrategy[int]:
    """A count of an array of `size` elements: mostly the whole, else anything near it or
    absurd (negative, beyond the array, beyond int64's range of products)."""
    return st.one_of(
        st.just(size), st.integers(-2, size + 2), st.sampled_from((2**40, 2**62, -(2**62)))
    )


#: Longest output array a test makes (more than any kernel writes; an absurd count asks
#: for more, and the call must refuse the shorter array).
MAX_OUT = 1 << 13


def out_length(draw: Draw, needed: int) -> int:
    """The length of an output array that should hold `needed`: enough, or not."""
    needed = min(needed, MAX_OUT)
    return draw(st.sampled_from((needed, needed + 3, max(needed - 1, 0), 0)))


def finite(values: Any) -> bool:
    return bool(np.all(np.isfinite(values)))


def moderate(*values: complex, bound: float = 1e100) -> bool:
    """Whether every value (real or complex) is at most `bound` in each part (so finite)."""
    return all(abs(v.real) <= bound and abs(v.imag) <= bound for v in values)


def members(points: NDArray[Any], pool: ComplexArray) -> bool:
    """Whether every point is one of the pool's (a hull's vertices are input points)."""
    return all(np.any(pool == point) for point in points)


# ----------------------------------------------------------------------------------------
# bind_slam_geometry.cpp: scalar helpers and polygons
# ----------------------------------------------------------------------------------------


@fuzz(a=hard_complexes, b=hard_complexes)
def test_cross_and_dot_of_any_complex_numbers(a: complex, b: complex) -> None:
    for entry in (_core.cross, _core.dot):
        value = result(entry, a, b)
        assert isinstance(value, float)
        if moderate(a, b):
            assert math.isfinite(value)


@fuzz(angle=hard_floats, size=hard_floats, magnitude=hard_floats)
def test_wrap_and_tolerance_of_any_float(angle: float, size: float, magnitude: float) -> None:
    wrapped = result(_core.wrap, angle)
    assert isinstance(wrapped, float)
    if math.isfinite(angle):
        assert -math.pi <= wrapped <= math.pi
    tolerance = result(_core.tolerance_of, size, magnitude)
    assert isinstance(tolerance, float)
    if moderate(size, magnitude, bound=1e300):
        assert math.isfinite(tolerance)


@fuzz(poly=polygons(), data=st.data())
def test_scale_of_any_polygon(poly: ComplexArray, data: st.DataObject) -> None:
    n = data.draw(counts_for(poly.size))
    scale = result(_core.scale_of, poly, n)
    if scale is None:
        return
    assert 1 <= poly.size and 0 <= n <= poly.size
    size, magnitude = scale
    assert isinstance(size, float) and isinstance(magnitude, float)
    if finite(poly[: max(n, 1)]) and np.all(np.abs(poly) <= 1e300):
        assert size >= 0.0 and magnitude >= 0.0


@st.composite
def point_clouds(draw: st.DrawFn) -> ComplexArray:
    """Hull inputs: small polygons, or clouds of up to one point past the hull's capacity."""
    if draw(st.integers(0, 9)) > 0:
        return draw(polygons(max_size=12))
    rng = np.random.default_rng(draw(SEEDS))
    size = draw(st.sampled_from((kernels.CAPACITY, MAX_HULL_POINTS, MAX_HULL_POINTS + 1)))
    return rng.uniform(-1.0, 1.0, size) + 1j * rng.uniform(-1.0, 1.0, size)


@fuzz(points=point_clouds(), data=st.data())
def test_convex_hulls_of_any_points(points: ComplexArray, data: st.DataObject) -> None:
    n = data.draw(counts_for(points.size))
    tol = data.draw(st.one_of(st.just(0.0), hard_floats))
    length = out_length(data.draw, max(n, 0) + 1)
    for entry, dtype in (
        (_core.convex_hull, np.complex128),
        (_core.small_convex_hull, np.complex128),
        (_core.small_hull_indices, np.int64),
    ):
        out = np.zeros(length, dtype=dtype)
        args = (points, n, out) if entry is _core.convex_hull else (points, n, out, tol)
        k = result(entry, *args)
        if k is None:
            continue
        assert isinstance(k, int) and 0 <= k <= min(length, max(n, 0) + 1)
        if dtype == np.int64:
            assert np.all((0 <= out[:k]) & (out[:k] < n))
        elif finite(points[:n]):
            assert members(out[:k], points[:n])


@fuzz(clean=st.booleans(), data=st.data())
def test_area_centroid_and_containment_of_any_polygon(clean: bool, data: st.DataObject) -> None:
    poly = data.draw(polygons(clean=clean))
    n = data.draw(counts_for(poly.size))
    area_centroid = result(_core.area_centroid, poly, n)
    if area_centroid is not None:
        area, centroid = area_centroid
        assert isinstance(area, float) and isinstance(centroid, complex)
        assert not area < 0.0
        # A convex (or degenerate) polygon's area and centroid (else the vertex mean).
        if clean and n >= 1:
            assert math.isfinite(area) and finite(centroid)
    point = data.draw(st.one_of(moderate_complexes, hard_complexes))
    relative = data.draw(st.one_of(st.just(1e-9), hard_floats))
    inside = result(_core.contains_point, poly, n, point, relative)
    assert inside is None or isinstance(inside, bool)
    longest = result(_core.longest_edge, poly, n)
    if longest is not None:
        assert isinstance(longest, float)
        if finite(poly[: max(n, 0)]) and np.all(np.abs(poly[: max(n, 0)]) <= 1e100):
            assert 0.0 <= longest < math.inf


@fuzz(p=polygons(), q=polygons(), data=st.data())
def test_polygon_distance_of_any_polygons(
    p: ComplexArray, q: ComplexArray, data: st.DataObject
) -> None:
    n_p, n_q = data.draw(counts_for(p.size)), data.draw(counts_for(q.size))
    distance = result(_core.polygon_distance, p, n_p, q, n_q)
    if distance is None:
        return
    assert isinstance(distance, float)
    both = np.concatenate([p[:n_p], q[:n_q]])
    if n_p >= 1 and n_q >= 1 and finite(both) and np.all(np.abs(both) <= 1e100):
        assert 0.0 <= distance < math.inf


@fuzz(poly=polygons(), data=st.data())
def test_simplify_and_drop_edges_of_any_polygon(poly: ComplexArray, data: st.DataObject) -> None:
    n = data.draw(counts_for(poly.size))
    tol = data.draw(st.one_of(st.just(1e-12), hard_floats))
    simplified = poly.copy()
    k = result(_core.simplify, simplified, n, tol)
    if k is not None:
        assert isinstance(k, int) and 0 <= k <= n
        if finite(poly[:n]):
            assert members(simplified[:k], poly[:n])
    capacity = data.draw(st.one_of(st.integers(-2, 12), st.sampled_from(SPECIAL_INTS)))
    reduced = poly.copy()
    k = result(_core.drop_edges_outward, reduced, n, capacity)
    if k is not None:
        assert isinstance(k, int) and (k == n if n <= capacity else 0 <= k <= n)


@fuzz(subject=polygons(), clipper=polygons(), data=st.data())
def test_clip_convex_of_any_polygons(
    subject: ComplexArray, clipper: ComplexArray, data: st.DataObject
) -> None:
    n_subject = data.draw(counts_for(subject.size))
    n_clipper = data.draw(counts_for(clipper.size))
    out = np.zeros(out_length(data.draw, kernels.SCRATCH), dtype=np.complex128)
    work = np.zeros(out_length(data.draw, kernels.SCRATCH), dtype=np.complex128)
    k = result(_core.clip_convex, subject, n_subject, clipper, n_clipper, out, work)
    if k is None:
        return
    assert isinstance(k, int) and (k == 0 or 3 <= k <= kernels.CAPACITY)


@fuzz(clean=st.booleans(), data=st.data())
def test_offset_outward_of_any_polygon(clean: bool, data: st.DataObject) -> None:
    poly = data.draw(polygons(clean=clean))
    n = data.draw(counts_for(poly.size))
    radius = data.draw(st.floats(0.0, 1.0) if clean else hard_floats)
    out = np.zeros(out_length(data.draw, max(n, 0) + 3), dtype=np.complex128)
    k = result(_core.offset_outward, poly, n, radius, out)
    if k is None:
        return
    assert isinstance(k, int) and (k == 4 if n <= 2 else n <= k <= n + 3)
    # Finite edges of nonzero length (distinct vertices) give a finite offset.
    if clean and np.unique(poly[:n]).size == n:
        assert finite(out[:k])


@fuzz(a=hard_floats, b=hard_floats, epsilon=hard_floats, data=st.data())
def test_cone_region_of_any_bearings(
    a: float, b: float, epsilon: float, data: st.DataObject
) -> None:
    out = np.zeros(out_length(data.draw, kernels.FR_VERTICES), dtype=np.complex128)
    region = result(_core.cone_region, a, b, epsilon, out)
    if region is None:
        return
    n, status = region
    assert status in (kernels.FR_BOUNDED, kernels.FR_UNBOUNDED, kernels.FR_EMPTY)
    assert 0 <= n <= kernels.FR_VERTICES and (n > 0) == (status == kernels.FR_BOUNDED)
    if math.isfinite(a) and math.isfinite(b) and math.isfinite(epsilon):
        assert finite(out[:n])


@fuzz(poly=polygons(), data=st.data())
def test_boundary_samples_of_any_polygon(poly: ComplexArray, data: st.DataObject) -> None:
    n = data.draw(counts_for(poly.size))
    per_edge = data.draw(st.one_of(st.integers(-1, 9), st.sampled_from(SPECIAL_INTS)))
    needed = max(n, 0) * max(per_edge, 0)
    out = np.zeros(out_length(data.draw, needed), dtype=np.complex128)
    k = result(_core.boundary_samples, poly, n, per_edge, out)
    if k is None:
        return
    assert k == needed and k <= out.size
    if finite(poly[:n]) and np.all(np.abs(poly[:n]) <= 1e100):
        assert finite(out[:k])


def fr_region(draw: Draw) -> ComplexArray:
    """A landmark's FR region as the update makes it (cone_region of two bearings), or a
    drawn polygon when the bearings bound no region; at times corrupted."""
    rng = np.random.default_rng(draw(SEEDS))
    out = np.zeros(kernels.FR_VERTICES, dtype=np.complex128)
    a, b = rng.uniform(-np.pi, np.pi, 2).tolist()
    n, _ = _core.cone_region(a, b, 0.03, out)
    region = out[:n] if n > 0 else draw(polygons(max_size=kernels.FR_VERTICES))
    region = region.copy()
    corrupt(draw, region)
    return region


@st.composite
def frame_changes(draw: st.DrawFn) -> kernels.FrameChange:
    """A FrameChange as the update makes it (frame_plan, then sample_hypotheses, of two FR
    regions), from any regions, at times with a field corrupted."""
    a1, a2 = fr_region(draw), fr_region(draw)
    conservative = draw(st.booleans())
    plan = result(_core.frame_plan, a1, a1.size, a2, a2.size, conservative, 3)
    per_edge = 3 if plan is None else plan[1]
    distance, delta1, delta2 = (1.0, 0.1, 0.1) if plan is None else plan[2:]
    h1 = np.zeros(kernels.MAX_PAIRS, dtype=np.complex128)
    inv_d = np.zeros(kernels.MAX_PAIRS, dtype=np.complex128)
    pairs = result(_core.sample_hypotheses, a1, a1.size, a2, a2.size, per_edge, h1, inv_d)
    frame = kernels.FrameChange(
        a1, a1.size, a2, a2.size, h1, inv_d, pairs or 0, conservative, distance, delta1, delta2
    )
    field = draw(st.sampled_from(("none", "n1", "n2", "n_pairs", "distance", "delta1")))
    if field == "none":
        return frame
    change: dict[str, Any] = {
        field: draw(hard_ints if field in ("n1", "n2", "n_pairs") else hard_floats)
    }
    return frame._replace(**change)


@fuzz(a1=polygons(max_size=5), a2=polygons(max_size=5), data=st.data())
def test_frame_plan_and_hypotheses_of_any_regions(
    a1: ComplexArray, a2: ComplexArray, data: st.DataObject
) -> None:
    n1, n2 = data.draw(counts_for(a1.size)), data.draw(counts_for(a2.size))
    edge_samples = data.draw(st.one_of(st.integers(-1, 9), st.sampled_from(SPECIAL_INTS)))
    plan = result(_core.frame_plan, a1, n1, a2, n2, data.draw(st.booleans()), edge_samples)
    if plan is not None:
        status, per_edge, distance, delta1, delta2 = plan
        assert status in (
            kernels.FRAME_OK,
            kernels.FRAME_L1_L2_OVERLAP,
            kernels.FRAME_L1_L2_TOO_CLOSE,
        )
        assert isinstance(per_edge, int)
        assert all(isinstance(value, float) for value in (distance, delta1, delta2))
    per_edge = data.draw(st.one_of(st.integers(-1, 9), st.sampled_from(SPECIAL_INTS)))
    room = out_length(data.draw, kernels.MAX_PAIRS)
    h1 = np.zeros(room, dtype=np.complex128)
    inv_d = np.zeros(out_length(data.draw, room), dtype=np.complex128)
    k = result(_core.sample_hypotheses, a1, n1, a2, n2, per_edge, h1, inv_d)
    if k is not None:
        assert isinstance(k, int) and 0 <= k <= min(h1.size, inv_d.size)


@fuzz(target=polygons(max_size=6), frame=frame_changes(), data=st.data())
def test_transfer_region_of_any_target_and_frame(
    target: ComplexArray, frame: kernels.FrameChange, data: st.DataObject
) -> None:
    n_target = data.draw(counts_for(target.size))
    cloud = np.zeros(out_length(data.draw, kernels.MAX_CLOUD), dtype=np.complex128)
    hull = np.zeros(out_length(data.draw, kernels.MAX_CLOUD + 1), dtype=np.complex128)
    out = np.zeros(out_length(data.draw, kernels.SCRATCH), dtype=np.complex128)
    k = result(_core.transfer_region, target, n_target, frame, cloud, hull, out)
    if k is not None:
        assert isinstance(k, int) and 0 <= k <= kernels.CAPACITY


TRANSFER_CODES = (
    kernels.TRANSFER_CONSERVATIVE, kernels.TRANSFER_PAPER, kernels.TRANSFER_CONSERVATIVE_GLOBAL
)  # fmt: skip


@fuzz(target=polygons(max_size=6), data=st.data())
def test_transfer_polygon_of_any_target_and_regions(
    target: ComplexArray, data: st.DataObject
) -> None:
    a1, a2 = fr_region(data.draw), fr_region(data.draw)
    # Mostly valid codes, counts and sizes: the kernels, not only the checks, get most
    # examples (an empty target or region stands in for the FR regions of L1 and L2 at
    # fixed points then; their values stay the drawn, possibly corrupt, ones otherwise).
    valid = data.draw(st.integers(0, 3)) > 0
    if valid:
        target = target if target.size else np.array([0.5 + 2.0j])
        a1 = a1 if a1.size else np.array([2.0 + 1.0j, 2.2 + 1.0j, 2.1 + 1.2j])
        a2 = a2 if a2.size else np.array([3.0 - 1.0j, 3.2 - 1.0j, 3.1 - 0.8j])
    transfer = data.draw(st.sampled_from(TRANSFER_CODES) if valid else st.integers(-2, 5))
    edge_samples = data.draw(
        st.integers(1, kernels.MAX_EDGE_SAMPLES)
        if valid
        else st.one_of(st.integers(-1, 9), st.sampled_from(SPECIAL_INTS))
    )
    room = kernels.SCRATCH if valid else out_length(data.draw, kernels.SCRATCH)
    out = np.zeros(room, dtype=np.complex128)
    returned = result(_core.transfer_polygon, target, a1, a2, transfer, edge_samples, out)
    if returned is not None:
        status, k = returned
        assert status in (kernels.FRAME_OK, kernels.FRAME_L1_L2_OVERLAP,
                          kernels.FRAME_L1_L2_TOO_CLOSE)  # fmt: skip
        assert isinstance(k, int) and 0 <= k <= kernels.CAPACITY
        assert status == kernels.FRAME_OK or k == 0


@fuzz(target=polygons(max_size=6), data=st.data())
def test_sub_square_growths_of_any_target_and_regions(
    target: ComplexArray, data: st.DataObject
) -> None:
    a1, a2 = fr_region(data.draw), fr_region(data.draw)
    per_edge = data.draw(st.one_of(st.integers(-1, 9), st.sampled_from(SPECIAL_INTS)))
    needed = target.size * kernels.MAX_SAMPLES * kernels.MAX_SAMPLES
    out = np.zeros(out_length(data.draw, needed), dtype=np.float64)
    returned = result(_core.sub_square_growths, target, a1, a2, per_edge, out)
    if returned is not None:
        m1, m2 = returned
        assert 0 <= m1 <= kernels.MAX_SAMPLES and 0 <= m2 <= kernels.MAX_SAMPLES
        assert target.size * m1 * m2 <= out.size


# ----------------------------------------------------------------------------------------
# bind_slam.cpp: the map update and its helpers
# ----------------------------------------------------------------------------------------

#: The fuzzed map batches: a few maps of a few landmarks, after real movements.
MAPS, LANDMARKS, EPSILON = 4, 5, 0.03
FRAME_CODES = {
    kernels.FRAME_OK, kernels.FRAME_L1_UNBOUNDED, kernels.FRAME_L2_UNBOUNDED,
    kernels.FRAME_L1_L2_OVERLAP, kernels.FRAME_L1_L2_TOO_CLOSE, kernels.FRAME_L1_MISSING,
    kernels.FRAME_L2_MISSING, kernels.FRAME_REJECTED,
}  # fmt: skip
LANDMARK_CODES = {
    kernels.LANDMARK_UPDATED, kernels.LANDMARK_UNBOUNDED, kernels.LANDMARK_INCONSISTENT,
    kernels.LANDMARK_SKIPPED, kernels.LANDMARK_MISSING,
}  # fmt: skip


@functools.cache
def updated_batch(fusion: str) -> BatchedPolygonSLAM:
    """A batch of maps with the fusion after a few movements of a seeded world: regions,
    robot regions, the relaxed window and bases, the robust levels and history filled."""
    batch = BatchedPolygonSLAM(MAPS, LANDMARKS, EPSILON, fusion=fusion, window=4)
    rng = np.random.default_rng(11)
    landmarks = rng.uniform(0.0, 1.0, (MAPS, LANDMARKS)) + 1j * rng.uniform(
        0.0, 1.0, (MAPS, LANDMARKS)
    )
    position = np.full(MAPS, 0.5 + 0.35j)
    for _ in range(8):
        heading = rng.uniform(-np.pi, np.pi, MAPS)
        end = position + 0.25 * np.exp(1j * heading)
        noise = rng.uniform(-EPSILON, EPSILON, (2, MAPS, LANDMARKS))
        readings = [
            np.angle(landmarks - at[:, None]) - heading[:, None] + offsets
            for at, offsets in ((position, noise[0]), (end, noise[1]))
        ]
        batch.update(*(np.angle(np.exp(1j * values)) for values in readings))
        position = end
    return batch


def state_copy(fusion: str) -> kernels.State:
    """A copy of the batch's state arrays (a call may write them), as a State tuple."""
    batch = updated_batch(fusion)
    return kernels.State(*(np.copy(getattr(batch, name)) for name in kernels.State._fields))


def params_of(fusion: str) -> _core.Params:
    return updated_batch(fusion)._kernel_params(True)


def corrupt_state(draw: Draw, state: kernels.State) -> None:
    """Special values in some of the state's float and complex arrays, and at times in its
    counts and cursors."""
    for name in draw(st.lists(st.sampled_from(kernels.State._fields), max_size=4, unique=True)):
        corrupt(draw, getattr(state, name))
    corrupt_counts(draw, list(state))


@st.composite
def map_rows(draw: st.DrawFn, size: int) -> IntArray:
    """Rows into `size` maps: some of them, none, repeated ones or out of range ones."""
    kind = draw(st.sampled_from(("distinct", "empty", "repeated", "outside")))
    if kind == "empty":
        return np.zeros(0, dtype=np.int64)
    if kind == "distinct":
        rows = draw(st.lists(st.integers(0, size - 1), min_size=1, max_size=size, unique=True))
    elif kind == "repeated":
        rows = draw(st.lists(st.integers(0, size - 1), min_size=2, max_size=2 * size))
    else:
        rows = [*draw(st.lists(st.integers(0, size - 1), max_size=2)), draw(hard_ints)]
    return np.array(rows, dtype=np.int64)


@st.composite
def bearings(draw: st.DrawFn, rows: int, columns: int) -> FloatArray:
    """Bearings (rows, columns): plain ones, with special values, all NaN (nothing seen),
    or NaN for L1 or L2."""
    rng = np.random.default_rng(draw(SEEDS))
    values = rng.uniform(-np.pi, np.pi, (rows, columns))
    kind = draw(st.sampled_from(("plain", "special", "all_nan", "no_l1", "no_l2")))
    if kind == "special":
        corrupt(draw, values)
    elif kind == "all_nan":
        values[:] = np.nan
    elif kind == "no_l1" and columns > 0:
        values[:, 0] = np.nan
    elif kind == "no_l2" and columns > 1:
        values[:, 1] = np.nan
    return values


@fuzz(
    fusion=st.sampled_from(FUSIONS),
    with_robot=st.booleans(),
    threads=st.sampled_from((1, 2, 3, 0)),
    data=st.data(),
)
def test_update_maps_of_any_bearings(
    fusion: str, with_robot: bool, threads: int, data: st.DataObject
) -> None:
    state = state_copy(fusion)
    corrupt_state(data.draw, state)
    maps = result(_core.MapState, state)
    assert maps is not None and maps.num_maps == MAPS and maps.n_mapped == LANDMARKS - 2
    base = params_of(fusion)
    settings = {name: getattr(base, name) for name, *_ in _core.SCHEMAS["Params"]}
    settings.update(with_robot=with_robot, likely=data.draw(st.booleans()))
    params = _core.Params(**settings)
    rows = data.draw(map_rows(MAPS))
    start = data.draw(bearings(rows.size, LANDMARKS))
    end = data.draw(bearings(rows.size, LANDMARKS))
    out = kernels.Outputs(
        np.full(rows.size, -1, dtype=np.int8),
        np.full((rows.size, LANDMARKS - 2), -1, dtype=np.int8),
        np.full(rows.size, -1, dtype=np.int64),
    )
    # The counts the update indexes its buffers with, as they were before the call.
    corrupted = bool(np.all((0 <= rows) & (rows < MAPS))) and (
        any(map(outside_region, state.counts[rows].ravel().tolist()))
        or any(map(outside_region, state.robot_counts[rows].tolist()))
    )
    if not completes(_core.update_maps, start, end, rows, params, maps, out, threads):
        return
    assert not corrupted  # a map with a count past its region's slots is refused
    assert set(out.frame_status.tolist()) <= FRAME_CODES
    assert set(out.landmark_status.ravel().tolist()) <= LANDMARK_CODES
    assert np.all((out.n_bad >= 0) & (out.n_bad <= LANDMARKS - 2))


@fuzz(
    epsilon=st.one_of(st.floats(1e-3, 0.2), hard_floats),
    # transfer, edge_samples, on_inconsistency, fusion, max_outliers: in range or anything.
    codes=st.one_of(
        st.tuples(
            st.integers(0, 1),
            st.integers(1, 8),
            st.integers(0, 1),
            st.integers(0, 2),
            st.integers(0, 31),
        ),
        st.tuples(*(hard_ints for _ in range(5))),
    ),
    risk=st.one_of(st.floats(0.0, 1.0), hard_floats),
    flags=st.tuples(st.booleans(), st.booleans(), st.booleans()),
)
def test_params_of_any_settings(
    epsilon: float, codes: tuple[int, ...], risk: float, flags: tuple[bool, ...]
) -> None:
    transfer, edge_samples, on_inconsistency, fusion, max_outliers = codes
    with_robot, likely, estimate_bound = flags
    drawn = {"with_robot": with_robot, "likely": likely, "estimate_bound": estimate_bound}
    drawn.update(epsilon=epsilon, transfer=transfer, edge_samples=edge_samples)
    drawn.update(on_inconsistency=on_inconsistency, fusion=fusion, max_outliers=max_outliers)
    params = result(_core.Params, **drawn, risk=risk)
    if params is not None:
        assert math.isfinite(params.epsilon) and params.epsilon > 0.0
        assert 1 <= params.edge_samples <= kernels.MAX_EDGE_SAMPLES
        assert 0 <= params.max_outliers < kernels.MAX_WINDOW and math.isfinite(params.risk)


@fuzz(fusion=st.sampled_from(FUSIONS), data=st.data())
def test_map_state_of_any_array_shapes(fusion: str, data: st.DataObject) -> None:
    """A State whose arrays have other lengths on some axes (or other dtypes) is refused
    or taken, never read out of bounds."""
    state = state_copy(fusion)
    changed: list[NDArray[Any]] = list(state)
    for k in data.draw(st.lists(st.integers(0, len(changed) - 1), max_size=3, unique=True)):
        array = changed[k]
        how = data.draw(st.sampled_from(("axis", "empty", "dtype", "scalar")))
        if how == "axis" and array.ndim > 0:
            axis = data.draw(st.integers(0, array.ndim - 1))
            shape = list(array.shape)
            shape[axis] = data.draw(st.integers(0, shape[axis] + 2))
            changed[k] = np.zeros(shape, dtype=array.dtype)
        elif how == "empty":
            changed[k] = np.zeros((0,) * array.ndim, dtype=array.dtype)
        elif how == "dtype":
            changed[k] = np.zeros(array.shape, dtype=np.float32)
        else:
            changed[k] = np.zeros((), dtype=array.dtype)
    candidate: Any = kernels.State(*changed)
    if data.draw(st.booleans()):
        candidate = tuple(changed[: data.draw(st.integers(0, len(changed)))])
    maps = result(_core.MapState, candidate)
    if maps is None:
        return
    assert maps.num_maps == changed[0].shape[0] and maps.n_mapped == changed[0].shape[1]
    assert maps.window == changed[12].shape[1] and maps.levels == changed[22].shape[2]
    # What the map state took, the update reads: from any rows of it.
    rows = np.arange(maps.num_maps, dtype=np.int64)
    width = maps.n_mapped + 2
    out = kernels.Outputs(
        np.zeros(rows.size, dtype=np.int8),
        np.zeros((rows.size, maps.n_mapped), dtype=np.int8),
        np.zeros(rows.size, dtype=np.int64),
    )
    start = np.random.default_rng(0).uniform(-np.pi, np.pi, (rows.size, width))
    completes(_core.update_maps, start, start[:, ::-1].copy(), rows, params_of(fusion), maps, out)


@fuzz(source=st.sampled_from(FUSIONS), target=st.sampled_from(FUSIONS), data=st.data())
def test_copy_maps_between_any_states(source: str, target: str, data: st.DataObject) -> None:
    from_state = state_copy(source)
    corrupt_state(data.draw, from_state)
    kept = data.draw(st.integers(0, MAPS))  # the target batch may have fewer maps
    kept_rows: list[NDArray[Any]] = [np.copy(values[:kept]) for values in state_copy(target)]
    to_state = kernels.State(*kept_rows)
    from_maps = _core.MapState(from_state)
    to_maps = from_maps if data.draw(st.integers(0, 5)) == 0 else _core.MapState(to_state)
    rows = data.draw(map_rows(MAPS))
    if not completes(_core.copy_maps, from_maps, rows, to_maps):
        return
    assert source == target and to_maps is not from_maps and rows.size <= kept
    for copied, original in zip(to_state, from_state, strict=True):
        assert copied[: rows.size].tobytes() == np.ascontiguousarray(original[rows]).tobytes()


@st.composite
def index_arrays(draw: st.DrawFn) -> IntArray:
    values = draw(st.lists(st.one_of(st.integers(-2, 12), st.sampled_from(SPECIAL_INTS))))
    return np.array(values, dtype=np.int64)


def reference_check(indices: IntArray, size: int, distinct: bool) -> int:
    """check_indices in Python: the first problem met, in order."""
    seen: set[int] = set()
    for index in indices.tolist():
        if not 0 <= index < size:
            return int(kernels.INDEX_OUT_OF_RANGE)
        if distinct and index in seen:
            return int(kernels.INDEX_REPEATED)
        seen.add(index)
    return int(kernels.INDEX_OK)


@fuzz(
    indices=index_arrays(),
    size=st.one_of(st.integers(-2, 12), st.sampled_from(SPECIAL_INTS)),
    distinct=st.booleans(),
)
def test_check_indices_of_any_indices_and_size(
    indices: IntArray, size: int, distinct: bool
) -> None:
    outcome = result(_core.check_indices, indices, size, distinct)
    if outcome is None:
        assert (distinct and size < 0) or not -(2**63) <= size < 2**63
        return
    assert outcome == reference_check(indices, size, distinct)


@fuzz(
    shape=st.lists(st.integers(0, 4), max_size=3),
    view=st.sampled_from(("contiguous", "strided", "read_only")),
    data=st.data(),
)
def test_none_infinite_of_any_float_array(shape: list[int], view: str, data: st.DataObject) -> None:
    values = np.random.default_rng(data.draw(SEEDS)).uniform(-1.0, 1.0, [2 * s for s in shape])
    corrupt(data.draw, values)
    flat = values.reshape(-1)  # (check_bearings' C-contiguous bearings, as it passes them)
    if view == "strided":
        flat = flat[::2]
        if flat.size > 1:
            with pytest.raises(ValueError, match="values must be C-contiguous"):
                _core.none_infinite(flat)
            return
    elif view == "read_only":
        flat.flags.writeable = False
    assert result(_core.none_infinite, flat) == (not np.any(np.isinf(flat)))


@fuzz(data=st.data())
def test_contains_points_of_any_points_and_counts(data: st.DataObject) -> None:
    state = state_copy("intersect")
    corrupt(data.draw, state.vertices)
    counts = state.counts
    if data.draw(st.booleans()):  # counts as callers may pass them: any ints
        flat = counts.reshape(-1)
        flat[data.draw(st.integers(0, flat.size - 1))] = data.draw(
            st.sampled_from((-1, 0, 1, 2, kernels.CAPACITY, kernels.CAPACITY + 1, 2**62))
        )
    rows = data.draw(map_rows(MAPS))
    points = np.array(
        data.draw(
            st.lists(
                moderate_complexes | hard_complexes, min_size=rows.size * 3, max_size=rows.size * 3
            )
        ),
        dtype=np.complex128,
    ).reshape(rows.size, 3)
    relative = data.draw(st.one_of(st.just(1e-9), hard_floats))
    out = np.zeros(points.shape, dtype=bool)
    if completes(_core.contains_points, state.vertices, counts, rows, points, relative, out):
        assert np.all(counts[rows] <= kernels.CAPACITY)  # else refused, not read past
        assert not np.any(out[counts[rows] <= 0])


@fuzz(
    n=st.one_of(st.integers(-2, 1000), st.sampled_from(SPECIAL_INTS)),
    p=hard_floats,
    risk=st.one_of(st.just(0.05), hard_floats),
    # q_cap when the risk is never met (risk <= 0), at once however large.
    q_cap=st.one_of(st.integers(-3, 10_000), st.sampled_from(SPECIAL_INTS)),
)
def test_binomial_q_of_any_settings(n: int, p: float, risk: float, q_cap: int) -> None:
    q = result(_core.binomial_q, n, p, risk, q_cap)
    if q is not None:
        assert isinstance(q, int) and 0 <= q <= max(q_cap, 0)


def outside_region(count: int) -> bool:
    """Whether a region's vertex count lies outside its CAPACITY slots."""
    return not 0 <= count <= kernels.CAPACITY


@fuzz(data=st.data())
def test_relaxed_region_of_any_slots(data: st.DataObject) -> None:
    state = state_copy("relaxed")
    corrupt_state(data.draw, state)
    maps = _core.MapState(state)
    window = maps.window
    row = data.draw(st.one_of(st.integers(0, MAPS - 1), hard_ints))
    j = data.draw(st.one_of(st.integers(0, LANDMARKS - 3), hard_ints))
    slots = np.array(
        data.draw(
            st.one_of(
                st.lists(st.integers(0, window - 1), min_size=1, max_size=window),
                st.lists(st.integers(-1, window), max_size=window + 2),
            )
        ),
        dtype=np.int64,
    )
    use_base = data.draw(st.booleans())
    max_outliers = data.draw(st.one_of(st.integers(-1, 4), st.sampled_from(SPECIAL_INTS)))
    out = np.zeros(out_length(data.draw, kernels.SCRATCH), dtype=np.complex128)
    valid = 0 <= row < MAPS and 0 <= j < LANDMARKS - 2 and 1 <= slots.size <= window
    valid = valid and bool(np.all((0 <= slots) & (slots < window)))
    if valid and data.draw(st.booleans()):  # the counts of the regions this call reads
        slot = data.draw(st.sampled_from(slots.tolist()))
        state.window_counts[row, slot, j] = data.draw(st.sampled_from(COUNT_SPECIALS))
        state.base_counts[row, j] = data.draw(st.sampled_from(COUNT_SPECIALS))
    region = result(_core.relaxed_region, maps, row, j, slots, use_base, max_outliers, out)
    if region is not None:
        n, q = region
        assert 0 <= n <= kernels.SCRATCH and 0 <= q <= max_outliers
    if valid:
        # A count past its region's slots would be read past them: it is refused.
        counts = [*state.window_counts[row, slots, j].tolist()]
        counts += [int(state.base_counts[row, j])] if use_base else []
        if any(outside_region(count) for count in counts):
            assert region is None


@fuzz(data=st.data())
def test_update_levels_of_any_fresh_region(data: st.DataObject) -> None:
    state = state_copy("robust")
    corrupt_state(data.draw, state)
    maps = _core.MapState(state)
    row = data.draw(st.one_of(st.integers(0, MAPS - 1), hard_ints))
    j = data.draw(st.one_of(st.integers(0, LANDMARKS - 3), hard_ints))
    fresh = data.draw(st.one_of(polygons(max_size=8), polygons(max_size=kernels.CAPACITY + 1)))
    valid = 0 <= row < MAPS and 0 <= j < LANDMARKS - 2
    if valid and data.draw(st.booleans()):  # the counts of the levels this call reads
        level = data.draw(st.integers(0, maps.levels - 1))
        state.level_counts[row, j, level] = data.draw(st.sampled_from(COUNT_SPECIALS))
        state.n_regions[row, j] = data.draw(st.sampled_from(COUNT_SPECIALS))
    corrupted = valid and (
        state.n_regions[row, j] < 0 or any(map(outside_region, state.level_counts[row, j].tolist()))
    )
    if completes(_core.update_levels, maps, row, j, fresh):
        assert 3 <= fresh.size <= kernels.CAPACITY and not corrupted
        assert np.all(state.level_counts[row, j] <= kernels.CAPACITY)


# ----------------------------------------------------------------------------------------
# bind_sim.cpp: the simulator
# ----------------------------------------------------------------------------------------


@st.composite
def obstacle_sets(draw: st.DrawFn) -> tuple[FloatArray, IntArray]:
    """Packed obstacles (vertices (V, 2), starts (k + 1,)) as bearing_env.obstacles packs
    them, of degenerate polygons too, at times with starts past the vertices or out of
    order."""
    shapes = draw(st.lists(polygons(max_size=5), max_size=3))
    vertices = (
        np.zeros((0, 2))
        if not shapes
        else np.concatenate([np.stack([shape.real, shape.imag], axis=1) for shape in shapes])
    )
    starts = np.cumsum([0, *(shape.size for shape in shapes)]).astype(np.int64)
    kind = draw(st.sampled_from(("packed", "packed", "beyond", "reversed", "negative")))
    if kind == "beyond" and starts.size > 1:
        starts[-1] += draw(st.integers(1, 3))
    elif kind == "reversed":
        starts = starts[::-1].copy()
    elif kind == "negative" and starts.size > 1:
        starts[0] = -draw(st.integers(1, 3))
    return np.ascontiguousarray(vertices, dtype=np.float64), starts


@fuzz(values=st.tuples(*(hard_floats for _ in range(9))))
def test_scalar_geometry_of_any_floats(values: tuple[float, ...]) -> None:
    x, y, a, b, c, d, e, f, g = values
    for entry, args in (
        (_core.bearing, (x, y, a, b, c)),
        (_core._edge_entry, (x, y, a, b, c, d, e, f, g)),
        (_core._disc_entry, (x, y, a, b, c, d, e)),
        (_core._cross, (x, y, a, b, c, d)),
        (_core._segment_distance, (x, y, a, b, c, d)),
    ):
        value = result(entry, *args)
        assert isinstance(value, float)
    for predicate, points in (
        (_core.segments_cross, (x, y, a, b, c, d, e, f)),
        (_core._on_segment, (x, y, a, b, c, d)),
    ):
        assert isinstance(result(predicate, *points), bool)
    if moderate(*values):
        assert -math.pi <= _core.bearing(x, y, a, b, c) <= math.pi
        assert math.isfinite(_core._segment_distance(x, y, a, b, c, d))


@fuzz(values=st.tuples(*(hard_floats for _ in range(8))), arena=st.booleans())
def test_straight_move_of_any_pose_and_arena(values: tuple[float, ...], arena: bool) -> None:
    # With `arena`, a real arena and margins, and a hard pose and length.
    args = (*values[:4], 1.0, 0.7, 0.05, 0.02) if arena else values
    move = result(_core.straight_move, *args)
    assert move is not None
    x, y, travelled, blocked = move
    assert all(isinstance(value, float) for value in (x, y, travelled))
    assert isinstance(blocked, bool)
    if arena and all(math.isfinite(value) for value in args):
        assert 0.05 <= x <= 0.95 and 0.05 <= y <= 0.65


def indexes_past(vertices: FloatArray, starts: IntArray) -> bool:
    """Whether some polygon's range first < last of the starts leaves the vertices (an
    empty or reversed range is no polygon)."""
    return any(
        first < last and (first < 0 or last > vertices.shape[0])
        for first, last in zip(starts[:-1].tolist(), starts[1:].tolist(), strict=True)
    )


@fuzz(
    pose=st.tuples(hard_floats, hard_floats, hard_floats, hard_floats),
    move_settings=st.tuples(hard_floats, hard_floats, hard_floats, hard_floats),
    obstacles=obstacle_sets(),
    margin=hard_floats,
)
def test_obstacle_queries_of_any_pose_and_obstacles(
    pose: tuple[float, float, float, float],
    move_settings: tuple[float, float, float, float],
    obstacles: tuple[FloatArray, IntArray],
    margin: float,
) -> None:
    x, y, heading, length = pose
    vertices, starts = obstacles
    move = result(_core.obstructed_move, x, y, heading, length, move_settings, vertices, starts)
    room = result(_core.free_length, x, y, heading, vertices, starts, margin)
    sight = result(_core.line_of_sight, x, y, heading, length, vertices, starts)
    seen = result(_core.visible, x, y, heading, length, margin, x, y, vertices, starts)
    distance = result(_core.clearance, x, y, vertices, starts)
    # Each refuses exactly the starts that index past the vertices.
    past = indexes_past(vertices, starts)
    assert all((outcome is None) == past for outcome in (move, room, sight, seen, distance))
    if not past:
        assert move is not None and isinstance(move[3], bool)
        assert isinstance(room, float) and isinstance(distance, float)
        assert isinstance(sight, bool) and isinstance(seen, bool)
        if finite(vertices) and all(math.isfinite(v) for v in (x, y)) and starts.size > 1:
            assert distance >= 0.0


@fuzz(polygon=polygons(max_size=6), point=st.tuples(hard_floats, hard_floats), data=st.data())
def test_inside_polygon_of_any_range(
    polygon: ComplexArray, point: tuple[float, float], data: st.DataObject
) -> None:
    vertices = np.ascontiguousarray(np.stack([polygon.real, polygon.imag], axis=1))
    first = data.draw(st.one_of(st.integers(-2, polygon.size + 2), st.sampled_from(SPECIAL_INTS)))
    last = data.draw(st.one_of(st.integers(-2, polygon.size + 2), st.sampled_from(SPECIAL_INTS)))
    inside = result(_core.inside_polygon, *point, vertices, first, last)
    if inside is None:
        assert first < last and (first < 0 or last > polygon.size)
    else:
        assert isinstance(inside, bool)


@st.composite
def poses(draw: st.DrawFn) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Landmarks (N, n, 2), positions (N, 2) and headings (N,) of N = 0..3 rows, some
    corrupted."""
    rows, columns = draw(st.integers(0, 3)), draw(st.integers(0, 5))
    rng = np.random.default_rng(draw(SEEDS))
    landmarks = rng.uniform(0.0, 1.0, (rows, columns, 2))
    positions = rng.uniform(0.0, 1.0, (rows, 2))
    headings = rng.uniform(-np.pi, np.pi, rows)
    for array in (landmarks, positions, headings):
        corrupt(draw, array)
    return landmarks, positions, headings


@fuzz(pose=poses(), data=st.data())
def test_bearing_arrays_of_any_poses(
    pose: tuple[FloatArray, FloatArray, FloatArray], data: st.DataObject
) -> None:
    landmarks, positions, headings = pose
    shape = landmarks.shape[:2]
    out_shape = data.draw(st.sampled_from((shape, (shape[0], shape[1] + 1))))
    true = np.zeros(out_shape)
    if completes(_core._true_bearings_into, landmarks, positions, headings, true):
        assert out_shape == shape
        clean = finite(landmarks) and finite(positions) and finite(headings)
        assert not clean or np.all(np.abs(true) <= np.pi)
    offsets = np.zeros(shape)
    corrupt(data.draw, offsets)
    is_outlier = np.array(
        data.draw(st.lists(st.booleans(), min_size=offsets.size, max_size=offsets.size)), dtype=bool
    ).reshape(shape)
    replacement = np.full(shape, 0.5)
    corrupt(data.draw, replacement)
    noisy = np.zeros(out_shape)
    if completes(_core._add_wrapped, true, offsets, noisy):
        assert out_shape == shape
    if completes(_core._add_wrapped_with_outliers, true, offsets, is_outlier, replacement, noisy):
        assert out_shape == shape
        with np.errstate(all="ignore"):
            inputs = np.where(is_outlier, replacement, true + offsets)
        assert np.all(np.abs(noisy[np.isfinite(inputs)]) <= np.pi)


@fuzz(pose=poses(), obstacles=obstacle_sets(), sensor=st.tuples(hard_floats, hard_floats))
def test_visible_rows_of_any_poses_and_obstacles(
    pose: tuple[FloatArray, FloatArray, FloatArray],
    obstacles: tuple[FloatArray, IntArray],
    sensor: tuple[float, float],
) -> None:
    landmarks, positions, headings = pose
    out = np.ones(landmarks.shape[:2], dtype=bool)
    taken = completes(_core.visible_rows, landmarks, positions, headings, *sensor, *obstacles, out)
    assert taken != indexes_past(*obstacles)


# ----------------------------------------------------------------------------------------
# bind_env.cpp: the env step
# ----------------------------------------------------------------------------------------

#: Rows of the fuzzed env states, and their configs: a world with obstacles and every info
#: (the robot map, shape observations), and the relaxed and robust fusions.
ENV_ROWS = 3
WORLDS: dict[str, dict[str, Any]] = {
    "intersect": {
        "scenario": "random", "n_landmarks": 4, "robot_map_info": True,
        "observation": "shapes", "obstacles": {"random": 2, "seed": 7},
    },
    "relaxed": {
        "scenario": "random", "n_landmarks": 4, "fusion": "relaxed", "robot_map_info": True,
    },
    "robust": {"scenario": "random", "n_landmarks": 5, "fusion": "robust"},
}  # fmt: skip


@dataclasses.dataclass(frozen=True)
class World:
    """A started env state, as core.reset_rows and core.step leave it."""

    config: EnvConfig
    state: BatchState
    batch: BatchedPolygonSLAM
    n: int


@functools.cache
def started_world(name: str) -> World:
    config = EnvConfig.create(**WORLDS[name])
    state = BatchState.empty(ENV_ROWS, config.observations.max_landmarks)
    maps = MapBank(ENV_ROWS)
    rows = np.arange(ENV_ROWS)
    rngs = [np.random.default_rng(seed) for seed in range(ENV_ROWS)]
    core.reset_rows(state, rows, config, rngs, maps)
    for actions in np.random.default_rng(1).uniform(-1.0, 1.0, (6, ENV_ROWS, 2)):
        turns, lengths = CONTINUOUS.decode(config, actions)
        core.step(state, maps.group(state, rows, config), turns, lengths)
    n = int(state.n_landmarks[0])
    return World(config, state, maps.batch(n, config), n)


@dataclasses.dataclass
class Fresh:
    """Copies of a world's kernel inputs (a call writes the state and the maps)."""

    settings: Settings
    params: _core.Params
    maps: kernels.State
    state: BatchState


def fresh(name: str) -> Fresh:
    world = started_world(name)
    arrays: dict[str, Any] = {
        field: np.copy(getattr(world.state, field))
        for field in STATE_ARRAYS
        if isinstance(getattr(world.state, field), np.ndarray)
    }
    maps = kernels.State(*(np.copy(getattr(world.batch, field)) for field in kernels.State._fields))
    return Fresh(
        core.kernel_settings(world.n, world.config),
        world.batch._kernel_params(True),
        maps,
        dataclasses.replace(world.state, **arrays),
    )


#: The settings' float fields (the rest: n, n_slots, flags, max_moves, obstacles).
SETTINGS_FLOATS = (
    "width", "height", "margin", "min_baseline", "floor", "cap", "target_area",
    "path_cost", "move_cost", "coordinate_limit", "tolerance", "half_fov", "max_range",
)  # fmt: skip


def corrupt_world(draw: Draw, world: Fresh) -> bool:
    """Special values in some settings and arrays of the env state and its maps (floats,
    and at times counts and cursors); whether anything changed."""
    changed = False
    changes: dict[str, Any] = {
        name: draw(hard_floats)
        for name in draw(st.lists(st.sampled_from(SETTINGS_FLOATS), max_size=3, unique=True))
    }
    if draw(st.integers(0, 4)) == 0:
        n = world.settings.n
        changes["n_slots"] = draw(st.sampled_from((n - 1, n, n + 1, 2**40, 2**62)))
        changes["max_moves"] = draw(hard_ints)
    if changes:
        world.settings = world.settings._replace(**changes)
        changed = True
    if draw(st.integers(0, 4)) == 0:
        vertices, starts = draw(obstacle_sets())
        world.settings = world.settings._replace(obstacle_vertices=vertices, obstacle_starts=starts)
        changed = True
    floats = [
        name
        for name in STATE_ARRAYS
        if isinstance(getattr(world.state, name), np.ndarray)
        and getattr(world.state, name).dtype.kind in "fc"
    ]
    for name in draw(st.lists(st.sampled_from(floats), max_size=4, unique=True)):
        changed = corrupt(draw, getattr(world.state, name)) or changed
    for name in draw(st.lists(st.sampled_from(kernels.State._fields), max_size=3, unique=True)):
        changed = corrupt(draw, getattr(world.maps, name)) or changed
    state_ints = [getattr(world.state, name) for name in STATE_ARRAYS if name not in floats]
    changed = corrupt_counts(draw, [a for a in state_ints if isinstance(a, np.ndarray)]) or changed
    return corrupt_counts(draw, list(world.maps)) or changed


def env_inputs(world: Fresh) -> Any:
    """The world's EnvInputs, or None when its corrupted settings are refused."""
    return result(_core.EnvInputs, world.settings, world.params, world.maps, world.state)


def env_rows(draw: Draw) -> IntArray:
    return draw(map_rows(ENV_ROWS))


def check_report(report: tuple[NDArray[Any], ...], rows: int, inputs: Any) -> None:
    """A report's 16 arrays: kernels.Report's dtypes, `rows` rows."""
    assert len(report) == len(Report._fields)
    assert report[0].shape == (rows, inputs.observation_size) and report[0].dtype == np.float32
    for values in report:
        assert values.shape[0] == rows


@fuzz(name=st.sampled_from(sorted(WORLDS)), with_map=st.booleans(), data=st.data())
def test_step_rows_of_any_state_and_actions(name: str, with_map: bool, data: st.DataObject) -> None:
    world = fresh(name)
    clean = not corrupt_world(data.draw, world)
    inputs = env_inputs(world)
    if inputs is None:
        assert not clean
        return
    report = result(_core.new_report, ENV_ROWS, inputs)
    assert report is not None
    check_report(report, ENV_ROWS, inputs)
    every_row = np.arange(ENV_ROWS, dtype=np.int64)
    encoded = result(_core.encode_map, inputs, every_row, inputs.n) if with_map else None
    outputs = result(_core.StepOutputs, inputs, report, encoded)
    assert outputs is not None and outputs.capacity == ENV_ROWS
    rows = env_rows(data.draw)
    length = data.draw(st.sampled_from((rows.size, rows.size, rows.size + 1)))
    turns = np.array(data.draw(st.lists(hard_floats, min_size=length, max_size=length)))
    lengths = np.array(data.draw(st.lists(hard_floats, min_size=length, max_size=length)))
    threads = data.draw(st.sampled_from((1, 2, 0)))
    trajectory = world.state.trajectory
    status = result(
        _core.step_rows, rows, turns, lengths, inputs, trajectory, threads, outputs, with_map
    )
    if status is not None:
        assert status in (_core.STEP_DONE, _core.STEP_NEEDS_NOISE, _core.STEP_NEEDS_TRAJECTORY)
        if clean and finite(turns) and finite(lengths) and status == _core.STEP_DONE:
            assert finite(report[0][: rows.size])
    # The reset's report of some rows into the same reused arrays.
    rows = env_rows(data.draw)
    if completes(_core.report_rows_into, rows, inputs, outputs, data.draw(st.booleans())):
        assert np.unique(rows).size == rows.size
        assert not clean or finite(report[0][: rows.size])


def test_step_outputs_belong_to_their_group_and_settings() -> None:
    """StepOutputs are checked against the group they were made for: a report shaped for
    other settings, another group's inputs and with_map without the encoded arrays are
    refused, each with its reason."""
    inputs, other = env_inputs(fresh("intersect")), env_inputs(fresh("intersect"))
    every_row = np.arange(ENV_ROWS, dtype=np.int64)
    report = _core.new_report(ENV_ROWS, inputs)
    fewer_columns = tuple(np.ascontiguousarray(a[:, :-1]) if a.ndim == 2 else a for a in report)
    with pytest.raises(ValueError, match=r"report\.observations has axis 1"):
        _core.StepOutputs(inputs, fewer_columns)
    outputs = _core.StepOutputs(inputs, report)
    assert outputs.capacity == ENV_ROWS and not outputs.with_map
    with pytest.raises(ValueError, match="outputs were made for other inputs"):
        _core.report_rows_into(every_row, other, outputs, False)
    with pytest.raises(ValueError, match="with_map needs outputs made with the encoded arrays"):
        _core.report_rows_into(every_row, inputs, outputs, True)
    _core.report_rows_into(every_row, inputs, outputs, False)
    assert np.all(np.isfinite(report[0]))


@fuzz(name=st.sampled_from(sorted(WORLDS)), data=st.data())
def test_reports_and_potentials_of_any_state(name: str, data: st.DataObject) -> None:
    world = fresh(name)
    clean = not corrupt_world(data.draw, world)
    inputs = env_inputs(world)
    if inputs is None:
        return
    rows = env_rows(data.draw)
    size = data.draw(st.integers(-2, 5))
    report = result(_core.new_report, size, inputs)
    if report is not None:
        check_report(report, size, inputs)
    out = np.zeros(out_length(data.draw, rows.size))
    if completes(_core.potentials, rows, inputs, out) and clean:
        assert not np.any(np.isnan(out))


AXES = ("maps", "m", "w", "levels", "h", "base_capacity", "probe_capacity", "N", "slots",
        "values", "rows", "obs")  # fmt: skip


@fuzz(
    schema=st.sampled_from(("State", "BatchState", "Report", "Settings", "Nothing")),
    lengths=st.fixed_dictionaries({axis: st.integers(0, 6) for axis in AXES}),
    changes=st.dictionaries(st.sampled_from((*AXES, "CAPACITY", "other")), st.integers(-3, 6)),
    drop=st.lists(st.sampled_from(AXES), max_size=2),
)
def test_new_arrays_of_any_lengths(
    schema: str, lengths: dict[str, int], changes: dict[str, int], drop: list[str]
) -> None:
    lengths = {axis: n for axis, n in {**lengths, **changes}.items() if axis not in drop}
    arrays = result(_core.new_arrays, schema, lengths)
    if arrays is None:
        return
    fields = _core.SCHEMAS[schema]
    assert len(arrays) == len(fields)
    known = {"CAPACITY": _core.CAPACITY, **lengths}
    for array, (name, dtype, rule, _) in zip(arrays, fields, strict=True):
        shape = tuple(known[a[:-2]] - 2 if a.endswith("-2") else int(a) if a.isdigit() else known[a]
                      for a in rule.split())  # fmt: skip
        assert array.dtype == np.dtype(dtype) and array.shape == shape, name
        assert not array.any(), name


@fuzz(name=st.sampled_from(sorted(WORLDS)), data=st.data())
def test_move_and_read_of_any_move(name: str, data: st.DataObject) -> None:
    world = fresh(name)
    corrupt_world(data.draw, world)
    inputs = env_inputs(world)
    if inputs is None:
        return
    row = data.draw(st.one_of(st.integers(0, ENV_ROWS - 1), hard_ints))
    turn, length = data.draw(hard_floats), data.draw(hard_floats)
    n = inputs.n
    start = np.zeros(data.draw(st.sampled_from((n, n + 2, n - 1, 0))))
    end = np.zeros(data.draw(st.sampled_from((n, n - 1))))
    travelled = result(_core.move_and_read, row, turn, length, inputs, start, end)
    if travelled is not None:
        assert isinstance(travelled, float)


@fuzz(data=st.data())
def test_append_positions_of_any_lengths(data: st.DataObject) -> None:
    world = fresh("intersect")
    rows = env_rows(data.draw)
    positions = world.state.positions
    corrupt(data.draw, positions)
    trajectory = world.state.trajectory
    lengths = world.state.trajectory_length
    capacity = trajectory.shape[1]
    for row in data.draw(st.lists(st.integers(0, ENV_ROWS - 1), max_size=2)):
        lengths[row] = data.draw(st.sampled_from((-1, 0, capacity - 1, capacity, 2**62)))
    before = lengths.copy()
    appended = result(_core.append_positions, rows, positions, trajectory, lengths)
    if appended is not None:
        assert isinstance(appended, bool)
        if appended:
            assert np.array_equal(lengths, before + np.bincount(rows, minlength=ENV_ROWS))
        else:
            assert np.array_equal(lengths, before)


@fuzz(
    area=hard_floats,
    floor=st.one_of(st.just(1e-6), hard_floats),
    cap=st.one_of(st.just(10.0), hard_floats),
    log_area=st.booleans(),
    data=st.data(),
)
def test_potentials_of_any_areas(
    area: float, floor: float, cap: float, log_area: bool, data: st.DataObject
) -> None:
    capped = result(_core.capped, area, floor, cap)
    assert isinstance(capped, float)
    areas = np.array(data.draw(st.lists(hard_floats, max_size=5)))
    n_mapped = data.draw(st.one_of(st.integers(-1, areas.size + 1), st.sampled_from(SPECIAL_INTS)))
    potential = result(_core.potential_of, areas, n_mapped, log_area, floor, cap)
    if potential is None:
        assert n_mapped > areas.size or not -(2**63) <= n_mapped < 2**63
    else:
        assert isinstance(potential, float)
    rows = np.array(data.draw(st.lists(hard_floats, max_size=6)))
    rows = rows[: rows.size // 3 * 3].reshape(-1, 3) if data.draw(st.booleans()) else rows
    out = np.zeros(out_length(data.draw, rows.shape[0]))
    if completes(_core._potentials_of_rows, rows, log_area, floor, cap, out):
        assert rows.ndim == 2 and out.size == rows.shape[0]


@fuzz(vertices=polygons(max_size=8), data=st.data())
def test_write_shape_of_any_region(vertices: ComplexArray, data: st.DataObject) -> None:
    count = data.draw(counts_for(vertices.size))
    slots = data.draw(st.integers(0, 3))
    j = data.draw(st.integers(-1, slots))
    out = np.zeros(3 * slots, dtype=np.float32)
    if completes(_core._write_shape, vertices, count, out, j):
        assert 0 <= j < slots
        clean = finite(vertices[:count]) and np.all(np.abs(vertices[:count]) <= 1e3)
        assert not clean or finite(out)


@fuzz(
    dtype=st.sampled_from((np.float32, np.float64)),
    bounds=st.tuples(st.one_of(st.just(0.05), hard_floats), st.one_of(st.just(0.3), hard_floats)),
    data=st.data(),
)
def test_decode_continuous_of_any_actions(
    dtype: type[np.floating[Any]], bounds: tuple[float, float], data: st.DataObject
) -> None:
    rows = data.draw(st.integers(0, 4))
    values = data.draw(
        st.lists(st.one_of(st.floats(-1.0, 1.0), hard_floats), min_size=2 * rows, max_size=2 * rows)
    )
    with np.errstate(over="ignore"):
        actions = np.array(values, dtype=dtype).reshape(rows, 2)
    turns = np.zeros(out_length(data.draw, rows))
    lengths = np.zeros(rows)
    status = result(_core.decode_continuous, actions, *bounds, turns, lengths)
    if status is None:
        return
    assert status in (_core.ACTIONS_OK, _core.ACTIONS_NOT_FINITE, _core.ACTIONS_OUTSIDE)
    if status == _core.ACTIONS_OK:
        assert finite(actions) and np.all(np.abs(turns) <= np.pi)


@fuzz(value=hard_complexes, start=hard_complexes, data=st.data())
def test_known_and_move_ends_of_any_points(
    value: complex, start: complex, data: st.DataObject
) -> None:
    known = result(_core._known, value)
    assert isinstance(known, complex)
    if math.isnan(value.real) or math.isnan(value.imag):
        assert known == complex(math.inf, math.inf)
    else:
        assert known == value
    headings = np.array(data.draw(st.lists(hard_floats, max_size=4)))
    distances = np.array(
        data.draw(st.lists(hard_floats, min_size=headings.size, max_size=headings.size + 1))
    )
    out = np.zeros(out_length(data.draw, headings.size), dtype=np.complex128)
    if completes(_core._move_ends, start, headings, distances, out):
        assert distances.size == headings.size == out.size


@fuzz(data=st.data())
def test_bearings_of_any_points(data: st.DataObject) -> None:
    size = data.draw(st.integers(0, 5))
    differences = np.array(data.draw(st.lists(hard_complexes, min_size=size, max_size=size)))
    headings = np.array(
        data.draw(st.lists(hard_floats, min_size=size, max_size=size + 1)), dtype=np.float64
    )
    out = np.zeros(out_length(data.draw, size))
    if completes(_core._bearings_of, differences.astype(np.complex128), headings, out):
        angles = out[np.isfinite(differences) & np.isfinite(headings)]
        assert np.all((-np.pi <= angles) & (angles < np.pi))


@fuzz(fusion=st.sampled_from(FUSIONS), data=st.data())
def test_simulate_potentials_of_any_state(fusion: str, data: st.DataObject) -> None:
    state = state_copy(fusion)
    corrupt_state(data.draw, state)
    maps = result(_core.MapState, state)
    trials = _core.MapState(state_copy(fusion))
    if maps is None:
        return
    count = data.draw(st.integers(0, MAPS + 1))
    landmarks = np.array(
        data.draw(st.lists(hard_complexes, min_size=LANDMARKS, max_size=LANDMARKS + 1)),
        dtype=np.complex128,
    )
    headings = np.array(data.draw(st.lists(hard_floats, min_size=count, max_size=count)))
    distances = np.array(data.draw(st.lists(hard_floats, min_size=count, max_size=count)))
    out = np.zeros(out_length(data.draw, count))
    row = data.draw(st.one_of(st.integers(0, MAPS - 1), hard_ints))
    moving = data.draw(map_rows(max(count, 1)))[:count]
    readings = data.draw(bearings(moving.size, LANDMARKS))
    if completes(
        _core._score_readings, maps, row, params_of(fusion), moving, readings, readings.copy(),
        4.0, 1e-3, data.draw(st.booleans()), trials, np.zeros(out_length(data.draw, count)),
    ):  # fmt: skip
        assert np.unique(moving).size == moving.size
    rows = data.draw(map_rows(MAPS))
    start = data.draw(bearings(rows.size, LANDMARKS))
    scores = np.zeros(out_length(data.draw, rows.size))
    if completes(
        _core._score_rows, maps, rows, params_of(fusion), start, start.copy(), 4.0, 1e-3,
        data.draw(st.booleans()), trials, scores, data.draw(st.sampled_from((1, 2, 0))),
    ):  # fmt: skip
        assert scores.size >= rows.size
    if completes(
        _core._simulate_potentials, maps, row, params_of(fusion), data.draw(hard_complexes),
        landmarks, headings.astype(np.float64), distances.astype(np.float64), 1e-9, 4.0, 1e-3,
        data.draw(st.booleans()), trials, out,
    ):  # fmt: skip
        assert out.size == count


def map_state_forms(world: Fresh, inputs: Any) -> dict[str, Any]:
    """The forms the codec takes a map state in: MapState, State, a batch, EnvInputs."""
    forms: dict[str, Any] = {
        "tuple": world.maps,
        "batch": SimpleNamespace(**world.maps._asdict()),
        "map_state": _core.MapState(world.maps),
    }
    if inputs is not None:
        forms["inputs"] = inputs
    return forms


@fuzz(
    name=st.sampled_from(sorted(WORLDS)),
    form=st.sampled_from(("tuple", "batch", "map_state", "inputs")),
    data=st.data(),
)
def test_robot_map_codec_of_any_state(name: str, form: str, data: st.DataObject) -> None:
    world = fresh(name)
    corrupt_world(data.draw, world)
    inputs = env_inputs(world)
    state = map_state_forms(world, inputs).get(form, world.maps)
    rows = data.draw(map_rows(ENV_ROWS))
    m = world.maps.counts.shape[1]
    slots = data.draw(st.integers(m - 1, m + 2))
    encoded = result(_core.encode_map, state, rows, slots)
    if encoded is not None:
        assert len(encoded) == 12 and encoded[0].shape == (rows.size, slots, kernels.CAPACITY)
        for values in encoded:
            assert values.shape[0] == rows.size
        into_rows = data.draw(st.sampled_from((rows, rows[:-1], np.zeros(0, dtype=np.int64))))
        # encoded must have a row per row, no rows included (an expected length of 0 is
        # 0, not any length).
        into = completes(_core.encode_map_into, state, into_rows, encoded)
        assert into == (into_rows.size == rows.size)
    window = result(_core.encode_window, state, rows, slots)
    if window is not None:
        assert len(window) == 10 and all(values.shape[0] == rows.size for values in window)
    levels = result(_core.encode_levels, state, rows, slots)
    if levels is not None:
        assert len(levels) == 13 and all(values.shape[0] == rows.size for values in levels)


# ----------------------------------------------------------------------------------------
# Bad arguments: TypeError or ValueError naming the argument
# ----------------------------------------------------------------------------------------


def square() -> ComplexArray:
    return np.array([0.0, 1.0, 1.0 + 1.0j, 1.0j], dtype=np.complex128)


def geometry_arguments(entry: str) -> dict[str, Any]:
    """Valid keyword arguments of a polygon or frame kernel."""
    a1 = np.array([2.0 + 0.0j, 3.0 + 0.0j, 3.0 + 1.0j], dtype=np.complex128)
    a2 = np.array([-3.0 + 0.0j, -2.0 + 0.0j, -2.0 + 1.0j], dtype=np.complex128)
    h1 = np.zeros(kernels.MAX_PAIRS, dtype=np.complex128)
    inv_d = np.zeros(kernels.MAX_PAIRS, dtype=np.complex128)
    pairs = _core.sample_hypotheses(a1, 3, a2, 3, 2, h1, inv_d)
    frame = kernels.FrameChange(a1, 3, a2, 3, h1, inv_d, pairs, True, 5.0, 0.5, 0.5)
    scratch = kernels.SCRATCH
    arguments: dict[str, dict[str, Any]] = {
        "convex_hull": {"points": square(), "n_points": 4, "out": np.zeros(5, dtype=np.complex128)},
        "small_hull_indices": {
            "points": square(),
            "n_points": 4,
            "out": np.zeros(5, dtype=np.int64),
            "tol": 0.0,
        },
        "clip_convex": {
            "subject": square(),
            "n_subject": 4,
            "clipper": square() + 0.5,
            "n_clipper": 4,
            "out": np.zeros(scratch, dtype=np.complex128),
            "work": np.zeros(scratch, dtype=np.complex128),
        },
        "simplify": {"poly": square(), "n": 4, "tol": 1e-12},
        "offset_outward": {
            "poly": square(),
            "n": 4,
            "radius": 0.1,
            "out": np.zeros(7, dtype=np.complex128),
        },
        "cone_region": {
            "a": 0.5,
            "b": 1.5,
            "epsilon": 0.05,
            "out": np.zeros(4, dtype=np.complex128),
        },
        "sample_hypotheses": {
            "a1": a1,
            "n1": 3,
            "a2": a2,
            "n2": 3,
            "per_edge": 2,
            "h1": np.zeros(kernels.MAX_PAIRS, dtype=np.complex128),
            "inv_d": np.zeros(kernels.MAX_PAIRS, dtype=np.complex128),
        },
        "transfer_region": {
            "target": square(),
            "n_target": 4,
            "frame": frame,
            "cloud": np.zeros(kernels.MAX_CLOUD, dtype=np.complex128),
            "hull": np.zeros(kernels.MAX_CLOUD + 1, dtype=np.complex128),
            "out": np.zeros(scratch, dtype=np.complex128),
        },
    }
    return arguments[entry]


def update_arguments(entry: str) -> dict[str, Any]:
    """Valid keyword arguments of the map update's entry points."""
    state = state_copy("relaxed" if entry == "relaxed_region" else "robust")
    rows = np.arange(2, dtype=np.int64)
    start = np.random.default_rng(3).uniform(-np.pi, np.pi, (2, LANDMARKS))
    arguments: dict[str, dict[str, Any]] = {
        "MapState": {"state": state},
        "update_maps": {
            "bearings_start": start,
            "bearings_end": start[:, ::-1].copy(),
            "rows": rows,
            "params": params_of("robust"),
            "state": _core.MapState(state),
            "out": kernels.Outputs(
                np.zeros(2, dtype=np.int8),
                np.zeros((2, LANDMARKS - 2), dtype=np.int8),
                np.zeros(2, dtype=np.int64),
            ),
        },
        "copy_maps": {
            "from_state": _core.MapState(state),
            "rows": rows,
            "to_state": _core.MapState(state_copy("robust")),
        },
        "check_indices": {"indices": rows, "size": 4, "distinct": True},
        "none_infinite": {"values": start.reshape(-1)},
        "contains_points": {
            "vertices": state.vertices,
            "counts": state.counts,
            "rows": rows,
            "points": np.zeros((2, LANDMARKS - 2), dtype=np.complex128),
            "relative": 1e-9,
            "out": np.zeros((2, LANDMARKS - 2), dtype=bool),
        },
        "relaxed_region": {
            "state": _core.MapState(state),
            "row": 0,
            "j": 0,
            "slots": np.arange(2, dtype=np.int64),
            "use_base": True,
            "max_outliers": 1,
            "out": np.zeros(kernels.SCRATCH, dtype=np.complex128),
        },
        "update_levels": {
            "state": _core.MapState(state),
            "row": 0,
            "j": 0,
            "fresh": square(),
        },
    }
    return arguments[entry]


def sim_arguments(entry: str) -> dict[str, Any]:
    """Valid keyword arguments of the simulator's array kernels."""
    rng = np.random.default_rng(5)
    landmarks, positions, headings = (
        rng.uniform(0, 1, (2, 3, 2)),
        rng.uniform(0, 1, (2, 2)),
        rng.uniform(-3, 3, 2),
    )
    vertices = np.array([[0.2, 0.2], [0.4, 0.2], [0.4, 0.4]])
    starts = np.array([0, 3], dtype=np.int64)
    arguments: dict[str, dict[str, Any]] = {
        "_add_wrapped": {
            "true_bearings": rng.uniform(-3, 3, (2, 3)),
            "offsets": np.zeros((2, 3)),
            "out": np.zeros((2, 3)),
        },
        "_add_wrapped_with_outliers": {
            "true_bearings": rng.uniform(-3, 3, (2, 3)),
            "offsets": np.zeros((2, 3)),
            "is_outlier": np.zeros((2, 3), dtype=bool),
            "replacement": np.zeros((2, 3)),
            "out": np.zeros((2, 3)),
        },
        "_true_bearings_into": {
            "landmarks": landmarks,
            "positions": positions,
            "headings": headings,
            "out": np.zeros((2, 3)),
        },
        "free_length": {
            "x": 0.5,
            "y": 0.5,
            "heading": 0.0,
            "vertices": vertices,
            "starts": starts,
            "margin": 0.05,
        },
        "obstructed_move": {
            "x": 0.5,
            "y": 0.5,
            "heading": 0.0,
            "length": 0.2,
            "settings": (1.0, 0.7, 0.05, 0.02),
            "vertices": vertices,
            "starts": starts,
        },
        "inside_polygon": {"x": 0.3, "y": 0.3, "vertices": vertices, "first": 0, "last": 3},
        "visible_rows": {
            "landmarks": landmarks,
            "positions": positions,
            "headings": headings,
            "half_fov": 1.0,
            "max_range": 2.0,
            "vertices": vertices,
            "starts": starts,
            "out": np.zeros((2, 3), dtype=bool),
        },
    }
    return arguments[entry]


def env_arguments(entry: str) -> dict[str, Any]:
    """Valid keyword arguments of the env step's entry points."""
    world = fresh("intersect")
    inputs = _core.EnvInputs(world.settings, world.params, world.maps, world.state)
    rows = np.arange(2, dtype=np.int64)
    report = Report._make(_core.new_report(ENV_ROWS, inputs))
    encoded = _core.encode_map(inputs, np.arange(ENV_ROWS, dtype=np.int64), inputs.n)
    arguments: dict[str, dict[str, Any]] = {
        "EnvInputs": {
            "settings": world.settings,
            "params": world.params,
            "maps": world.maps,
            "state": world.state,
        },
        "StepOutputs": {"inputs": inputs, "report": report, "encoded": encoded},
        "step_rows": {
            "rows": rows,
            "turns": np.zeros(2),
            "lengths": np.full(2, 0.1),
            "inputs": inputs,
            "trajectory": world.state.trajectory,
            "threads": 1,
            "outputs": _core.StepOutputs(inputs, report, encoded),
            "with_map": True,
        },
        "report_rows_into": {
            "rows": rows,
            "inputs": inputs,
            "outputs": _core.StepOutputs(inputs, report, encoded),
            "with_map": True,
        },
        "potentials": {"rows": rows, "inputs": inputs, "out": np.zeros(2)},
        "move_and_read": {
            "row": 0,
            "turn": 0.1,
            "length": 0.1,
            "inputs": inputs,
            "reading_start": np.zeros(inputs.n),
            "reading_end": np.zeros(inputs.n),
        },
        "append_positions": {
            "rows": rows,
            "positions": world.state.positions,
            "trajectory": world.state.trajectory,
            "lengths": world.state.trajectory_length,
        },
        "potential_of": {
            "areas": np.ones(3),
            "n_mapped": 3,
            "log_area": True,
            "floor": 1e-6,
            "cap": 10.0,
        },
        "_write_shape": {
            "vertices": square(),
            "count": 4,
            "out": np.zeros(6, dtype=np.float32),
            "j": 1,
        },
        "decode_continuous": {
            "actions": np.zeros((2, 2)),
            "lo": 0.05,
            "hi": 0.3,
            "turns": np.zeros(2),
            "lengths": np.zeros(2),
        },
        "encode_map": {"state": world.maps, "rows": rows, "slots": inputs.n},
        "encode_map_into": {
            "state": world.maps,
            "rows": np.arange(ENV_ROWS, dtype=np.int64),
            "encoded": encoded,
        },
        "_potentials_of_rows": {
            "rows": np.ones((2, 3)),
            "log_area": True,
            "floor": 1e-6,
            "cap": 10.0,
            "out": np.zeros(2),
        },
        "_move_ends": {
            "start": 0.5 + 0.5j,
            "headings": np.zeros(2),
            "distances": np.ones(2),
            "out": np.zeros(2, dtype=np.complex128),
        },
    }
    return arguments[entry]


ARGUMENTS: dict[str, Callable[[str], dict[str, Any]]] = {
    "geometry": geometry_arguments,
    "update": update_arguments,
    "sim": sim_arguments,
    "env": env_arguments,
}

#: Another dtype of the same shape, for each dtype the bindings take.
OTHER_DTYPE: dict[str, Any] = {
    "complex128": np.float64,
    "float64": np.float32,
    "float32": np.float64,
    "int64": np.int32,
    "int8": np.int16,
    "bool": np.uint8,
}


def spoiled(value: Any, how: str) -> Any:
    """`value` (an array) made bad: another dtype, one more dimension, a strided view of
    the same shape, read-only, one element short on its first axis, or a list."""
    if how == "dtype":
        return np.zeros(value.shape, dtype=OTHER_DTYPE[value.dtype.name])
    if how == "ndim":
        return value[np.newaxis]
    if how == "strided":
        doubled = np.repeat(value, 2, axis=-1)
        return doubled[..., ::2]
    if how == "read_only":
        copy = value.copy()
        copy.flags.writeable = False
        return copy
    if how == "short":
        return value[:-1].copy()
    assert how == "list"
    return value.tolist()


def with_spoiled(arguments: dict[str, Any], path: str, how: str) -> dict[str, Any]:
    """The arguments with the array at `path` spoiled: an argument, or a field of one
    (`out.frame_status`: a field of a namedtuple, a dataclass or an object)."""
    name, _, field = path.partition(".")
    if not field:
        return {**arguments, name: spoiled(arguments[name], how)}
    holder = arguments[name]
    bad = spoiled(getattr(holder, field), how)
    if hasattr(holder, "_replace"):
        replaced = holder._replace(**{field: bad})
    elif dataclasses.is_dataclass(holder) and not isinstance(holder, type):
        replaced = dataclasses.replace(holder, **{field: bad})
    else:
        replaced = SimpleNamespace(**{**vars(holder), field: bad})
    return {**arguments, name: replaced}


#: (binding file, entry point, argument path, how it is spoiled, the exception, the name
#: the message must give). Read-only cases are outputs the kernel writes.
BAD_ARGUMENTS: list[tuple[str, str, str, str, type[Exception], str]] = [
    # bind_slam_geometry.cpp
    ("geometry", "convex_hull", "points", "dtype", TypeError, "points"),
    ("geometry", "convex_hull", "points", "ndim", ValueError, "points"),
    ("geometry", "convex_hull", "points", "strided", ValueError, "points"),
    ("geometry", "convex_hull", "points", "list", TypeError, "points"),
    ("geometry", "convex_hull", "out", "read_only", ValueError, "out"),
    ("geometry", "convex_hull", "out", "short", ValueError, "out"),
    ("geometry", "small_hull_indices", "out", "dtype", TypeError, "out"),
    ("geometry", "clip_convex", "clipper", "strided", ValueError, "clipper"),
    ("geometry", "clip_convex", "work", "read_only", ValueError, "work"),
    ("geometry", "clip_convex", "out", "short", ValueError, "out"),
    ("geometry", "simplify", "poly", "read_only", ValueError, "poly"),
    ("geometry", "offset_outward", "out", "short", ValueError, "out"),
    ("geometry", "cone_region", "out", "dtype", TypeError, "out"),
    ("geometry", "cone_region", "out", "short", ValueError, "out"),
    ("geometry", "sample_hypotheses", "a2", "ndim", ValueError, "a2"),
    ("geometry", "sample_hypotheses", "inv_d", "strided", ValueError, "inv_d"),
    ("geometry", "sample_hypotheses", "h1", "read_only", ValueError, "h1"),
    ("geometry", "transfer_region", "frame.h1", "dtype", TypeError, "frame.h1"),
    ("geometry", "transfer_region", "frame.a1", "strided", ValueError, "frame.a1"),
    ("geometry", "transfer_region", "cloud", "dtype", TypeError, "cloud"),
    ("geometry", "transfer_region", "hull", "read_only", ValueError, "hull"),
    ("geometry", "transfer_region", "out", "short", ValueError, "out"),
    # bind_slam.cpp
    ("update", "MapState", "state.counts", "dtype", TypeError, "state.counts"),
    ("update", "MapState", "state.vertices", "strided", ValueError, "state.vertices"),
    ("update", "MapState", "state.window_inlier", "ndim", ValueError, "state.window_inlier"),
    ("update", "MapState", "state.areas", "short", ValueError, "state.areas"),
    ("update", "update_maps", "bearings_start", "dtype", TypeError, "bearings_start"),
    ("update", "update_maps", "bearings_end", "strided", ValueError, "bearings_end"),
    ("update", "update_maps", "bearings_end", "short", ValueError, "bearings_end"),
    ("update", "update_maps", "rows", "dtype", TypeError, "rows"),
    ("update", "update_maps", "out.frame_status", "read_only", ValueError, "out.frame_status"),
    ("update", "update_maps", "out.landmark_status", "dtype", TypeError, "out.landmark_status"),
    ("update", "update_maps", "out.n_bad", "short", ValueError, "out.n_bad"),
    ("update", "copy_maps", "rows", "dtype", TypeError, "rows"),
    ("update", "check_indices", "indices", "dtype", TypeError, "indices"),
    ("update", "check_indices", "indices", "ndim", ValueError, "indices"),
    ("update", "none_infinite", "values", "dtype", TypeError, "values"),
    ("update", "none_infinite", "values", "strided", ValueError, "values"),
    ("update", "contains_points", "points", "short", ValueError, "points"),
    ("update", "contains_points", "counts", "dtype", TypeError, "counts"),
    ("update", "contains_points", "out", "read_only", ValueError, "out"),
    ("update", "relaxed_region", "slots", "dtype", TypeError, "slots"),
    ("update", "relaxed_region", "out", "read_only", ValueError, "out"),
    ("update", "update_levels", "fresh", "strided", ValueError, "fresh"),
    ("update", "update_levels", "fresh", "dtype", TypeError, "fresh"),
    # bind_sim.cpp
    ("sim", "_add_wrapped", "offsets", "short", ValueError, "offsets"),
    ("sim", "_add_wrapped", "out", "read_only", ValueError, "out"),
    ("sim", "_add_wrapped_with_outliers", "is_outlier", "dtype", TypeError, "is_outlier"),
    ("sim", "_add_wrapped_with_outliers", "replacement", "strided", ValueError, "replacement"),
    ("sim", "_true_bearings_into", "positions", "short", ValueError, "positions"),
    ("sim", "_true_bearings_into", "landmarks", "ndim", ValueError, "landmarks"),
    ("sim", "free_length", "vertices", "strided", ValueError, "vertices"),
    ("sim", "free_length", "starts", "dtype", TypeError, "starts"),
    ("sim", "obstructed_move", "vertices", "list", TypeError, "vertices"),
    ("sim", "inside_polygon", "vertices", "dtype", TypeError, "vertices"),
    ("sim", "visible_rows", "headings", "short", ValueError, "headings"),
    ("sim", "visible_rows", "out", "read_only", ValueError, "out"),
    ("sim", "visible_rows", "out", "dtype", TypeError, "out"),
    # bind_env.cpp
    ("env", "EnvInputs", "settings.obstacle_vertices", "dtype", TypeError, "obstacle_vertices"),
    ("env", "EnvInputs", "state.positions", "strided", ValueError, "positions"),
    ("env", "EnvInputs", "state.noise_used", "dtype", TypeError, "noise_used"),
    ("env", "EnvInputs", "state.headings", "read_only", ValueError, "headings"),
    ("env", "EnvInputs", "maps.counts", "short", ValueError, "maps.counts"),
    ("env", "StepOutputs", "report.rewards", "dtype", TypeError, "report.rewards"),
    ("env", "StepOutputs", "report.observations", "read_only", ValueError, "report.observations"),
    ("env", "step_rows", "turns", "dtype", TypeError, "turns"),
    ("env", "step_rows", "lengths", "short", ValueError, "lengths"),
    ("env", "step_rows", "trajectory", "read_only", ValueError, "trajectory"),
    ("env", "step_rows", "rows", "strided", ValueError, "rows"),
    ("env", "report_rows_into", "rows", "dtype", TypeError, "rows"),
    ("env", "potentials", "out", "read_only", ValueError, "out"),
    ("env", "move_and_read", "reading_start", "dtype", TypeError, "reading_start"),
    ("env", "move_and_read", "reading_end", "read_only", ValueError, "reading_end"),
    ("env", "append_positions", "lengths", "read_only", ValueError, "lengths"),
    ("env", "append_positions", "positions", "short", ValueError, "positions"),
    ("env", "potential_of", "areas", "dtype", TypeError, "areas"),
    ("env", "_write_shape", "out", "dtype", TypeError, "out"),
    ("env", "decode_continuous", "turns", "read_only", ValueError, "turns"),
    ("env", "decode_continuous", "actions", "strided", ValueError, "actions"),
    ("env", "encode_map", "rows", "dtype", TypeError, "rows"),
    ("env", "encode_map", "state.vertices", "dtype", TypeError, "maps.vertices"),
    ("env", "_potentials_of_rows", "rows", "ndim", ValueError, "rows"),
    ("env", "_move_ends", "out", "read_only", ValueError, "out"),
    ("env", "_move_ends", "distances", "short", ValueError, "distances"),
]  # fmt: skip


@pytest.mark.parametrize(
    ("part", "entry", "path", "how", "error", "named"),
    BAD_ARGUMENTS,
    ids=[f"{entry}-{path}-{how}" for _, entry, path, how, _, _ in BAD_ARGUMENTS],
)
def test_a_bad_array_argument_raises_an_error_naming_it(
    part: str, entry: str, path: str, how: str, error: type[Exception], named: str
) -> None:
    arguments = ARGUMENTS[part](entry)
    function = getattr(_core, entry)
    function(**arguments)  # the valid arguments are taken
    bad = with_spoiled(ARGUMENTS[part](entry), path, how)
    with pytest.raises(error, match=rf"(?<![\w.]){re.escape(named)}\b"):
        function(**bad)


def test_the_bad_argument_table_covers_every_binding_file() -> None:
    assert {part for part, *_ in BAD_ARGUMENTS} == set(ARGUMENTS)
    for part in ARGUMENTS:
        kinds = {how for row_part, _, _, how, _, _ in BAD_ARGUMENTS if row_part == part}
        assert {"dtype", "ndim", "short", "strided", "read_only"} <= kinds, part


# ----------------------------------------------------------------------------------------
# Coverage
# ----------------------------------------------------------------------------------------


def stub_private_functions() -> set[str]:
    """The underscore functions the stub declares (kernels bound for the Python modules)."""
    tree = ast.parse(STUB.read_text(encoding="utf-8"))
    return {
        node.name
        for node in tree.body
        if isinstance(node, ast.FunctionDef) and node.name.startswith("_")
    }


def test_every_entry_point_of_the_native_core_is_fuzzed() -> None:
    public = {
        name
        for name in dir(_core)
        if not name.startswith("_")
        and callable(getattr(_core, name))
        # CapacityError is what a call raises, and the codes' enums are values, not
        # something to call.
        and not (
            isinstance(getattr(_core, name), type)
            and issubclass(getattr(_core, name), BaseException | enum.Enum)
        )
    }
    private = stub_private_functions()
    assert private <= set(dir(_core))
    assert sorted(FUZZED - (public | private)) == []
    assert sorted((public | private) - FUZZED) == []


def test_every_fuzzed_entry_point_is_called_by_this_module() -> None:
    source = Path(__file__).read_text(encoding="utf-8")
    called = set(re.findall(r"_core\.(\w+)", source))
    assert sorted(FUZZED - called) == []


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(FUZZ_BODIES))
def test_a_longer_fuzz(name: str) -> None:
    body, strategies = FUZZ_BODIES[name]
    SLOW(given(**strategies)(body))()


def test_every_fuzzed_entry_point_got_past_its_checks() -> None:
    """The fuzz reaches the kernels, not only the argument checks: each entry point called
    in this session (by the tests above, whichever ran) returned on some example."""
    assert sorted(name for name in CALLS if RETURNS[name] == 0) == []
