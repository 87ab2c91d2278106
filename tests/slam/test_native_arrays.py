"""The bindings' array checks beyond dtype and shape: an array must be aligned for its
dtype, a bool array must hold only the bytes 0 and 1, an array a kernel writes must not
share memory with another of its arguments, and an expected axis of length 0 means 0."""

from __future__ import annotations

import numpy as np
import pytest

from bearing_env import _core
from bearing_env.slam import BatchedPolygonSLAM
from bearing_env.slam.batch import STATE_ARRAYS
from bearing_env.slam.kernels import State

SQUARE = np.array([0, 1, 1 + 1j, 1j], dtype=np.complex128)


def test_a_misaligned_array_is_refused_naming_it() -> None:
    raw = np.zeros(SQUARE.nbytes + 1, dtype=np.uint8)
    misaligned = np.frombuffer(raw.data, dtype=np.complex128, count=4, offset=1)
    assert not misaligned.flags.aligned
    with pytest.raises(ValueError, match="poly must be aligned to 8 bytes"):
        _core.area_centroid(misaligned, 4)
    aligned = np.frombuffer(raw.data, dtype=np.complex128, count=4, offset=0)
    _core.area_centroid(aligned, 4)  # the same call on an aligned view runs


def test_a_bool_array_with_another_byte_is_refused_naming_it() -> None:
    maps = BatchedPolygonSLAM(2, 4, 0.05, fusion="relaxed")
    arrays = [getattr(maps, name).copy() for name in STATE_ARRAYS]
    _core.MapState(State(*arrays))  # the state as it is is taken
    inlier = arrays[STATE_ARRAYS.index("window_inlier")]
    inlier.view(np.uint8)[1, 2, 0] = 2
    with pytest.raises(ValueError, match=r"state\.window_inlier holds the byte 2 at flat index"):
        _core.MapState(State(*arrays))


def test_an_output_sharing_memory_with_an_input_is_refused() -> None:
    buffer = np.zeros(16, dtype=np.complex128)
    buffer[:4] = SQUARE
    with pytest.raises(ValueError, match="poly and out must not share memory"):
        _core.offset_outward(buffer[:4], 4, 0.1, buffer[2:9])
    # Apart in the same buffer: fine.
    assert _core.offset_outward(buffer[:4], 4, 0.1, buffer[4:11]) >= 4
    with pytest.raises(ValueError, match="points and out must not share memory"):
        _core.convex_hull(buffer[:4], 4, buffer[:5])


def test_an_expected_axis_of_zero_is_not_any_length() -> None:
    # rows is empty, so the bearings must have 0 rows, not any number.
    maps = BatchedPolygonSLAM(2, 4, 0.05)
    state = maps._kernel_state()
    params = maps._kernel_params(True)
    rows = np.zeros(0, dtype=np.int64)
    out = (np.empty(0, np.int8), np.empty((0, 2), np.int8), np.empty(0, np.int64))
    with pytest.raises(ValueError, match="bearings_start has axis 0 of length 2, expected 0"):
        _core.update_maps(np.zeros((2, 4)), np.zeros((2, 4)), rows, params, state, out)
    _core.update_maps(np.zeros((0, 4)), np.zeros((0, 4)), rows, params, state, out)
