"""The compiled core as installed software: where its machine code is cached, and that
a fresh process with a warm cache is ready quickly.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import bearing_env

#: The package as imported: the checkout's, or an installed one (tests/tools/test_install.py).
PACKAGE = Path(bearing_env.__file__).resolve().parent

#: Runs one map update in a fresh process, with the package folder made unwritable for
#: numba (root ignores file modes, so the test refuses writes where numba checks them).
READ_ONLY_PACKAGE = textwrap.dedent(
    """
    import json, os, sys, time
    start = time.perf_counter()
    import numba.core.caching as caching

    package = os.path.join(sys.argv[1], "bearing_env")
    in_tree = caching.InTreeCacheLocator.ensure_cache_path

    def refuse_package_folder(self):
        if os.path.realpath(self.get_cache_path()).startswith(os.path.realpath(package)):
            raise PermissionError(f"read-only: {self.get_cache_path()}")
        in_tree(self)

    caching.InTreeCacheLocator.ensure_cache_path = refuse_package_folder
    import numpy as np
    from bearing_env.slam import PolygonSLAM

    slam = PolygonSLAM(4, np.deg2rad(2.0))
    result = slam.update([1.0, 1.5, 2.0, -1.0], [1.2, 1.9, 2.3, -1.3])
    print(json.dumps({"status": result.frame_status, "seconds": time.perf_counter() - start}))
    """
)


def run_isolated(script: str, cache_home: Path, package_root: Path) -> dict:
    env = {
        key: value
        for key, value in os.environ.items()
        if not key.startswith("NUMBA_") and key != "PYTHONPATH"
    }
    env["XDG_CACHE_HOME"] = str(cache_home)
    env["PYTHONPATH"] = str(package_root)
    out = subprocess.run(
        [sys.executable, "-c", script, str(package_root)],
        capture_output=True,
        text=True,
        env=env,
        cwd=package_root,
        timeout=600,
        check=False,
    )
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def copy_package(target: Path) -> Path:
    """A copy of the bearing_env package in its own folder, without any cached code."""
    shutil.copytree(
        PACKAGE,
        target / "bearing_env",
        ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"),
    )
    return target


def test_a_read_only_package_caches_its_compiled_code_in_the_user_cache(tmp_path):
    package_root = copy_package(tmp_path / "site")
    cache_home = tmp_path / "cache"
    first = run_isolated(READ_ONLY_PACKAGE, cache_home, package_root)
    assert first["status"] == "ok"
    in_package = list((package_root / "bearing_env").rglob("*.nbi"))
    in_user_cache = list((cache_home / "numba").rglob("*.nbi"))
    assert not in_package, in_package
    assert in_user_cache, "numba wrote no cache index into the user cache"
    # A second fresh process loads the cached code instead of compiling: ready far sooner.
    second = run_isolated(READ_ONLY_PACKAGE, cache_home, package_root)
    assert second["status"] == "ok"
    assert second["seconds"] < first["seconds"] / 3, (first, second)
