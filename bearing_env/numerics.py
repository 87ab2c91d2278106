"""Low-level numerics shared by the simulator (``bearing_env.world``) and the estimator
(``bearing_env.slam``): this module sits below both, so neither imports the other.

* :func:`wrap`: one angle wrapped to [-pi, pi), native (the same function as the C++
  kernels use, ``csrc/include/bearing_core/core/pymath.hpp``);
* :func:`wrap_angle`: the same for arrays, in numpy.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env._core import wrap as wrap

TWO_PI = 2.0 * math.pi


def wrap_angle(angle: ArrayLike) -> NDArray[np.float64]:
    """Wrap angles (any shape) to [-pi, pi)."""
    return np.asarray((np.asarray(angle, dtype=np.float64) + math.pi) % TWO_PI - math.pi)
