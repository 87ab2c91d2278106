"""The C++ library ``bearing_core`` builds without Python and passes its C++ tests, as
``docs/cpp.md`` says.

The page's ``cmake`` and ``ctest`` commands are read from it and run as written, with the
build folder moved into a temporary one (``-DBEARING_ENV_WERROR=ON`` added, as ``make``
builds): configuring must not look for Python or nanobind, the build gives the library
and its tests, and ctest runs them (the golden map corpus replayed bit for bit on 256 KB
thread stacks, the owning types' validation). About 30 s on two cores.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

from bearing_env.extras import install_command

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "cpp.md"
#: The build folder the page's commands name; the tests build in a temporary one instead.
DOCUMENTED_BUILD = "build/cpp"
#: The venv's own tools first (the dev extra installs cmake and ninja there).
PATH = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])
if any(shutil.which(tool, path=PATH) is None for tool in ("cmake", "ninja")):
    pytest.skip(f"needs the dev extra (cmake, ninja): {install_command('dev')}",
                allow_module_level=True)  # fmt: skip


def page_commands(prefix: str) -> list[str]:
    """The page's shell commands (its ``sh`` blocks, ``\\`` continuations joined) that
    start with ``prefix``, in order."""
    commands = []
    for block in re.findall(r"```sh\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.S):
        for command in block.replace("\\\n", " ").splitlines():
            command = " ".join(command.split("#", 1)[0].split())
            if command.startswith(prefix):
                commands.append(command)
    return commands


#: The commands that configure, build and test the library alone, as the page gives them.
BUILD_COMMANDS = [c for c in page_commands("cmake ") + page_commands("ctest ")
                  if DOCUMENTED_BUILD in c]  # fmt: skip


@dataclass
class Build:
    folder: Path
    log: str


def run(argv: list[str], cwd: Path = ROOT, timeout: float = 600) -> str:
    result = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                            env={**os.environ, "PATH": PATH})  # fmt: skip
    assert result.returncode == 0, f"{argv}\n{result.stdout[-4000:]}\n{result.stderr[-4000:]}"
    return result.stdout + result.stderr


@pytest.fixture(scope="module")
def library_build(tmp_path_factory: pytest.TempPathFactory) -> Build:
    folder = tmp_path_factory.mktemp("cpp") / "build"
    log = ""
    for command in BUILD_COMMANDS:
        argv = [str(folder) if a == DOCUMENTED_BUILD else a for a in shlex.split(command)]
        if "-S" in argv:  # the configure step: warnings are errors, as make builds
            argv.append("-DBEARING_ENV_WERROR=ON")
        if "--build" in argv:
            argv += ["--parallel", "2"]
        if argv[0] == "ctest":
            argv += ["--parallel", "2"]
        log += run(argv)
    return Build(folder, log)


def test_the_page_configures_without_python_builds_and_tests() -> None:
    configure, build, test = BUILD_COMMANDS
    assert "-DBEARING_ENV_PYTHON=OFF" in configure and configure.startswith("cmake -S . -B ")
    assert build.startswith("cmake --build ")
    assert test.startswith("ctest --test-dir ")


def test_the_library_builds_without_finding_python_or_nanobind(library_build: Build) -> None:
    assert (library_build.folder / "libbearing_core.a").is_file()
    cache = (library_build.folder / "CMakeCache.txt").read_text(encoding="utf-8")
    assert "BEARING_ENV_PYTHON:BOOL=OFF" in cache
    assert not re.search(r"^(Python_EXECUTABLE|nanobind_DIR)[:=]", cache, re.M)
    assert "/_core.dir/" not in (library_build.folder / "build.ninja").read_text(encoding="utf-8")



def test_ctest_runs_the_golden_replay_and_the_owning_types_tests(library_build: Build) -> None:
    # ctest's summary, and each test's own line (the replay names every case it ran).
    assert "100% tests passed out of 2" in library_build.log
    for name in ("golden_replay", "map_batch"):
        assert re.search(rf"Test +#\d+: {name} \.+ +Passed", library_build.log), name


def test_the_fp_flags_are_usage_requirements_of_the_library(library_build: Build) -> None:
    # A consumer's compile line (the C++ tests link bearing_core and set no flags of their
    # own) carries the library's floating-point flags: the inline arithmetic of its
    # headers compiles as the library's own does.
    ninja = (library_build.folder / "build.ninja").read_text(encoding="utf-8")
    consumer = re.search(r"build tests/cpp/CMakeFiles/test_map_batch\.dir/[^\n]*\n(.*?)\n\n",
                         ninja, re.S)  # fmt: skip
    assert consumer is not None
    flags = re.search(r"FLAGS = (.*)", consumer.group(1))
    assert flags is not None
    for flag in ("-ffp-contract=off", "-fno-tree-vectorize", "-fno-fast-math"):
        assert flag in flags.group(1).split(), flag
