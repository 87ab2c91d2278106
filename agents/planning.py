"""One-step look-ahead on a map: score candidate movements by simulated SLAM updates.

Everything happens in the landmark frame FL (L1 = 0, L2 = 1). Bearings are invariant
under the similarity between FL and the world (no reflection), so noise-free bearings
computed from FL positions are exactly the bearings the robot would read in the world,
provided the move length is converted to FL units.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env.belief import bearings_from as bearings_from
from bearing_env.envs.config import AREA_FLOOR
from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM
from bearing_env.slam.kernels import PARALLEL_MIN_MAPS, threads

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]


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


#: ``potential_of`` of every row of areas (rows, m) into ``out``, and ``out[k]``: where
#: candidate ``k`` ends (``start + distances[k] * (cos + i sin)(headings[k])``), each in
#: one native call (csrc/env/planning.cpp, the same bits as the numba loops they were).
_potentials_of_rows = _core._potentials_of_rows
_move_ends = _core._move_ends


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

    Every moving candidate is fused into its own copy of the map, copies, updates and
    potentials in one native call; the bearings are computed here (with a sensor, in
    Python), so the update skips its input checks. Without a sensor, the readings too are
    computed natively (:func:`_simulate_natively`).
    """
    headings = np.ascontiguousarray(headings, dtype=np.float64)
    distances = np.ascontiguousarray(distances, dtype=np.float64)
    if sensor is None:
        return _simulate_natively(
            slam, start, landmarks, headings, distances, area_cap, min_distance, log_area, scratch
        )
    count = headings.size
    moving = np.flatnonzero(distances >= min_distance)
    headings, distances = headings[moving], distances[moving]
    known = np.isfinite(landmarks)
    targets = np.where(known, landmarks, 0.0)
    ends = np.empty(headings.size, dtype=np.complex128)
    _move_ends(complex(start), headings, distances, ends)
    bearings_start = bearings_from(start, headings, targets)
    bearings_end = np.where(known, bearings_from(ends, headings, targets), bearings_start)
    bearings_start = sensor(bearings_start, np.full(headings.shape, start), headings)
    bearings_end = sensor(bearings_end, ends, headings)
    trials = _scratch_batch(slam, count, scratch)
    potentials = np.empty(count, dtype=np.float64)
    # Bearings made here are finite float arrays of the batch's shape (or NaN, a miss).
    _core._score_readings(
        slam.batch._kernel_state(), slam.index, slam.batch._kernel_params(False), moving,
        np.ascontiguousarray(bearings_start, dtype=np.float64),
        np.ascontiguousarray(bearings_end, dtype=np.float64), float(area_cap), AREA_FLOOR,
        bool(log_area), trials._kernel_state(), potentials,
    )  # fmt: skip
    return potentials


def _scratch_batch(
    slam: PolygonSLAM, count: int, scratch: dict[int, BatchedPolygonSLAM] | None
) -> BatchedPolygonSLAM:
    """A batch of ``count`` maps of ``slam``'s settings for the candidates' copies: the one
    kept in ``scratch`` under ``count``, or a new one (kept there)."""
    trials = None if scratch is None else scratch.get(count)
    if trials is None or not trials.same_settings(slam.batch):
        trials = slam.batch.empty_like(max(count, 1))
        if scratch is not None:
            scratch[count] = trials
    return trials


def _simulate_natively(
    slam: PolygonSLAM,
    start: complex,
    landmarks: NDArray[np.complex128],
    headings: FloatArray,
    distances: FloatArray,
    area_cap: float,
    min_distance: float,
    log_area: bool,
    scratch: dict[int, BatchedPolygonSLAM] | None,
) -> FloatArray:
    """:func:`simulate_potentials` without a sensor, in one native call (the same bits):
    the candidates' copies of the map go to a scratch batch of one map per candidate,
    kept in ``scratch`` under the candidate count."""
    batch, count = slam.batch, headings.size
    trials = _scratch_batch(slam, count, scratch)
    potentials = np.empty(count, dtype=np.float64)
    _core._simulate_potentials(
        batch._kernel_state(), slam.index, batch._kernel_params(False), complex(start),
        np.ascontiguousarray(landmarks, dtype=np.complex128), headings, distances,
        float(min_distance), float(area_cap), AREA_FLOOR, bool(log_area),
        trials._kernel_state(), potentials,
    )  # fmt: skip
    return potentials


def _scratch_of(
    maps: BatchedPolygonSLAM, size: int, batches: dict[tuple[str, int], BatchedPolygonSLAM]
) -> BatchedPolygonSLAM:
    """The beam's batch of ``size`` expansions (of ``maps``' settings), kept in ``batches``."""
    trials = batches.get(("trials", size))
    if trials is None or not trials.same_settings(maps):
        trials = batches["trials", size] = maps.empty_like(size)
    return trials


def _score_rows(
    maps: BatchedPolygonSLAM,
    rows: NDArray[np.int64],
    b1: FloatArray,
    b2: FloatArray,
    area_cap: float,
    trials: BatchedPolygonSLAM,
) -> FloatArray:
    """The potential after each expansion: ``trials``' map i a copy of ``maps``' map
    rows[i] fused from the readings b1[i], b2[i] (copies, updates and potentials in one
    native call, split over threads for a large batch)."""
    n = maps.n_landmarks
    potentials = np.empty(rows.size, dtype=np.float64)
    _core._score_rows(
        maps._kernel_state(), rows.astype(np.int64), maps._kernel_params(False),
        np.ascontiguousarray(b1.reshape(-1, n), dtype=np.float64),
        np.ascontiguousarray(b2.reshape(-1, n), dtype=np.float64), float(area_cap),
        AREA_FLOOR, True, trials._kernel_state(), potentials,
        threads() if rows.size >= PARALLEL_MIN_MAPS else 1,
    )  # fmt: skip
    return potentials


def landmark_positions_fl(slam: PolygonSLAM) -> NDArray[np.complex128]:
    """The map's landmark positions in FL (n,): L1 = 0, L2 = 1, then the estimates (NaN
    where not initialised)."""
    estimates = slam.estimates
    mapped = estimates[:, 0] + 1j * estimates[:, 1]
    return np.concatenate([[0.0 + 0.0j, 1.0 + 0.0j], mapped])


@dataclass(frozen=True)
class Worlds:
    """The hypothesised worlds a plan is scored in (all in FL)."""

    #: Landmark positions (H, n): L1 = 0, L2 = 1, then one position per mapped landmark
    #: (NaN where it has no region yet).
    landmarks: ComplexArray
    #: The robot's position in each world (H,).
    positions: ComplexArray


def sample_in_polygon(vertices: ComplexArray, count: int, rng: np.random.Generator) -> ComplexArray:
    """``count`` points drawn uniformly inside a convex polygon (its vertices, in order)."""
    if vertices.size < 3:
        return np.full(count, vertices.mean() if vertices.size else complex(np.nan, np.nan))
    # A fan of triangles from vertex 0, chosen by area, then a uniform point in each.
    a, b, c = vertices[0], vertices[1:-1], vertices[2:]
    areas = np.abs(((b - a).conjugate() * (c - a)).imag)
    total = float(areas.sum())
    if total <= 0.0:
        return np.full(count, vertices.mean())
    triangle = rng.choice(areas.size, size=count, p=areas / total)
    u, v = rng.random(count), rng.random(count)
    flip = u + v > 1.0
    u, v = np.where(flip, 1.0 - u, u), np.where(flip, 1.0 - v, v)
    return np.asarray(a + u * (b[triangle] - a) + v * (c[triangle] - a))


#: Distances (nodes, K, H) in FL units travelled by each candidate from each node's
#: positions (nodes, H) with headings (nodes, K).
Mover = Callable[[ComplexArray, FloatArray, FloatArray], FloatArray]


def beam_search(
    slam: PolygonSLAM,
    worlds: Worlds,
    heading: float,
    turns: FloatArray,
    lengths: FloatArray,
    first_allowed: NDArray[np.bool_],
    mover: Mover,
    depth: int,
    width: int,
    area_cap: float,
    scratch: dict[tuple[str, int], BatchedPolygonSLAM] | None = None,
    sensor: Sensor | None = None,
) -> tuple[int, float]:
    """The index of the first candidate of the best plan, and that plan's mean score.

    Candidates are ``(turns[k], lengths[k])`` (turn relative to the heading, length in
    metres); only the ``first_allowed`` ones may start a plan. Each depth's expansions
    are one native call (:func:`_score_rows`: the bearings are made here) on copies of the
    beam's maps; ``scratch``: the caller's batches of copies
    by role and size, kept between calls and refilled in place
    (:meth:`BatchedPolygonSLAM.take`) instead of made anew at each depth. ``sensor``
    predicts the readings' misses (its landmarks are the worlds'; None: every landmark
    seen).
    """
    batches: dict[tuple[str, int], BatchedPolygonSLAM] = {} if scratch is None else scratch
    n_worlds = worlds.positions.size
    known = np.isfinite(worlds.landmarks)  # (H, n)
    targets = np.where(known, worlds.landmarks, 0.0)
    maps = slam.replicate(n_worlds, into=batches.get(("root", n_worlds)))  # node 0, per world
    batches["root", n_worlds] = maps
    positions = worlds.positions[None, :]  # (nodes, H)
    headings = np.array([heading])  # (nodes,)
    firsts = np.array([-1])
    best_first, best_score = -1, math.inf
    for level in range(depth):
        allowed = first_allowed if level == 0 else np.ones(turns.size, dtype=bool)
        ks = np.flatnonzero(allowed)
        n_nodes, n_k = positions.shape[0], ks.size
        new_headings = headings[:, None] + turns[ks][None, :]  # (nodes, K)
        distances = mover(positions, new_headings, lengths[ks])  # (nodes, K, H)
        step = distances * np.exp(1j * new_headings)[:, :, None]
        starts = np.broadcast_to(positions[:, None, :], step.shape)
        ends = starts + step
        heading_grid = np.broadcast_to(new_headings[:, :, None], step.shape)
        b1 = bearings_from(starts, heading_grid, targets[None, None, :, :])
        b2 = bearings_from(ends, heading_grid, targets[None, None, :, :])
        # A landmark without a region, or a move too short, gives no information.
        moving = (distances > 0.0)[..., None] & known[None, None, :, :]
        b2 = np.where(moving, b2, b1)
        if sensor is not None:
            b1, b2 = sensor(b1, starts, heading_grid), sensor(b2, ends, heading_grid)
        rows = np.arange(n_nodes)[:, None, None] * n_worlds + np.arange(n_worlds)[None, None, :]
        rows = np.broadcast_to(rows, step.shape).reshape(-1)
        trials = _scratch_of(maps, rows.size, batches)
        potentials = _score_rows(maps, rows, b1, b2, area_cap, trials)
        potentials = potentials.reshape(n_nodes, n_k, n_worlds)
        scores = potentials.mean(axis=2)  # (nodes, K)
        node_firsts = np.where(firsts[:, None] < 0, ks[None, :], firsts[:, None])
        order = np.argsort(scores, axis=None, kind="stable")
        best = int(order[0])
        best_first, best_score = int(node_firsts.reshape(-1)[best]), float(scores.reshape(-1)[best])
        if level == depth - 1:
            break
        keep = order[: min(width, order.size)]
        node_index, k_index = np.unravel_index(keep, scores.shape)
        chosen = (node_index * n_k + k_index)[:, None] * n_worlds + np.arange(n_worlds)[None, :]
        chosen_rows = chosen.reshape(-1).astype(np.int64)
        maps = trials.take(chosen_rows, into=batches.get(("beam", chosen_rows.size)))
        batches["beam", chosen_rows.size] = maps
        positions = ends[node_index, k_index]
        headings = new_headings[node_index, k_index]
        firsts = node_firsts[node_index, k_index]
    return best_first, best_score
