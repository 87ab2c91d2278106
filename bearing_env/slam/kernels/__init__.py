"""The world model's kernels: the native core (C++17, ``csrc/slam/``, compiled into
:mod:`bearing_env._core` by the package's build), one module per topic.

* :mod:`~bearing_env.slam.kernels.common`: capacities, status codes, scalar helpers
  (``cross``, ``dot``, tolerances) and :func:`threads`.
* :mod:`~bearing_env.slam.kernels.polygons`: convex polygons in fixed-capacity arrays:
  hulls, area and centroid, containment, distances, simplification, capacity
  reduction, clipping and outward offsets.
* :mod:`~bearing_env.slam.kernels.frames`: a landmark's cone region in the robot frame
  FR, and the change of frames FR -> FL (frame plan, hypotheses, transfer).
* :mod:`~bearing_env.slam.kernels.state`: the structures the update takes: ``State``
  (the per-map state arrays, listed once; passed as a native ``MapState``), ``Params``
  (the settings, with the transfer, inconsistency policy and fusion as codes) and
  ``Outputs`` (per-call statuses).
* :mod:`~bearing_env.slam.kernels.fusion`: the strict intersection and the relaxed
  fusion's window and bases.
* :mod:`~bearing_env.slam.kernels.robust`: the robust fusion's levels and noise bound.
* :mod:`~bearing_env.slam.kernels.update`: one movement per map for a batch of maps, in
  one native call (serial, or blocks of maps on threads), and batch helpers.

Every public name of the topic modules is re-exported here, so callers import
``bearing_env.slam.kernels`` and never a topic module. Each kernel checks its arrays'
dtypes, shapes and contiguity and raises ``TypeError`` or ``ValueError`` naming the
argument; a fixed capacity that would overflow raises ``CapacityError``.
"""

from __future__ import annotations

from bearing_env._core import CapacityError
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
    MAX_LANDMARKS,
    MAX_PAIRS,
    MAX_SAMPLES,
    MAX_WINDOW,
    PARALLEL_MIN_MAPS,
    RELATIVE_TOLERANCE,
    SCRATCH,
    THREADS_VARIABLE,
    cross,
    dot,
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
from bearing_env.slam.kernels.fusion import relaxed_region
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
    small_hull_indices,
)
from bearing_env.slam.kernels.robust import (
    BOUND_GROWTH,
    HISTORY,
    MAX_BOUND,
    MAX_NOISE_SCALE,
    PRIOR_CONTRADICTIONS,
    PRIOR_REGIONS,
    PROBE_SHRINK,
    ROBUST_LEVELS,
    UNSEEN_FACTOR,
    binomial_q,
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
    MapState,
    Outputs,
    Params,
    State,
    state_ref,
)
from bearing_env.slam.kernels.update import (
    INDEX_OK,
    INDEX_OUT_OF_RANGE,
    INDEX_REPEATED,
    check_indices,
    contains_points,
    copy_maps,
    none_infinite,
    update_maps,
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
    "MAX_BOUND",
    "MAX_CLOUD",
    "MAX_EDGE_SAMPLES",
    "MAX_FR_EXTENT",
    "MAX_LANDMARKS",
    "MAX_NOISE_SCALE",
    "MAX_PAIRS",
    "MAX_SAMPLES",
    "MAX_WINDOW",
    "PARALLEL_MIN_MAPS",
    "PRIOR_CONTRADICTIONS",
    "PRIOR_REGIONS",
    "PROBE_SHRINK",
    "RELATIVE_TOLERANCE",
    "ROBUST_LEVELS",
    "SCRATCH",
    "THREADS_VARIABLE",
    "TRANSFER_CONSERVATIVE",
    "TRANSFER_PAPER",
    "UNSEEN_FACTOR",
    "CapacityError",
    "FrameChange",
    "MapState",
    "Outputs",
    "Params",
    "State",
    "area_centroid",
    "binomial_q",
    "boundary_samples",
    "check_indices",
    "clip_convex",
    "cone_region",
    "contains_point",
    "contains_points",
    "convex_hull",
    "copy_maps",
    "cross",
    "dot",
    "drop_edges_outward",
    "frame_plan",
    "longest_edge",
    "none_infinite",
    "offset_outward",
    "polygon_distance",
    "relaxed_region",
    "sample_hypotheses",
    "scale_of",
    "simplify",
    "small_convex_hull",
    "small_hull_indices",
    "state_ref",
    "threads",
    "tolerance_of",
    "transfer_region",
    "update_levels",
    "update_maps",
]
