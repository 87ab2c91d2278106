"""The structures the update kernels take, each spelled once.

* :class:`State`: a batch's per-map state arrays (every one with the map axis first).
  Its field list is the only place the state is listed;
  ``bearing_env.slam.batch.STATE_ARRAYS`` is ``State._fields``. The kernels receive it
  as a :class:`StateRef` (a numba ``structref`` holding the same arrays): a batch builds
  its reference once and passes it on every call. A namedtuple of the (then) 22 arrays was
  measured to cost about 4.5 us more per call than the structref (numba types each
  field of a namedtuple argument in Python on every call; a structref is typed once),
  about a sixth of a 4-landmark update.
* :class:`Params`: the update's settings, with the transfer, the inconsistency policy
  and the fusion as the codes below (indices into ``TRANSFERS``, ``INCONSISTENCY_POLICIES``
  and ``FUSIONS``), and whether the robot is transferred.
* :class:`Outputs`: what one call reports per updated map.
* :class:`Scratch`: the polygon buffers one thread of the update works in.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
from numba import njit
from numba.core import types
from numba.experimental import structref
from numpy.typing import NDArray

from bearing_env.slam.kernels.common import _JIT, MAX_CLOUD, MAX_WINDOW, SCRATCH

#: Transfer codes: indices into ``bearing_env.slam.transfer.TRANSFERS``.
TRANSFER_CONSERVATIVE = 0
TRANSFER_PAPER = 1
#: Inconsistency-policy codes: indices into ``batch.INCONSISTENCY_POLICIES``.
INCONSISTENCY_RESTART = 0
INCONSISTENCY_KEEP = 1
#: Fusion codes: indices into ``batch.FUSIONS``.
FUSION_INTERSECT = 0
FUSION_RELAXED = 1
FUSION_ROBUST = 2

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


@structref.register
class StateType(types.StructRef):
    """numba's type of a :class:`StateRef`: one field per :class:`State` field."""

    def preprocess_fields(self, fields: Any) -> tuple[tuple[str, Any], ...]:
        # why (each ignore below): these numba functions carry no annotations
        return tuple((name, types.unliteral(typ)) for name, typ in fields)  # type: ignore[no-untyped-call]


class StateRef(structref.StructRefProxy):
    """A :class:`State` as the kernels take it: one reference to the same arrays."""


structref.define_constructor(StateRef, StateType, State._fields)  # type: ignore[no-untyped-call]
structref.define_boxing(StateType, StateRef)  # type: ignore[no-untyped-call]


@njit(**_JIT)
def state_ref(state: State) -> State:
    """The :class:`StateRef` of a state (the same arrays, not copies).

    Annotated as :class:`State`, as the kernels' ``state`` parameters are: a StateRef
    has exactly State's fields, and the kernels only read them.
    """
    return StateRef(*state)  # type: ignore[no-untyped-call, return-value]


class Params(NamedTuple):
    """One update call's settings."""

    epsilon: float  #: bearing error bound, radians
    transfer: int  #: TRANSFER_CONSERVATIVE or TRANSFER_PAPER
    edge_samples: int  #: samples per edge of A_L1 and A_L2 (conservative transfer)
    on_inconsistency: int  #: INCONSISTENCY_RESTART or INCONSISTENCY_KEEP
    fusion: int  #: FUSION_INTERSECT, FUSION_RELAXED or FUSION_ROBUST
    max_outliers: int  #: relaxed fusion: most regions left out per landmark
    with_robot: bool  #: also transfer the robot's position
    risk: float  #: robust fusion: the binomial tail the reported level leaves
    likely: bool  #: robust fusion: report the likely set, not the guaranteed one
    estimate_bound: bool  #: robust fusion: estimate the noise bound (else keep epsilon)


class Outputs(NamedTuple):
    """What one call did, per bearings row ``i`` (the map ``rows[i]``)."""

    frame_status: NDArray[np.int8]  #: (rows,) a FRAME_* code
    landmark_status: NDArray[np.int8]  #: (rows, m) a LANDMARK_* code
    n_bad: IntArray  #: (rows,) landmarks found inconsistent by this movement


class Scratch(NamedTuple):
    """Polygon buffers of one thread: ``fresh`` takes a transferred region, ``fused``
    and ``work`` a clip's result and its working copy, ``cloud`` and ``hull`` a
    transfer's images and their hull, ``acc`` the relaxed fusion's union and ``slots``
    the window slots it combines."""

    fresh: ComplexArray
    fused: ComplexArray
    work: ComplexArray
    cloud: ComplexArray
    hull: ComplexArray
    acc: ComplexArray
    slots: IntArray


@njit(**_JIT)
def new_scratch() -> Scratch:
    """Buffers large enough for every kernel that takes a :class:`Scratch`."""
    return Scratch(
        np.empty(max(MAX_CLOUD + 1, SCRATCH), dtype=np.complex128),
        np.empty(SCRATCH, dtype=np.complex128),
        np.empty(SCRATCH, dtype=np.complex128),
        np.empty(MAX_CLOUD, dtype=np.complex128),
        np.empty(MAX_CLOUD + 1, dtype=np.complex128),
        np.empty(SCRATCH, dtype=np.complex128),
        np.empty(MAX_WINDOW, dtype=np.int64),
    )
