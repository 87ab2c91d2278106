"""The compiled core of the world model (numba), one module per topic.

* :mod:`~bearing_env.slam.kernels.common`: capacities, status codes, compile options,
  the threading layer, and scalar helpers (``wrap``, ``cross``, tolerances).
* :mod:`~bearing_env.slam.kernels.polygons`: convex polygons in fixed-capacity arrays:
  hulls, area and centroid, containment, distances, simplification, capacity
  reduction, clipping and outward offsets.
* :mod:`~bearing_env.slam.kernels.frames`: a landmark's cone region in the robot frame
  FR, and the change of frames FR -> FL (frame plan, hypotheses, transfer).
* :mod:`~bearing_env.slam.kernels.state`: the structures the update takes: ``State``
  (the per-map state arrays, listed once; passed as a ``StateRef`` structref),
  ``Params`` (the settings, with the transfer, inconsistency policy and fusion as
  codes), ``Outputs`` (per-call statuses) and ``Scratch`` (a thread's buffers).
* :mod:`~bearing_env.slam.kernels.fusion`: fusing a movement's region into a map: the
  strict intersection, and the relaxed fusion's window and bases.
* :mod:`~bearing_env.slam.kernels.update`: one movement per map for a batch of maps, in
  one compiled call (serial, or ``prange`` over blocks of maps), and batch helpers.

Every public name of the topic modules is re-exported here, so callers import
``bearing_env.slam.kernels`` and never a topic module.

numba's cache (``cache=True``) checks only the source file of the function it
compiled, not the modules whose kernels that function calls: after editing one topic
module, delete ``bearing_env/slam/kernels/__pycache__`` (or the ``NUMBA_CACHE_DIR``)
so that the callers in the other modules are compiled again.
"""

from __future__ import annotations

from bearing_env.numerics import JitOptions, wrap
from bearing_env.slam.kernels.common import (
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
    MAX_PAIRS,
    MAX_SAMPLES,
    MAX_WINDOW,
    RELATIVE_TOLERANCE,
    SCRATCH,
    cross,
    dot,
    entry_point,
    scale_of,
    threads,
    tolerance_of,
)
from bearing_env.slam.kernels.frames import (
    FrameChange,
    boundary_samples,
    cone_region,
    frame_plan,
    sample_hypotheses,
    transfer_region,
)
from bearing_env.slam.kernels.fusion import (
    age_out_oldest,
    intersect_landmark,
    relaxed_movement,
    relaxed_region,
)
from bearing_env.slam.kernels.polygons import (
    area_centroid,
    clip_convex,
    contains_point,
    convex_hull,
    drop_edges_outward,
    longest_edge,
    offset_outward,
    polygon_distance,
    simplify,
    small_convex_hull,
)
from bearing_env.slam.kernels.robust import (
    BOUND_GROWTH,
    HISTORY,
    MAX_NOISE_SCALE,
    PROBE_SHRINK,
    ROBUST_LEVELS,
    binomial_q,
    contamination,
    update_levels,
)
from bearing_env.slam.kernels.state import (
    FUSION_INTERSECT,
    FUSION_RELAXED,
    FUSION_ROBUST,
    INCONSISTENCY_KEEP,
    INCONSISTENCY_RESTART,
    TRANSFER_CONSERVATIVE,
    TRANSFER_PAPER,
    Outputs,
    Params,
    Scratch,
    State,
    StateRef,
    StateType,
    new_scratch,
    state_ref,
)
from bearing_env.slam.kernels.update import (
    INDEX_OK,
    INDEX_OUT_OF_RANGE,
    INDEX_REPEATED,
    check_indices,
    contains_points,
    none_infinite,
    update_maps,
    update_maps_parallel,
)

__all__ = [
    "BOUND_GROWTH",
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
    "FUSION_INTERSECT",
    "FUSION_RELAXED",
    "FUSION_ROBUST",
    "HISTORY",
    "INCONSISTENCY_KEEP",
    "INCONSISTENCY_RESTART",
    "INDEX_OK",
    "INDEX_OUT_OF_RANGE",
    "INDEX_REPEATED",
    "LANDMARK_INCONSISTENT",
    "LANDMARK_MISSING",
    "LANDMARK_SKIPPED",
    "LANDMARK_UNBOUNDED",
    "LANDMARK_UPDATED",
    "MAX_CLOUD",
    "MAX_EDGE_SAMPLES",
    "MAX_FR_EXTENT",
    "MAX_NOISE_SCALE",
    "MAX_PAIRS",
    "MAX_SAMPLES",
    "MAX_WINDOW",
    "PROBE_SHRINK",
    "RELATIVE_TOLERANCE",
    "ROBUST_LEVELS",
    "SCRATCH",
    "TRANSFER_CONSERVATIVE",
    "TRANSFER_PAPER",
    "FrameChange",
    "JitOptions",
    "Outputs",
    "Params",
    "Scratch",
    "State",
    "StateRef",
    "StateType",
    "age_out_oldest",
    "area_centroid",
    "binomial_q",
    "boundary_samples",
    "check_indices",
    "clip_convex",
    "cone_region",
    "contains_point",
    "contains_points",
    "contamination",
    "convex_hull",
    "cross",
    "dot",
    "drop_edges_outward",
    "entry_point",
    "frame_plan",
    "intersect_landmark",
    "longest_edge",
    "new_scratch",
    "none_infinite",
    "offset_outward",
    "polygon_distance",
    "relaxed_movement",
    "relaxed_region",
    "sample_hypotheses",
    "scale_of",
    "simplify",
    "small_convex_hull",
    "state_ref",
    "threads",
    "tolerance_of",
    "transfer_region",
    "update_levels",
    "update_maps",
    "update_maps_parallel",
    "wrap",
]
