"""numba's parallel runtime starts when the kernels are imported (``kernels.common``).

A cached kernel that calls a parallel one holds a copy of it, but its cache entry starts
the runtime on loading only if the parallel kernel was compiled in the same process.
Compiled where the parallel kernel came from the cache, the entry is saved without, and a
fresh process that loads it first calls address 0: the env's step kernel segfaulted that
way. These tests build that case with two small modules, in processes of their own.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

PARALLEL_MODULE = """
from numba import njit, prange

@njit(cache=True, parallel=True)
def total(values):
    result = 0.0
    for i in prange(values.shape[0]):
        result += values[i]
    return result
"""

CALLER_MODULE = """
from numba import njit
from parallel_module import total

@njit(cache=True)
def twice(values):
    return 2.0 * total(values)
"""


def _run(code: str, folder: Path) -> subprocess.CompletedProcess[str]:
    """``code`` in a fresh interpreter, importing from ``folder``, with its own cache."""
    env = dict(os.environ, PYTHONPATH=str(folder), NUMBA_CACHE_DIR=str(folder / "cache"))
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
        cwd=folder,
    )


def _cache_a_caller_without_the_runtime(folder: Path) -> None:
    """Cache ``twice`` compiled in a process where ``total`` came from the cache."""
    (folder / "parallel_module.py").write_text(PARALLEL_MODULE)
    (folder / "caller_module.py").write_text(CALLER_MODULE)
    first = "import numpy as np, parallel_module\nparallel_module.total(np.ones(8))\n"
    second = "import numpy as np, caller_module\ncaller_module.twice(np.ones(8))\n"
    for code in (first, second):
        result = _run(code, folder)
        assert result.returncode == 0, result.stderr[-2000:]


def test_the_kernels_start_the_parallel_runtime_on_import(tmp_path: Path) -> None:
    code = """
        import llvmlite.binding as ll
        assert ll.address_of_symbol("do_scheduling_unsigned") is None
        import bearing_env.slam.kernels
        assert ll.address_of_symbol("do_scheduling_unsigned") is not None
    """
    result = _run(code, tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]


def test_a_caller_cached_without_the_runtime_runs_once_the_kernels_are_imported(
    tmp_path: Path,
) -> None:
    _cache_a_caller_without_the_runtime(tmp_path)
    load = "import numpy as np, caller_module\nprint(caller_module.twice(np.ones(8)))\n"
    # The hazard itself: loaded first in a fresh process, the caller crashes.
    bare = _run(load, tmp_path)
    assert bare.returncode != 0, "numba no longer leaves the runtime unstarted: see common.py"
    protected = _run("import bearing_env.slam.kernels\n" + load, tmp_path)
    assert protected.returncode == 0, protected.stderr[-2000:]
    assert protected.stdout.split() == ["16.0"]
