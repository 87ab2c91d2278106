"""Constants, compile options and scalar helpers shared by every kernel module.

Points are complex numbers (x + iy). Every kernel of :mod:`bearing_env.slam.kernels` is
compiled with :data:`_JIT` (``cache=True``: the machine code is kept beside its module,
or in numba's user-wide cache directory when the package folder is read-only, or in
``NUMBA_CACHE_DIR`` when that is set).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any, cast

import numba
import numpy as np
from numba import njit

from bearing_env.numerics import JIT_OPTIONS, JitOptions

#: Most vertices a map region holds (conservative hulls measured up to 107).
CAPACITY = 128
#: Most samples per edge of A_L1 and A_L2 the conservative transfer uses.
MAX_EDGE_SAMPLES = 8
#: Vertices of a robot-frame region: the intersection of two cones has at most four.
FR_VERTICES = 4
#: Most hypotheses per region: (4 edges x MAX_EDGE_SAMPLES samples) per region of L1, L2.
MAX_SAMPLES = FR_VERTICES * MAX_EDGE_SAMPLES
MAX_PAIRS = MAX_SAMPLES * MAX_SAMPLES
#: Room for a polygon before it is reduced to CAPACITY (clipping two CAPACITY-gons gives at
#: most 2 * CAPACITY vertices; offsetting adds at most 3 bevels).
SCRATCH = 2 * CAPACITY + 8
#: Largest point cloud: a robot-frame region's vertices under every hypothesis pair.
MAX_CLOUD = FR_VERTICES * MAX_PAIRS

#: FR-region vertices farther than this (in FR units, |R1 R2| = 1) mean near-parallel
#: cones: the region is numerically unbounded and carries no usable information.
MAX_FR_EXTENT = 1e4

#: Relative tolerance of the polygon predicates (times the polygons' scale).
RELATIVE_TOLERANCE = 1e-12

FR_BOUNDED = 0
FR_UNBOUNDED = 1
FR_EMPTY = 2
FR_MISSING = 3

#: Frame-change codes (indices into batch.FRAME_STATUSES).
FRAME_OK = 0
FRAME_L1_UNBOUNDED = 1
FRAME_L2_UNBOUNDED = 2
FRAME_L1_L2_OVERLAP = 3
FRAME_L1_L2_TOO_CLOSE = 4
FRAME_L1_MISSING = 5
FRAME_L2_MISSING = 6
FRAME_REJECTED = 7

#: Landmark codes (indices into batch.LANDMARK_STATUSES).
LANDMARK_UPDATED = 0
LANDMARK_UNBOUNDED = 1
LANDMARK_INCONSISTENT = 2
LANDMARK_SKIPPED = 3
LANDMARK_MISSING = 4

#: The relaxed fusion keeps at most this many movements per map in its window.
MAX_WINDOW = 32


#: The options every kernel is compiled with (one home: :mod:`bearing_env.numerics`).
_JIT: JitOptions = JIT_OPTIONS

# OpenMP's default busy-waiting made prange several times slower than serial code on a
# 2-core machine; numba's own workqueue layer waits passively. A layer chosen by the user
# (NUMBA_THREADING_LAYER) is left alone.
if "NUMBA_THREADING_LAYER" not in os.environ:
    # why: numba.config defines its settings at import through globals(), unseen by mypy
    numba.config.THREADING_LAYER = "workqueue"  # type: ignore[attr-defined]

# numba's parallel runtime starts here, before any kernel is loaded from the cache (about
# 20 ms). A cached kernel that calls the parallel update (the env's step) holds a copy of
# it, and its cache entry starts the runtime on loading only if the parallel update was
# compiled in the process that compiled the kernel: compiled where it came from the cache
# (another process, or an edit that emptied one module's cache), the entry is saved
# without, and loading it in a fresh process left the runtime's symbols unresolved, so
# the step called address 0 (a segfault; see the performance page's compile notes).
numba.get_num_threads()


def entry_point(dispatcher: Any, args: tuple[Any, ...]) -> Callable[..., Any]:
    """The compiled function ``dispatcher`` runs for the types of ``args`` (compiled, or
    loaded from the cache, first if need be), to be called directly with arguments of
    exactly those types.

    A dispatcher types every argument in Python on each call: about 4 us each for a
    structref or a namedtuple (measured), so about 15 us of a 4-landmark update's call
    went to typing its state, settings and outputs. The compiled function only unboxes
    them. It checks no type: callers pass arrays they made themselves, of the types they
    were resolved with. Falls back on the dispatcher if numba's internals (``overloads``,
    ``entry_point``) are not as expected.
    """
    try:
        key = tuple(dispatcher.typeof_pyval(arg) for arg in args)
        if key not in dispatcher.overloads:
            dispatcher.compile(key)
        return cast(Callable[..., Any], dispatcher.overloads[key].entry_point)
    except (AttributeError, KeyError, TypeError):  # why: numba's dispatcher is not public API
        return cast(Callable[..., Any], dispatcher)


def threads() -> int:
    """Threads the batched update may use: numba's current thread count."""
    return int(numba.get_num_threads())


@njit(**_JIT)
def cross(a: complex, b: complex) -> float:
    """2-D cross product ``a.x * b.y - a.y * b.x``."""
    return a.real * b.imag - a.imag * b.real


@njit(**_JIT)
def dot(a: complex, b: complex) -> float:
    return a.real * b.real + a.imag * b.imag


@njit(**_JIT)
def scale_of(poly: np.ndarray, n: int) -> tuple[float, float]:
    """(bounding-box size, largest coordinate magnitude) of ``poly[:n]``."""
    lo_x = hi_x = poly[0].real
    lo_y = hi_y = poly[0].imag
    for i in range(1, n):
        x, y = poly[i].real, poly[i].imag
        lo_x, hi_x = min(lo_x, x), max(hi_x, x)
        lo_y, hi_y = min(lo_y, y), max(hi_y, y)
    size = max(hi_x - lo_x, hi_y - lo_y)
    magnitude = max(max(abs(lo_x), abs(hi_x)), max(abs(lo_y), abs(hi_y)))
    return size, magnitude


@njit(**_JIT)
def tolerance_of(size: float, magnitude: float) -> float:
    """Distance below which two features count as touching, for polygons of that scale."""
    return RELATIVE_TOLERANCE * size + 4e-16 * magnitude
