"""Low-level numerics shared by the simulator (``bearing_env.world``) and the estimator
(``bearing_env.slam``): this module sits below both, so neither imports the other.

* :data:`JIT_OPTIONS`: the options every compiled kernel of the project is built with;
* :func:`wrap`: one angle wrapped to [-pi, pi), compiled (callable from kernels and from
  Python);
* :func:`wrap_angle`: the same for arrays, in numpy.
"""

from __future__ import annotations

import math
from typing import Literal, TypedDict

import numpy as np
from numba import njit
from numpy.typing import ArrayLike, NDArray

TWO_PI = 2.0 * math.pi


class JitOptions(TypedDict):
    """The keyword options every kernel is compiled with (typed for ``njit(**JIT_OPTIONS)``)."""

    cache: bool
    nogil: bool
    error_model: Literal["python", "numpy"]


JIT_OPTIONS: JitOptions = {"cache": True, "nogil": True, "error_model": "numpy"}


@njit(**JIT_OPTIONS)
def wrap(angle: float) -> float:
    """Wrap an angle to [-pi, pi)."""
    return (angle + math.pi) % TWO_PI - math.pi


def wrap_angle(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles (any shape) to [-pi, pi)."""
    return np.asarray((np.asarray(angle, dtype=np.float64) + math.pi) % TWO_PI - math.pi)
