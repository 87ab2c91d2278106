"""Many maps updated in one batched computation: the engine under every PolygonSLAM.

:class:`BatchedPolygonSLAM` holds ``num_maps`` independent maps with the same number of
landmarks and the same settings, as arrays with a leading map axis, and fuses one
movement per map in a single numpy computation. :class:`~bearing_env.slam.PolygonSLAM`
is a batch of one; the batched vector environment steps all its sub-environments'
maps at once.

A map's result never depends on which other maps share its batch: every operation is
elementwise or a reduction within one map's rows, and data-dependent choices (how
finely to sample the hypotheses, whether two K-gons are nested) are made per map.
That is what lets the vector environment reproduce the single environment bit for bit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env.slam.geometry import FR_BOUNDED, FR_EMPTY, KGon, cone_intersections
from bearing_env.slam.transfer import (
    PLAN_OVERLAP,
    PLAN_TOO_CLOSE,
    TRANSFERS,
    FramePlan,
    plan_frame_changes,
    sample_hypotheses,
    transfer_support,
)

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Frame statuses, as codes (index into this tuple) and as the strings of the public API.
FRAME_STATUSES: tuple[str, ...] = (
    "ok",
    "l1_unbounded",
    "l2_unbounded",
    "l1_l2_overlap",
    "l1_l2_too_close",
)
FRAME_CODE = {name: code for code, name in enumerate(FRAME_STATUSES)}

#: Landmark statuses, as codes and strings.
LANDMARK_STATUSES: tuple[str, ...] = ("updated", "unbounded", "inconsistent", "skipped")
LANDMARK_CODE = {name: code for code, name in enumerate(LANDMARK_STATUSES)}

INCONSISTENCY_POLICIES = ("restart", "keep")


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


class BatchedPolygonSLAM:
    """``num_maps`` independent polygon-SLAM maps, updated together.

    Args mirror :class:`~bearing_env.slam.PolygonSLAM`, plus ``num_maps``.
    """

    def __init__(
        self,
        num_maps: int,
        n_landmarks: int,
        epsilon: float,
        transfer: str = "conservative",
        directions: int = 32,
        edge_samples: int = 3,
        on_inconsistency: str = "restart",
    ) -> None:
        self.num_maps = _int_at_least(num_maps, 1, "num_maps")
        self.n_landmarks = _int_at_least(n_landmarks, 3, "n_landmarks", "(L1, L2 and one more)")
        epsilon = float(epsilon)
        if not 0.0 < epsilon < np.pi / 2:
            raise ValueError(f"epsilon must be in (0, pi/2) radians, got {epsilon!r}")
        if transfer not in TRANSFERS:
            raise ValueError(f"transfer must be one of {TRANSFERS}, got {transfer!r}")
        if on_inconsistency not in INCONSISTENCY_POLICIES:
            raise ValueError(
                f"on_inconsistency must be one of {INCONSISTENCY_POLICIES}, "
                f"got {on_inconsistency!r}"
            )
        self.epsilon = epsilon
        self.transfer = transfer
        self.edge_samples = _int_at_least(edge_samples, 1, "edge_samples")
        self.on_inconsistency = on_inconsistency
        if isinstance(directions, bool) or not isinstance(directions, (int, np.integer)):
            raise TypeError(f"directions must be an int, got {directions!r}")
        self.kgon = KGon(int(directions))
        n, m, k = self.num_maps, self.n_landmarks - 2, self.kgon.k
        self.support = np.empty((n, m, k))
        self.initialised = np.empty((n, m), dtype=bool)
        self.areas = np.empty((n, m))
        self.centroids = np.empty((n, m), dtype=complex)
        self.robot_support = np.empty((n, k))
        self.has_robot = np.empty(n, dtype=bool)
        self.robot_area = np.empty(n)
        self.robot_centroid = np.empty(n, dtype=complex)
        self.robot_heading = np.empty(n)
        self.n_updates = np.empty(n, dtype=np.int64)
        self.n_frame_changes = np.empty(n, dtype=np.int64)
        self.n_inconsistent = np.empty(n, dtype=np.int64)
        self.reset()

    def reset(self, maps: ArrayLike | None = None) -> None:
        """Forget everything in the given maps (indices or a mask; default all)."""
        rows = slice(None) if maps is None else np.asarray(maps)
        self.support[rows] = np.inf
        self.initialised[rows] = False
        self.areas[rows] = np.inf
        self.centroids[rows] = complex(np.nan, np.nan)
        self.robot_support[rows] = np.inf
        self.has_robot[rows] = False
        self.robot_area[rows] = np.inf
        self.robot_centroid[rows] = complex(np.nan, np.nan)
        self.robot_heading[rows] = np.nan
        self.n_updates[rows] = 0
        self.n_frame_changes[rows] = 0
        self.n_inconsistent[rows] = 0

    def update(
        self,
        bearings_start: ArrayLike,
        bearings_end: ArrayLike,
        maps: ArrayLike | None = None,
    ) -> BatchUpdateResult:
        """Fuse one movement into each of the given maps.

        Args:
            bearings_start: bearings (len(maps), n_landmarks) at R1, radians CCW from the
                direction of motion; column 0 is L1, column 1 is L2.
            bearings_end: bearings at R2, same shape.
            maps: indices of the maps to update (default: all, in order).

        Raises:
            ValueError: on a wrong shape or a non-finite bearing.
        """
        rows = np.arange(self.num_maps) if maps is None else np.asarray(maps, dtype=np.int64)
        b1 = self._check_bearings(bearings_start, rows.size, "bearings_start")
        b2 = self._check_bearings(bearings_end, rows.size, "bearings_end")
        return self._update_checked(b1, b2, rows)

    def _update_checked(
        self, b1: FloatArray, b2: FloatArray, rows: IntArray
    ) -> BatchUpdateResult:
        """:meth:`update` on bearings already checked (float arrays (len(rows), n))."""
        n_rows, n_mapped = rows.size, self.n_landmarks - 2
        self.n_updates[rows] += 1
        regions, fr_status = cone_intersections(b1, b2, self.epsilon)

        frame = np.full(n_rows, FRAME_CODE["ok"], dtype=np.int8)
        frame[fr_status[:, 1] != FR_BOUNDED] = FRAME_CODE["l2_unbounded"]
        frame[fr_status[:, 0] != FR_BOUNDED] = FRAME_CODE["l1_unbounded"]
        bounded = np.flatnonzero(frame == FRAME_CODE["ok"])
        plan = plan_frame_changes(
            regions[bounded, 0], regions[bounded, 1], self.transfer, self.edge_samples
        )
        frame[bounded[plan.status == PLAN_OVERLAP]] = FRAME_CODE["l1_l2_overlap"]
        frame[bounded[plan.status == PLAN_TOO_CLOSE]] = FRAME_CODE["l1_l2_too_close"]

        landmark = np.full((n_rows, n_mapped), LANDMARK_CODE["skipped"], dtype=np.int8)
        changed = frame == FRAME_CODE["ok"]
        ok = np.flatnonzero(changed)
        if ok.size:
            landmark[ok] = np.where(
                fr_status[ok, 2:] == FR_EMPTY,
                LANDMARK_CODE["inconsistent"],
                LANDMARK_CODE["unbounded"],
            )
            self._fuse(rows, ok, regions, fr_status, plan, bounded, landmark)
        bad = np.count_nonzero(landmark == LANDMARK_CODE["inconsistent"], axis=-1)
        self.n_inconsistent[rows] += bad
        return BatchUpdateResult(changed, frame, landmark, bad)

    def _fuse(
        self,
        rows: IntArray,
        ok: IntArray,
        regions: NDArray[np.complex128],
        fr_status: NDArray[np.int8],
        plan: FramePlan,
        bounded: IntArray,
        landmark: NDArray[np.int8],
    ) -> None:
        """Transfer and intersect the regions of the movements ``ok`` (indices into ``rows``)."""
        k = self.kgon.k
        n_mapped = self.n_landmarks - 2
        robot_new = np.empty((ok.size, k))
        landmark_new = np.empty((ok.size, n_mapped, k))
        conservative = self.transfer == "conservative"
        in_plan = np.searchsorted(bounded, ok)  # every movement in ok is in the plan
        per_edge_of = plan.per_edge[in_plan]
        # Maps needing the same sampling are transferred together; each map's sampling
        # depends on its own regions only.
        if np.all(per_edge_of == per_edge_of[0]):
            groups = [(int(per_edge_of[0]), np.arange(ok.size))]
        else:
            groups = [
                (int(per_edge), np.flatnonzero(per_edge_of == per_edge))
                for per_edge in np.unique(per_edge_of)
            ]
        for per_edge, group in groups:
            members = ok[group]
            hyp = sample_hypotheses(
                regions[members, 0],
                regions[members, 1],
                plan.take(in_plan[group]),
                per_edge,
                conservative,
            )
            targets = regions[members, 2:]
            usable = fr_status[members, 2:] == FR_BOUNDED
            # Unbounded targets hold nan vertices; any finite stand-in keeps the arithmetic
            # quiet, and their results are discarded below.
            targets = np.where(usable[..., None], targets, 0.0)
            robot, landmarks = transfer_support(self.kgon, hyp, targets)
            robot_new[group] = robot
            landmark_new[group] = landmarks

        targets_ok = fr_status[ok, 2:] == FR_BOUNDED
        update = targets_ok & np.all(np.isfinite(landmark_new), axis=-1)
        map_rows = rows[ok]
        which_map, which_landmark = np.nonzero(update)
        new = landmark_new[which_map, which_landmark]
        global_map = map_rows[which_map]
        was_init = self.initialised[global_map, which_landmark]
        fused = new.copy()
        inconsistent = np.zeros(new.shape[0], dtype=bool)
        if was_init.any():
            old = self.support[global_map[was_init], which_landmark[was_init]]
            merged, empty = self.kgon.intersect(old, new[was_init])
            fallback = old if self.on_inconsistency == "keep" else new[was_init]
            merged[empty] = fallback[empty]
            fused[was_init] = merged
            inconsistent[np.flatnonzero(was_init)[empty]] = True
        landmark[ok[which_map], which_landmark] = np.where(
            inconsistent, LANDMARK_CODE["inconsistent"], LANDMARK_CODE["updated"]
        )
        self.support[global_map, which_landmark] = fused
        self.initialised[global_map, which_landmark] = True
        area, centroid = self.kgon.area_centroid(fused)
        self.areas[global_map, which_landmark] = area
        self.centroids[global_map, which_landmark] = centroid

        self.robot_support[map_rows] = robot_new
        self.has_robot[map_rows] = True
        robot_area, robot_centroid = self.kgon.area_centroid(robot_new)
        self.robot_area[map_rows] = robot_area
        self.robot_centroid[map_rows] = robot_centroid
        # Heading: the FR x-axis seen through T at the vertex means of A_L1 and A_L2.
        means = regions[ok, :2].mean(axis=-1)
        self.robot_heading[map_rows] = -np.angle(means[:, 1] - means[:, 0])
        self.n_frame_changes[map_rows] += 1

    def _check_bearings(self, bearings: ArrayLike, n_rows: int, name: str) -> FloatArray:
        arr = np.asarray(bearings, dtype=np.float64)
        if arr.shape != (n_rows, self.n_landmarks):
            raise ValueError(
                f"{name} must have shape ({n_rows}, {self.n_landmarks}), got {arr.shape}"
            )
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must be finite, got {arr.tolist()}")
        return arr

    def contains(self, points: ArrayLike, maps: ArrayLike | None = None) -> NDArray[np.bool_]:
        """Whether region ``i`` of each map contains FL point ``i`` (boundary counts).

        Args:
            points: complex FL points (len(maps), n_landmarks - 2).
            maps: indices of the maps (default: all, in order).

        Returns:
            Bool (len(maps), n_landmarks - 2); False where a landmark is not initialised.
        """
        rows = np.arange(self.num_maps) if maps is None else np.asarray(maps, dtype=np.int64)
        z = np.asarray(points, dtype=np.complex128)
        if z.shape != (rows.size, self.n_landmarks - 2):
            raise ValueError(
                f"points must have shape ({rows.size}, {self.n_landmarks - 2}), got {z.shape}"
            )
        initialised = self.initialised[rows]
        inside = np.zeros(z.shape, dtype=bool)
        if initialised.any():
            inside[initialised] = self.kgon.contains(self.support[rows][initialised], z[initialised])
        return inside

    def copy_map(self, source: int, target: int) -> None:
        """Overwrite map ``target`` with map ``source`` (planning: clone a map in place)."""
        for name in STATE_ARRAYS:
            array = getattr(self, name)
            array[target] = array[source]


#: The per-map state, every array with the map axis first.
STATE_ARRAYS = (
    "support",
    "initialised",
    "areas",
    "centroids",
    "robot_support",
    "has_robot",
    "robot_area",
    "robot_centroid",
    "robot_heading",
    "n_updates",
    "n_frame_changes",
    "n_inconsistent",
)


def _int_at_least(value: object, minimum: int, name: str, why: str = "") -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an int, got {value!r}")
    if value < minimum:
        suffix = f" {why}" if why else ""
        raise ValueError(f"{name} must be >= {minimum}{suffix}, got {value}")
    return int(value)
