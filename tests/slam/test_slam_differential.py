"""The map against an independent shapely implementation of the paper's method.

On a seeded suite of random layouts, a reference map is built here from scratch: the FR
regions by exact line intersections (``tests/slam_sim.py``), the paper's vertex hulls
in FL by shapely, and their intersection over movements by shapely. With
``transfer="paper"`` the map's regions must equal the reference to 1e-9 relative area,
movement by movement, restarts after inconsistencies included.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from bearing_env.slam import LANDMARK_INCONSISTENT, PolygonSLAM
from tests.slam_sim import cone_region_vertices, random_episode, to_xy

EPS = np.deg2rad(2.0)
#: FR extents between these two are "numerically unbounded" for one side and not for
#: the other; such movements are outside what the comparison can decide.
AMBIGUOUS_EXTENT = (1e3, 1e4)


def vertex_hull(points) -> shapely.Polygon:
    return shapely.convex_hull(shapely.multipoints(to_xy(np.asarray(points).reshape(-1))))


class ReferenceMap:
    """The paper's method in shapely: vertex-hypothesis hulls, intersected over moves."""

    def __init__(self, n_landmarks: int, epsilon: float = EPS) -> None:
        self.epsilon = epsilon
        self.regions: list[shapely.Polygon | None] = [None] * (n_landmarks - 2)
        #: Landmarks whose reference is too close to a tie to compare (see below).
        self.undecided = np.zeros(n_landmarks - 2, dtype=bool)

    def update(self, b1: np.ndarray, b2: np.ndarray) -> bool:
        """Fuse one movement; False when the movement itself is undecidable."""
        fr = [cone_region_vertices(b1[i], b2[i], self.epsilon) for i in range(b1.size)]
        extents = [np.inf if r is None else np.abs(r).max() for r in fr]
        if any(AMBIGUOUS_EXTENT[0] <= e <= AMBIGUOUS_EXTENT[1] for e in extents):
            return False
        if fr[0] is None or fr[1] is None or extents[0] > 1e4 or extents[1] > 1e4:
            return True  # the frame cannot change: nothing to fuse
        a1, a2 = vertex_hull(fr[0]), vertex_hull(fr[1])
        gap = a1.distance(a2)
        if 0.0 < gap < 1e-9:
            return False
        if gap == 0.0:
            return True
        h1 = np.asarray(a1.exterior.coords)[:-1] @ [1, 1j]
        h2 = np.asarray(a2.exterior.coords)[:-1] @ [1, 1j]
        for i, region in enumerate(fr[2:]):
            if region is None or extents[i + 2] > 1e4:
                continue
            images = (region[:, None, None] - h1[None, :, None]) / (
                h2[None, None, :] - h1[None, :, None]
            )
            hull = vertex_hull(images)
            old = self.regions[i]
            if old is None:
                self.regions[i] = hull
                continue
            fused = old.intersection(hull)
            smaller = min(old.area, hull.area)
            if fused.area <= 1e-9 * smaller and fused.area > 0.0:
                self.undecided[i] = True  # empty or not is a matter of rounding
            # An empty intersection: the map restarts from the newest region (default).
            self.regions[i] = fused if fused.area > 0.0 else hull
        return True


def episodes(n: int):
    for seed in range(n):
        rng = np.random.default_rng(20_000 + seed)
        noise = "extreme" if seed % 3 == 2 else "uniform"
        yield random_episode(rng, 6, 10, noise=noise)


@pytest.mark.parametrize("chunk", range(4))
def test_paper_map_equals_the_shapely_intersection_of_vertex_hulls(chunk):
    compared = restarts = 0
    for index, episode in enumerate(episodes(60)):
        if index % 4 != chunk:
            continue
        slam = PolygonSLAM(6, EPS, transfer="paper")
        reference = ReferenceMap(6)
        for b1, b2 in episode.readings(EPS):
            result = slam.update(b1, b2)
            if not reference.update(b1, b2):
                break  # undecidable from here on: stop comparing this episode
            restarts += int(np.sum(result.landmark_status == LANDMARK_INCONSISTENT))
            for j, (mine, ref) in enumerate(zip(slam.regions, reference.regions, strict=True)):
                if reference.undecided[j]:
                    continue
                assert (mine is None) == (ref is None), (index, j)
                if ref is None:
                    continue
                assert slam.areas[j] == pytest.approx(ref.area, rel=1e-9), (index, j)
                assert mine.symmetric_difference(ref).area <= 1e-9 * ref.area, (index, j)
                centroid = complex(ref.centroid.x, ref.centroid.y)
                size = np.sqrt(ref.area) + abs(centroid)
                estimate = complex(*slam.estimates[j])
                assert abs(estimate - centroid) <= 1e-9 * size, (index, j)
                compared += 1
    # The suite is not vacuous: most (move, landmark) pairs are compared.
    assert compared >= 15 * 10 * 4 * 0.6, compared
    if chunk == 2:  # holds the worst-case-noise episodes that force restarts
        assert restarts > 0


def test_wide_cones_without_noise_give_the_exact_nonnegative_intersection():
    """The K-gon engine gave negative areas here (regions sharing a vertex exactly):
    3 landmarks, epsilon = 20 degrees, noise-free movements, the paper transfer."""
    eps = np.deg2rad(20.0)
    compared = 0
    for seed in range(150):
        episode = random_episode(
            np.random.default_rng(30_000 + seed), 3, 3, length_range=(0.4, 0.9), noise="none"
        )
        slam = PolygonSLAM(3, eps, transfer="paper")
        reference = ReferenceMap(3, eps)
        for b1, b2 in episode.readings(eps):
            slam.update(b1, b2)
            if not reference.update(b1, b2):
                break
            assert np.all(slam.areas[slam.initialised] > 0.0), (seed, slam.areas)
            ref = reference.regions[0]
            if ref is None or reference.undecided[0]:
                continue
            assert slam.areas[0] == pytest.approx(ref.area, rel=1e-9), seed
            # Noise-free bearings: the truth lies in every region.
            assert slam.contains(episode.truth_fl()).all() or not slam.initialised.all()
            compared += 1
    assert compared > 200, compared
