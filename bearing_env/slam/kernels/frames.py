"""Cones in the robot frame FR and the change of frames FR -> FL (see
:mod:`bearing_env.slam.transfer` for the method and its proof).

The kernels are C++ (``csrc/slam/frames.cpp``); these are their bindings, and
:class:`FrameChange`, one movement's change of frames as :func:`transfer_region` takes it.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from bearing_env._core import (
    boundary_samples,
    cone_region,
    frame_plan,
    sample_hypotheses,
    sub_square_growths,
    transfer_polygon,
    transfer_region,
)

ComplexArray = NDArray[np.complex128]


class FrameChange(NamedTuple):
    """One movement's change of frames FR -> FL, as :func:`transfer_region` applies it:
    the FR regions of L1 and L2, the hypothesis pairs of :func:`sample_hypotheses`, and
    the conservative bound's terms from :func:`frame_plan`."""

    a1: ComplexArray  #: the FR region of L1 (``a1[:n1]``)
    n1: int
    a2: ComplexArray  #: the FR region of L2 (``a2[:n2]``)
    n2: int
    h1: ComplexArray  #: hypotheses ``h1`` (``h1[:n_pairs]``)
    inv_d: ComplexArray  #: their ``1 / (h2 - h1)``
    n_pairs: int
    #: grow the hull by the global bound (else the paper's hull); the local bound needs
    #: the movement's sub-squares, which :func:`transfer_polygon` plans
    conservative: bool
    distance: float  #: distance between the regions of L1 and L2
    delta1: float  #: sample spacing on L1's edges
    delta2: float


__all__ = [
    "FrameChange",
    "boundary_samples",
    "cone_region",
    "frame_plan",
    "sample_hypotheses",
    "sub_square_growths",
    "transfer_polygon",
    "transfer_region",
]
