"""The structures the update kernels take, each declared once, in the C++ library (its
X-macros; :mod:`bearing_env._schema` is generated from them).

* :class:`State`: a batch's per-map state arrays (every one with the map axis first);
  ``bearing_env.slam.batch.STATE_ARRAYS`` is ``State._fields``. The native update takes
  it as a :class:`MapState` (:func:`state_ref`): the arrays checked once (dtype, shape,
  contiguity) and kept, so each call passes one reference.
* :class:`Params`: the update's settings (native, validated), with the transfer, the
  inconsistency policy and the fusion as the codes below (indices into ``TRANSFERS``,
  ``INCONSISTENCY_POLICIES`` and ``FUSIONS``), and whether the robot is transferred.
* :class:`Outputs`: what one call reports per updated map.
"""

from __future__ import annotations

from bearing_env._core import (
    FUSION_INTERSECT,
    FUSION_RELAXED,
    FUSION_ROBUST,
    INCONSISTENCY_KEEP,
    INCONSISTENCY_RESTART,
    TRANSFER_CONSERVATIVE,
    TRANSFER_CONSERVATIVE_GLOBAL,
    TRANSFER_PAPER,
    MapState,
    Params,
)
from bearing_env._schema import Outputs, State


def state_ref(state: State) -> MapState:
    """The native update's reference to ``state``'s arrays (checked once; not copies)."""
    return MapState(state)


__all__ = [
    "FUSION_INTERSECT",
    "FUSION_RELAXED",
    "FUSION_ROBUST",
    "INCONSISTENCY_KEEP",
    "INCONSISTENCY_RESTART",
    "TRANSFER_CONSERVATIVE",
    "TRANSFER_CONSERVATIVE_GLOBAL",
    "TRANSFER_PAPER",
    "MapState",
    "Outputs",
    "Params",
    "State",
    "state_ref",
]
