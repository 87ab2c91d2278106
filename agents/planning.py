"""One-step look-ahead on a map: score candidate movements by simulated SLAM updates.

Everything happens in the landmark frame FL (L1 = 0, L2 = 1). Bearings are invariant
under the similarity between FL and the world (no reflection), so noise-free bearings
computed from FL positions are exactly the bearings the robot would read in the world,
provided the move length is converted to FL units.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from bearing_env.envs.config import AREA_FLOOR
from bearing_env.envs.kernels import potential_of
from bearing_env.numerics import wrap_angle
from bearing_env.slam import PolygonSLAM


def uncertainty_potential(
    areas: NDArray[np.float64], area_cap: float, log_area: bool = True
) -> NDArray[np.float64]:
    """The env's uncertainty potential over the last axis (one value per map for areas
    (..., n - 2)): the compiled ``potential_of`` the env's reward uses, so the planner
    scores moves as the env rewards them, for ``reward="log_area"`` (sum of log capped
    areas, the default) and ``reward="area"`` (``log_area=False``: sum of capped areas)."""
    values = np.asarray(areas, dtype=np.float64)
    rows = np.ascontiguousarray(values.reshape(-1, values.shape[-1]))
    potentials = np.array(
        [potential_of(row, row.size, log_area, AREA_FLOOR, float(area_cap)) for row in rows]
    )
    return potentials.reshape(values.shape[:-1])


def bearings_from(
    position: complex | NDArray[np.complex128],
    heading: float | NDArray[np.float64],
    points: NDArray[np.complex128],
) -> NDArray[np.float64]:
    """Noise-free bearings (..., n) of ``points`` (n,) in FL from ``position`` facing
    ``heading`` (scalars, or arrays of one shape for many poses)."""
    angles = np.angle(points - np.asarray(position)[..., None]) - np.asarray(heading)[..., None]
    return wrap_angle(angles)


@dataclass(frozen=True)
class SimulatedMove:
    """A candidate in FL: the new heading and the distance actually travelled (FL units)."""

    heading: float
    distance: float


def simulate_potentials(
    slam: PolygonSLAM,
    start: complex,
    landmarks: NDArray[np.complex128],
    moves: Sequence[SimulatedMove],
    area_cap: float,
    min_distance: float = 1e-9,
    log_area: bool = True,
) -> NDArray[np.float64]:
    """The uncertainty potential after each candidate move, simulated on a copy of ``slam``.

    Args:
        slam: the map to start from (left untouched).
        start: the robot's position in FL.
        landmarks: all landmark positions in FL (n,), L1 = 0 and L2 = 1 first; NaN for a
            landmark whose position is unknown: it is given the same bearing at both
            ends (parallel cones, so no region), i.e. no predicted progress.
        moves: the candidates.
        area_cap: the cap (and the value of an uninitialised landmark) of the potential.
        min_distance: a move shorter than this (FL units) does not update the map.
        log_area: the env's ``reward`` is ``"log_area"`` (True) or ``"area"`` (False).

    Every candidate is fused into its own copy of the map, all in one batched update.
    """
    current = uncertainty_potential(slam.areas, area_cap, log_area)
    known = np.isfinite(landmarks)
    targets = np.where(known, landmarks, 0.0)
    potentials = np.full(len(moves), current)
    moving = [index for index, move in enumerate(moves) if move.distance >= min_distance]
    if not moving:
        return potentials
    headings = np.array([moves[index].heading for index in moving])
    distances = np.array([moves[index].distance for index in moving])
    # The same arithmetic as one candidate at a time, so decisions do not depend on batching.
    ends = np.array(
        [
            start + distance * complex(math.cos(heading), math.sin(heading))
            for heading, distance in zip(headings.tolist(), distances.tolist(), strict=True)
        ]
    )
    bearings_start = bearings_from(start, headings, targets)
    bearings_end = np.where(known, bearings_from(ends, headings, targets), bearings_start)
    trials = slam.replicate(len(moving))
    trials.update(bearings_start, bearings_end, robot=False)  # scores need areas only
    potentials[moving] = uncertainty_potential(trials.areas, area_cap, log_area)
    return potentials


def landmark_positions_fl(slam: PolygonSLAM) -> NDArray[np.complex128]:
    """The map's landmark positions in FL (n,): L1 = 0, L2 = 1, then the estimates (NaN
    where not initialised)."""
    estimates = slam.estimates
    mapped = estimates[:, 0] + 1j * estimates[:, 1]
    return np.concatenate([[0.0 + 0.0j, 1.0 + 0.0j], mapped])
