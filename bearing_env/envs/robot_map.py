"""The robot-map codec: the robot's own map as data in every info, and back.

``info[KEY]`` carries the map's state arrays (those its fusion uses:
``BatchedPolygonSLAM.state_names``) for one env, in a canonical form so that equal maps
give equal infos and Gymnasium can batch them:

* complex FL points are (x, y) pairs on a last axis of 2 (Gymnasium batches real arrays
  and scalars only);
* vertex slots beyond a region's count are 0;
* unknown values (NaN in the map: a centroid without a region, the robot's centroid or
  heading before it has one) are inf (:data:`UNKNOWN_AS_INF`);
* the per-landmark arrays (``bearing_env.slam.batch.LANDMARK_AXES``) are padded to the
  env's ``max_landmarks - 2`` slots (:data:`PADDING`), whatever the episode's count.

:func:`encode` is the env's side (:mod:`bearing_env.envs.core` builds the infos with
it); :func:`decode` is the policies' (``bearing_env.agents.env_access.MapReader``). It is
what the robot knows, never ground truth.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from bearing_env.slam import MapSettings, PolygonSLAM
from bearing_env.slam.batch import LANDMARK_AXES, VERTEX_COUNTS, BatchedPolygonSLAM

#: The info key of the robot's own map: the one key of an info robot policies read.
KEY = "robot_map"
#: Fill of the empty landmark slots (default 0: count 0 is an empty region).
PADDING: dict[str, Any] = {"areas": np.inf, "centroids": complex(np.inf, np.inf)}
#: The arrays whose unknown values (NaN in the map) are inf in an info.
UNKNOWN_AS_INF: tuple[str, ...] = ("centroids", "robot_centroid", "robot_heading")


def encode(batch: BatchedPolygonSLAM, rows: NDArray[np.int64], slots: int) -> dict[str, Any]:
    """The map state of the batch's ``rows``, as an info's data (arrays with the rows
    first), per-landmark arrays padded to ``slots`` landmark slots."""
    mapped = batch.n_landmarks - 2
    out: dict[str, Any] = {}
    for name in batch.state_names:
        values = getattr(batch, name)[rows]
        if name in VERTEX_COUNTS:
            used = getattr(batch, VERTEX_COUNTS[name])[rows]
            values[np.arange(values.shape[-1]) >= used[..., None]] = 0
        elif name in UNKNOWN_AS_INF:
            unknown = np.isnan(values)
            values[unknown] = complex(np.inf, np.inf) if values.dtype.kind == "c" else np.inf
        axis = LANDMARK_AXES.get(name)
        if axis is not None and slots > mapped:
            shape = list(values.shape)
            shape[axis] = slots
            padded = np.full(shape, PADDING.get(name, 0), dtype=values.dtype)
            used_slots = [slice(None)] * values.ndim
            used_slots[axis] = slice(0, mapped)
            padded[tuple(used_slots)] = values
            values = padded
        if values.dtype.kind == "c":
            values = values.view(np.float64).reshape(*values.shape, 2)
        out[name] = values
    return out


def decode(data: Mapping[str, Any], n_landmarks: int, settings: MapSettings) -> PolygonSLAM:
    """A new map (an independent copy) holding one env's ``info[KEY]`` data, for
    ``n_landmarks`` landmarks and the world model's ``settings``
    (``EnvConfig.map_settings``)."""
    slam = PolygonSLAM.from_settings(int(n_landmarks), settings)
    batch, mapped = slam.batch, int(n_landmarks) - 2
    for name in batch.state_names:
        target = getattr(batch, name)
        values = np.array(data[name])
        if name in LANDMARK_AXES:  # one env's arrays have no map axis
            values = np.take(values, np.arange(mapped), axis=LANDMARK_AXES[name] - 1)
        if target.dtype.kind == "c":  # (x, y) pairs back to complex
            points = np.asarray(values[..., 0], dtype=np.complex128)
            points.imag = values[..., 1]
            values = points
        if name in UNKNOWN_AS_INF:
            unknown = complex(np.nan, np.nan) if values.dtype.kind == "c" else np.nan
            values[np.isinf(values)] = unknown  # back to the map's "unknown"
        target[0] = values
    return slam
