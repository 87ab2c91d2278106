"""The one-line notice printed before the compiled core is built for the first time."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

from bearing_env.slam import PolygonSLAM
from bearing_env.slam.compile_notice import NOTICE

# Making a batch is where the check runs; it compiles nothing itself, so this is cheap.
MAKE_A_MAP = "from bearing_env.slam import PolygonSLAM; PolygonSLAM(4, 0.03)"


def _stderr_of(code: str, cache_dir: Path | None) -> str:
    env = dict(os.environ)
    env.pop("NUMBA_CACHE_DIR", None)
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(cache_dir)
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600,
        check=True,
    )  # fmt: skip
    return done.stderr


def test_notice_with_an_empty_cache(tmp_path: Path) -> None:
    stderr = _stderr_of(MAKE_A_MAP, tmp_path)
    assert stderr.count(NOTICE) == 1, stderr


def test_no_notice_with_a_warm_cache() -> None:
    # Compile (or load) the serial update in this process's cache, then a fresh process
    # using the same cache must stay silent.
    slam = PolygonSLAM(4, np.deg2rad(2.0))
    slam.update(np.array([0.1, 0.5, 1.0, 2.0]), np.array([0.2, 0.7, 1.3, 2.4]))
    cache_dir = os.environ.get("NUMBA_CACHE_DIR")
    stderr = _stderr_of(MAKE_A_MAP, Path(cache_dir) if cache_dir else None)
    assert NOTICE not in stderr, stderr
