"""The package imports and the world model runs one update."""

import numpy as np

from bearing_env.slam import PolygonSLAM


def test_one_update_initialises_a_landmark() -> None:
    # R1 = 0, R2 = 1 in FR; landmarks placed so every cone pair is well separated.
    fr = np.array([2 + 2j, 3 + 2j, 1 + 3j, -1 - 2j])
    slam = PolygonSLAM(4, np.deg2rad(2.0))
    result = slam.update(np.angle(fr), np.angle(fr - 1))
    assert result.frame_changed
    assert slam.initialised.all()
    assert np.all(np.isfinite(slam.areas)) and np.all(slam.areas > 0)
