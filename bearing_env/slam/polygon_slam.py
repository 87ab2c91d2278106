"""The map: the paper's polygon bearing-only SLAM, fused over movements in FL."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from bearing_env.slam import kernels
from bearing_env.slam.batch import (
    CONTAINMENT_TOLERANCE,
    FRAME_STATUSES,
    LANDMARK_STATUSES,
    BatchedPolygonSLAM,
    check_bearings,
)
from bearing_env.slam.settings import (
    DEFAULT_MAX_OUTLIERS,
    DEFAULT_RISK,
    DEFAULT_WINDOW,
    FUSIONS,
    INCONSISTENCY_POLICIES,
    HasMapSettings,
    MapSettings,
)
from bearing_env.validation import int_at_least

if TYPE_CHECKING:  # imported where used: making and stepping an env never needs it
    import shapely

(
    FRAME_OK,
    FRAME_L1_UNBOUNDED,
    FRAME_L2_UNBOUNDED,
    FRAME_L1_L2_OVERLAP,
    FRAME_L1_L2_TOO_CLOSE,
    FRAME_L1_MISSING,
    FRAME_L2_MISSING,
    FRAME_REJECTED,
) = FRAME_STATUSES
(
    LANDMARK_UPDATED,
    LANDMARK_UNBOUNDED,
    LANDMARK_INCONSISTENT,
    LANDMARK_SKIPPED,
    LANDMARK_MISSING,
) = LANDMARK_STATUSES
_LANDMARK_NAMES = np.array(LANDMARK_STATUSES, dtype="<U12")

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
    "PolygonSLAM",
    "UpdateResult",
    "fl_to_world",
    "world_to_fl",
]


@dataclass(frozen=True)
class UpdateResult:
    """What one movement did to the map.

    Attributes:
        frame_changed: the movement could change frames and update the map.
        frame_status: ``"ok"``, or why not: ``"l1_unbounded"`` / ``"l2_unbounded"`` (a
            cone pair of L1 or L2 is near-parallel or misses), ``"l1_l2_overlap"`` (their
            FR regions touch, so ``h2 - h1`` can be 0), ``"l1_l2_too_close"`` (conservative
            transfer only: they are disjoint but so close, relative to their size, that
            the transfer has no useful bound).
        landmark_status: per landmark ``i >= 3`` (index ``i - 3``): ``"updated"``,
            ``"unbounded"`` (its cones gave no bounded region; left alone),
            ``"inconsistent"`` (empty cone intersection, or empty intersection with the
            map's region) or ``"skipped"`` (the frame could not be changed).
        n_inconsistent: number of landmarks marked ``"inconsistent"``.
    """

    frame_changed: bool
    frame_status: str
    landmark_status: NDArray[np.str_]
    n_inconsistent: int


def world_to_fl(points: ArrayLike, l1: ArrayLike, l2: ArrayLike) -> NDArray[np.float64]:
    """Landmark-frame coordinates of world points: ``(z - L1) / (L2 - L1)``.

    Args:
        points: array (..., 2) of world coordinates.
        l1, l2: world positions (2,) of the two frame landmarks.
    """
    z = _to_complex(points)
    c1, c2 = _to_complex(l1), _to_complex(l2)
    fl = (z - c1) / (c2 - c1)
    return np.stack([fl.real, fl.imag], axis=-1)


def fl_to_world(points: ArrayLike, l1: ArrayLike, l2: ArrayLike) -> NDArray[np.float64]:
    """Inverse of :func:`world_to_fl`."""
    z = _to_complex(points)
    c1, c2 = _to_complex(l1), _to_complex(l2)
    w = c1 + z * (c2 - c1)
    return np.stack([w.real, w.imag], axis=-1)


def _to_complex(points: ArrayLike) -> NDArray[np.complex128]:
    arr = np.asarray(points, dtype=np.float64)
    if arr.shape[-1:] != (2,):
        raise ValueError(f"expected points with a last axis of size 2, got shape {arr.shape}")
    return arr[..., 0] + 1j * arr[..., 1]


class PolygonSLAM(HasMapSettings):
    """Bearing-only SLAM with uncertainty polygons (Huang, Maire & Keeratipranon 2005).

    Feed it the two panoramic readings of each straight movement; it keeps, for every
    landmark ``i >= 3``, the intersection of its FL regions over all movements that could
    change frames, and the robot's region at the end of the last such movement.

    Each region is an exact convex polygon (see :mod:`bearing_env.slam.kernels`), and
    every update runs in compiled code. With ``transfer="paper"`` a landmark's region is
    exactly the intersection of the vertex hulls of its movements, as in the paper.

    Args:
        n_landmarks: number of landmarks, >= 3; landmark 0 is L1, landmark 1 is L2.
        epsilon: bearing error bound, radians, in (0, pi/2).
        transfer: ``"conservative"`` (regions contain the truth whenever the bearing
            noise is within +-epsilon) or ``"paper"`` (vertex hypotheses + hull).
        edge_samples: samples per edge of A_L1 and A_L2 for the conservative transfer,
            1..8 (more are used, up to 8, when L1's and L2's regions are close relative
            to their size).
        on_inconsistency: what a landmark's region becomes when a movement's region
            misses it (the observations contradict epsilon): ``"restart"`` replaces it by
            the movement's region (the newest evidence; the old intersection is known to
            be wrong), ``"keep"`` leaves it unchanged. Either way it is counted. With
            ``fusion="relaxed"`` this applies when more than ``max_outliers`` of the
            window's regions disagree.
        fusion: ``"intersect"`` (the paper: the intersection of all of a landmark's
            regions) or ``"relaxed"``: the q-relaxed intersection of the regions of the
            last ``window`` movements (plus the intersection of the older regions it
            kept), which leaves out up to ``max_outliers`` regions per landmark, and
            whole movements that are outliers for most landmarks (a misread L1 or L2).
            See :func:`bearing_env.slam.kernels.relaxed_movement`. Or ``"robust"``:
            the relaxed intersection of all of a landmark's regions, leaving out as many
            as a risk target asks (see ``risk``).
        max_outliers: with ``fusion="relaxed"``, the most regions per landmark that the
            window may leave out (0 <= max_outliers < window).
        window: with ``fusion="relaxed"``, the movements kept per map, 1..32.
        risk: with ``fusion="robust"``, the target chance, under the map's estimated
            contamination rate, that more of a landmark's regions are contaminated than
            its guaranteed set leaves out, in (0, 0.5]. See
            :mod:`bearing_env.slam.kernels.robust`; ``fusion="robust"`` ignores
            ``max_outliers`` and ``window`` (it leaves out at most ``ROBUST_LEVELS - 1``
            regions of the whole history).
        robust_set: with ``fusion="robust"``, the set the map reports: ``"guaranteed"``
            (leaves out enough regions for ``risk``) or ``"likely"`` (only those that
            contradict the others).
        noise_bound: with ``fusion="robust"``, the bound bearings are read with:
            ``"estimate"`` (``epsilon``, grown when a probe map shows it too small, and
            the regions then rebuilt from the last movements; see :attr:`bound` and
            :mod:`bearing_env.slam.kernels.robust`) or ``"nominal"`` (``epsilon``
            throughout).

    These are the fields of :class:`~bearing_env.slam.settings.MapSettings`, which
    validates them (the map's :attr:`settings`); :meth:`from_settings` takes one whole.
    A bearing given as NaN is a missed reading: that landmark is skipped for the
    movement (status ``"missing"``), and a missed L1 or L2 skips the movement
    (``"l1_missing"``, ``"l2_missing"``).
    """

    def __init__(
        self,
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
        self._batch = BatchedPolygonSLAM(
            1,
            n_landmarks,
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
        self._attach(self._batch, 0)

    def _attach(self, batch: BatchedPolygonSLAM, index: int) -> None:
        self._batch = batch
        self._index = index
        self._rows = np.array([index])
        self.n_landmarks = batch.n_landmarks
        # What the kernel reports for this map's updates, made at the first and written
        # in place by each one (PolygonSLAM.update hands out copies only).
        self._outputs: kernels.Outputs | None = None
        #: The map's settings (validated; ``self.epsilon`` and the others read them).
        self.settings = batch.settings

    @classmethod
    def from_settings(cls, n_landmarks: int, settings: MapSettings) -> PolygonSLAM:
        """An empty map of ``n_landmarks`` landmarks with ``settings``."""
        return cls.view(BatchedPolygonSLAM.from_settings(1, n_landmarks, settings), 0)

    @classmethod
    def view(cls, batch: BatchedPolygonSLAM, index: int) -> PolygonSLAM:
        """Map ``index`` of a batch, shared: updating either updates both.

        The batched vector environment gives each sub-environment such a view, so the
        sub-environment's code reads its map while the vector environment updates all
        maps in one call.
        """
        if not 0 <= index < batch.num_maps:
            raise IndexError(f"map index {index} out of range for a batch of {batch.num_maps}")
        slam = cls.__new__(cls)
        slam._attach(batch, int(index))
        return slam

    @property
    def batch(self) -> BatchedPolygonSLAM:
        """The batch holding this map (a batch of one unless this is a :meth:`view`)."""
        return self._batch

    @property
    def index(self) -> int:
        """This map's index in :attr:`batch`."""
        return self._index

    @property
    def rows(self) -> NDArray[np.int64]:
        """``[index]``: this map's rows of :attr:`batch`, for batched calls."""
        return self._rows

    # -- state -----------------------------------------------------------------------------

    def reset(self) -> None:
        """Forget everything: no landmark initialised, no robot region."""
        self._batch.reset(self._rows)

    def copy(self) -> PolygonSLAM:
        """An independent copy (for planning: simulate moves without touching the map)."""
        return PolygonSLAM.view(self.replicate(1), 0)

    def replicate(self, count: int, into: BatchedPolygonSLAM | None = None) -> BatchedPolygonSLAM:
        """``count`` independent copies of this map, as one batch.

        For planning: score many candidate movements with one batched
        :meth:`BatchedPolygonSLAM.update`, each candidate on its own copy. ``into``: a
        batch from an earlier call to overwrite instead of making a new one, when it has
        ``count`` maps and this map's settings (a planner's scratch; else a new batch).
        """
        count = int_at_least(count, 1, "replicate count")
        if into is not None and into.num_maps == count and into.same_settings(self._batch):
            into.fill_from(self._batch, self._index)
            return into
        return self._batch.take(np.full(count, self._index, dtype=np.int64))

    @property
    def n_updates(self) -> int:
        """Movements fed to :meth:`update`."""
        return int(self._batch.n_updates[self._index])

    @property
    def n_frame_changes(self) -> int:
        """Movements that could change frames and update the map."""
        return int(self._batch.n_frame_changes[self._index])

    @property
    def bound(self) -> float:
        """The bearing error bound the map reads bearings with now, radians: ``epsilon``,
        or larger once the robust fusion's estimate has grown it (``noise_bound``)."""
        return float(self.epsilon * self._batch.noise_scale[self._index])

    @property
    def n_inconsistent(self) -> int:
        """Landmark updates that met an inconsistency, over all movements."""
        return int(self._batch.n_inconsistent[self._index])

    @property
    def outliers(self) -> NDArray[np.int64]:
        """(n-2,) per landmark, the regions its fused region leaves out (``"relaxed"``;
        always 0 with ``"intersect"``)."""
        return self._batch.outliers[self._index].copy()

    # -- the update --------------------------------------------------------------------------

    def update(self, bearings_start: ArrayLike, bearings_end: ArrayLike) -> UpdateResult:
        """Fuse one straight movement.

        Args:
            bearings_start: bearings (n_landmarks,) at R1, radians counter-clockwise from
                the direction of motion; index 0 is L1, index 1 is L2.
            bearings_end: bearings (n_landmarks,) at R2.

        Raises:
            ValueError: on a wrong shape or a non-finite bearing.
        """
        b1 = self._check_bearings(bearings_start, "bearings_start")
        b2 = self._check_bearings(bearings_end, "bearings_end")
        # Checked above, for this map's shape; the batch need not check again.
        out = self._outputs
        if out is None:
            out = self._outputs = kernels.Outputs(
                np.empty(1, dtype=np.int8),
                np.empty((1, self.n_landmarks - 2), dtype=np.int8),
                np.empty(1, dtype=np.int64),
            )
        self._batch._run_update(b1[None], b2[None], self._rows, True, out)
        frame = FRAME_STATUSES[out.frame_status[0]]
        return UpdateResult(
            frame_changed=frame == FRAME_OK,
            frame_status=frame,
            landmark_status=_LANDMARK_NAMES[out.landmark_status[0]],  # a new array
            n_inconsistent=int(out.n_bad[0]),
        )

    def _check_bearings(self, bearings: ArrayLike, name: str) -> NDArray[np.float64]:
        return check_bearings(bearings, (self.n_landmarks,), name)

    def __getstate__(self) -> dict[str, Any]:
        # The outputs are made again (an out-of-band pickle would make them read-only).
        state = self.__dict__.copy()
        state["_outputs"] = None
        return state

    # -- queries -----------------------------------------------------------------------------

    @property
    def initialised(self) -> NDArray[np.bool_]:
        """Bool (n_landmarks - 2,): landmark ``i >= 3`` has a region."""
        return self._batch.initialised[self._index].copy()

    @property
    def areas(self) -> NDArray[np.float64]:
        """Region areas (n_landmarks - 2,) in FL units squared; ``inf`` if not initialised."""
        return self._batch.areas[self._index].copy()

    @property
    def estimates(self) -> NDArray[np.float64]:
        """Region centroids (n_landmarks - 2, 2) in FL; ``nan`` if not initialised."""
        centroids = self._batch.centroids[self._index]
        return np.stack([centroids.real, centroids.imag], axis=-1)

    @property
    def polygons(self) -> list[NDArray[np.float64] | None]:
        """Region vertices (k, 2) counter-clockwise in FL per landmark, or None."""
        batch, index = self._batch, self._index
        return [
            _xy(batch.polygon(index, j)) if batch.counts[index, j] else None
            for j in range(self.n_landmarks - 2)
        ]

    @property
    def regions(self) -> list[shapely.Polygon | None]:
        """Regions of landmarks 3..n as shapely Polygons in FL (None if not initialised)."""
        import shapely

        return [None if p is None else shapely.Polygon(p) for p in self.polygons]

    @property
    def robot_polygon(self) -> NDArray[np.float64] | None:
        """The robot's current region (R2 of the last frame-changing move) as vertices."""
        if not self._batch.robot_counts[self._index]:
            return None
        return _xy(self._batch.robot_polygon(self._index))

    @property
    def robot_region(self) -> shapely.Polygon | None:
        poly = self.robot_polygon
        import shapely

        return None if poly is None else shapely.Polygon(poly)

    @property
    def robot_estimate(self) -> NDArray[np.float64]:
        """Centroid (2,) of the robot's region in FL; ``nan`` before any frame change."""
        centroid = self._batch.robot_centroid[self._index]
        return np.array([centroid.real, centroid.imag])

    @property
    def robot_area(self) -> float:
        """Area of the robot's region in FL units squared; ``inf`` before any frame change."""
        return float(self._batch.robot_area[self._index])

    @property
    def robot_heading(self) -> float:
        """Direction (radians, FL) of the last frame-changing movement; ``nan`` if none."""
        return float(self._batch.robot_heading[self._index])

    def contains(self, points_fl: ArrayLike) -> NDArray[np.bool_]:
        """Whether region ``i`` contains FL point ``i`` (shape (n_landmarks - 2, 2)).

        False for landmarks that are not initialised.
        """
        z = _to_complex(points_fl)
        if z.shape != (self.n_landmarks - 2,):
            raise ValueError(
                f"points_fl must have shape ({self.n_landmarks - 2}, 2), got {np.shape(points_fl)}"
            )
        return self._batch.contains(z[None], self._rows)[0]

    def robot_contains(self, point_fl: ArrayLike) -> bool:
        """Whether the robot's region contains ``point_fl`` (2,)."""
        batch, index = self._batch, self._index
        if not batch.robot_counts[index]:
            return False
        polygon = batch.robot_vertices[index]
        return bool(
            kernels.contains_point(
                polygon,
                int(batch.robot_counts[index]),
                complex(_to_complex(point_fl)),
                CONTAINMENT_TOLERANCE,
            )
        )


def _xy(points: NDArray[np.complex128]) -> NDArray[np.float64]:
    return np.stack([points.real, points.imag], axis=-1)
