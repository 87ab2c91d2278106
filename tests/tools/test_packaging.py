"""Packaging metadata: the MIT license in SPDX form, shipped in the distribution."""

from __future__ import annotations

import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from tests.extras import build_backend_missing

tomllib = pytest.importorskip("tomllib")

ROOT = Path(__file__).resolve().parents[2]


def _pyproject() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_license_is_an_spdx_expression_with_its_file() -> None:
    project = _pyproject()["project"]
    assert project["license"] == "MIT"
    assert project["license-files"] == ["LICENSE"]
    # The SPDX form replaces license classifiers; setuptools refuses both together.
    assert not any(c.startswith("License ::") for c in project.get("classifiers", []))


def test_the_build_system_compiles_the_native_core_with_nanobind() -> None:
    build_system = _pyproject()["build-system"]
    assert build_system["build-backend"] == "scikit_build_core.build"
    names = {re.split(r"[<>=!~ ]", r, maxsplit=1)[0] for r in build_system["requires"]}
    assert names == {"scikit-build-core", "nanobind"}
    # PEP 639 licenses (the SPDX `license` with `license-files`) need scikit-build-core 0.11.
    (core,) = [r for r in build_system["requires"] if r.startswith("scikit-build-core")]
    minimum = re.fullmatch(r"scikit-build-core>=(\d+)\.(\d+)", core)
    assert minimum is not None and (int(minimum[1]), int(minimum[2])) >= (0, 11)


def test_license_file_is_mit_for_the_bearing_env_developers() -> None:
    text = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert text.startswith("MIT License\n")
    assert "Copyright (c) 2026 the bearing_env developers" in text
    assert "THE SOFTWARE IS PROVIDED \"AS IS\", WITHOUT WARRANTY OF ANY KIND" in text


@pytest.mark.slow
def test_the_wheel_carries_the_license_without_a_deprecation_warning(tmp_path: Path) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "-v", "--no-deps", "-w", str(tmp_path), str(ROOT)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    log = result.stdout + result.stderr
    assert "project.license` as a TOML table is deprecated" not in log
    assert "License classifiers are deprecated" not in log
    (wheel,) = tmp_path.glob("bearing_env-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        names = archive.namelist()
        (metadata,) = [n for n in names if n.endswith(".dist-info/METADATA")]
        text = archive.read(metadata).decode()
        assert "License-Expression: MIT" in text.splitlines()
        assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names)


@pytest.mark.skipif(build_backend_missing() is not None, reason=build_backend_missing() or "")
def test_the_sdist_carries_the_tests_the_native_sources_and_no_build_output(
    tmp_path: Path,
) -> None:
    import tarfile

    from scikit_build_core import build as build_backend

    name = build_backend.build_sdist(str(tmp_path))
    with tarfile.open(tmp_path / name) as sdist:
        names = {
            Path(*Path(member).parts[1:]).as_posix()
            for member in sdist.getnames()
            if "/" in member
        }
    repository_tests = {p.relative_to(ROOT).as_posix() for p in (ROOT / "tests").rglob("*.py")}
    assert repository_tests <= names, sorted(repository_tests - names)
    native = {p.relative_to(ROOT).as_posix() for p in (ROOT / "csrc").rglob("*") if p.is_file()}
    assert native and native <= names, sorted(native - names)
    assert {"LICENSE", "CITATION.cff", "docs/design.md", "CMakeLists.txt"} <= names
    # The C++ library's package config and its example project (docs/cpp.md).
    assert {"cmake/bearing_coreConfig.cmake.in", "examples/cpp/CMakeLists.txt",
            "examples/cpp/replay.cpp", "examples/cpp/bearing_log.csv"} <= names  # fmt: skip
    assert not [n for n in names if n.endswith((".nbi", ".nbc", ".pyc", ".so", ".o"))]
    assert not [n for n in names if n.startswith(("build/", ".venv/", "docs/_build/"))]


#: The repository folders that install as subpackages of bearing_env.
SUBPACKAGE_FOLDERS = {"agents": "bearing_env/agents", "train": "bearing_env/train",
                      "benchmarks": "bearing_env/benchmarks"}  # fmt: skip


def test_every_subpackage_folder_is_mapped_into_the_package() -> None:
    # scikit-build-core ships a folder under the name its wheel.packages table gives it;
    # everything below it (modules, subpackages and the data folders) comes along.
    packages = _pyproject()["tool"]["scikit-build"]["wheel"]["packages"]
    assert packages == {"bearing_env": "bearing_env", **{
        name: folder for folder, name in SUBPACKAGE_FOLDERS.items()}}  # fmt: skip


def _imported_modules(path: Path) -> set[str]:
    import ast

    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module is not None:
            names.add(node.module)
    return names


def test_the_tools_and_agents_never_import_the_benchmarks() -> None:
    # benchmarks/ may use the tools; the bearing-env command line names benchmark modules
    # only as strings, for importlib.
    offenders = sorted(
        f"{path.relative_to(ROOT)}: {module}"
        for folder in ("bearing_env", "agents", "train")
        for path in (ROOT / folder).rglob("*.py")
        for module in _imported_modules(path)
        if module == "bearing_env.benchmarks" or module.startswith("bearing_env.benchmarks.")
    )
    assert offenders == []
