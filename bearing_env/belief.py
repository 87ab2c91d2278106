"""What a robot can work out from its own readings, beyond its map: the scale of its
landmark frame, and the bearings it would read from a believed pose.

Both the env's planner features (:mod:`bearing_env.envs.candidates`) and the planners of
``bearing_env.agents`` use these; nothing here reads ground truth.

**The FL scale** (metres per FL unit, i.e. the unknown |L1 - L2| in metres) turns a
commanded length into FL units. For every movement that changed frames, L1 and L2 are
triangulated in the robot frame FR (R1 = 0, R2 = 1) from the bearings at both ends of the
move; |L1 - L2| in FR units times the commanded length is one sample. Samples from
bearing pairs with too little parallax (< :data:`MIN_PARALLAX_EPSILONS` epsilon) are
dropped: their range error is large.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env.numerics import wrap, wrap_angle

#: Minimum bearing change (in units of epsilon) for a triangulation to give a scale sample.
MIN_PARALLAX_EPSILONS = 4.0


def triangulate_fr(bearing_start: float, bearing_end: float) -> complex | None:
    """Position in FR (R1 = 0, R2 = 1) of a point seen at these bearings from R1 and R2.

    None if the rays do not meet in front of both observation points.
    """
    denominator = math.sin(bearing_end - bearing_start)
    if abs(denominator) < 1e-12:
        return None
    range_from_start = math.sin(bearing_end) / denominator
    range_from_end = math.sin(bearing_start) / denominator
    if range_from_start <= 0.0 or range_from_end <= 0.0:
        return None
    return range_from_start * complex(math.cos(bearing_start), math.sin(bearing_start))


def scale_sample(
    bearings_start: NDArray[np.float64],
    bearings_end: NDArray[np.float64],
    length: float,
    epsilon: float,
) -> float | None:
    """Metres per FL unit from one movement of ``length`` metres (None if ill-conditioned)."""
    points = []
    for index in (0, 1):
        if not (math.isfinite(bearings_start[index]) and math.isfinite(bearings_end[index])):
            return None  # a missed reading of L1 or L2
        parallax = abs(wrap(float(bearings_end[index] - bearings_start[index])))
        if parallax < MIN_PARALLAX_EPSILONS * epsilon:
            return None
        point = triangulate_fr(float(bearings_start[index]), float(bearings_end[index]))
        if point is None:
            return None
        points.append(point)
    return length * abs(points[1] - points[0])


def bearings_from(
    position: complex | NDArray[np.complex128],
    heading: float | NDArray[np.float64],
    points: NDArray[np.complex128],
) -> NDArray[np.float64]:
    """Noise-free bearings (..., n) of ``points`` (n,) in FL from ``position`` facing
    ``heading`` (scalars, or arrays of one shape for many poses): the native kernel's
    atan2, so that a planner scores the same bits on every machine and in the native
    scoring (numpy's own atan2 differs from libm's in the last bit on some CPUs)."""
    differences = np.asarray(points, dtype=np.complex128) - np.asarray(position)[..., None]
    headings = np.asarray(heading, dtype=np.float64)[..., None]
    shape = np.broadcast_shapes(differences.shape, headings.shape)
    differences, headings = np.broadcast_to(differences, shape), np.broadcast_to(headings, shape)
    out = np.empty(shape, dtype=np.float64)
    _core._bearings_of(
        np.ascontiguousarray(differences).reshape(-1),
        np.ascontiguousarray(headings).reshape(-1),
        out.reshape(-1),
    )
    return out


def median(values: list[float]) -> float:
    """np.median's value of a short list (the middle value, or the mean of the middle
    two), without its array overhead: it is read at every decision."""
    ordered = sorted(values)
    middle = len(ordered) // 2
    if len(ordered) % 2:
        return float(ordered[middle])
    return float((ordered[middle - 1] + ordered[middle]) / 2)


class PoseBeliefs:
    """What ``num_rows`` robots believe of their pose between map fixes, one row each,
    from their own readings and commands (the env's side of
    ``bearing_env.agents.belief.RobotBelief``).

    The map gives a fix after every movement that changed frames: the robot's region at
    its end (the centroid) and its direction in FL. Since then a robot knows the turns it
    commanded (exact: it turns on the spot) and the lengths (exact unless a wall stopped
    it, which it senses; a stopped leg counts as 0), so its believed pose in FL is

    - heading = the fix's heading + :attr:`turn_since_fix`;
    - position = the fix + e^(i fix heading) * :attr:`legs` / :attr:`scale`.

    The scale's samples are triangulations of L1 and L2 from the two readings of each
    movement that changed frames (:func:`scale_sample`); the scale is their median, and
    samples of blocked moves (which travelled less than commanded, so overestimate it)
    count only while there is no other. Unlike a policy, which sees only the reading
    after each move, the env holds both readings of the movement.
    """

    def __init__(self, num_rows: int) -> None:
        #: Turns commanded since the last movement that changed frames (N,), radians.
        self.turn_since_fix = np.zeros(num_rows)
        #: The legs driven since then (N,): the sum of length * e^(i offset), metres,
        #: each leg's offset taken from the fix's heading.
        self.legs = np.zeros(num_rows, dtype=np.complex128)
        #: Metres per FL unit (N,); NaN until a movement gave a usable triangulation.
        self.scale = np.full(num_rows, np.nan)
        self._samples: list[list[float]] = [[] for _ in range(num_rows)]
        self._blocked_samples: list[list[float]] = [[] for _ in range(num_rows)]

    def reset(self, rows: NDArray[np.int64]) -> None:
        """New episodes in ``rows``: nothing carries over."""
        self.turn_since_fix[rows] = 0.0
        self.legs[rows] = 0.0
        self.scale[rows] = np.nan
        for row in rows.tolist():
            self._samples[row] = []
            self._blocked_samples[row] = []

    def poses(
        self,
        rows: NDArray[np.int64],
        fix: NDArray[np.complex128],
        fix_heading: NDArray[np.float64],
    ) -> tuple[NDArray[np.complex128], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
        """The believed poses of the ``ready`` rows (position, heading in FL, and metres
        per FL unit: one per ready row) from their maps' last fixes (``fix``: the robot's
        centroid, ``fix_heading``: its heading in FL, NaN before the first; one per row),
        and ``ready`` (len(rows),): the row has a fix and a scale."""
        scale = self.scale[rows]
        ready = np.isfinite(fix) & np.isfinite(fix_heading) & np.isfinite(scale)
        chosen, scale = rows[ready], scale[ready]
        position = fix[ready] + np.exp(1j * fix_heading[ready]) * self.legs[chosen] / scale
        heading = fix_heading[ready] + self.turn_since_fix[chosen]
        return position, heading, scale, ready

    def moved(
        self,
        rows: NDArray[np.int64],
        turns: NDArray[np.float64],
        lengths: NDArray[np.float64],
        frame_changed: NDArray[np.bool_],
        blocked: NDArray[np.bool_],
        readings: tuple[NDArray[np.float64], NDArray[np.float64]],
        epsilon: float,
    ) -> None:
        """Account for one commanded movement (``turns``, ``lengths``: radians, metres) of
        each of ``rows``: whether it changed frames and whether a wall stopped it, and
        its ``readings`` of L1 and L2 (start, end: (len(rows), 2) each, relative to the
        move's direction, NaN where missed)."""
        kept = ~frame_changed
        if kept.any():
            still = rows[kept]
            self.turn_since_fix[still] = wrap_angle(self.turn_since_fix[still] + turns[kept])
            driven = kept & ~blocked
            self.legs[rows[driven]] += lengths[driven] * np.exp(
                1j * self.turn_since_fix[rows[driven]]
            )
        for index in np.flatnonzero(frame_changed).tolist():
            row = int(rows[index])
            self.turn_since_fix[row] = 0.0
            self.legs[row] = 0.0
            sample = scale_sample(
                readings[0][index], readings[1][index], float(lengths[index]), epsilon
            )
            if sample is None:
                continue
            (self._blocked_samples if blocked[index] else self._samples)[row].append(sample)
            self.scale[row] = median(self._samples[row] or self._blocked_samples[row])
