"""The structures the update kernels take, each spelled once.

* :class:`State`: a batch's per-map state arrays (every one with the map axis first).
  Its field list is the only place the state is listed;
  ``bearing_env.slam.batch.STATE_ARRAYS`` is ``State._fields``. The native update takes
  it as a :class:`MapState` (:func:`state_ref`): the arrays checked once (dtype, shape,
  contiguity) and kept, so each call passes one reference.
* :class:`Params`: the update's settings (native, validated), with the transfer, the
  inconsistency policy and the fusion as the codes below (indices into ``TRANSFERS``,
  ``INCONSISTENCY_POLICIES`` and ``FUSIONS``), and whether the robot is transferred.
* :class:`Outputs`: what one call reports per updated map.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from bearing_env._core import (
    FUSION_INTERSECT,
    FUSION_RELAXED,
    FUSION_ROBUST,
    INCONSISTENCY_KEEP,
    INCONSISTENCY_RESTART,
    TRANSFER_CONSERVATIVE,
    TRANSFER_CONSERVATIVE_GLOBAL,
    TRANSFER_PAPER,
    MapState,
    Params,
)

ComplexArray = NDArray[np.complex128]
IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


class State(NamedTuple):
    """A batch's state, one array per field, the map axis first (m: mapped landmarks,
    w: the relaxed fusion's window, 0 under ``"intersect"``)."""

    vertices: ComplexArray  #: (maps, m, CAPACITY) the landmarks' regions
    counts: IntArray  #: (maps, m) their vertex counts (0: not initialised)
    areas: FloatArray  #: (maps, m)
    centroids: ComplexArray  #: (maps, m)
    robot_vertices: ComplexArray  #: (maps, CAPACITY) the robot's region
    robot_counts: IntArray  #: (maps,)
    robot_area: FloatArray  #: (maps,)
    robot_centroid: ComplexArray  #: (maps,)
    robot_heading: FloatArray  #: (maps,)
    n_updates: IntArray  #: (maps,) movements fused
    n_frame_changes: IntArray  #: (maps,) of which changed frames
    n_inconsistent: IntArray  #: (maps,) inconsistent landmark regions so far
    window_vertices: ComplexArray  #: (maps, w, m, CAPACITY) the window's regions
    window_counts: IntArray  #: (maps, w, m)
    window_inlier: BoolArray  #: (maps, w, m) kept by the landmark's region
    window_rejected: BoolArray  #: (maps, w) the movement is left out for every landmark
    window_length: IntArray  #: (maps,) movements in the window
    window_next: IntArray  #: (maps,) the slot the next movement goes to
    base_vertices: ComplexArray  #: (maps, m, CAPACITY or 0) inliers older than the window
    base_counts: IntArray  #: (maps, m)
    n_dropped: IntArray  #: (maps, m) regions left out for good
    outliers: IntArray  #: (maps, m) regions left out, window included
    level_vertices: ComplexArray  #: (maps, m, levels, CAPACITY) the robust fusion's levels
    level_counts: IntArray  #: (maps, m, levels) (levels: 0 unless ``"robust"``)
    n_regions: IntArray  #: (maps, m) regions fused into the robust levels
    robot_fixed_at: IntArray  #: (maps,) the movement (``n_updates``) that set the robot region
    # The robust fusion's noise-bound estimate (h: ``HISTORY`` under ``"robust"``, else 0).
    noise_scale: FloatArray  #: (maps,) the bound fused with, over the nominal epsilon
    bound_events: IntArray  #: (maps,) times the probe found the bound too small
    probe_vertices: ComplexArray  #: (maps, m, CAPACITY or 0) the probe's regions
    probe_counts: IntArray  #: (maps, m)
    history_frame_bearings: FloatArray  #: (maps, h, 2, 2) L1's and L2's, at R1 then R2
    history_bearings: FloatArray  #: (maps, h, 2, m) the mapped landmarks', at R1 then R2
    history_length: IntArray  #: (maps,) movements in the history
    history_next: IntArray  #: (maps,) the slot the next movement goes to


def state_ref(state: State) -> MapState:
    """The native update's reference to ``state``'s arrays (checked once; not copies)."""
    return MapState(state)


class Outputs(NamedTuple):
    """What one call did, per bearings row ``i`` (the map ``rows[i]``)."""

    frame_status: NDArray[np.int8]  #: (rows,) a FRAME_* code
    landmark_status: NDArray[np.int8]  #: (rows, m) a LANDMARK_* code
    n_bad: IntArray  #: (rows,) landmarks found inconsistent by this movement


__all__ = [
    "FUSION_INTERSECT",
    "FUSION_RELAXED",
    "FUSION_ROBUST",
    "INCONSISTENCY_KEEP",
    "INCONSISTENCY_RESTART",
    "TRANSFER_CONSERVATIVE",
    "TRANSFER_CONSERVATIVE_GLOBAL",
    "TRANSFER_PAPER",
    "MapState",
    "Outputs",
    "Params",
    "State",
    "state_ref",
]
