"""Constants and scalar helpers shared by every kernel topic, from the native core.

Points are complex numbers (x + iy). The kernels are C++17 (``csrc/slam/``), compiled
into :mod:`bearing_env._core` by the package's build; the constants here are read from
the native core, so the Python side and the kernels share one definition.

:func:`threads` is how many threads a large batch's update may use.
"""

from __future__ import annotations

import functools
import os

from bearing_env._core import (
    CAPACITY,
    FR_BOUNDED,
    FR_EMPTY,
    FR_MISSING,
    FR_UNBOUNDED,
    FR_VERTICES,
    FRAME_L1_L2_OVERLAP,
    FRAME_L1_L2_TOO_CLOSE,
    FRAME_L1_MISSING,
    FRAME_L1_UNBOUNDED,
    FRAME_L2_MISSING,
    FRAME_L2_UNBOUNDED,
    FRAME_OK,
    FRAME_REJECTED,
    LANDMARK_INCONSISTENT,
    LANDMARK_MISSING,
    LANDMARK_SKIPPED,
    LANDMARK_UNBOUNDED,
    LANDMARK_UPDATED,
    MAX_CLOUD,
    MAX_EDGE_SAMPLES,
    MAX_FR_EXTENT,
    MAX_LANDMARKS,
    MAX_PAIRS,
    MAX_SAMPLES,
    MAX_WINDOW,
    PARALLEL_MIN_MAPS,
    RELATIVE_TOLERANCE,
    SCRATCH,
    cross,
    dot,
    scale_of,
    tolerance_of,
)

#: The environment variable that sets :func:`threads` (a positive integer).
THREADS_VARIABLE = "BEARING_ENV_NUM_THREADS"


def threads() -> int:
    """Threads a large batch's update may use: ``BEARING_ENV_NUM_THREADS`` if set, else
    the CPUs this process may run on. The results never depend on it (each map is
    computed by the same code, whichever thread runs it)."""
    setting = os.environ.get(THREADS_VARIABLE)
    if setting is None:
        return _available_cpus()
    try:
        count = int(setting)
    except ValueError:
        count = 0
    if count < 1:
        raise ValueError(f"{THREADS_VARIABLE} must be a positive integer, got {setting!r}")
    return count


@functools.cache
def _available_cpus() -> int:
    """The CPUs this process may run on, read once (every batched step asks)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # why: no sched_getaffinity outside Linux
        return max(1, os.cpu_count() or 1)


__all__ = [
    "CAPACITY",
    "FRAME_L1_L2_OVERLAP",
    "FRAME_L1_L2_TOO_CLOSE",
    "FRAME_L1_MISSING",
    "FRAME_L1_UNBOUNDED",
    "FRAME_L2_MISSING",
    "FRAME_L2_UNBOUNDED",
    "FRAME_OK",
    "FRAME_REJECTED",
    "FR_BOUNDED",
    "FR_EMPTY",
    "FR_MISSING",
    "FR_UNBOUNDED",
    "FR_VERTICES",
    "LANDMARK_INCONSISTENT",
    "LANDMARK_MISSING",
    "LANDMARK_SKIPPED",
    "LANDMARK_UNBOUNDED",
    "LANDMARK_UPDATED",
    "MAX_CLOUD",
    "MAX_EDGE_SAMPLES",
    "MAX_FR_EXTENT",
    "MAX_LANDMARKS",
    "MAX_PAIRS",
    "MAX_SAMPLES",
    "MAX_WINDOW",
    "PARALLEL_MIN_MAPS",
    "RELATIVE_TOLERANCE",
    "SCRATCH",
    "THREADS_VARIABLE",
    "cross",
    "dot",
    "scale_of",
    "threads",
    "tolerance_of",
]
