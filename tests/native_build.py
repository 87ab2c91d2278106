"""Build the native core into a folder of its own, and run pytest against that build.

The normal build is the installed extension (``make`` builds it). This helper is for the
builds the normal one cannot be: the sanitizer build (AddressSanitizer + UBSan) of
``tests/slam/test_native_sanitizers.py``. ``python -m tests.native_build SO [pytest args]``
runs pytest with ``bearing_env._core`` taken from the extension file ``SO``.
"""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def build_core(build_dir: Path, *, sanitize: bool = False, timeout: float = 900) -> Path:
    """Configure and build the extension in ``build_dir``; returns the module's file."""
    configure = [
        "cmake", "-S", str(ROOT), "-B", str(build_dir), "-G", "Ninja",
        f"-DPython_EXECUTABLE={sys.executable}", "-DBEARING_ENV_WERROR=ON",
        f"-DBEARING_ENV_SANITIZE={'ON' if sanitize else 'OFF'}",
    ]  # fmt: skip
    for command in (configure, ["cmake", "--build", str(build_dir)]):
        result = subprocess.run(command, capture_output=True, text=True, timeout=timeout)
        if result.returncode != 0:
            raise RuntimeError(f"{' '.join(command)} failed:\n{result.stdout[-4000:]}\n"
                               f"{result.stderr[-4000:]}")  # fmt: skip
    (module,) = build_dir.glob("_core.*.so")
    return module


def load_core(module_file: Path) -> None:
    """Register ``module_file`` as ``bearing_env._core`` before anything imports it."""
    spec = importlib.util.spec_from_file_location("bearing_env._core", module_file)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load {module_file}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sys.modules["bearing_env._core"] = module
    import bearing_env

    bearing_env._core = module  # type: ignore[attr-defined]


def main(argv: list[str]) -> int:
    if not argv:
        print("usage: python -m tests.native_build MODULE_FILE [pytest arguments]", file=sys.stderr)
        return 2
    load_core(Path(argv[0]))
    import pytest

    return int(pytest.main(argv[1:]))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
