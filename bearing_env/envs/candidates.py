"""The planner features (``planner_features=True``): for every move of the action grid,
what a one-step planner predicts of it from the robot's own map and believed pose.

The candidates are the discrete action grid's moves (``n_turns`` x ``n_move_lengths``,
candidate ``k`` is ``BearingSLAMDiscrete``'s action ``k``: :func:`candidate_moves`), so a
policy on the discrete id executes candidate ``k`` by sending ``k``. For each candidate
the observation carries :data:`CANDIDATE_FEATURES`:

- ``predicted``: 1 when the robot has a pose to predict from (a map fix and an FL
  scale: :class:`~bearing_env.belief.PoseBeliefs`), else 0 and the next three are 0;
- ``gain``: the predicted decrease of the uncertainty potential (the reward's
  potential before the move minus after it): the move simulated on a copy of the map
  with noise-free bearings from the believed pose to L1 = 0, L2 = 1 and the landmark
  estimates (a landmark without a region gets no predicted progress), as
  ``GreedyOneStep`` scores moves; 0 for a move shorter than ``min_baseline``, which
  does not update the map;
- ``sees_l1``, ``sees_l2``: whether the sensor is predicted to see L1 and L2 at both
  readings of the move (its field of view about the move's direction and its range,
  with the believed scale; always 1 with the panoramic camera);
- ``blocked``: whether the move is predicted to be stopped: the robot does not know
  where the walls are, only that the last move was stopped ahead, so a move within
  :data:`BLOCKED_AHEAD` of straight ahead after a stopped one is predicted blocked.

Every sub-env's candidates are scored in one native call (copies, updates and
potentials: ``_core._score_rows``) after the batched step. Nothing here reads ground
truth: the map, the readings the robot took, and its commands.
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from bearing_env import _core
from bearing_env.envs.actions import grid_tables
from bearing_env.envs.config import AREA_FLOOR, EnvConfig
from bearing_env.slam import BatchedPolygonSLAM
from bearing_env.slam import kernels as slam_kernels
from bearing_env.slam.batch import PARALLEL_MIN_MAPS

if TYPE_CHECKING:
    from bearing_env.envs.state import BatchState

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: The features of each candidate, in order (see the module doc).
CANDIDATE_FEATURES: tuple[str, ...] = ("predicted", "gain", "sees_l1", "sees_l2", "blocked")
_PREDICTED, _GAIN, _SEES_L1, _SEES_L2, _BLOCKED = range(len(CANDIDATE_FEATURES))
#: After a stopped move, a move turning less than this is predicted blocked (radians).
BLOCKED_AHEAD = math.pi / 3


def candidate_moves(config: EnvConfig) -> tuple[FloatArray, FloatArray]:
    """The candidates' (turns (K,), lengths (K,)): the discrete action grid's moves, in
    its order (candidate ``k`` is action ``k``), read-only (made once per grid)."""
    grid = config.actions
    lo, hi = grid.move_length
    return _grid_moves_of(grid.n_turns, grid.n_move_lengths, float(lo), float(hi))


@functools.lru_cache(maxsize=64)
def _grid_moves_of(
    n_turns: int, n_move_lengths: int, lo: float, hi: float
) -> tuple[FloatArray, FloatArray]:
    turns, lengths = grid_tables(n_turns, n_move_lengths, lo, hi)
    moves = np.repeat(turns, lengths.size), np.tile(lengths, turns.size)
    for values in moves:
        values.flags.writeable = False
    return moves


def candidate_count(config: EnvConfig) -> int:
    """K, the candidates per observation."""
    return int(config.actions.n_turns * config.actions.n_move_lengths)


def features_size(config: EnvConfig) -> int:
    """The planner features' length in the flat observation (0 with the option off)."""
    if not config.observations.planner_features:
        return 0
    return candidate_count(config) * len(CANDIDATE_FEATURES)


def gain_limit(config: EnvConfig) -> float:
    """The largest |gain| the potential allows: every landmark slot from the cap to the
    floor (log-areas) or from the cap to 0 (areas)."""
    slots = config.observations.max_landmarks - 2
    if config.task.reward == "log_area":
        return slots * (math.log(config.task.area_cap) - math.log(AREA_FLOOR))
    return slots * float(config.task.area_cap)


def feature_bounds(config: EnvConfig) -> tuple[FloatArray, FloatArray]:
    """The features' (low, high) over the K candidates, flattened."""
    limit = gain_limit(config)
    low = np.tile([0.0, -limit, 0.0, 0.0, 0.0], candidate_count(config))
    high = np.tile([1.0, limit, 1.0, 1.0, 1.0], candidate_count(config))
    return low, high


def write_features(
    state: BatchState,
    rows: IntArray,
    batch: BatchedPolygonSLAM,
    config: EnvConfig,
    before: FloatArray,
    out: NDArray[np.float32],
    scratch: dict[Any, Any],
) -> None:
    """The planner features of ``rows`` (one landmark count, maps in ``batch``) into
    ``out`` (len(rows), K * len(CANDIDATE_FEATURES)), from their current potentials
    ``before``. ``scratch`` keeps the candidates' map copies between calls."""
    turns, lengths = candidate_moves(config)
    features = np.zeros((rows.size, turns.size, len(CANDIDATE_FEATURES)))
    ahead = np.abs(turns) < BLOCKED_AHEAD
    features[:, :, _BLOCKED] = state.blocked[rows][:, None] & ahead[None, :]
    position, heading, scale, ready = state.beliefs.poses(
        rows, batch.robot_centroid[rows], batch.robot_heading[rows]
    )
    if ready.any():
        after, sees = _predict(
            batch, rows[ready], (position, heading, scale), before[ready],
            (turns, lengths), config, scratch,
        )  # fmt: skip
        predicted = features[ready]
        predicted[:, :, _PREDICTED] = 1.0
        predicted[:, :, _GAIN] = before[ready][:, None] - after
        predicted[:, :, _SEES_L1] = sees[:, :, 0]
        predicted[:, :, _SEES_L2] = sees[:, :, 1]
        features[ready] = predicted
    limit = gain_limit(config)
    np.clip(features[:, :, _GAIN], -limit, limit, out=features[:, :, _GAIN])
    out[:] = features.reshape(rows.size, -1)


def _predict(
    batch: BatchedPolygonSLAM,
    rows: IntArray,
    poses: tuple[NDArray[np.complex128], FloatArray, FloatArray],
    before: FloatArray,
    moves: tuple[FloatArray, FloatArray],
    config: EnvConfig,
    scratch: dict[Any, Any],
) -> tuple[FloatArray, NDArray[np.bool_]]:
    """The potential after each candidate (R, K) of each row's map from its believed pose
    (position, heading in FL, metres per FL unit: (R,) each), and whether L1 and L2 are
    predicted seen at both readings (R, K, 2). A move shorter than ``min_baseline`` does
    not update the map: its potential stays ``before``."""
    (position, heading, scale), (turns, lengths) = poses, moves
    n, count = batch.n_landmarks, turns.size
    headings = heading[:, None] + turns[None, :]  # (R, K)
    ends = position[:, None] + lengths[None, :] / scale[:, None] * np.exp(1j * headings)
    landmarks = np.empty((rows.size, n), dtype=np.complex128)  # (R, n), FL: L1, L2, the rest
    landmarks[:, 0], landmarks[:, 1] = 0.0, 1.0
    landmarks[:, 2:] = np.where(batch.counts[rows] > 0, batch.centroids[rows], np.nan + 0j)
    known = np.isfinite(landmarks)
    targets = np.where(known, landmarks, 0.0)
    # Both readings' bearings in one native call: from the start (0) and the end (1).
    places = np.empty((2, *headings.shape), dtype=np.complex128)
    places[0], places[1] = position[:, None], ends
    differences = targets[None, :, None, :] - places[..., None]  # (2, R, K, n)
    angles = np.empty(differences.shape)
    angles[...] = headings[None, :, :, None]
    bearings = np.empty(differences.shape)
    _core._bearings_of(differences.reshape(-1), angles.reshape(-1), bearings.reshape(-1))
    b1 = bearings[0]
    # A landmark without a region gives no information: the same bearing at both ends.
    b2 = np.where(known[:, None, :], bearings[1], b1)
    sensor = config.sensor
    if sensor.half_fov < math.pi or math.isfinite(sensor.max_range):
        limits = (scale, sensor.half_fov, sensor.max_range)
        b1 = _missed(b1, places[0][:, :, None], targets[:, None, :], *limits)
        b2 = _missed(b2, ends[:, :, None], targets[:, None, :], *limits)
    sees = np.isfinite(b1[:, :, :2]) & np.isfinite(b2[:, :, :2])
    after = np.repeat(before[:, None], count, axis=1)
    moving = np.flatnonzero(lengths >= config.layout.arena.min_baseline)
    size = rows.size * moving.size
    if size == 0:
        return after, sees
    trials = scratch.get(("candidates", size))
    if trials is None or not trials.same_settings(batch):
        trials = scratch["candidates", size] = batch.empty_like(size)
    potentials = np.empty(size)
    if moving.size < count:
        b1, b2 = b1[:, moving], b2[:, moving]
    _core._score_rows(
        batch._kernel_state(), np.repeat(rows, moving.size), batch._kernel_params(False),
        np.ascontiguousarray(b1).reshape(size, n), np.ascontiguousarray(b2).reshape(size, n),
        float(config.task.area_cap), AREA_FLOOR, config.task.reward == "log_area",
        trials._kernel_state(), potentials,
        slam_kernels.threads() if size >= PARALLEL_MIN_MAPS else 1,
    )  # fmt: skip
    after[:, moving] = potentials.reshape(rows.size, moving.size)
    return after, sees


def _missed(
    bearings: FloatArray,
    positions: NDArray[np.complex128],
    targets: NDArray[np.complex128],
    scale: FloatArray,
    half_fov: float,
    max_range: float,
) -> FloatArray:
    """``bearings`` (R, K, n) with NaN where the sensor is predicted to miss: outside the
    field of view, or farther than the range (FL distances times the believed scale)."""
    ranges = np.abs(targets - positions) * scale[:, None, None]
    seen = (np.abs(bearings) <= half_fov) & (ranges <= max_range)
    return np.where(seen, bearings, np.nan)
