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

import weakref
from collections.abc import Mapping
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from bearing_env._core import _known as _known
from bearing_env._core import encode_levels as encode_levels
from bearing_env._core import encode_map as encode_map
from bearing_env._core import encode_map_into as encode_map_into
from bearing_env._core import encode_window as encode_window
from bearing_env.slam import MapSettings, PolygonSLAM
from bearing_env.slam.batch import (
    LANDMARK_AXES,
    RELAXED_STATE_ARRAYS,
    STATE_ARRAYS,
    BatchedPolygonSLAM,
)

#: The info key of the robot's own map: the one key of an info robot policies read.
KEY = "robot_map"
#: Fill of the empty landmark slots (default 0: count 0 is an empty region), as the
#: compiled encoding (:func:`encode_map`, :func:`encode_window`) writes them.
PADDING: dict[str, Any] = {"areas": np.inf, "centroids": complex(np.inf, np.inf)}
#: The arrays every fusion uses, as :func:`encode_map` gives them (the relaxed fusion's
#: are these, then :data:`~bearing_env.slam.batch.RELAXED_STATE_ARRAYS`; the robust
#: fusion's, these, then :data:`~bearing_env.slam.batch.ROBUST_STATE_ARRAYS`).
MAP_ARRAYS: tuple[str, ...] = STATE_ARRAYS[: STATE_ARRAYS.index(RELAXED_STATE_ARRAYS[0])]
#: The arrays whose unknown values (NaN in the map) are inf in an info.
UNKNOWN_AS_INF: tuple[str, ...] = ("centroids", "robot_centroid", "robot_heading")


def encode(batch: BatchedPolygonSLAM, rows: NDArray[np.int64], slots: int) -> dict[str, Any]:
    """The map state of the batch's ``rows``, as an info's data (arrays with the rows
    first), per-landmark arrays padded to ``slots`` landmark slots.

    One native call gathers every array at once, already in the canonical form, into
    arrays it makes (:func:`encode_map`, and :func:`encode_window` for the relaxed
    fusion's window and bases): a Python loop over the arrays costs several times more."""
    state, slots = batch._kernel_state(), max(int(slots), batch.n_landmarks - 2)
    rows = np.ascontiguousarray(rows, dtype=np.int64)
    arrays = encode_map(state, rows, slots)
    if batch.fusion == "relaxed":
        arrays += encode_window(state, rows, slots)
    elif batch.fusion == "robust":
        arrays += encode_levels(state, rows, slots)
    return as_info(batch.state_names, arrays)


def as_info(names: tuple[str, ...], arrays: tuple[NDArray[Any], ...]) -> dict[str, Any]:
    """The info's dict of encoded ``arrays`` (:func:`encode_map`'s, then, for the relaxed
    fusion, :func:`encode_window`'s, or for the robust fusion, :func:`encode_levels`'s),
    named ``names``: complex points become (x, y) pairs on a last axis (views, not
    copies)."""
    return {
        name: values.view(np.float64).reshape(*values.shape, 2)
        if values.dtype.kind == "c"
        else values
        for name, values in zip(names, arrays, strict=True)
    }


class Buffers(NamedTuple):
    """:func:`encode_map`'s arrays, kept from step to step, in two forms over the same
    memory: as the info gives them (``info``, by name, complex points as (x, y) pairs) and
    as :func:`encode_map_into` writes them (``kernel``, complex views)."""

    info: dict[str, NDArray[Any]]
    kernel: tuple[NDArray[Any], ...]

    def rows(self, size: int) -> Buffers:
        """The first ``size`` rows (views)."""
        return Buffers(
            {name: values[:size] for name, values in self.info.items()},
            tuple(values[:size] for values in self.kernel),
        )


def buffers(arrays: tuple[NDArray[Any], ...]) -> Buffers:
    """:class:`Buffers` holding (copies of) :func:`encode_map`'s ``arrays``: its padding
    stays, as only the mapped slots are written again."""
    info, kernel = {}, []
    for name, values in zip(MAP_ARRAYS, arrays, strict=True):
        if values.dtype.kind == "c":
            pairs = np.ascontiguousarray(values).view(np.float64).reshape(*values.shape, 2)
            info[name] = pairs = pairs.copy()
            kernel.append(pairs.view(np.complex128).reshape(values.shape))
        else:
            info[name] = values = values.copy()
            kernel.append(values)
    return Buffers(info, tuple(kernel))


# The codec's kernels are native (csrc/env/robot_map.cpp): ``encode_map`` (a map
# batch's arrays for ``rows``, with ``slots`` landmark slots), ``encode_map_into`` (the
# same into arrays made once), ``encode_window`` and ``encode_levels`` (the relaxed and
# robust fusions' arrays); each takes a native MapState, a State or an EnvInputs.


def decode(
    data: Mapping[str, Any],
    n_landmarks: int,
    settings: MapSettings,
    into: PolygonSLAM | None = None,
) -> PolygonSLAM:
    """The map holding one env's ``info[KEY]`` data, for ``n_landmarks`` landmarks and the
    world model's ``settings`` (``EnvConfig.map_settings``): a new map (an independent
    copy), or ``into``, overwritten in place, when it has those landmarks and settings (a
    policy's map from its last decision: no new arrays for every info)."""
    n_landmarks = int(n_landmarks)
    fits = (
        into is not None
        and into.batch.num_maps == 1
        and into.n_landmarks == n_landmarks
        and into.settings == settings
    )
    slam = into if fits and into is not None else PolygonSLAM.from_settings(n_landmarks, settings)
    for step in _decoding_plan(slam):
        step.target[...] = np.asarray(data[step.name])[step.used_slots]
        if step.unknown is not None:  # inf in an info, the map's "unknown" (NaN) again
            step.row[np.isinf(step.row)] = step.unknown
    return slam


class DecodingStep(NamedTuple):
    """How :func:`decode` writes one state array of a map."""

    #: The array's name in the info.
    name: str
    #: The map's row (an array even for a 1-D state array).
    row: NDArray[Any]
    #: ``row`` as the info's arrays come: complex numbers as (x, y) pairs over its memory.
    target: NDArray[Any]
    #: The info's landmark slots the map uses (one env's arrays have no map axis).
    used_slots: tuple[slice, ...]
    #: The map's "unknown" for the info's inf, or None (no unknown values).
    unknown: float | complex | None


def _decoding_plan(slam: PolygonSLAM) -> list[DecodingStep]:
    """The map's decoding steps, made on its first decode and kept while its batch lives (a
    policy decodes into the same map at every decision)."""
    batch = slam.batch
    plan = _DECODING_PLANS.get(batch)
    if plan is not None:
        return plan
    plan, mapped = [], batch.n_landmarks - 2
    for name in batch.state_names:
        row = getattr(batch, name)[:1]
        complex_row = row.dtype.kind == "c"
        target = row.view(np.float64).reshape(*row.shape, 2) if complex_row else row
        axis = LANDMARK_AXES.get(name)
        used = () if axis is None else (slice(None),) * (axis - 1) + (slice(mapped),)
        unknown: float | complex | None = None
        if name in UNKNOWN_AS_INF:
            unknown = complex(np.nan, np.nan) if complex_row else np.nan
        plan.append(DecodingStep(name, row, target, used, unknown))
    _DECODING_PLANS[batch] = plan
    return plan


#: Each batch's decoding steps (views of its arrays: kept out of the batch, so that
#: pickling a batch never copies them apart from the arrays they view).
_DECODING_PLANS: weakref.WeakKeyDictionary[BatchedPolygonSLAM, list[DecodingStep]] = (
    weakref.WeakKeyDictionary()
)
