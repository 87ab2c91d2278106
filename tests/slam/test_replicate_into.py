"""PolygonSLAM.replicate into a planner's scratch batch: the same copies as a new batch."""

from __future__ import annotations

import numpy as np
import pytest

from bearing_env.slam import BatchedPolygonSLAM, PolygonSLAM, kernels
from bearing_env.slam.batch import STATE_ARRAYS


def _mapped(seed: int) -> PolygonSLAM:
    rng = np.random.default_rng(seed)
    slam = PolygonSLAM(5, np.deg2rad(2.0))
    landmarks = np.array([0.0, 1.0, 0.4 + 0.8j, 0.7 - 0.6j, -0.5 + 0.3j])
    position = -1.0 - 1.0j
    for _ in range(6):
        step = 0.5 * np.exp(1j * rng.uniform(-np.pi, np.pi))
        heading = np.angle(step)
        b1 = np.angle(landmarks - position) - heading
        b2 = np.angle(landmarks - (position + step)) - heading
        slam.update(b1, b2)
        position += step
    return slam


def test_replicate_into_overwrites_the_scratch_with_the_same_copies() -> None:
    first, second = _mapped(0), _mapped(1)
    assert first.initialised.any() and second.initialised.any()
    scratch = first.replicate(3)
    refilled = second.replicate(3, into=scratch)
    fresh = second.replicate(3)
    assert refilled is scratch
    for name in STATE_ARRAYS:
        np.testing.assert_array_equal(getattr(refilled, name), getattr(fresh, name), err_msg=name)


def test_replicate_into_a_batch_that_does_not_fit_makes_a_new_one() -> None:
    slam = _mapped(2)
    wrong_count = slam.replicate(2)
    assert slam.replicate(3, into=wrong_count) is not wrong_count
    other_settings = PolygonSLAM(5, np.deg2rad(2.0), transfer="paper").replicate(3)
    assert slam.replicate(3, into=other_settings) is not other_settings


def test_take_into_overwrites_the_scratch_with_the_same_copies() -> None:
    source = _mapped(3).replicate(3)
    source.update_trusted(*(np.ascontiguousarray(b) for b in _bearings_for(source, 4)))
    rows = np.array([2, 0, 2, 1])
    scratch = _mapped(4).replicate(4)
    refilled = source.take(rows, into=scratch)
    fresh = source.take(rows)
    assert refilled is scratch
    for name in STATE_ARRAYS:
        np.testing.assert_array_equal(getattr(refilled, name), getattr(fresh, name), err_msg=name)


def test_take_into_refuses_the_batch_it_copies_from() -> None:
    batch = _mapped(5).replicate(2)
    with pytest.raises(ValueError, match="another batch"):
        batch.take(np.array([1, 0]), into=batch)


def _bearings_for(batch: BatchedPolygonSLAM, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Noise-free bearings of a different seeded move for each map of ``batch``."""
    rng = np.random.default_rng(seed)
    landmarks = np.array([0.0, 1.0, 0.4 + 0.8j, 0.7 - 0.6j, -0.5 + 0.3j])
    start = rng.uniform(-1.5, 1.5, batch.num_maps) + 1j * rng.uniform(-1.5, 1.5, batch.num_maps)
    step = 0.5 * np.exp(1j * rng.uniform(-np.pi, np.pi, batch.num_maps))
    heading = np.angle(step)[:, None]
    b1 = np.angle(landmarks[None, :] - start[:, None]) - heading
    b2 = np.angle(landmarks[None, :] - (start + step)[:, None]) - heading
    return b1, b2


def test_copy_maps_refuses_mismatched_states_and_rows() -> None:
    four, five = (
        BatchedPolygonSLAM(2, 4, np.deg2rad(2.0)),
        BatchedPolygonSLAM(2, 5, np.deg2rad(2.0)),
    )
    rows = np.zeros(2, dtype=np.int64)
    with pytest.raises(ValueError, match="same landmarks"):
        kernels.copy_maps(four._kernel_state(), rows, five._kernel_state())
    with pytest.raises(ValueError, match="two different states"):
        kernels.copy_maps(four._kernel_state(), rows, four._kernel_state())
    other = four.empty_like(2)
    with pytest.raises(ValueError, match=r"rows holds -?\d+ at position \d+, outside \[0, "):
        kernels.copy_maps(four._kernel_state(), np.array([0, 2]), other._kernel_state())
    with pytest.raises(ValueError, match="more than to's 2 maps"):
        kernels.copy_maps(four._kernel_state(), np.zeros(3, dtype=np.int64), other._kernel_state())
    with pytest.raises(TypeError, match="rows"):
        kernels.copy_maps(four._kernel_state(), np.zeros(2), other._kernel_state())
