"""Many maps updated in one native call: the engine under every PolygonSLAM.

:class:`BatchedPolygonSLAM` holds ``num_maps`` independent maps with the same number of
landmarks and the same settings, as arrays with a leading map axis, and fuses one
movement per map in one call of the native kernel
:func:`~bearing_env.slam.kernels.update_maps`. :class:`~bearing_env.slam.PolygonSLAM`
is a batch of one; the batched vector environment steps all its sub-environments'
maps at once.

Each region is an exact convex polygon: up to :data:`~bearing_env.slam.kernels.CAPACITY`
vertices in ``vertices[map, landmark]``, of which the first ``counts[map, landmark]``
are used (0: not initialised). A map's result never depends on which other maps share
its batch, because the kernel updates each map on its own; that is what lets the vector
environment reproduce the single environment bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env import _core
from bearing_env._schema import StateArrays
from bearing_env.slam import kernels
from bearing_env.slam.settings import (
    DEFAULT_MAX_OUTLIERS,
    DEFAULT_RISK,
    DEFAULT_WINDOW,
    FUSIONS,
    INCONSISTENCY_POLICIES,
    HasMapSettings,
    MapSettings,
)
from bearing_env.slam.transfer import TRANSFERS
from bearing_env.validation import int_at_least

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]


def _names_by_code(names: dict[int, str]) -> tuple[str, ...]:
    """Status names indexed by the kernels' codes, which must be 0, 1, 2, ... exactly."""
    if sorted(names) != list(range(len(names))):
        raise ValueError(f"status codes must be 0..{len(names) - 1}, got {sorted(names)}")
    return tuple(names[code] for code in range(len(names)))


#: Frame statuses, as codes (index into this tuple; the kernels' constants) and as the
#: strings of the public API.
FRAME_STATUSES: tuple[str, ...] = _names_by_code(
    {
        kernels.FRAME_OK: "ok",
        kernels.FRAME_L1_UNBOUNDED: "l1_unbounded",
        kernels.FRAME_L2_UNBOUNDED: "l2_unbounded",
        kernels.FRAME_L1_L2_OVERLAP: "l1_l2_overlap",
        kernels.FRAME_L1_L2_TOO_CLOSE: "l1_l2_too_close",
        kernels.FRAME_L1_MISSING: "l1_missing",
        kernels.FRAME_L2_MISSING: "l2_missing",
        kernels.FRAME_REJECTED: "rejected",
    }
)
FRAME_CODE = {name: code for code, name in enumerate(FRAME_STATUSES)}

#: Landmark statuses, as codes and strings.
LANDMARK_STATUSES: tuple[str, ...] = _names_by_code(
    {
        kernels.LANDMARK_UPDATED: "updated",
        kernels.LANDMARK_UNBOUNDED: "unbounded",
        kernels.LANDMARK_INCONSISTENT: "inconsistent",
        kernels.LANDMARK_SKIPPED: "skipped",
        kernels.LANDMARK_MISSING: "missing",
    }
)
LANDMARK_CODE = {name: code for code, name in enumerate(LANDMARK_STATUSES)}


#: Batches of at least this many maps are updated on :func:`bearing_env.slam.kernels.threads`
#: threads (``BEARING_ENV_NUM_THREADS``, else the CPUs the process may use). Below it,
#: waking a worker costs more than it saves (csrc/include/bearing_core/slam/state.hpp,
#: which holds the value).
PARALLEL_MIN_MAPS: int = kernels.PARALLEL_MIN_MAPS

#: How far outside a region a point may lie and still count as inside, relative to the
#: region's size: far above rounding, far below any bearing error.
CONTAINMENT_TOLERANCE = 1e-9


@dataclass(frozen=True)
class BatchUpdateResult:
    """What one movement per map did (arrays over the updated maps).

    ``frame_status`` indexes :data:`FRAME_STATUSES`; ``landmark_status`` (maps,
    n_landmarks - 2) indexes :data:`LANDMARK_STATUSES`.
    """

    frame_changed: NDArray[np.bool_]
    frame_status: NDArray[np.int8]
    landmark_status: NDArray[np.int8]
    n_inconsistent: IntArray


class BatchedPolygonSLAM(HasMapSettings, StateArrays):
    """``num_maps`` independent polygon-SLAM maps, updated together.

    Args mirror :class:`~bearing_env.slam.PolygonSLAM`, plus ``num_maps``; they are
    validated as one :class:`~bearing_env.slam.settings.MapSettings` (:attr:`settings`),
    and :meth:`from_settings` takes one whole.

    The state is public, as arrays with the map axis first (read them; write them only
    through :meth:`update` and :meth:`reset`): ``vertices`` (maps, landmarks, CAPACITY)
    complex and ``counts`` (maps, landmarks) for the regions of landmarks 3..n,
    ``areas`` and ``centroids`` (complex), ``robot_vertices``/``robot_counts``,
    ``robot_area``, ``robot_centroid`` and ``robot_heading`` for the robot, and the
    counters ``n_updates``, ``n_frame_changes`` and ``n_inconsistent``.
    """

    def __init__(
        self,
        num_maps: int,
        n_landmarks: int,
        epsilon: float,
        transfer: str = "conservative",
        edge_samples: int = 3,
        on_inconsistency: str = "restart",
        fusion: str = "intersect",
        max_outliers: int = DEFAULT_MAX_OUTLIERS,
        window: int = DEFAULT_WINDOW,
        risk: float = DEFAULT_RISK,
        robust_set: str = "guaranteed",
        noise_bound: str = "estimate",
    ) -> None:
        settings = MapSettings(
            epsilon,
            transfer=transfer,
            edge_samples=edge_samples,
            on_inconsistency=on_inconsistency,
            fusion=fusion,
            max_outliers=max_outliers,
            window=window,
            risk=risk,
            robust_set=robust_set,
            noise_bound=noise_bound,
        )
        self._allocate(num_maps, n_landmarks, settings)

    def _allocate(self, num_maps: int, n_landmarks: int, settings: MapSettings) -> None:
        """The empty maps' state arrays for ``settings`` (already validated)."""
        self.num_maps = int_at_least(num_maps, 1, "num_maps")
        self.n_landmarks = int_at_least(n_landmarks, 3, "n_landmarks", "(L1, L2 and one more)")
        #: The map's settings, validated (``self.epsilon`` and the others read them).
        self.settings = settings
        # The state's arrays (State's fields, shaped by their rules); the fusion's arrays
        # not used have an empty axis.
        relaxed, robust = self.fusion == "relaxed", self.fusion == "robust"
        lengths = {
            "maps": self.num_maps,
            "m": self.n_landmarks - 2,
            "w": self.window if relaxed else 0,
            "base_capacity": kernels.CAPACITY if relaxed else 0,
            "levels": kernels.ROBUST_LEVELS if robust else 0,
            "probe_capacity": kernels.CAPACITY if robust else 0,
            "h": kernels.HISTORY if robust else 0,
        }
        for name, array in zip(STATE_ARRAYS, _core.new_arrays("State", lengths), strict=True):
            setattr(self, name, array)
        self._state_ref: kernels.MapState | None = None
        self.reset()

    @classmethod
    def from_settings(
        cls, num_maps: int, n_landmarks: int, settings: MapSettings
    ) -> BatchedPolygonSLAM:
        """A batch of ``num_maps`` empty maps with ``settings``."""
        if not isinstance(settings, MapSettings):
            raise TypeError(f"settings must be a MapSettings, got {settings!r}")
        # A MapSettings is validated when made: no second validation, no dict of it
        # (planners rebuild a map from every info, and dataclasses.asdict alone cost
        # about 65 us of GreedyOneStep's ~1 ms decision).
        batch = cls.__new__(cls)
        batch._allocate(num_maps, n_landmarks, settings)
        return batch

    def empty_like(self, num_maps: int) -> BatchedPolygonSLAM:
        """A new batch of ``num_maps`` empty maps with this batch's settings."""
        return BatchedPolygonSLAM.from_settings(num_maps, self.n_landmarks, self.settings)

    @property
    def initialised(self) -> NDArray[np.bool_]:
        """Bool (maps, landmarks): the landmark has a region."""
        return self.counts > 0

    @property
    def has_robot(self) -> NDArray[np.bool_]:
        """Bool (maps,): the robot has a region (a movement has changed frames)."""
        return self.robot_counts > 0

    def reset(self, maps: ArrayLike | None = None) -> None:
        """Forget everything in the given maps (indices or a mask; default all)."""
        rows = slice(None) if maps is None else np.asarray(maps)
        self.counts[rows] = 0
        self.areas[rows] = np.inf
        self.centroids[rows] = complex(np.nan, np.nan)
        self.robot_counts[rows] = 0
        self.robot_area[rows] = np.inf
        self.robot_centroid[rows] = complex(np.nan, np.nan)
        self.robot_heading[rows] = np.nan
        self.n_updates[rows] = 0
        self.n_frame_changes[rows] = 0
        self.n_inconsistent[rows] = 0
        self.window_counts[rows] = 0
        self.window_length[rows] = 0
        self.window_next[rows] = 0
        self.base_counts[rows] = 0
        self.n_dropped[rows] = 0
        self.outliers[rows] = 0
        self.level_counts[rows] = 0
        self.n_regions[rows] = 0
        self.robot_fixed_at[rows] = 0
        self.noise_scale[rows] = 1.0
        self.bound_events[rows] = 0
        self.probe_counts[rows] = 0
        self.history_length[rows] = 0
        self.history_next[rows] = 0

    def update(
        self,
        bearings_start: ArrayLike,
        bearings_end: ArrayLike,
        maps: ArrayLike | None = None,
        robot: bool = True,
    ) -> BatchUpdateResult:
        """Fuse one movement into each of the given maps.

        Args:
            bearings_start: bearings (len(maps), n_landmarks) at R1, radians CCW from the
                direction of motion; column 0 is L1, column 1 is L2.
            bearings_end: bearings at R2, same shape.
            maps: distinct indices of the maps to update (default: all, in order).
            robot: also transfer the robot's position. Planning that scores candidate
                moves by their landmark areas alone passes False, which saves a third of
                the work; the robot's region and heading then keep their old values.

        Raises:
            TypeError: on non-numeric bearings or map indices.
            ValueError: on a wrong shape, a non-finite bearing, or map indices that are
                out of range or repeated.
        """
        rows = self._check_maps(maps)
        b1 = self._check_bearings(bearings_start, rows.size, "bearings_start")
        b2 = self._check_bearings(bearings_end, rows.size, "bearings_end")
        return self._update_checked(b1, b2, rows, robot)

    def update_trusted(
        self, bearings_start: FloatArray, bearings_end: FloatArray, robot: bool = True
    ) -> BatchUpdateResult:
        """:meth:`update` of every map, in order, without the input checks: for callers
        that made the bearings themselves (a planner's simulated readings), as C-contiguous
        float64 arrays (num_maps, n_landmarks) with no infinite value. Wrong input here is
        not caught: it can corrupt the maps."""
        return self._update_checked(bearings_start, bearings_end, np.arange(self.num_maps), robot)

    def _update_checked(
        self, b1: FloatArray, b2: FloatArray, rows: IntArray, robot: bool = True
    ) -> BatchUpdateResult:
        """:meth:`update` on checked input (float arrays (len(rows), n), distinct rows)."""
        n_rows, n_mapped = rows.size, self.n_landmarks - 2
        # Fresh outputs: the result hands them out.
        out = kernels.Outputs(
            np.empty(n_rows, dtype=np.int8),
            np.empty((n_rows, n_mapped), dtype=np.int8),
            np.empty(n_rows, dtype=np.int64),
        )
        self._run_update(b1, b2, rows, bool(robot), out)
        frame, landmark, bad = out
        return BatchUpdateResult(frame == FRAME_CODE["ok"], frame, landmark, bad)

    def _run_update(
        self, b1: FloatArray, b2: FloatArray, rows: IntArray, robot: bool, out: kernels.Outputs
    ) -> None:
        """The native update on checked input, writing what it did to ``out`` (arrays
        over ``rows``): one thread, or blocks of maps on several for a large batch."""
        threads = kernels.threads() if rows.size >= PARALLEL_MIN_MAPS else 1
        kernels.update_maps(
            b1, b2, rows, self._kernel_params(robot), self._kernel_state(), out, threads
        )

    def contains(self, points: ArrayLike, maps: ArrayLike | None = None) -> NDArray[np.bool_]:
        """Whether region ``i`` of each map contains FL point ``i`` (boundary counts).

        Args:
            points: complex FL points (len(maps), n_landmarks - 2).
            maps: indices of the maps (default: all, in order).

        Returns:
            Bool (len(maps), n_landmarks - 2); False where a landmark is not initialised.
        """
        rows = self._check_maps(maps, distinct=False)
        z = np.asarray(points, dtype=np.complex128)
        if z.shape != (rows.size, self.n_landmarks - 2):
            raise ValueError(
                f"points must have shape ({rows.size}, {self.n_landmarks - 2}), got {z.shape}"
            )
        inside = np.empty(z.shape, dtype=bool)
        kernels.contains_points(self.vertices, self.counts, rows, z, CONTAINMENT_TOLERANCE, inside)
        return inside

    def polygon(self, map_index: int, landmark: int) -> NDArray[np.complex128]:
        """The vertices (CCW) of one region; empty if the landmark is not initialised."""
        return self.vertices[map_index, landmark, : self.counts[map_index, landmark]].copy()

    def robot_polygon(self, map_index: int) -> NDArray[np.complex128]:
        """The vertices (CCW) of a map's robot region; empty before any frame change."""
        return self.robot_vertices[map_index, : self.robot_counts[map_index]].copy()

    def same_settings(self, other: BatchedPolygonSLAM) -> bool:
        """Whether ``other`` was made with this batch's settings (its map count aside)."""
        return self.n_landmarks == other.n_landmarks and (
            self.settings is other.settings or self.settings == other.settings
        )

    def fill_from(self, source: BatchedPolygonSLAM, map_index: int) -> None:
        """Make every map of this batch a copy of ``source``'s map ``map_index`` (same
        settings), in place: a planner's scratch batch, refilled for each decision."""
        rows = np.full(self.num_maps, int(map_index), dtype=np.int64)
        kernels.copy_maps(source._kernel_state(), rows, self._kernel_state())

    def take(self, maps: ArrayLike, into: BatchedPolygonSLAM | None = None) -> BatchedPolygonSLAM:
        """A batch whose map ``i`` is a copy of map ``maps[i]`` (indices may repeat): for
        planning, many candidates from each of a few maps. ``into``: a batch from an
        earlier call to overwrite instead of making a new one, when it has ``len(maps)``
        maps and this batch's settings (a planner's scratch; else a new batch). It must
        not be this batch."""
        rows = self._check_maps(maps, distinct=False)
        if into is self:
            raise ValueError("take(into=...) must be another batch than the one copied from")
        if into is not None and into.num_maps == rows.size and into.same_settings(self):
            copies = into
        else:
            copies = self.empty_like(rows.size)
        kernels.copy_maps(self._kernel_state(), rows, copies._kernel_state())
        return copies

    @property
    def state_names(self) -> tuple[str, ...]:
        """The state arrays this batch's fusion uses: those of every fusion, then the
        relaxed fusion's window and bases (:data:`RELAXED_STATE_ARRAYS`) under
        ``"relaxed"``, or the robust fusion's levels (:data:`ROBUST_STATE_ARRAYS`) under
        ``"robust"``."""
        common = tuple(
            name
            for name in STATE_ARRAYS
            if name not in RELAXED_STATE_ARRAYS and name not in ROBUST_STATE_ARRAYS
        )
        if self.fusion == "relaxed":
            return common + RELAXED_STATE_ARRAYS
        if self.fusion == "robust":
            return common + ROBUST_STATE_ARRAYS
        return common

    def _kernel_state(self) -> kernels.MapState:
        """The state as the kernels take it: a native :class:`kernels.MapState` of this
        batch's arrays, made on first use and kept (the arrays are only ever written in
        place)."""
        ref: kernels.MapState | None = self._state_ref
        if ref is None:
            d = self.__dict__
            ref = kernels.state_ref(kernels.State(*(d[name] for name in STATE_ARRAYS)))
            self._state_ref = ref
        return ref

    def _kernel_params(self, with_robot: bool) -> kernels.Params:
        """The kernels' settings for one update (see :class:`kernels.Params`), made once
        per batch (its settings never change) rather than on every call."""
        both: tuple[kernels.Params, kernels.Params] | None = self.__dict__.get("_params")
        if both is None:
            # Params' fields (declared in the C++ library) from this batch's settings:
            # the codes of the named choices, the rest under their own names.
            codes: dict[str, Any] = {
                "transfer": TRANSFERS.index(self.transfer),
                "on_inconsistency": INCONSISTENCY_POLICIES.index(self.on_inconsistency),
                "fusion": FUSIONS.index(self.fusion),
                "likely": self.robust_set == "likely",
                "estimate_bound": self.noise_bound == "estimate",
            }
            settings = {
                name: codes[name] if name in codes else getattr(self, name)
                for name, *_ in _core.SCHEMAS["Params"]
                if name != "with_robot"
            }
            both = (
                kernels.Params(**settings, with_robot=False),
                kernels.Params(**settings, with_robot=True),
            )
            self._params = both
        return both[with_robot]

    def _check_maps(self, maps: ArrayLike | None, distinct: bool = True) -> IntArray:
        if maps is None:
            return np.arange(self.num_maps)
        raw = np.asarray(maps)
        if raw.dtype.kind not in "iu" or raw.ndim != 1:
            raise TypeError(f"maps must be a 1-D array of int map indices, got {maps!r}")
        rows = np.ascontiguousarray(raw, dtype=np.int64)
        problem = kernels.check_indices(rows, self.num_maps, distinct)
        if problem == kernels.INDEX_OUT_OF_RANGE:
            raise ValueError(f"maps must be indices in [0, {self.num_maps}), got {rows.tolist()}")
        if problem == kernels.INDEX_REPEATED:
            raise ValueError(f"maps must not repeat a map, got {rows.tolist()}")
        return rows

    def _check_bearings(self, bearings: ArrayLike, n_rows: int, name: str) -> FloatArray:
        return check_bearings(bearings, (n_rows, self.n_landmarks), name)

    def __getstate__(self) -> dict[str, Any]:
        # The native reference to the arrays and the native settings are not pickled;
        # they are made again on first use.
        state = self.__dict__.copy()
        state["_state_ref"] = None
        state.pop("_params", None)  # native settings: made again from the batch's own
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        # Out-of-band pickles (Ray's object store) hand back read-only buffers; the
        # kernel writes the state in place.
        for key, value in state.items():
            if isinstance(value, np.ndarray) and not value.flags.writeable:
                state[key] = value.copy()
        state["_state_ref"] = None
        self.__dict__.update(state)


#: The per-map state, every array with the map axis first: the fields of
#: :class:`bearing_env.slam.kernels.State`, in its order.
STATE_ARRAYS: tuple[str, ...] = kernels.State._fields


#: The part of the state only the relaxed fusion uses (its window and bases).
RELAXED_STATE_ARRAYS = STATE_ARRAYS[
    STATE_ARRAYS.index("window_vertices") : STATE_ARRAYS.index("outliers") + 1
]
#: The part of the state the robust fusion uses besides every fusion's: the regions each
#: landmark leaves out (``outliers``, shared with the relaxed fusion), its levels and its
#: noise-bound estimate (bound, probe and bearing history).
ROBUST_STATE_ARRAYS = ("outliers", *STATE_ARRAYS[STATE_ARRAYS.index("level_vertices") :])

#: The state arrays with a landmark axis, and which axis it is (the map axis is 0): what
#: pads or trims a map's state to a number of landmark slots.
LANDMARK_AXES: dict[str, int] = {
    name: rule.split().index("m")
    for name, _, rule, _ in _core.SCHEMAS["State"]
    if "m" in rule.split()
}

#: The vertex arrays of the state and the arrays counting their used vertices.
VERTEX_COUNTS: dict[str, str] = {
    "vertices": "counts",
    "robot_vertices": "robot_counts",
    "window_vertices": "window_counts",
    "base_vertices": "base_counts",
    "level_vertices": "level_counts",
    "probe_vertices": "probe_counts",
}


def check_bearings(bearings: ArrayLike, shape: tuple[int, ...], name: str) -> FloatArray:
    """Bearings as a float array of ``shape``, or a clear error naming the value."""
    if (
        type(bearings) is np.ndarray
        and bearings.dtype == np.float64
        and bearings.shape == shape
        and bearings.flags.c_contiguous
        and kernels.none_infinite(bearings.reshape(-1))
    ):
        return bearings  # the common case, checked without temporaries
    raw = np.asarray(bearings)
    if raw.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be numbers (radians), got {bearings!r}")
    arr = raw.astype(np.float64, copy=False)
    if arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {arr.shape}")
    if np.any(np.isinf(arr)):
        raise ValueError(f"{name} must be finite or NaN (a missed reading), got {arr.tolist()}")
    return np.ascontiguousarray(arr)
