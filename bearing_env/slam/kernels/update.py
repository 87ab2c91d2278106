"""One movement per map for a batch of maps, and batch helpers (``csrc/slam/update.cpp``).

:func:`update_maps` fuses one movement into each map ``rows[i]`` (bearings row ``i``),
in place, in one native call with the GIL released. A map's state (see
:class:`~bearing_env.slam.kernels.state.State`) is its regions
(``vertices[map, j, :counts[map, j]]``; count 0 means not initialised), their areas and
centroids, the robot's region and heading (left as they were when ``params.with_robot``
is False), its counters and the relaxed and robust fusions' arrays. Each map is updated
on its own, so its result never depends on the other maps of the batch; with
``threads > 1`` the rows are split into that many contiguous blocks, one per thread, and
the results are the same bit for bit. What each movement did goes to ``out``.

:func:`copy_maps` makes map ``i`` of one state a copy of map ``rows[i]`` of another, every
array in one native call (planners' copies of a map).
"""

from __future__ import annotations

from bearing_env._core import (
    INDEX_OK,
    INDEX_OUT_OF_RANGE,
    INDEX_REPEATED,
    check_indices,
    contains_points,
    copy_maps,
    none_infinite,
    update_maps,
)

__all__ = [
    "INDEX_OK",
    "INDEX_OUT_OF_RANGE",
    "INDEX_REPEATED",
    "check_indices",
    "contains_points",
    "copy_maps",
    "none_infinite",
    "update_maps",
]
