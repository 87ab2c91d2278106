"""The envs' step, native: a group of rows moves, reads, updates its maps, and gets its
rewards, terminations, observations and infos in one call of the C++ core
(``csrc/env/``, bound in :mod:`bearing_env._core`).

:func:`~bearing_env._core.step_rows` is the whole step; ``report_rows_into`` the
observations and infos alone (after a reset), into the same reused arrays.
:mod:`bearing_env.envs.core` calls them for the single env (a group of one row) and the
vector env alike, so both compute every number with the same code. The noise of the
readings is drawn ahead, in blocks, by each row's own generator (``core.fill_noise``)
into the rows' noise buffers, which the step reads by index.

A group's long-lived inputs (its :class:`Settings`, its maps' update settings, its map
batch's state and the envs' ``BatchState``) are checked once into a native
``EnvInputs``; its output arrays (a :class:`Report` and the robot map's encoded arrays)
are made once into a native ``StepOutputs`` and reused: what an env hands out of them,
it copies. This module keeps the Python structures and re-exports the kernels that other
modules call one by one.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from bearing_env._core import (
    ACTIONS_NOT_FINITE,
    ACTIONS_OK,
    ACTIONS_OUTSIDE,
    STEP_DONE,
    STEP_NEEDS_NOISE,
    STEP_NEEDS_TRAJECTORY,
    _write_shape,
    capped,
    decode_continuous,
    potential_of,
)

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


class Settings(NamedTuple):
    """A group's settings (one config, one landmark count), as the kernels take them."""

    n: int  #: landmarks of the group's rows
    n_slots: int  #: the observation's landmark slots (max_landmarks)
    shape_features: bool  #: the flat vector ends with the regions' shapes ("shapes" kind)
    width: float  #: the arena, metres
    height: float
    margin: float  #: the wall margin
    min_baseline: float  #: shortest move that changes frames
    log_area: bool  #: the reward's potential sums log-areas (else areas)
    floor: float  #: areas are floored here before taking logs
    cap: float  #: and capped here (area_cap)
    target_area: float  #: success: every landmark's area at most this
    max_moves: int
    path_cost: float  #: per metre
    move_cost: float  #: per move
    coordinate_limit: float  #: FL coordinates are clipped to +-this in the observation
    tolerance: float  #: relative tolerance of the info's containment test
    half_fov: float  #: half the sensor's field of view, radians (pi: panoramic)
    max_range: float  #: the sensor's range, metres (inf: no limit)
    obstacle_vertices: FloatArray  #: the obstacles, packed (see bearing_env.sensing)
    obstacle_starts: NDArray[np.int64]


class Report(NamedTuple):
    """What a step (or a reset) of a group gives, per row (arrays of the group's length):
    the observations, the rewards and episode ends, and the infos' arrays (see the env's
    Info section; the reward parts sum to the reward)."""

    observations: NDArray[np.float32]
    rewards: FloatArray
    terminated: BoolArray
    truncated: BoolArray
    frame_changed: BoolArray
    inconsistent: NDArray[np.int64]
    path_length: FloatArray
    uncertainty: FloatArray
    path_cost: FloatArray
    move_cost: FloatArray
    landmark_area: FloatArray
    landmark_error: FloatArray
    landmark_contains_truth: BoolArray
    total_area: FloatArray
    robot_error: FloatArray
    outliers: NDArray[np.int64]


__all__ = [
    "ACTIONS_NOT_FINITE",
    "ACTIONS_OK",
    "ACTIONS_OUTSIDE",
    "STEP_DONE",
    "STEP_NEEDS_NOISE",
    "STEP_NEEDS_TRAJECTORY",
    "Report",
    "Settings",
    "_write_shape",
    "capped",
    "decode_continuous",
    "potential_of",
]
