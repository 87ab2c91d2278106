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
from bearing_env._schema import Report, Settings

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
