"""The map: the paper's polygon bearing-only SLAM, fused over movements in FL."""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
import shapely
from numpy.typing import ArrayLike, NDArray

from bearing_env.slam.geometry import (
    FR_BOUNDED,
    FR_EMPTY,
    KGon,
    cone_intersections,
)
from bearing_env.slam.transfer import TRANSFERS, Hypotheses, make_hypotheses, transfer_support

FRAME_OK = "ok"
FRAME_L1_UNBOUNDED = "l1_unbounded"
FRAME_L2_UNBOUNDED = "l2_unbounded"
FRAME_L1_L2_OVERLAP = "l1_l2_overlap"
FRAME_L1_L2_TOO_CLOSE = "l1_l2_too_close"

LANDMARK_UPDATED = "updated"
LANDMARK_UNBOUNDED = "unbounded"
LANDMARK_INCONSISTENT = "inconsistent"
LANDMARK_SKIPPED = "skipped"

INCONSISTENCY_POLICIES = ("restart", "keep")


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


class PolygonSLAM:
    """Bearing-only SLAM with uncertainty polygons (Huang, Maire & Keeratipranon 2005).

    Feed it the two panoramic readings of each straight movement; it keeps, for every
    landmark ``i >= 3``, the intersection of its FL regions over all movements that could
    change frames, and the robot's region at the end of the last such movement.

    The map stores each region as a circumscribed K-gon with ``directions`` fixed
    normals (see :mod:`bearing_env.slam.geometry`). That makes fusion exact and every
    update one batched numpy computation; the price is that a region is the K-gon around
    the transferred hull, slightly larger than the hull itself (never smaller, so
    containment is preserved).

    Args:
        n_landmarks: number of landmarks, >= 3; landmark 0 is L1, landmark 1 is L2.
        epsilon: bearing error bound, radians, in (0, pi/2).
        transfer: ``"conservative"`` (regions contain the truth whenever the bearing
            noise is within +-epsilon) or ``"paper"`` (vertex hypotheses + hull).
        directions: number K of normals of the region K-gons (even, >= 8).
        edge_samples: samples per edge of A_L1 and A_L2 for the conservative transfer
            (more are used, up to 8, when L1's and L2's regions are close relative to
            their size).
        on_inconsistency: what a landmark's region becomes when a movement's region
            misses it (the observations contradict epsilon): ``"restart"`` replaces it by
            the movement's region (the newest evidence; the old intersection is known to
            be wrong), ``"keep"`` leaves it unchanged. Either way it is counted.
    """

    def __init__(
        self,
        n_landmarks: int,
        epsilon: float,
        transfer: str = "conservative",
        directions: int = 32,
        edge_samples: int = 3,
        on_inconsistency: str = "restart",
    ) -> None:
        if isinstance(n_landmarks, bool) or not isinstance(n_landmarks, (int, np.integer)):
            raise TypeError(f"n_landmarks must be an int, got {n_landmarks!r}")
        if n_landmarks < 3:
            raise ValueError(f"n_landmarks must be >= 3 (L1, L2 and one more), got {n_landmarks}")
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
        if isinstance(edge_samples, bool) or not isinstance(edge_samples, (int, np.integer)):
            raise TypeError(f"edge_samples must be an int, got {edge_samples!r}")
        if edge_samples < 1:
            raise ValueError(f"edge_samples must be >= 1, got {edge_samples}")
        self.n_landmarks = int(n_landmarks)
        self.epsilon = epsilon
        self.transfer = transfer
        self.edge_samples = int(edge_samples)
        self.on_inconsistency = on_inconsistency
        if isinstance(directions, bool) or not isinstance(directions, (int, np.integer)):
            raise TypeError(f"directions must be an int, got {directions!r}")
        self.kgon = KGon(int(directions))
        self.reset()

    # -- state -----------------------------------------------------------------------------

    def reset(self) -> None:
        """Forget everything: no landmark initialised, no robot region."""
        n = self.n_landmarks - 2
        self._support = np.full((n, self.kgon.k), np.inf)
        self._initialised = np.zeros(n, dtype=bool)
        self._robot_support: NDArray[np.float64] | None = None
        self._robot_heading = float("nan")
        self._areas = np.full(n, np.inf)
        self._centroids = np.full(n, complex(np.nan, np.nan))
        self._robot_centroid = complex(np.nan, np.nan)
        self._robot_area = float("inf")
        self.n_updates = 0
        self.n_frame_changes = 0
        self.n_inconsistent = 0

    def copy(self) -> PolygonSLAM:
        """An independent copy (for planning: simulate moves without touching the map)."""
        return copy.deepcopy(self)

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
        self.n_updates += 1
        n_mapped = self.n_landmarks - 2
        regions, fr_status = cone_intersections(b1, b2, self.epsilon)

        frame_status = FRAME_OK
        if fr_status[0] != FR_BOUNDED:
            frame_status = FRAME_L1_UNBOUNDED
        elif fr_status[1] != FR_BOUNDED:
            frame_status = FRAME_L2_UNBOUNDED
        hyp: Hypotheses | str = frame_status
        if frame_status == FRAME_OK:
            hyp = make_hypotheses(regions[0], regions[1], self.transfer, self.edge_samples)
        if isinstance(hyp, str):
            frame_status = hyp
            skipped = np.full(n_mapped, LANDMARK_SKIPPED, dtype="<U12")
            return UpdateResult(False, frame_status, skipped, 0)

        self.n_frame_changes += 1
        status = np.full(n_mapped, LANDMARK_UNBOUNDED, dtype="<U12")
        status[fr_status[2:] == FR_EMPTY] = LANDMARK_INCONSISTENT
        idx = np.flatnonzero(fr_status[2:] == FR_BOUNDED)

        # One batched transfer: row 0 is the robot's R2 = 1 in FR, then the landmarks.
        targets = np.empty((idx.size + 1, 4), dtype=complex)
        targets[0] = 1.0
        targets[1:] = regions[2 + idx]
        new = transfer_support(self.kgon, hyp, targets)
        robot, new = new[0], new[1:]
        finite = np.all(np.isfinite(new), axis=-1)
        idx, new = idx[finite], new[finite]

        fused = new
        was_init = self._initialised[idx]
        inconsistent = np.zeros(idx.size, dtype=bool)
        if was_init.any():
            old = self._support[idx[was_init]]
            merged, empty = self.kgon.intersect(old, new[was_init])
            fallback = old if self.on_inconsistency == "keep" else new[was_init]
            merged[empty] = fallback[empty]
            fused = new.copy()
            fused[was_init] = merged
            inconsistent[np.flatnonzero(was_init)[empty]] = True
        status[idx] = np.where(inconsistent, LANDMARK_INCONSISTENT, LANDMARK_UPDATED)
        self._support[idx] = fused
        self._initialised[idx] = True
        self._robot_support = robot
        area, centroid = self.kgon.area_centroid(np.concatenate([robot[None], fused]))
        self._robot_centroid = complex(centroid[0])
        self._robot_area = float(area[0])
        self._areas[idx] = area[1:]
        self._centroids[idx] = centroid[1:]
        # Heading: the FR x-axis seen through T at the vertex means of A_L1 and A_L2.
        self._robot_heading = float(-np.angle(regions[1].mean() - regions[0].mean()))

        n_bad = int(np.count_nonzero(status == LANDMARK_INCONSISTENT))
        self.n_inconsistent += n_bad
        return UpdateResult(True, FRAME_OK, status, n_bad)

    def _check_bearings(self, bearings: ArrayLike, name: str) -> NDArray[np.float64]:
        arr = np.asarray(bearings, dtype=np.float64)
        if arr.shape != (self.n_landmarks,):
            raise ValueError(
                f"{name} must have shape ({self.n_landmarks},), got {arr.shape}"
            )
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} must be finite, got {arr.tolist()}")
        return arr

    # -- queries -----------------------------------------------------------------------------

    @property
    def initialised(self) -> NDArray[np.bool_]:
        """Bool (n_landmarks - 2,): landmark ``i >= 3`` has a region."""
        return self._initialised.copy()

    @property
    def areas(self) -> NDArray[np.float64]:
        """Region areas (n_landmarks - 2,) in FL units squared; ``inf`` if not initialised."""
        return self._areas.copy()

    @property
    def estimates(self) -> NDArray[np.float64]:
        """Region centroids (n_landmarks - 2, 2) in FL; ``nan`` if not initialised."""
        return np.stack([self._centroids.real, self._centroids.imag], axis=-1)

    @property
    def supports(self) -> NDArray[np.float64]:
        """Raw K-gon support values (n_landmarks - 2, K); ``inf`` rows if not initialised."""
        return self._support.copy()

    @property
    def polygons(self) -> list[NDArray[np.float64] | None]:
        """Region vertices (k, 2) counter-clockwise in FL per landmark, or None."""
        return [
            _kgon_vertices_xy(self.kgon, h) if ok else None
            for h, ok in zip(self._support, self._initialised, strict=True)
        ]

    @property
    def regions(self) -> list[shapely.Polygon | None]:
        """Regions of landmarks 3..n as shapely Polygons in FL (None if not initialised)."""
        return [None if p is None else shapely.Polygon(p) for p in self.polygons]

    @property
    def robot_polygon(self) -> NDArray[np.float64] | None:
        """The robot's current region (R2 of the last frame-changing move) as vertices."""
        if self._robot_support is None:
            return None
        return _kgon_vertices_xy(self.kgon, self._robot_support)

    @property
    def robot_region(self) -> shapely.Polygon | None:
        poly = self.robot_polygon
        return None if poly is None else shapely.Polygon(poly)

    @property
    def robot_estimate(self) -> NDArray[np.float64]:
        """Centroid (2,) of the robot's region in FL; ``nan`` before any frame change."""
        return np.array([self._robot_centroid.real, self._robot_centroid.imag])

    @property
    def robot_area(self) -> float:
        """Area of the robot's region in FL units squared; ``inf`` before any frame change."""
        return self._robot_area

    @property
    def robot_heading(self) -> float:
        """Direction (radians, FL) of the last frame-changing movement; ``nan`` if none."""
        return self._robot_heading

    def contains(self, points_fl: ArrayLike) -> NDArray[np.bool_]:
        """Whether region ``i`` contains FL point ``i`` (shape (n_landmarks - 2, 2)).

        False for landmarks that are not initialised.
        """
        z = _to_complex(points_fl)
        if z.shape != self._initialised.shape:
            raise ValueError(
                f"points_fl must have shape ({self.n_landmarks - 2}, 2), got {np.shape(points_fl)}"
            )
        inside = np.zeros(z.shape, dtype=bool)
        ok = self._initialised
        inside[ok] = self.kgon.contains(self._support[ok], z[ok])
        return inside

    def robot_contains(self, point_fl: ArrayLike) -> bool:
        """Whether the robot's region contains ``point_fl`` (2,)."""
        if self._robot_support is None:
            return False
        return bool(self.kgon.contains(self._robot_support, _to_complex(point_fl)))


def _kgon_vertices_xy(kgon: KGon, h: NDArray[np.float64]) -> NDArray[np.float64]:
    v = kgon.vertices(h)
    # Drop the zero-length edges that tightness leaves at sharp corners.
    keep = np.abs(v - np.roll(v, 1)) > 1e-12 * (1.0 + np.abs(v).max())
    if keep.sum() >= 3:
        v = v[keep]
    return np.stack([v.real, v.imag], axis=-1)
