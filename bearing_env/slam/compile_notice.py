"""A one-line notice on stderr before the compiled core is built for the first time.

Compiling the kernels from an empty numba cache takes a minute or two (a first Khepera
``env.step`` measured 72-76 s on a quiet 2-core machine, 103-113 s on a slower day of
it), during which it would otherwise hang in silence. The first
:class:`~bearing_env.slam.batch.BatchedPolygonSLAM` a process makes checks numba's own
cache index of the batched update (the serial and the parallel kernel, whichever the
process will use): numba loads an index only when it matches the kernel's source file
and this numba version, so an empty index means the core is about to compile (empty or
stale cache). Then it prints the notice, once; with a warm cache it prints nothing.
"""

from __future__ import annotations

import sys
from typing import Any

#: The notice's estimate, from the cold compiles measured on the 2-core development
#: machine: 72-76 s on its quiet days, 103-113 s on slower ones.
COLD_COMPILE_MINUTES = "1-2"
NOTICE = (
    f"bearing_env: compiling the numba core, once (about {COLD_COMPILE_MINUTES} minutes; "
    "later runs load it from numba's cache)..."
)

_checked = False


def cache_is_warm(dispatchers: tuple[Any, ...]) -> bool | None:
    """Whether any of the numba ``dispatchers`` has a valid on-disk cache index (None
    when numba's cache internals are not as expected: then nothing is claimed)."""
    try:
        return any(bool(d._cache._cache_file._load_index()) for d in dispatchers)
    except (AttributeError, OSError):  # why: numba's cache layout is not public API
        return None


def announce_compile_once() -> None:
    """Print :data:`NOTICE` on stderr if the batched update has not been compiled for
    this source and numba version; checks only once per process."""
    global _checked
    if _checked:
        return
    _checked = True
    from bearing_env.slam import kernels

    if cache_is_warm((kernels.update_maps, kernels.update_maps_parallel)) is False:
        print(NOTICE, file=sys.stderr, flush=True)
