"""The world model: the paper's bearing-only polygon SLAM, as a compiled library.

This package imports neither gymnasium nor pygame: it runs on bearings logged by a real
robot as well as on the simulator's.

Public API:

* :class:`PolygonSLAM` and :class:`UpdateResult`: the map, fused over movements.
* :class:`MapSettings`: a map's settings (epsilon, transfer, fusion, ...), one frozen,
  validated, hashable object (``PolygonSLAM.from_settings``).
* :class:`BatchedPolygonSLAM`: many maps updated in one computation (the engine under
  every ``PolygonSLAM``, which is a batch of one, and under the batched vector env).
* :func:`fr_region`: the FR region of one landmark from a bearing pair.
* :func:`transfer_polygon` / :func:`transfer_point`: the FR -> FL transfer of a region
  or a point, as shapely geometry (one movement, for inspection and tests).
* :func:`world_to_fl` / :func:`fl_to_world`: frame conversions given L1 and L2.
* :mod:`bearing_env.slam.kernels`: the native kernels underneath (C++17, ``csrc/slam/``),
  a package of topical modules (``common``, ``polygons``, ``frames``, ``state``,
  ``fusion``, ``robust``, ``update``) whose names it re-exports; the update takes the
  map's state as a ``State`` (34 arrays, passed as a native ``MapState``), its settings
  as ``Params`` and returns statuses in ``Outputs``. :mod:`bearing_env.slam.geometry`: their entry
  points for one-off polygon geometry.
"""

from bearing_env.slam.api import fr_region, transfer_point, transfer_polygon
from bearing_env.slam.batch import BatchedPolygonSLAM, BatchUpdateResult
from bearing_env.slam.polygon_slam import (
    FRAME_L1_L2_OVERLAP,
    FRAME_L1_L2_TOO_CLOSE,
    FRAME_L1_MISSING,
    FRAME_L1_UNBOUNDED,
    FRAME_L2_MISSING,
    FRAME_L2_UNBOUNDED,
    FRAME_OK,
    FRAME_REJECTED,
    FUSIONS,
    INCONSISTENCY_POLICIES,
    LANDMARK_INCONSISTENT,
    LANDMARK_MISSING,
    LANDMARK_SKIPPED,
    LANDMARK_UNBOUNDED,
    LANDMARK_UPDATED,
    PolygonSLAM,
    UpdateResult,
    fl_to_world,
    world_to_fl,
)
from bearing_env.slam.settings import MapSettings
from bearing_env.slam.transfer import TRANSFERS

__all__ = [
    "FRAME_L1_L2_OVERLAP",
    "FRAME_L1_L2_TOO_CLOSE",
    "FRAME_L1_MISSING",
    "FRAME_L1_UNBOUNDED",
    "FRAME_L2_MISSING",
    "FRAME_L2_UNBOUNDED",
    "FRAME_OK",
    "FRAME_REJECTED",
    "FUSIONS",
    "INCONSISTENCY_POLICIES",
    "LANDMARK_INCONSISTENT",
    "LANDMARK_MISSING",
    "LANDMARK_SKIPPED",
    "LANDMARK_UNBOUNDED",
    "LANDMARK_UPDATED",
    "TRANSFERS",
    "BatchUpdateResult",
    "BatchedPolygonSLAM",
    "MapSettings",
    "PolygonSLAM",
    "UpdateResult",
    "fl_to_world",
    "fr_region",
    "transfer_point",
    "transfer_polygon",
    "world_to_fl",
]
