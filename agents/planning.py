"""One-step look-ahead on a map: score candidate movements by simulated SLAM updates.

Everything happens in the landmark frame FL (L1 = 0, L2 = 1). Bearings are invariant
under the similarity between FL and the world (no reflection), so noise-free bearings
computed from FL positions are exactly the bearings the robot would read in the world,
provided the move length is converted to FL units.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numba import njit
from numpy.typing import NDArray

from bearing_env.envs.config import AREA_FLOOR
from bearing_env.envs.kernels import potential_of
from bearing_env.numerics import JIT_OPTIONS, wrap_angle
from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM


def uncertainty_potential(
    areas: NDArray[np.float64], area_cap: float, log_area: bool = True
) -> NDArray[np.float64]:
    """The env's uncertainty potential over the last axis (one value per map for areas
    (..., n - 2)): the compiled ``potential_of`` the env's reward uses, so the planner
    scores moves as the env rewards them, for ``reward="log_area"`` (sum of log capped
    areas, the default) and ``reward="area"`` (``log_area=False``: sum of capped areas)."""
    values = np.asarray(areas, dtype=np.float64)
    rows = np.ascontiguousarray(values.reshape(-1, values.shape[-1]))
    potentials = np.empty(rows.shape[0], dtype=np.float64)
    _potentials_of_rows(rows, bool(log_area), AREA_FLOOR, float(area_cap), potentials)
    return potentials.reshape(values.shape[:-1])


@njit(**JIT_OPTIONS)
def _potentials_of_rows(
    rows: np.ndarray, log_area: bool, floor: float, cap: float, out: np.ndarray
) -> None:
    """``potential_of`` of every row, in one compiled call (no Python per map)."""
    for i in range(rows.shape[0]):
        out[i] = potential_of(rows[i], rows.shape[1], log_area, floor, cap)


@njit(**JIT_OPTIONS)
def _move_ends(
    start: complex, headings: np.ndarray, distances: np.ndarray, out: np.ndarray
) -> None:
    """``out[k]``: where candidate ``k`` ends, in one compiled loop. math.cos and math.sin
    (libm's, as Python's math module calls them), so the ends are the same bit for bit
    as when they were computed one candidate at a time in Python."""
    for k in range(headings.size):
        out[k] = start + distances[k] * complex(math.cos(headings[k]), math.sin(headings[k]))


def bearings_from(
    position: complex | NDArray[np.complex128],
    heading: float | NDArray[np.float64],
    points: NDArray[np.complex128],
) -> NDArray[np.float64]:
    """Noise-free bearings (..., n) of ``points`` (n,) in FL from ``position`` facing
    ``heading`` (scalars, or arrays of one shape for many poses)."""
    angles = np.angle(points - np.asarray(position)[..., None]) - np.asarray(heading)[..., None]
    return wrap_angle(angles)


#: A visibility prediction: simulated bearings (S + (n,)) from positions and headings
#: (S) with NaN where the reading would miss the landmark
#: (:meth:`bearing_env.agents.visibility.VisibilityPredictor.missed`).
Sensor = Callable[
    [NDArray[np.float64], NDArray[np.complex128], NDArray[np.float64]], NDArray[np.float64]
]


def simulate_potentials(
    slam: PolygonSLAM,
    start: complex,
    landmarks: NDArray[np.complex128],
    headings: NDArray[np.float64],
    distances: NDArray[np.float64],
    area_cap: float,
    min_distance: float = 1e-9,
    log_area: bool = True,
    scratch: dict[int, BatchedPolygonSLAM] | None = None,
    sensor: Sensor | None = None,
) -> NDArray[np.float64]:
    """The uncertainty potential after each candidate move, simulated on a copy of ``slam``.

    Args:
        slam: the map to start from (left untouched).
        start: the robot's position in FL.
        landmarks: all landmark positions in FL (n,), L1 = 0 and L2 = 1 first; NaN for a
            landmark whose position is unknown: it is given the same bearing at both
            ends (parallel cones, so no region), i.e. no predicted progress.
        headings: each candidate's new heading in FL (K,).
        distances: the distance each candidate actually travels, in FL units (K,).
        area_cap: the cap (and the value of an uninitialised landmark) of the potential.
        min_distance: a move shorter than this (FL units) does not update the map.
        log_area: the env's ``reward`` is ``"log_area"`` (True) or ``"area"`` (False).
        scratch: the caller's batches of copies by size, kept between calls and refilled
            (see :meth:`PolygonSLAM.replicate`) instead of made anew for each decision.
        sensor: the visibility prediction (None: the panoramic camera sees every landmark).

    Every moving candidate is fused into its own copy of the map, all in one batched
    update; the bearings are computed here, so the update skips its input checks.
    """
    current = uncertainty_potential(slam.areas, area_cap, log_area)
    headings = np.asarray(headings, dtype=np.float64)
    distances = np.asarray(distances, dtype=np.float64)
    potentials = np.full(headings.size, current)
    moving = np.flatnonzero(distances >= min_distance)
    if moving.size == 0:
        return potentials
    headings, distances = headings[moving], distances[moving]
    known = np.isfinite(landmarks)
    targets = np.where(known, landmarks, 0.0)
    ends = np.empty(headings.size, dtype=np.complex128)
    _move_ends(complex(start), headings, distances, ends)
    bearings_start = bearings_from(start, headings, targets)
    bearings_end = np.where(known, bearings_from(ends, headings, targets), bearings_start)
    if sensor is not None:
        bearings_start = sensor(bearings_start, np.full(headings.shape, start), headings)
        bearings_end = sensor(bearings_end, ends, headings)
    if scratch is None:
        trials = slam.replicate(moving.size)
    else:
        trials = slam.replicate(moving.size, into=scratch.get(moving.size))
        scratch[moving.size] = trials
    # Bearings made here are finite float arrays of the batch's shape: no checks needed.
    trials.update_trusted(bearings_start, bearings_end, robot=False)  # scores need areas only
    potentials[moving] = uncertainty_potential(trials.areas, area_cap, log_area)
    return potentials


def landmark_positions_fl(slam: PolygonSLAM) -> NDArray[np.complex128]:
    """The map's landmark positions in FL (n,): L1 = 0, L2 = 1, then the estimates (NaN
    where not initialised)."""
    estimates = slam.estimates
    mapped = estimates[:, 0] + 1j * estimates[:, 1]
    return np.concatenate([[0.0 + 0.0j, 1.0 + 0.0j], mapped])
