"""Planning where the map gives nothing to plan on: moves scored in hypothesised worlds.

With a forward camera a movement maps a landmark only when L1, L2 and it stay in view
at both readings and the move gives them parallax. Before the robot's map holds a
landmark (and often before it holds a frame), and whenever no move is predicted to
help on the map, the map-based planners have nothing to simulate;
:class:`HypothesisPlanner` scores moves in worlds built from what the robot knows:

- where it saw each landmark (:class:`RayMemory`: rays in its odometry frame, from its
  own commands): at the rays' triangulation when two of them cross, else along the
  last ray at a range unknown to the robot, drawn log-uniformly from the prior
  :data:`RANGE_PRIOR` in units of its longest move (its own hardware: the landmarks of
  a room it crosses in a few moves stand a few moves away); a landmark never seen
  stays unknown and predicts no progress;
- once the map has a pose, the map itself (FL): its estimates, and the landmarks it
  has not mapped, or only vaguely, put where the rays say (:meth:`HypothesisPlanner.fill_unmapped`);
- its camera (field of view and range, :class:`~bearing_env.agents.visibility.VisibilityPredictor`),
  the places where moves were blocked, and a prior arena (:func:`arena_limits`: the
  walls stand about :data:`ARENA_MARGIN` longest moves beyond the landmarks).

Worlds in the robot's own frame are in metres (the robot at 0, heading 0): bearings
are invariant under the similarity to FL, so the world model's update needs no scale.
Candidate moves and plans of several moves are scored by the same beam search as
:class:`~bearing_env.agents.lookahead.Lookahead` (:func:`~bearing_env.agents.planning.beam_search`)
on copies of the robot's map, by the mean predicted potential over the worlds.
Nothing here reads ground truth.
"""

from __future__ import annotations

import math
from functools import partial

import numpy as np
from numpy.typing import NDArray

from bearing_env.belief import MIN_PARALLAX_EPSILONS
from bearing_env.numerics import wrap_angle
from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM
from bearing_env.validation import int_at_least

from .base import ActionCodec, Movement
from .planning import (
    ComplexArray,
    FloatArray,
    Mover,
    Sensor,
    Worlds,
    beam_search,
    uncertainty_potential,
)
from .visibility import BUMP_RADIUS, OBSTACLE_RADIUS, VisibilityPredictor, travel_until

#: The prior on a remembered landmark's range, in units of the robot's longest move
#: (low, high; log-uniform).
RANGE_PRIOR = (0.5, 3.0)
#: The prior on the arena, in longest moves: its walls stand about this far beyond the
#: landmarks and the robot (their convex hull), so planned moves stop there.
ARENA_MARGIN = 0.5


def arena_limits(
    landmarks: ComplexArray, positions: ComplexArray, margin: float
) -> tuple[ComplexArray, FloatArray]:
    """Per world (H,), the half-planes of the prior arena: the convex hull of the known
    ``landmarks`` (H x n, NaN: unknown) and the robot's ``positions`` (H,), each edge
    pushed out by ``margin``; (H x E) outward unit normals and offsets (a point p is
    inside when Re(p conj(normal)) <= offset for every edge; padding: offset inf)."""
    hulls = [
        _convex_hull(np.concatenate([row[np.isfinite(row)], [position]]))
        for row, position in zip(landmarks, positions, strict=True)
    ]
    edges = max(max(hull.size, 2) for hull in hulls)
    normals = np.ones((len(hulls), edges), dtype=np.complex128)
    offsets = np.full((len(hulls), edges), np.inf)
    for h, hull in enumerate(hulls):
        if hull.size < 2:
            continue
        if hull.size == 2:
            # A segment: its two sides and its two ends.
            along = (hull[1] - hull[0]) / abs(hull[1] - hull[0])
            sides = np.array([along * -1j, along * 1j, along, -along])
            anchors = np.array([hull[0], hull[0], hull[1], hull[0]])
        else:
            following = np.roll(hull, -1)
            sides = (following - hull) * -1j  # counter-clockwise hull: outward normals
            sides = sides / np.abs(sides)
            anchors = hull
        normals[h, : sides.size] = sides
        offsets[h, : sides.size] = (anchors * sides.conjugate()).real + margin
    return normals, offsets


def _convex_hull(points: ComplexArray) -> ComplexArray:
    """The convex hull of points, counter-clockwise (Andrew's monotone chain)."""
    unique = np.unique(points)  # sorted by real part, then imaginary
    if unique.size < 3:
        return unique

    def cross(o: complex, a: complex, b: complex) -> float:
        return ((a - o).conjugate() * (b - o)).imag

    lower: list[complex] = []
    for point in unique:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], point) <= 0.0:
            lower.pop()
        lower.append(complex(point))
    upper: list[complex] = []
    for point in unique[::-1]:
        while len(upper) >= 2 and cross(upper[-2], upper[-1], point) <= 0.0:
            upper.pop()
        upper.append(complex(point))
    return np.array(lower[:-1] + upper[:-1], dtype=np.complex128)


def travel_inside(
    positions: ComplexArray,
    headings: FloatArray,
    distances: FloatArray,
    normals: ComplexArray,
    offsets: FloatArray,
) -> FloatArray:
    """Distances (nodes, K, H) cut where moves from ``positions`` (nodes, H) along
    ``headings`` (nodes, K) leave the half-planes (H x E, :func:`arena_limits`); a move
    from outside that goes further out gets 0."""
    starts = (positions[:, None, :, None] * normals.conjugate()[None, None]).real
    rates = (np.exp(1j * headings)[:, :, None, None] * normals.conjugate()[None, None]).real
    with np.errstate(divide="ignore", invalid="ignore"):
        limits = np.where(rates > 1e-12, (offsets[None, None] - starts) / rates, np.inf)
    return np.minimum(distances, np.maximum(limits.min(axis=-1), 0.0))


class RayMemory:
    """The rays along which the robot saw each landmark, in its odometry frame.

    The odometry frame is the robot's pose at the episode's start (metres), carried by
    its own commands: the turns (exact) and the lengths (exact unless a move was
    blocked: a blocked move counts as 0, the robot does not know how far it got). Each
    reading adds, for every landmark it saw, a ray from the robot's odometry position
    in the direction read. :meth:`offsets` draws where the landmarks may stand: at the
    triangulation of the rays when two of them cross at a usable angle, else along the
    last ray at a range from the prior.
    """

    def __init__(self, epsilon: float) -> None:
        #: The smallest angle (radians) between two rays that triangulates a landmark.
        self.min_angle = MIN_PARALLAX_EPSILONS * float(epsilon)
        self.reset()

    def reset(self) -> None:
        self.position = 0j
        self.heading = 0.0
        self.rays: list[list[tuple[complex, float]]] = []
        #: Where moves were blocked (odometry frame): just ahead of the robot after them.
        self.bumps: list[complex] = []
        self._pending: tuple[float, float] | None = None

    def observe(
        self, bearings: FloatArray, seen: NDArray[np.bool_], fresh: bool, blocked: bool
    ) -> None:
        """Take in a reading (``bearings`` where ``seen``), after the commanded move;
        ``fresh``: a new episode."""
        if fresh or len(self.rays) != bearings.size:
            self.reset()
            self.rays = [[] for _ in range(bearings.size)]
        elif self._pending is not None:
            turn, length = self._pending
            self.heading = float(wrap_angle(self.heading + turn))
            ahead = complex(math.cos(self.heading), math.sin(self.heading))
            # A blocked move got somewhere along its length: half of it, on average.
            self.position += (0.5 if blocked else 1.0) * length * ahead
            if blocked:
                self.bumps.append(self.position + BUMP_RADIUS * ahead)
        self._pending = None
        for index in np.flatnonzero(seen):
            self.rays[index].append((self.position, self.heading + float(bearings[index])))

    def commanded(self, turn: float, length: float) -> None:
        """Remember the movement about to be made."""
        self._pending = (float(turn), float(length))

    def bump_offsets(self) -> ComplexArray:
        """The bumps relative to the robot, in metres in its frame (heading 0)."""
        turn_back = complex(math.cos(self.heading), -math.sin(self.heading))
        return (np.array(self.bumps, dtype=np.complex128) - self.position) * turn_back

    def offsets(
        self, count: int, ranges: tuple[float, float], rng: np.random.Generator
    ) -> ComplexArray:
        """``count`` draws (count x n) of where the landmarks stand relative to the robot,
        in metres in its frame (heading 0): a triangulated landmark within +-25% of its
        range along its last ray, another along its last ray at a range drawn
        log-uniformly from ``ranges`` (metres), NaN for a landmark never seen."""
        low, high = ranges
        out = np.full((count, len(self.rays)), complex(np.nan, np.nan))
        draws = rng.uniform(0.0, 1.0, out.shape)
        turn_back = complex(math.cos(self.heading), -math.sin(self.heading))
        for index, rays in enumerate(self.rays):
            if not rays:
                continue
            origin, direction = rays[-1]
            span = _triangulated_range(rays, self.min_angle)
            lo, hi = (low, high) if span is None else (0.8 * span, 1.25 * span)
            distance = np.exp(math.log(lo) + draws[:, index] * (math.log(hi) - math.log(lo)))
            points = origin + distance * complex(math.cos(direction), math.sin(direction))
            out[:, index] = (points - self.position) * turn_back
        return out


def _triangulated_range(rays: list[tuple[complex, float]], min_angle: float) -> float | None:
    """The range along the last ray of the point nearest (least squares) to all the rays
    that meet it at ``min_angle`` or more; None when no such ray, or behind a ray."""
    origin, direction = rays[-1]
    crossing = [(o, d) for o, d in rays[:-1] if abs(math.sin(d - direction)) >= math.sin(min_angle)]
    if not crossing:
        return None
    normal_sum = np.zeros((2, 2))
    target = np.zeros(2)
    for o, d in [*crossing, (origin, direction)]:
        unit = np.array([math.cos(d), math.sin(d)])
        projector = np.eye(2) - np.outer(unit, unit)
        normal_sum += projector
        target += projector @ np.array([o.real, o.imag])
    point = np.linalg.solve(normal_sum, target)
    along = [
        (point[0] - o.real) * math.cos(d) + (point[1] - o.imag) * math.sin(d)
        for o, d in [*crossing, (origin, direction)]
    ]
    if min(along) <= 0.0:
        return None
    return float(along[-1])


class HypothesisPlanner:
    """Plans a move in hypothesised worlds (see the module doc).

    Args:
        codec: the env's action codec (the candidates and the longest move).
        min_baseline: metres; a shorter move does not update the map.
        area_cap: the potential's cap.
        visibility: the robot's camera (None: simulate the panoramic camera).
        hypotheses: worlds per decision.
        depth, width: the beam search's moves per plan and plans kept per depth.
        n_turns, lengths: the candidate grid (:meth:`ActionCodec.candidates`).
        range_prior: (low, high) of the ranges, in longest moves.
    """

    def __init__(
        self,
        codec: ActionCodec,
        min_baseline: float,
        area_cap: float,
        visibility: VisibilityPredictor | None,
        hypotheses: int = 8,
        depth: int = 2,
        width: int = 8,
        n_turns: int = 24,
        lengths: int = 3,
        range_prior: tuple[float, float] = RANGE_PRIOR,
    ) -> None:
        for value, label in ((hypotheses, "hypotheses"), (depth, "depth"), (width, "width")):
            int_at_least(value, 1, label)
        low, high = (float(v) for v in range_prior)
        if not 0.0 < low <= high < math.inf:
            raise ValueError(f"range_prior must be 0 < low <= high < inf, got {range_prior!r}")
        self.codec = codec
        self.min_baseline = float(min_baseline)
        self.area_cap = float(area_cap)
        self.visibility = visibility
        self.hypotheses, self.depth, self.width = hypotheses, depth, width
        self.candidates = codec.candidates(int(n_turns), int(lengths))
        self.turns = np.array([c.turn for c in self.candidates], dtype=np.float64)
        self.lengths = np.array([c.length for c in self.candidates], dtype=np.float64)
        self.ranges = (low * codec.max_length, high * codec.max_length)
        #: The prior arena's margin beyond the landmarks, metres (:data:`ARENA_MARGIN`).
        self.margin = ARENA_MARGIN * codec.max_length
        #: The search's copies of the map, by role and size, refilled at each decision.
        self._beam: dict[tuple[str, int], BatchedPolygonSLAM] = {}

    def robot_frame_worlds(self, offsets: ComplexArray) -> Worlds:
        """Worlds in the robot's frame (metres, the robot at 0 with heading 0), the
        landmarks at ``offsets`` (H x n, :meth:`RayMemory.offsets`); for a map without
        a frame or a scale yet."""
        return Worlds(offsets, np.zeros(offsets.shape[0], dtype=np.complex128))

    @staticmethod
    def fill_unmapped(
        worlds: Worlds,
        offsets: ComplexArray,
        heading: float,
        metres_per_unit: float,
        replace: NDArray[np.bool_] | None = None,
    ) -> Worlds:
        """FL worlds (from the map) with every landmark they do not place (NaN), and those
        flagged in ``replace`` (n,), put at ``offsets`` (H x n, metres in the robot's
        frame) from the robot, turned by its believed ``heading`` and scaled to FL
        (where the offsets know the landmark)."""
        guessed = worlds.positions[:, None] + offsets * (np.exp(1j * heading) / metres_per_unit)
        keep = np.isfinite(worlds.landmarks)
        if replace is not None:
            keep &= ~(replace[None, :] & np.isfinite(guessed))
        landmarks = np.where(keep, worlds.landmarks, guessed)
        return Worlds(landmarks, worlds.positions)

    def mover(
        self, worlds: Worlds, metres_per_unit: float, obstacles: ComplexArray | None
    ) -> Mover:
        """The distances moves travel in ``worlds`` of ``metres_per_unit`` metres per
        unit: their lengths, cut at the ``obstacles`` (that frame) and at the prior
        arena's walls (:func:`arena_limits`), 0 below the minimum baseline."""
        radius = OBSTACLE_RADIUS / metres_per_unit
        normals, offsets = arena_limits(
            worlds.landmarks, worlds.positions, self.margin / metres_per_unit
        )

        def mover(positions: ComplexArray, headings: FloatArray, lengths: FloatArray) -> FloatArray:
            distances = np.broadcast_to(
                (lengths / metres_per_unit)[None, :, None],
                (positions.shape[0], lengths.size, positions.shape[1]),
            )
            if obstacles is not None and obstacles.size:
                distances = travel_until(
                    positions[:, None, :], headings[:, :, None], distances, obstacles, radius
                )
            distances = travel_inside(positions, headings, distances, normals, offsets)
            return np.where(distances * metres_per_unit >= self.min_baseline, distances, 0.0)

        return mover

    def plan(
        self,
        slam: PolygonSLAM,
        worlds: Worlds,
        heading: float,
        metres_per_unit: float,
        first_allowed: NDArray[np.bool_],
        depth: int | None = None,
        with_bumps: bool = True,
        obstacles: ComplexArray | None = None,
    ) -> Movement | None:
        """The first move of the best plan in ``worlds`` (their frame's units are
        ``metres_per_unit`` metres, the robot faces ``heading`` in it), or None when no
        plan is predicted to lower the map's potential (or no candidate is allowed).
        ``depth``: moves per plan (default the planner's); ``with_bumps``: the worlds are
        in FL, where the obstacles the robot bumped into are; ``obstacles``: where moves
        were blocked, in the worlds' frame: moves stop at :data:`OBSTACLE_RADIUS` from
        them."""
        if not first_allowed.any():
            return None

        mover = self.mover(worlds, metres_per_unit, obstacles)

        sensor: Sensor | None = None
        if self.visibility is not None:
            sensor = partial(
                self.visibility.missed,
                landmarks=worlds.landmarks,
                metres_per_unit=metres_per_unit,
                with_bumps=with_bumps,
            )
        first, score = beam_search(
            slam, worlds, heading, self.turns, self.lengths, first_allowed, mover,
            self.depth if depth is None else depth, self.width, self.area_cap,
            scratch=self._beam, sensor=sensor,
        )  # fmt: skip
        if first < 0 or score >= uncertainty_potential(slam.areas, self.area_cap):
            return None
        return self.candidates[first]
