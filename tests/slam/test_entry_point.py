"""The update kernels called through their compiled functions (kernels.entry_point):
the same maps as through numba's dispatcher, and results that are not overwritten."""

from __future__ import annotations

import pickle

import numpy as np

from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM, kernels
from bearing_env.slam.batch import STATE_ARRAYS


def _movements(seed: int, count: int, n_maps: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Noise-free bearings of seeded random moves among five landmarks, per map."""
    rng = np.random.default_rng(seed)
    landmarks = np.array([0.0, 1.0, 0.4 + 0.8j, 0.7 - 0.6j, -0.5 + 0.3j])
    positions = rng.uniform(-1.5, 1.5, n_maps) + 1j * rng.uniform(-1.5, 1.5, n_maps)
    moves = []
    for _ in range(count):
        steps = 0.5 * np.exp(1j * rng.uniform(-np.pi, np.pi, n_maps))
        headings = np.angle(steps)[:, None]
        b1 = np.angle(landmarks[None, :] - positions[:, None]) - headings
        b2 = np.angle(landmarks[None, :] - (positions + steps)[:, None]) - headings
        moves.append((np.ascontiguousarray(b1), np.ascontiguousarray(b2)))
        positions = positions + steps
    return moves


def test_the_compiled_function_updates_as_the_dispatcher_does() -> None:
    through_entry = BatchedPolygonSLAM(3, 5, np.deg2rad(2.0))
    through_dispatcher = BatchedPolygonSLAM(3, 5, np.deg2rad(2.0))
    rows = np.arange(3)
    params = through_dispatcher._kernel_params(True)
    for b1, b2 in _movements(0, 6, 3):
        result = through_entry.update(b1, b2)
        out = kernels.Outputs(
            np.empty(3, dtype=np.int8), np.empty((3, 3), dtype=np.int8), np.empty(3, dtype=np.int64)
        )
        kernels.update_maps(b1, b2, rows, params, through_dispatcher._kernel_state(), out)
        np.testing.assert_array_equal(result.frame_status, out.frame_status)
        np.testing.assert_array_equal(result.landmark_status, out.landmark_status)
    assert through_entry.counts.any()
    for name in STATE_ARRAYS:
        np.testing.assert_array_equal(
            getattr(through_entry, name), getattr(through_dispatcher, name), err_msg=name
        )


def test_entry_point_falls_back_on_what_is_not_a_dispatcher() -> None:
    def plain(value: int) -> int:
        return value + 1

    assert kernels.entry_point(plain, (1,)) is plain


def test_a_map_update_result_is_not_overwritten_by_the_next() -> None:
    slam = PolygonSLAM(5, np.deg2rad(2.0))
    results = [slam.update(b1[0], b2[0]) for b1, b2 in _movements(1, 8, 1)]
    statuses = [r.landmark_status.copy() for r in results]
    assert len({tuple(s) for s in statuses}) > 1  # the movements did different things
    for result, status in zip(results, statuses, strict=True):
        np.testing.assert_array_equal(result.landmark_status, status)


def test_a_pickled_map_updates_as_the_original() -> None:
    moves = _movements(2, 6, 1)
    slam = PolygonSLAM(5, np.deg2rad(2.0))
    for b1, b2 in moves[:3]:
        slam.update(b1[0], b2[0])
    copy = pickle.loads(pickle.dumps(slam))
    for b1, b2 in moves[3:]:
        mine, theirs = slam.update(b1[0], b2[0]), copy.update(b1[0], b2[0])
        assert mine.frame_status == theirs.frame_status
        np.testing.assert_array_equal(mine.landmark_status, theirs.landmark_status)
    np.testing.assert_array_equal(slam.areas, copy.areas)
