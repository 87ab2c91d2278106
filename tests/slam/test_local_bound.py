"""The conservative transfer's local bound (docs/world_model.md, "The local bound"),
checked step by step against its proof.

Each lemma is checked on its own in numpy (Lemma 1, the exact sagitta of the arc a
segment's inverse traces, and Lemma 2, the angle a segment subtends from afar); then
the native bound of one sub-square (``kernels.sub_square_growths``) against an
independent numpy evaluation of the page's formulas and against dense images of the
sub-square; then each condition the proof needs; and last the whole transfer
(``transfer_vertices``) against dense references and the exact transferred set. Every
draw comes from an explicitly seeded generator; larger budgets are marked ``slow``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
from numpy.typing import NDArray

from bearing_env.benchmarks.transfer_tightness import exact_member, reference_hull
from bearing_env.slam import kernels
from bearing_env.slam.geometry import FR_BOUNDED, cone_region
from bearing_env.slam.transfer import transfer_vertices

ComplexArray = NDArray[np.complex128]
FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: What the kernels make of a factor whose condition fails (local_bound.hpp's
#: INVALID_FACTOR); any sigma at or above HUGE comes from one.
INVALID_FACTOR = 1e300
HUGE = 1e290
#: Relative agreement between the native sigma and the numpy one (both in doubles, the
#: same formulas, different operation orders).
AGREEMENT = 1e-11
#: The rounding margin the transfers add to their radius: 1e-9 * (1 + V1 / D), and for
#: the local bound also 1e-13 * (M / D) * (1 + V1 / D), M the largest vertex modulus of
#: A_L1 and A_L2.
MARGIN = 1e-9
SAMPLES_MARGIN = 1e-13


# ----------------------------------------------------------------------------------------
# Plane geometry in numpy
# ----------------------------------------------------------------------------------------


def cross(u: ComplexArray, v: ComplexArray) -> FloatArray:
    return np.asarray((np.conj(u) * v).imag)


def dot(u: ComplexArray, v: ComplexArray) -> FloatArray:
    return np.asarray((np.conj(u) * v).real)


def segment_distance(p: ComplexArray, a: ComplexArray, b: ComplexArray) -> FloatArray:
    """Distance from each point p to the segment [a, b] (broadcast)."""
    along = b - a
    squared = np.abs(along) ** 2
    t = np.where(squared > 0.0, dot(along, p - a) / np.where(squared > 0.0, squared, 1.0), 0.0)
    return np.asarray(np.abs(p - (a + np.clip(t, 0.0, 1.0) * along)))


def segment_gap(a: ComplexArray, b: ComplexArray, c: ComplexArray, d: ComplexArray) -> FloatArray:
    """Distance between the disjoint segments [a, b] and [c, d]: attained at an end."""
    return np.minimum(
        np.minimum(segment_distance(a, c, d), segment_distance(b, c, d)),
        np.minimum(segment_distance(c, a, b), segment_distance(d, a, b)),
    )


def hull4_distance(points: ComplexArray, corners: ComplexArray) -> FloatArray:
    """Distance from points (..., N) to the convex hull of corners (..., 4).

    A point of the hull of four points lies in one of their four triangles (Caratheodory);
    outside it, its nearest hull point is on a hull edge, one of the six segments between
    the corners (the other segments lie inside the hull, no nearer)."""
    p = points
    q = [corners[..., k : k + 1] for k in range(4)]
    nearest = np.full(p.shape, np.inf)
    for i in range(4):
        for j in range(i + 1, 4):
            nearest = np.minimum(nearest, segment_distance(p, q[i], q[j]))
    inside = np.zeros(p.shape, dtype=bool)
    for i, j, k in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
        a, b, c = q[i], q[j], q[k]
        turn = np.sign(cross(b - a, c - a))
        inside |= (
            (turn != 0.0)
            & (turn * cross(b - a, p - a) >= 0.0)
            & (turn * cross(c - b, p - b) >= 0.0)
            & (turn * cross(a - c, p - c) >= 0.0)
        )
    return np.where(inside, 0.0, nearest)


def depth(region: ComplexArray, points: ComplexArray) -> FloatArray:
    """Signed distance of each point inside the convex CCW region: the smallest over its
    edges' lines (positive inside, negative outside)."""
    edge = np.roll(region, -1) - region
    edge, start = edge[np.abs(edge) > 0.0], region[np.abs(edge) > 0.0]
    offsets = points[..., None] - start
    return np.asarray((cross(edge, offsets) / np.abs(edge)).min(axis=-1))


def area(region: ComplexArray) -> float:
    """Shoelace area, about the first vertex (tiny regions far from 0 keep their digits)."""
    shifted = region - region[0]
    return float(0.5 * cross(shifted, np.roll(shifted, -1)).sum())


def on_circle(rng: np.random.Generator, n: int, centre: complex, radius: float) -> ComplexArray:
    """A convex CCW polygon of n vertices on a circle (a point for n = 1, a segment for 2)."""
    while True:
        angles = np.sort(rng.uniform(0.0, 2.0 * math.pi, n))
        gaps = np.diff(np.append(angles, angles[0] + 2.0 * math.pi))
        if n < 3 or gaps.max() < math.pi - 0.2:  # the centre strictly inside
            return np.ascontiguousarray(centre + radius * np.exp(1j * angles))


# ----------------------------------------------------------------------------------------
# Movements
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Movement:
    """One movement's FR regions (CCW complex vertices) of a target and of L1 and L2,
    and frame_plan's (per_edge, D, delta1, delta2) for the conservative transfer."""

    target: ComplexArray
    a1: ComplexArray
    a2: ComplexArray
    edge_samples: int
    per_edge: int
    distance: float
    delta1: float
    delta2: float

    @property
    def v1(self) -> float:
        return float(np.abs(self.target[:, None] - self.a1[None, :]).max())

    @property
    def v2(self) -> float:
        return float(np.abs(self.target[:, None] - self.a2[None, :]).max())

    @property
    def global_radius(self) -> float:
        """The bound of transfer="conservative_global", from frame_plan's figures."""
        return (self.v2 * self.delta1**2 + self.v1 * self.delta2**2) / (4.0 * self.distance**3)

    @property
    def margin(self) -> float:
        """The margin of transfer="conservative_global"."""
        return MARGIN * (1.0 + self.v1 / self.distance)

    @property
    def local_margin(self) -> float:
        """The margin of transfer="conservative": also the samples' rounding."""
        largest = float(np.abs(np.concatenate([self.a1, self.a2])).max())
        return self.margin + SAMPLES_MARGIN * (largest / self.distance) * (
            1.0 + self.v1 / self.distance
        )


def planned(
    target: ComplexArray, a1: ComplexArray, a2: ComplexArray, edge_samples: int
) -> Movement | None:
    """The movement, or None if frame_plan refuses it (overlap, too close)."""
    status, per_edge, distance, delta1, delta2 = kernels.frame_plan(
        a1, a1.size, a2, a2.size, True, edge_samples
    )
    if status != kernels.FRAME_OK:
        return None
    return Movement(target, a1, a2, edge_samples, per_edge, distance, delta1, delta2)


def fr_region(rng: np.random.Generator, point: complex, epsilon: float) -> ComplexArray | None:
    """The cone region of a landmark at FR point ``point`` read with noise within
    +-epsilon, as the update makes it; None if unbounded."""
    start = np.angle(point) + rng.uniform(-epsilon, epsilon)
    end = np.angle(point - 1.0) + rng.uniform(-epsilon, epsilon)
    vertices, status = cone_region(start, end, epsilon)
    return np.ascontiguousarray(vertices) if status == FR_BOUNDED else None


def landmark_point(rng: np.random.Generator) -> complex:
    """An FR landmark position off the baseline's line (R1 = 0, R2 = 1)."""
    return complex(rng.uniform(-2.5, 3.5), rng.choice([-1.0, 1.0]) * rng.uniform(0.4, 3.0))


def cone_movement(rng: np.random.Generator) -> Movement | None:
    """A movement whose regions are cone regions of three landmarks (epsilon 0.5 to 6
    degrees, 1 to 8 samples per edge asked for)."""
    epsilon = math.radians(rng.uniform(0.5, 6.0))
    regions = [fr_region(rng, landmark_point(rng), epsilon) for _ in range(3)]
    if any(r is None for r in regions):
        return None
    target, a1, a2 = regions
    assert target is not None and a1 is not None and a2 is not None
    return planned(target, a1, a2, int(rng.integers(1, kernels.MAX_EDGE_SAMPLES + 1)))


def polygon_movement(rng: np.random.Generator) -> Movement | None:
    """A movement of general small convex polygons: L1's and L2's of 1 to 4 vertices,
    the target's of 1 to 6, at random sizes and places."""
    turn = np.exp(1j * rng.uniform(-math.pi, math.pi))
    apart = rng.uniform(0.3, 3.0)
    a1 = on_circle(rng, int(rng.integers(1, 5)), -0.5 * apart * turn, rng.uniform(0.02, 1.0))
    centre2 = (0.5 * apart + rng.uniform(-0.2, 1.0)) * turn
    a2 = on_circle(rng, int(rng.integers(1, 5)), centre2, rng.uniform(0.02, 1.0))
    centre = complex(*rng.uniform(-3.0, 3.0, 2))
    target = on_circle(rng, int(rng.integers(1, 7)), centre, rng.uniform(0.0, 1.0))
    return planned(target, a1, a2, int(rng.integers(1, kernels.MAX_EDGE_SAMPLES + 1)))


def movements(seed: int, count: int) -> list[Movement]:
    """``count`` accepted movements, cone and polygon ones alternately."""
    rng = np.random.default_rng(seed)
    found: list[Movement] = []
    while len(found) < count:
        draw = cone_movement if len(found) % 2 == 0 else polygon_movement
        movement = draw(rng)
        if movement is not None:
            found.append(movement)
    return found


# ----------------------------------------------------------------------------------------
# The bound's pieces, native and in numpy
# ----------------------------------------------------------------------------------------


def samples(polygon: ComplexArray, per_edge: int) -> ComplexArray:
    out = np.empty(polygon.size * per_edge, dtype=np.complex128)
    count = kernels.boundary_samples(polygon, polygon.size, per_edge, out)
    return out[:count]


def native_sigma(
    target: ComplexArray, a1: ComplexArray, a2: ComplexArray, per_edge: int
) -> FloatArray:
    """sigma[point of target][piece of L1][piece of L2] from the kernels."""
    out = np.empty(target.size * kernels.MAX_SAMPLES**2)
    m1, m2 = kernels.sub_square_growths(target, a1, a2, per_edge, out)
    return out[: target.size * m1 * m2].reshape(target.size, m1, m2)


@dataclass(frozen=True)
class Pieces:
    """Every sub-square's corners, broadcast as [piece of L1][piece of L2]: P1 = [a, b],
    P2 = [c, d]."""

    a: ComplexArray
    b: ComplexArray
    c: ComplexArray
    d: ComplexArray

    @staticmethod
    def of(a1: ComplexArray, a2: ComplexArray, per_edge: int) -> Pieces:
        s1, s2 = samples(a1, per_edge), samples(a2, per_edge)
        return Pieces(s1[:, None], np.roll(s1, -1)[:, None], s2[None, :], np.roll(s2, -1)[None, :])


def exact_factor(
    a: ComplexArray, b: ComplexArray, c: ComplexArray, checked: bool = True
) -> FloatArray:
    """Lemma 1's sagitta factor of the arc 1 / (c - h), h along [a, b]: half the chord
    |b - a| / (|a - c| |b - c|) times tan(phi / 2); with ``checked``, INVALID_FACTOR
    where phi > 90 degrees."""
    ca, cb = a - c, b - c
    lengths = np.abs(ca) * np.abs(cb)
    cosine_part = dot(ca, cb)
    factor = np.abs(b - a) * np.abs(cross(ca, cb)) / (2.0 * lengths * (lengths + cosine_part))
    return np.where(checked & (cosine_part < 0.0), INVALID_FACTOR, factor)


def moving_factor(
    length: FloatArray,
    near_c: FloatArray,
    near_d: FloatArray,
    gap: FloatArray,
    checked: bool = True,
) -> FloatArray:
    """The moving hypothesis's factor |d - c|^2 / (4 dist(c, P1) dist(d, P1) gap); with
    ``checked``, INVALID_FACTOR where the piece is longer than twice the gap."""
    factor = length**2 / (4.0 * near_c * near_d * gap)
    return np.where(checked & (length > 2.0 * gap), INVALID_FACTOR, factor)


def orders(z: complex, p: Pieces, checked: bool = True) -> tuple[FloatArray, FloatArray]:
    """The bounds of order A and order B of target point z on every sub-square."""
    a, b, c, d = p.a, p.b, p.c, p.d
    gap = segment_gap(a, b, c, d)
    ra, rb, rc, rd = np.abs(z - a), np.abs(z - b), np.abs(z - c), np.abs(z - d)
    moving2 = moving_factor(
        np.abs(d - c), segment_distance(c, a, b), segment_distance(d, a, b), gap, checked
    )
    moving1 = moving_factor(
        np.abs(b - a), segment_distance(a, c, d), segment_distance(b, c, d), gap, checked
    )
    order_a = np.maximum(rc * exact_factor(a, b, c, checked), rd * exact_factor(a, b, d, checked))
    order_a = order_a + np.maximum(ra, rb) * moving2
    order_b = np.maximum(ra * exact_factor(c, d, a, checked), rb * exact_factor(c, d, b, checked))
    order_b = order_b + np.maximum(rc, rd) * moving1
    return np.asarray(order_a), np.asarray(order_b)


def images(z: complex | ComplexArray, h1: ComplexArray, h2: ComplexArray) -> ComplexArray:
    return np.asarray((z - h1) / (h2 - h1))


def sub_square_images(z: complex, p: Pieces, steps: int) -> ComplexArray:
    """Images (pieces..., steps * steps) of z under a grid of h1 in P1 and h2 in P2, the
    corners included."""
    t = np.linspace(0.0, 1.0, steps)
    h1 = p.a[..., None, None] + t[:, None] * (p.b - p.a)[..., None, None]
    h2 = p.c[..., None, None] + t[None, :] * (p.d - p.c)[..., None, None]
    shape = np.broadcast_shapes(h1.shape, h2.shape)
    return images(z, h1, h2).reshape(*shape[:-2], steps * steps)


def corner_images(z: complex, p: Pieces) -> ComplexArray:
    corners = [images(z, h1, h2) for h1 in (p.a, p.b) for h2 in (p.c, p.d)]
    return np.stack(np.broadcast_arrays(*corners), axis=-1)


# ----------------------------------------------------------------------------------------
# Lemma 1: the arc 1 / (c - h), h along a segment
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Arcs:
    """Random pieces [a, b] and points c (one per row), the arc points 1 / (c - h) of h
    dense along [a, b] (and of h at the bisector of the angle at c, last), the chord's
    ends and Lemma 1's sagitta (chord / 2) tan(phi / 2)."""

    arc: ComplexArray
    start: ComplexArray
    end: ComplexArray
    sagitta: FloatArray
    cosine: FloatArray  # cos(phi)


def arcs(seed: int, count: int, points: int = 2001) -> Arcs:
    rng = np.random.default_rng(seed)
    a, b, c = (rng.normal(size=count) + 1j * rng.normal(size=count) for _ in range(3))
    # The bisector of the angle at c meets [a, b] where |h - a| / |h - b| = |a - c| / |b - c|.
    bisector = a + np.abs(a - c) / (np.abs(a - c) + np.abs(b - c)) * (b - a)
    t = np.linspace(0.0, 1.0, points)
    h = np.concatenate([a[:, None] + t * (b - a)[:, None], bisector[:, None]], axis=1)
    lengths = np.abs(a - c) * np.abs(b - c)
    tan_half = np.abs(cross(a - c, b - c)) / (lengths + dot(a - c, b - c))
    chord = np.abs(b - a) / lengths
    return Arcs(
        arc=1.0 / (c[:, None] - h),
        start=np.asarray(1.0 / (c - a), dtype=np.complex128),
        end=np.asarray(1.0 / (c - b), dtype=np.complex128),
        sagitta=0.5 * chord * tan_half,
        cosine=dot(a - c, b - c) / lengths,
    )


def test_lemma_1_the_arc_lies_within_its_sagitta_of_the_chord_and_reaches_it() -> None:
    arcs_ = arcs(seed=11, count=600)
    within = arcs_.cosine >= 0.0  # phi <= 90 degrees: the lemma's case
    assert within.sum() > 200
    distance = segment_distance(arcs_.arc, arcs_.start[:, None], arcs_.end[:, None])[within]
    sagitta = arcs_.sagitta[within]
    scale = np.abs(arcs_.arc[within]).max(axis=1)
    assert (distance.max(axis=1) <= sagitta * (1.0 + 1e-9) + 1e-13 * scale).all()
    # Tight: the arc's midpoint (the image of the bisector's foot, the last point) is at
    # exactly the sagitta, and dense uniform points come within a few percent of it.
    assert np.allclose(distance[:, -1], sagitta, rtol=1e-9, atol=1e-13 * scale.max())
    assert (distance[:, :-1].max(axis=1) >= 0.97 * sagitta).all()
    # The arc stays over its chord: every point projects onto the chord segment.
    along = arcs_.end - arcs_.start
    t = dot(along[:, None], arcs_.arc - arcs_.start[:, None]) / np.abs(along[:, None]) ** 2
    assert (t[within] >= -1e-9).all() and (t[within] <= 1.0 + 1e-9).all()


def test_lemma_1_past_a_right_angle_the_arc_leaves_the_chords_strip_yet_keeps_the_bound() -> None:
    """With phi > 90 degrees the arc is more than a half circle and bulges past its
    chord's ends, so the strip argument fails (the kernels count the factor as
    INVALID_FACTOR there). The sagitta still bounds the distance to the chord *segment*:
    beyond the strip the nearer end is within 2 R |cos phi| <= R (1 - cos phi) (the
    page's arc fact)."""
    arcs_ = arcs(seed=12, count=600)
    past = arcs_.cosine < -0.05
    assert past.sum() > 100
    along = arcs_.end - arcs_.start
    t = dot(along[:, None], arcs_.arc - arcs_.start[:, None]) / np.abs(along[:, None]) ** 2
    assert ((t[past] < -1e-6) | (t[past] > 1.0 + 1e-6)).any(axis=1).all()
    distance = segment_distance(arcs_.arc, arcs_.start[:, None], arcs_.end[:, None])[past]
    scale = np.abs(arcs_.arc[past]).max(axis=1)
    assert (distance.max(axis=1) <= arcs_.sagitta[past] * (1.0 + 1e-9) + 1e-13 * scale).all()


# ----------------------------------------------------------------------------------------
# Lemma 2: the angle a segment subtends from a point
# ----------------------------------------------------------------------------------------


def tan_half_angle(p: ComplexArray, a: ComplexArray, b: ComplexArray) -> FloatArray:
    """tan(psi / 2), psi the angle [a, b] subtends at p: sin / (1 + cos), or (1 - cos) /
    sin past 90 degrees (no cancellation either way)."""
    pa, pb = a - p, b - p
    lengths, cosine_part, sine_part = np.abs(pa) * np.abs(pb), dot(pa, pb), np.abs(cross(pa, pb))
    with np.errstate(divide="ignore", invalid="ignore"):  # p on the segment: psi = 180
        past = (lengths - cosine_part) / sine_part
        return np.where(cosine_part >= 0.0, sine_part / (lengths + cosine_part), past)


def test_lemma_2_a_segment_subtends_at_most_its_half_length_over_the_distance() -> None:
    rng = np.random.default_rng(21)
    count = 20_000
    a = rng.normal(size=count) + 1j * rng.normal(size=count)
    b = a + rng.normal(size=count) + 1j * rng.normal(size=count)
    # Points from very near the segment (psi near 180 degrees) to far off it.
    spread = np.exp(rng.uniform(math.log(1e-3), math.log(30.0), count))
    p = 0.5 * (a + b) + spread * (rng.normal(size=count) + 1j * rng.normal(size=count))
    rho = segment_distance(p, a, b)
    delta = np.abs(b - a)
    assert (tan_half_angle(p, a, b) <= delta / (2.0 * rho) * (1.0 + 1e-12)).all()
    # Both sides of 90 degrees are drawn.
    assert (tan_half_angle(p, a, b) > 1.0).sum() > 1000
    assert (tan_half_angle(p, a, b) < 1.0).sum() > 1000


def test_lemma_2_is_an_equality_on_the_perpendicular_bisector() -> None:
    rng = np.random.default_rng(22)
    count = 5_000
    a = rng.normal(size=count) + 1j * rng.normal(size=count)
    b = a + rng.normal(size=count) + 1j * rng.normal(size=count)
    rho = np.exp(rng.uniform(math.log(1e-2), math.log(30.0), count))
    normal = 1j * (b - a) / np.abs(b - a)
    p = 0.5 * (a + b) + rng.choice([-1.0, 1.0], count) * rho * normal
    assert np.allclose(segment_distance(p, a, b), rho, rtol=1e-12)
    assert np.allclose(tan_half_angle(p, a, b), np.abs(b - a) / (2.0 * rho), rtol=1e-12)


# ----------------------------------------------------------------------------------------
# One sub-square
# ----------------------------------------------------------------------------------------


def close_movements(seed: int, count: int) -> list[tuple[ComplexArray, ComplexArray, ComplexArray]]:
    """(target, a1, a2) of general polygons whose L1 and L2 regions are close for their
    size, so that whole edges (per_edge = 1) break the conditions somewhere."""
    rng = np.random.default_rng(seed)
    found: list[tuple[ComplexArray, ComplexArray, ComplexArray]] = []
    while len(found) < count:
        turn = np.exp(1j * rng.uniform(-math.pi, math.pi))
        a1 = on_circle(rng, int(rng.integers(2, 5)), -turn, 1.0)
        a2 = on_circle(rng, int(rng.integers(2, 5)), (1.05 + rng.uniform(0.0, 0.5)) * turn, 1.0)
        if planned(a1, a1, a2, 1) is None:  # touching or overlapping
            continue
        target = on_circle(rng, int(rng.integers(1, 5)), complex(*rng.uniform(-3, 3, 2)), 0.5)
        found.append((target, a1, a2))
    return found


def near_a_threshold(p: Pieces) -> BoolArray:
    """Sub-squares with a condition within rounding of its threshold, where the kernels
    and numpy may decide it differently."""
    near = np.zeros(np.broadcast_shapes(p.a.shape, p.c.shape), dtype=bool)
    for x, y, at in ((p.a, p.b, p.c), (p.a, p.b, p.d), (p.c, p.d, p.a), (p.c, p.d, p.b)):
        lengths = np.abs(x - at) * np.abs(y - at)
        near |= np.abs(dot(x - at, y - at)) <= 1e-9 * lengths
    gap = segment_gap(p.a, p.b, p.c, p.d)
    for length in (np.abs(p.b - p.a), np.abs(p.d - p.c)):
        near |= np.abs(length - 2.0 * gap) <= 1e-9 * length
    return near


def test_native_sigma_is_the_pages_formula() -> None:
    """sub_square_growths against the page's formulas, in numpy: sigma is the smaller of
    order A and order B, a factor whose condition fails counting as INVALID_FACTOR;
    on planned movements and on close regions cut too coarsely."""
    cases = [(m.target, m.a1, m.a2, m.per_edge) for m in movements(seed=31, count=60)]
    cases += [(t, a1, a2, 1) for t, a1, a2 in close_movements(seed=32, count=80)]
    valid = invalid = one_order = 0
    for target, a1, a2, per_edge in cases:
        native = native_sigma(target, a1, a2, per_edge)
        p = Pieces.of(a1, a2, per_edge)
        near = near_a_threshold(p)
        for v, z in enumerate(target):
            order_a, order_b = orders(complex(z), p)
            expected = np.minimum(order_a, order_b)
            got = native[v]
            huge = ~near & (expected >= HUGE)
            assert (got[huge] >= HUGE).all()
            fine = ~near & (expected < HUGE)
            assert np.allclose(got[fine], expected[fine], rtol=AGREEMENT, atol=0.0)
            valid += int(fine.sum())
            invalid += int(huge.sum())
            one_order += int((fine & ((order_a >= HUGE) | (order_b >= HUGE))).sum())
    assert valid > 10_000 and invalid > 200 and one_order > 100, (valid, invalid, one_order)


def sigma_and_pieces(
    m: Movement, v: int, rng: np.random.Generator, picked: int | None
) -> tuple[FloatArray, Pieces]:
    """sigma of target point v on ``picked`` sub-squares (the largest half, the rest at
    random; all if None), and those sub-squares."""
    sigma = native_sigma(m.target, m.a1, m.a2, m.per_edge)[v].ravel()
    s1, s2 = samples(m.a1, m.per_edge), samples(m.a2, m.per_edge)
    m1, m2 = s1.size, s2.size
    if picked is None:
        chosen = np.arange(sigma.size)
    else:
        largest = np.argsort(sigma)[-picked // 2 :]
        chosen = np.unique(np.concatenate([largest, rng.integers(0, sigma.size, picked // 2)]))
    i, j = np.unravel_index(chosen, (m1, m2))
    pieces = Pieces(s1[i], s1[(i + 1) % m1], s2[j], s2[(j + 1) % m2])
    return sigma[chosen], pieces


def check_sub_squares(seed: int, count: int, picked: int | None) -> list[float]:
    """Dense images (40 x 40) of each sub-square checked against its sigma; returns each
    movement's largest ratio of an image's distance to the corner hull over sigma."""
    rng = np.random.default_rng(seed + 1)
    ratios = []
    for m in movements(seed, count):
        largest = 0.0
        for v, z in enumerate(m.target):
            sigma, pieces = sigma_and_pieces(m, v, rng, picked)
            assert (sigma < HUGE).all()
            dense = sub_square_images(complex(z), pieces, 40)
            distance = hull4_distance(dense, corner_images(complex(z), pieces)).max(axis=-1)
            # Rounding of the images, far below the margin the transfer adds.
            slack = 1e-13 * np.abs(dense).max(axis=-1)
            assert (distance <= sigma * (1.0 + 1e-9) + slack).all()
            positive = sigma > 0.0
            if positive.any():
                largest = max(largest, float((distance[positive] / sigma[positive]).max()))
        ratios.append(largest)
    return ratios


def test_every_image_of_a_sub_square_lies_within_sigma_of_its_corner_hull() -> None:
    ratios = check_sub_squares(seed=41, count=40, picked=16)
    # The bound is tight: somewhere an image is at sigma, and at most movements the
    # worst image is more than half-way there.
    assert max(ratios) > 0.99, sorted(ratios)
    assert float(np.median(ratios)) > 0.5, sorted(ratios)


@pytest.mark.slow
def test_every_image_of_every_sub_square_lies_within_sigma_of_its_corner_hull() -> None:
    ratios = check_sub_squares(seed=42, count=100, picked=None)
    assert max(ratios) > 0.99 and float(np.median(ratios)) > 0.5, sorted(ratios)


def test_the_bound_holds_past_its_conditions() -> None:
    """The page's remark on Lemma 1: the conditions phi <= 90 degrees and |piece| <=
    2 gap keep each arc under a half circle, but the sagitta bounds the distance to the
    chord segment for any arc, so both orders without their checks still bound the
    images. (The kernels keep the checks; frame_plan makes them hold.)"""
    rng = np.random.default_rng(51)
    checked = 0
    for target, a1, a2 in close_movements(seed=52, count=30):
        s1, s2 = samples(a1, 1), samples(a2, 1)
        p = Pieces.of(a1, a2, 1)
        for z in target:
            z = complex(z)
            order_a, order_b = orders(z, p, checked=True)
            past = (order_a >= HUGE) | (order_b >= HUGE)
            if not past.any():
                continue
            free_a, free_b = orders(z, p, checked=False)
            bound = np.minimum(free_a, free_b)[past]
            i, j = np.nonzero(past)
            picked = rng.permutation(i.size)[:6]
            i, j, bound = i[picked], j[picked], bound[picked]
            pieces = Pieces(s1[i], np.roll(s1, -1)[i], s2[j], np.roll(s2, -1)[j])
            dense = sub_square_images(z, pieces, 60)
            distance = hull4_distance(dense, corner_images(z, pieces)).max(axis=-1)
            slack = 1e-13 * np.abs(dense).max(axis=-1)
            assert (distance <= bound * (1.0 + 1e-9) + slack).all()
            checked += i.size
    assert checked > 100


# ----------------------------------------------------------------------------------------
# The conditions
# ----------------------------------------------------------------------------------------


def test_condition_l1_and_l2_regions_disjoint() -> None:
    """D > 0: every pole 1 / (h2 - h1) lies off the pieces. Touching or overlapping
    regions are refused before any bound is computed."""
    square = np.array([0, 1, 1 + 1j, 1j], dtype=np.complex128)
    target = np.array([3 + 3j], dtype=np.complex128)
    for shift in (1.0, 0.5, 0.5 + 0.5j, 1.0 + 1.0j):
        for transfer in ("conservative", "conservative_global"):
            assert transfer_vertices(target, square, square + shift, transfer) == "l1_l2_overlap"
    # Disjoint but closer than 1/16 of the longest edge: more than 8 pieces per edge.
    assert transfer_vertices(target, square, square + 1.05, "conservative") == "l1_l2_too_close"
    assert isinstance(transfer_vertices(target, square, square + 1.07), np.ndarray)


def test_condition_the_pieces_cover_each_boundary() -> None:
    """The samples hold every vertex exactly, in order, and the pieces between
    consecutive samples cover the boundary (every dense boundary point is on one)."""
    for m in movements(seed=61, count=60):
        for polygon in (m.a1, m.a2):
            s = samples(polygon, m.per_edge)
            assert s.size == polygon.size * m.per_edge
            assert np.array_equal(s[:: m.per_edge], polygon)
            t = np.linspace(0.0, 1.0, 101)[:, None]
            dense = (polygon + t * (np.roll(polygon, -1) - polygon)).ravel()
            gap = segment_distance(dense[:, None], s[None, :], np.roll(s, -1)[None, :])
            assert (gap.min(axis=1) <= 1e-14 * (1.0 + np.abs(polygon).max())).all()


def test_condition_pieces_longer_than_twice_their_distance_never_get_the_local_bound() -> None:
    """Where both pieces of a sub-square are longer than twice their distance, neither
    order's moving factor holds: the kernels' sigma is then INVALID_FACTOR-sized, so the
    transfer keeps the global bound (or refuses), never a local bound outside its
    conditions; where one piece is short the other order applies (the formula test)."""
    both = 0
    for target, a1, a2 in close_movements(seed=71, count=40):
        p = Pieces.of(a1, a2, 1)
        gap = segment_gap(p.a, p.b, p.c, p.d)
        long_pair = (np.abs(p.b - p.a) > 2.0 * gap * (1 + 1e-9)) & (
            np.abs(p.d - p.c) > 2.0 * gap * (1 + 1e-9)
        )
        native = native_sigma(target, a1, a2, 1)
        for v, z in enumerate(target):
            corners = np.stack(np.broadcast_arrays(p.a, p.b, p.c, p.d), axis=-1)
            off_corners = (np.abs(corners - z) > 0.0).all(axis=-1)
            assert (native[v][long_pair & off_corners] >= HUGE).all()
            both += int((long_pair & off_corners).sum())
    assert both > 50


def test_frame_plan_cuts_every_piece_within_the_conditions() -> None:
    """With frame_plan's samples per edge every piece is at most 2 D long, so every
    corner angle is at most 90 degrees (Lemma 2 at distance >= D) and every piece at
    most twice its distance to the other: both orders hold on every sub-square. Each
    factor is at most its counterpart in the global radius (the page's comparison)."""
    for m in movements(seed=81, count=120):
        p = Pieces.of(m.a1, m.a2, m.per_edge)
        for length, delta in ((np.abs(p.b - p.a), m.delta1), (np.abs(p.d - p.c), m.delta2)):
            assert (length <= delta * (1.0 + 1e-12)).all()
            assert delta <= 2.0 * m.distance * (1.0 + 1e-12)
        cube = 4.0 * m.distance**3
        for x, y, at, delta in ((p.a, p.b, p.c, m.delta1), (p.a, p.b, p.d, m.delta1),
                                (p.c, p.d, p.a, m.delta2), (p.c, p.d, p.b, m.delta2)):  # fmt: skip
            assert (dot(x - at, y - at) >= 0.0).all()
            assert (exact_factor(x, y, at) <= delta**2 / cube * (1.0 + 1e-9)).all()
        for z in m.target:
            order_a, order_b = orders(complex(z), p)
            assert (order_a < HUGE).all() and (order_b < HUGE).all()
        assert (native_sigma(m.target, m.a1, m.a2, m.per_edge) < HUGE).all()


def test_the_local_bound_is_at_most_the_global_one() -> None:
    """max sigma <= (V2 delta1^2 + V1 delta2^2) / (4 D^3), computed here from frame_plan's
    D, delta1 and delta2; and markedly smaller on most movements."""
    ratios = []
    for m in movements(seed=91, count=300):
        local = float(native_sigma(m.target, m.a1, m.a2, m.per_edge).max())
        assert local <= m.global_radius * (1.0 + 1e-12)
        if m.global_radius > 0.0:
            ratios.append(local / m.global_radius)
    assert float(np.median(ratios)) < 0.75, np.quantile(ratios, [0.1, 0.5, 0.9])


# ----------------------------------------------------------------------------------------
# The whole transfer
# ----------------------------------------------------------------------------------------


def sampled_images(m: Movement) -> ComplexArray:
    """Every target vertex's images under every pair of boundary samples."""
    s1, s2 = samples(m.a1, m.per_edge), samples(m.a2, m.per_edge)
    return images(m.target[:, None, None], s1[None, :, None], s2[None, None, :]).ravel()


def region(m: Movement, transfer: str) -> ComplexArray:
    vertices = transfer_vertices(m.target, m.a1, m.a2, transfer, m.edge_samples)
    assert isinstance(vertices, np.ndarray)
    return vertices


def test_the_region_is_the_sampled_hull_grown_by_the_smaller_bound_and_the_margin() -> None:
    """The region is the sampled hull grown by the radius: the sampled images' smallest
    depth in the region is min(max sigma, r) + its margin for "conservative" and r + the
    margin for "conservative_global", to a part in 1e6 of the margin (the hull's
    vertices lie exactly the radius inside the offset edges)."""
    for m in movements(seed=101, count=80):
        local = float(native_sigma(m.target, m.a1, m.a2, m.per_edge).max())
        points = sampled_images(m)
        for transfer, radius, margin in (
            ("conservative", min(local, m.global_radius), m.local_margin),
            ("conservative_global", m.global_radius, m.margin),
        ):
            grown = float(depth(region(m, transfer), points).min())
            assert grown - radius == pytest.approx(margin, rel=1e-6), transfer


def check_dense_reference(seed: int, count: int, reference_samples: int) -> None:
    for m in movements(seed, count):
        conservative = region(m, "conservative")
        reference = reference_hull(m.target, m.a1, m.a2, reference_samples)
        # Each reference point is in the exact set, so within max sigma of the sampled
        # hull: at least the margin deep in the region (half of it, for rounding).
        assert float(depth(conservative, reference).min()) >= 0.5 * m.margin
        # No larger than the global region, but for the local margin's extra term (the
        # samples' rounding): at most that much wider all round.
        coarse = region(m, "conservative_global")
        extra = m.local_margin - m.margin
        perimeter = float(np.abs(np.diff(np.append(coarse, coarse[0]))).sum())
        # (the last term: the areas' own rounding, a few ulps of the coordinates per unit
        # of perimeter, which counts for regions a margin wide)
        rounding = 1e-15 * float(np.abs(coarse).max()) * perimeter
        allowed = area(coarse) * (1.0 + 1e-9) + perimeter * extra + 4.0 * extra**2 + rounding
        assert area(conservative) <= allowed


def test_the_region_holds_the_dense_reference_and_is_no_larger_than_the_global_one() -> None:
    check_dense_reference(seed=111, count=300, reference_samples=31)
    check_dense_reference(seed=112, count=30, reference_samples=100)


@pytest.mark.slow
def test_the_region_holds_the_dense_reference_on_many_movements() -> None:
    check_dense_reference(seed=113, count=1000, reference_samples=100)


def test_the_region_holds_the_exact_set_on_a_grid() -> None:
    """exact_member (benchmarks/transfer_tightness.py, numpy apart from the kernels) on a
    grid over the region's box, widened by a tenth: every point of the exact set is in
    the region."""
    members = 0
    for m in movements(seed=121, count=8):
        conservative = region(m, "conservative")
        low = complex(conservative.real.min(), conservative.imag.min())
        high = complex(conservative.real.max(), conservative.imag.max())
        pad = 0.1 * (high - low)
        x = np.linspace(low.real - pad.real, high.real + pad.real, 150)
        y = np.linspace(low.imag - pad.imag, high.imag + pad.imag, 150)
        grid = (x[None, :] + 1j * y[:, None]).ravel()
        inside = exact_member(grid, m.target, m.a1, m.a2)
        assert float(depth(conservative, grid[inside]).min(initial=np.inf)) >= 0.5 * m.margin
        members += int(inside.sum())
    assert members > 8 * 1000
