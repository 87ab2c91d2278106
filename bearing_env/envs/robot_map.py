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
from typing import Any, NamedTuple

import numpy as np
from numba import njit
from numpy.typing import NDArray

from bearing_env.numerics import JIT_OPTIONS
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

    One compiled call gathers every array at once, already in the canonical form, into
    arrays it makes (:func:`encode_map`, and :func:`encode_window` for the relaxed
    fusion's window and bases): a Python loop over the arrays costs several times more."""
    state, slots = batch._kernel_state(), max(int(slots), batch.n_landmarks - 2)
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


@njit(**JIT_OPTIONS)
def _known(value: complex) -> complex:  # pragma: no cover  (compiled)
    """A complex point, inf + inf j if unknown (NaN in either part)."""
    if np.isnan(value.real) or np.isnan(value.imag):
        return complex(np.inf, np.inf)
    return value


@njit(**JIT_OPTIONS)
def encode_map(state: Any, rows: Any, slots: int) -> Any:  # pragma: no cover  (compiled)
    """The arrays every fusion uses (``STATE_ARRAYS`` up to ``n_inconsistent``), in
    their order, for ``rows``: landmark slots padded to ``slots`` (see the module doc)."""
    size, capacity = rows.size, state.vertices.shape[2]
    encoded = (
        np.zeros((size, slots, capacity), np.complex128),
        np.zeros((size, slots), np.int64),
        np.full((size, slots), np.inf),
        np.full((size, slots), complex(np.inf, np.inf)),
        np.zeros((size, capacity), np.complex128),
        np.empty(size, np.int64),
        np.empty(size),
        np.empty(size, np.complex128),
        np.empty(size),
        np.empty(size, np.int64),
        np.empty(size, np.int64),
        np.empty(size, np.int64),
    )
    encode_map_into(state, rows, encoded)
    return encoded


@njit(**JIT_OPTIONS)
def encode_map_into(state: Any, rows: Any, encoded: Any) -> None:  # pragma: no cover
    """:func:`encode_map` into its arrays ``encoded`` (of ``len(rows)`` rows, its slot
    count theirs), whatever they held: the env step reuses them from step to step."""
    (
        vertices,
        counts,
        areas,
        centroids,
        robot_vertices,
        robot_counts,
        robot_area,
        robot_centroid,
        robot_heading,
        n_updates,
        n_frame_changes,
        n_inconsistent,
    ) = encoded
    mapped = state.counts.shape[1]
    for i in range(rows.size):
        row = rows[i]
        for j in range(mapped):
            count = state.counts[row, j]
            counts[i, j] = count
            vertices[i, j, :count] = state.vertices[row, j, :count]
            vertices[i, j, count:] = 0.0
            areas[i, j] = state.areas[row, j]
            centroids[i, j] = _known(state.centroids[row, j])
        count = state.robot_counts[row]
        robot_counts[i] = count
        robot_vertices[i, :count] = state.robot_vertices[row, :count]
        robot_vertices[i, count:] = 0.0
        robot_area[i] = state.robot_area[row]
        robot_centroid[i] = _known(state.robot_centroid[row])
        heading = state.robot_heading[row]
        robot_heading[i] = np.inf if np.isnan(heading) else heading
        n_updates[i] = state.n_updates[row]
        n_frame_changes[i] = state.n_frame_changes[row]
        n_inconsistent[i] = state.n_inconsistent[row]


@njit(**JIT_OPTIONS)
def encode_window(state: Any, rows: Any, slots: int) -> Any:  # pragma: no cover  (compiled)
    """The relaxed fusion's arrays (``RELAXED_STATE_ARRAYS``), as :func:`encode_map`."""
    size, mapped = rows.size, state.counts.shape[1]
    window, capacity = state.window_vertices.shape[1], state.window_vertices.shape[3]
    base_capacity = state.base_vertices.shape[2]
    window_vertices = np.zeros((size, window, slots, capacity), np.complex128)
    window_counts = np.zeros((size, window, slots), np.int64)
    window_inlier = np.zeros((size, window, slots), np.bool_)
    window_rejected = np.empty((size, window), np.bool_)
    window_length = np.empty(size, np.int64)
    window_next = np.empty(size, np.int64)
    base_vertices = np.zeros((size, slots, base_capacity), np.complex128)
    base_counts = np.zeros((size, slots), np.int64)
    n_dropped = np.zeros((size, slots), np.int64)
    outliers = np.zeros((size, slots), np.int64)
    for i in range(size):
        row = rows[i]
        for k in range(window):
            window_rejected[i, k] = state.window_rejected[row, k]
            for j in range(mapped):
                count = state.window_counts[row, k, j]
                window_counts[i, k, j] = count
                window_vertices[i, k, j, :count] = state.window_vertices[row, k, j, :count]
                window_inlier[i, k, j] = state.window_inlier[row, k, j]
        window_length[i] = state.window_length[row]
        window_next[i] = state.window_next[row]
        for j in range(mapped):
            count = state.base_counts[row, j]
            base_counts[i, j] = count
            base_vertices[i, j, :count] = state.base_vertices[row, j, :count]
            n_dropped[i, j] = state.n_dropped[row, j]
            outliers[i, j] = state.outliers[row, j]
    return (
        window_vertices,
        window_counts,
        window_inlier,
        window_rejected,
        window_length,
        window_next,
        base_vertices,
        base_counts,
        n_dropped,
        outliers,
    )


@njit(**JIT_OPTIONS)
def encode_levels(state: Any, rows: Any, slots: int) -> Any:  # pragma: no cover  (compiled)
    """The robust fusion's arrays (``ROBUST_STATE_ARRAYS``), as :func:`_encode_map`."""
    size, mapped = rows.size, state.counts.shape[1]
    levels, capacity = state.level_vertices.shape[2], state.level_vertices.shape[3]
    history = state.history_bearings.shape[1]
    outliers = np.zeros((size, slots), np.int64)
    level_vertices = np.zeros((size, slots, levels, capacity), np.complex128)
    level_counts = np.zeros((size, slots, levels), np.int64)
    n_regions = np.zeros((size, slots), np.int64)
    robot_fixed_at = np.empty(size, np.int64)
    noise_scale = np.empty(size)
    bound_events = np.empty(size, np.int64)
    probe_vertices = np.zeros((size, slots, state.probe_vertices.shape[2]), np.complex128)
    probe_counts = np.zeros((size, slots), np.int64)
    history_frame_bearings = np.empty((size, history, 2, 2))
    history_bearings = np.zeros((size, history, 2, slots))
    history_length = np.empty(size, np.int64)
    history_next = np.empty(size, np.int64)
    for i in range(size):
        row = rows[i]
        robot_fixed_at[i] = state.robot_fixed_at[row]
        noise_scale[i] = state.noise_scale[row]
        bound_events[i] = state.bound_events[row]
        history_frame_bearings[i] = state.history_frame_bearings[row]
        history_length[i] = state.history_length[row]
        history_next[i] = state.history_next[row]
        for j in range(mapped):
            outliers[i, j] = state.outliers[row, j]
            n_regions[i, j] = state.n_regions[row, j]
            for k in range(levels):
                count = state.level_counts[row, j, k]
                level_counts[i, j, k] = count
                level_vertices[i, j, k, :count] = state.level_vertices[row, j, k, :count]
            count = state.probe_counts[row, j]
            probe_counts[i, j] = count
            probe_vertices[i, j, :count] = state.probe_vertices[row, j, :count]
            history_bearings[i, :, :, j] = state.history_bearings[row, :, :, j]
    return (
        outliers,
        level_vertices,
        level_counts,
        n_regions,
        robot_fixed_at,
        noise_scale,
        bound_events,
        probe_vertices,
        probe_counts,
        history_frame_bearings,
        history_bearings,
        history_length,
        history_next,
    )


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
