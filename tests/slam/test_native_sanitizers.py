"""The native core under AddressSanitizer and UBSan (slow: a build of its own).

The core is built with ``-fsanitize=address,undefined`` into a temporary folder, and the
world model's tests (``tests/slam``) and the env step's golden corpus
(``tests/envs/test_golden_env.py``: the simulator, the map update and the step) run
against that build, in a Python that preloads the ASan runtime. Any out-of-bounds
access, use after free or undefined behaviour aborts the run, and the test fails with
the sanitizer's report.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.native_build import ROOT, build_core

pytestmark = pytest.mark.slow


def _runtime(name: str) -> str:
    compiler = shutil.which("c++") or "c++"
    path = subprocess.run(
        [compiler, f"-print-file-name={name}"], capture_output=True, text=True, check=True
    ).stdout.strip()
    if not os.path.isabs(path):
        pytest.fail(f"the compiler has no {name} (gcc's sanitizer runtime)")
    return path


def test_the_world_model_tests_pass_under_asan_and_ubsan(tmp_path: Path) -> None:
    module = build_core(tmp_path / "build", sanitize=True)
    env = {
        **os.environ,
        # libstdc++ too: Python does not link it, and ASan's interceptor of C++ throws
        # needs the real __cxa_throw loaded before the extension.
        "LD_PRELOAD": f"{_runtime('libasan.so')} {_runtime('libstdc++.so')}",
        # Python's own allocations are never freed at exit: leaks are not the core's.
        "ASAN_OPTIONS": "detect_leaks=0:abort_on_error=1:allocator_may_return_null=1",
        "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1",
        "NUMBA_DISABLE_JIT": os.environ.get("NUMBA_DISABLE_JIT", "0"),
    }
    tests = sorted(
        str(p.relative_to(ROOT))
        for folder in ("slam", "envs")
        for p in (ROOT / "tests" / folder).glob("test_*.py")
        if folder == "slam" or p.name == "test_golden_env.py"
    )
    tests = [t for t in tests if not t.endswith("test_native_sanitizers.py")]
    result = subprocess.run(
        [sys.executable, "-m", "tests.native_build", str(module), "-q", "-x",
         "-p", "no:cacheprovider", "-m", "not slow", *tests],
        cwd=ROOT, env=env, capture_output=True, text=True, timeout=3600,
    )  # fmt: skip
    output = result.stdout + result.stderr
    assert "ERROR: AddressSanitizer" not in output, output[-6000:]
    assert "runtime error:" not in output, output[-6000:]
    assert result.returncode == 0, output[-6000:]
    assert " passed" in result.stdout.strip().splitlines()[-1]
