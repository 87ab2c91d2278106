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


def test_build_system_requires_a_setuptools_that_reads_spdx_licenses() -> None:
    requires = _pyproject()["build-system"]["requires"]
    versions = [re.fullmatch(r"setuptools>=(\d+)(\.\d+)*", r) for r in requires]
    (match,) = [m for m in versions if m]
    assert int(match.group(1)) >= 77


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
def test_the_sdist_carries_the_tests_with_their_helpers(tmp_path: Path) -> None:
    import tarfile

    from setuptools import build_meta

    name = build_meta.build_sdist(str(tmp_path))
    with tarfile.open(tmp_path / name) as sdist:
        names = {
            Path(*Path(member).parts[1:]).as_posix()
            for member in sdist.getnames()
            if "/" in member
        }
    repository_tests = {p.relative_to(ROOT).as_posix() for p in (ROOT / "tests").rglob("*.py")}
    assert repository_tests <= names, sorted(repository_tests - names)
    assert {"LICENSE", "CITATION.cff", "docs/design.md"} <= names
    assert not [n for n in names if n.endswith((".nbi", ".nbc", ".pyc"))]


#: The repository folders that install as subpackages of bearing_env (package-dir).
SUBPACKAGE_FOLDERS = {"agents": "bearing_env.agents", "train": "bearing_env.train",
                      "benchmarks": "bearing_env.benchmarks"}  # fmt: skip


def test_every_subpackage_folder_is_in_the_package_list() -> None:
    # setuptools ships only the packages it is told of: a folder of modules that the list
    # misses is left out of the wheel (the data folders: tests/tools/test_install.py).
    setuptools = _pyproject()["tool"]["setuptools"]
    for folder, name in SUBPACKAGE_FOLDERS.items():
        assert setuptools["package-dir"][name] == folder
    expected = set()
    for folder, name in SUBPACKAGE_FOLDERS.items():
        for path in (ROOT / folder).rglob("*"):
            if path.is_dir() and path.name != "__pycache__" and any(path.glob("*.py")):
                parts = path.relative_to(ROOT / folder).parts
                if "__pycache__" not in parts:
                    expected.add(".".join((name, *parts)))
        expected.add(name)
    assert sorted(expected - set(setuptools["packages"])) == []


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
