"""PolygonSLAM.replicate into a planner's scratch batch: the same copies as a new batch."""

from __future__ import annotations

import numpy as np

from bearing_env.slam import PolygonSLAM
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
