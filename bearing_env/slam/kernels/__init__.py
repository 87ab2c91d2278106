"""The world model's kernels: the native core (C++17, ``csrc/slam/``, compiled into
:mod:`bearing_env._core` by the package's build), one module per topic.

* :mod:`~bearing_env.slam.kernels.common`: capacities, status codes, scalar helpers
  (``cross``, ``dot``, tolerances) and :func:`threads`.
* :mod:`~bearing_env.slam.kernels.polygons`: convex polygons in fixed-capacity arrays:
  hulls, area and centroid, containment, distances, simplification, capacity
  reduction, clipping and outward offsets.
* :mod:`~bearing_env.slam.kernels.frames`: a landmark's cone region in the robot frame
  FR, and the change of frames FR -> FL (frame plan, hypotheses, transfer).
* :mod:`~bearing_env.slam.kernels.state`: the structures the update takes: ``State``
  (the per-map state arrays, listed once; passed as a native ``MapState``), ``Params``
  (the settings, with the transfer, inconsistency policy and fusion as codes) and
  ``Outputs`` (per-call statuses).
* :mod:`~bearing_env.slam.kernels.fusion`: the strict intersection and the relaxed
  fusion's window and bases.
* :mod:`~bearing_env.slam.kernels.robust`: the robust fusion's levels and noise bound.
* :mod:`~bearing_env.slam.kernels.update`: one movement per map for a batch of maps, in
  one native call (serial, or blocks of maps on threads), and batch helpers.

Every public name of the topic modules is re-exported here, so callers import
``bearing_env.slam.kernels`` and never a topic module. Each kernel checks its arrays'
dtypes, shapes and contiguity and raises ``TypeError`` or ``ValueError`` naming the
argument; a fixed capacity that would overflow raises ``CapacityError``.
"""

from __future__ import annotations

from bearing_env._core import CapacityError
from bearing_env.slam.kernels import common, frames, fusion, polygons, robust, state, update
from bearing_env.slam.kernels.common import *  # noqa: F403
from bearing_env.slam.kernels.frames import *  # noqa: F403
from bearing_env.slam.kernels.fusion import *  # noqa: F403
from bearing_env.slam.kernels.polygons import *  # noqa: F403
from bearing_env.slam.kernels.robust import *  # noqa: F403
from bearing_env.slam.kernels.state import *  # noqa: F403
from bearing_env.slam.kernels.update import *  # noqa: F403

# Each topic module lists its public names once, in its own __all__.
__all__ = ["CapacityError"]
__all__ += common.__all__
__all__ += frames.__all__
__all__ += fusion.__all__
__all__ += polygons.__all__
__all__ += robust.__all__
__all__ += state.__all__
__all__ += update.__all__
