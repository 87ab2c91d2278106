"""The C++ library ``bearing_core`` builds without Python, passes its C++ tests, installs
as a CMake package, and its example replays a bearing log as the Python package does, as
``docs/cpp.md`` says.

Every shell command of the page is run as written, in order, with its folders moved into
a temporary one (``-DBEARING_ENV_WERROR=ON`` added to the library's configure step, as
``make`` builds): configuring must not look for Python or nanobind; the build gives the
library and its tests, which ctest runs (the golden map corpus replayed bit for bit on
256 KB thread stacks, the owning types' validation); the install holds the headers, the
library and the package; the example project finds it with ``find_package`` and its
``replay`` prints, bit for bit, the regions ``BatchedPolygonSLAM`` computes from the same
log (read by ``bearing_env.slam.bearing_log``). About 15-40 s on two cores.
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

import numpy as np
import pytest

from bearing_env.extras import install_command
from bearing_env.slam import BatchedPolygonSLAM
from bearing_env.slam.bearing_log import read_bearing_log

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "cpp.md"
#: The venv's own tools first (the dev extra installs cmake and ninja there).
PATH = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])
if any(shutil.which(tool, path=PATH) is None for tool in ("cmake", "ninja")):
    pytest.skip(f"needs the dev extra (cmake, ninja): {install_command('dev')}",
                allow_module_level=True)  # fmt: skip


def page_commands(prefix: str = "") -> list[str]:
    """The page's shell commands (its ``sh`` blocks, ``\\`` continuations joined) that
    start with ``prefix``, in order."""
    commands = []
    for block in re.findall(r"```sh\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.S):
        for command in block.replace("\\\n", " ").splitlines():
            command = " ".join(command.split("#", 1)[0].split())
            if command and command.startswith(prefix):
                commands.append(command)
    return commands


#: The page's folders, and the temporary ones the tests use instead.
FOLDERS = {"build/cpp": "build", "/opt/bearing_core": "prefix", "build/replay": "replay"}
#: The example program, as the page runs it.
REPLAY = "build/replay/replay"


@dataclass
class Build:
    folder: Path  # the temporary folder of FOLDERS' folders
    log: str  # every command's output
    replay: str  # the replay program's output


def run(argv: list[str], cwd: Path = ROOT, timeout: float = 600) -> str:
    result = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=timeout,
                            env={**os.environ, "PATH": PATH})  # fmt: skip
    assert result.returncode == 0, f"{argv}\n{result.stdout[-4000:]}\n{result.stderr[-4000:]}"
    return result.stdout + result.stderr


def localised(command: str, base: Path) -> list[str]:
    """A page command's arguments, its folders moved below ``base``."""
    argv = []
    for argument in shlex.split(command):
        for documented, local in FOLDERS.items():
            if argument == documented or argument.startswith(documented + "/"):
                argument = str(base / local) + argument[len(documented) :]
            elif argument.endswith("=" + documented):
                argument = argument[: -len(documented)] + str(base / local)
        argv.append(argument)
    return argv


@pytest.fixture(scope="module")
def library_build(tmp_path_factory: pytest.TempPathFactory) -> Build:
    base = tmp_path_factory.mktemp("cpp")
    log = replay = ""
    for command in page_commands():
        argv = localised(command, base)
        if command.startswith("cmake -S . "):  # the library: warnings are errors, as make builds
            argv.append("-DBEARING_ENV_WERROR=ON")
        if "--build" in argv or argv[0] == "ctest":
            argv += ["--parallel", "2"]
        output = run(argv)
        log += output
        if command.startswith(REPLAY):
            replay = output
    return Build(base, log, replay)


def test_the_page_builds_tests_installs_and_runs_the_example() -> None:
    configure, build, test, install, example, example_build, replay = page_commands()
    assert configure == "cmake -S . -B build/cpp -G Ninja -DBEARING_ENV_PYTHON=OFF"
    assert build.startswith("cmake --build build/cpp") and test.startswith("ctest --test-dir")
    assert install == "cmake --install build/cpp --prefix /opt/bearing_core"
    assert example.startswith("cmake -S examples/cpp") and "CMAKE_PREFIX_PATH" in example
    assert example_build.startswith("cmake --build build/replay") and replay.startswith(REPLAY)


def test_the_library_builds_without_finding_python_or_nanobind(library_build: Build) -> None:
    folder = library_build.folder / "build"
    assert (folder / "libbearing_core.a").is_file()
    cache = (folder / "CMakeCache.txt").read_text(encoding="utf-8")
    assert "BEARING_ENV_PYTHON:BOOL=OFF" in cache
    assert not re.search(r"^(Python_EXECUTABLE|nanobind_DIR)[:=]", cache, re.M)
    assert "/_core.dir/" not in (folder / "build.ninja").read_text(encoding="utf-8")



def test_ctest_runs_the_golden_replay_and_the_owning_types_tests(library_build: Build) -> None:
    # ctest's summary, and each test's own line (the replay names every case it ran).
    assert "100% tests passed out of 2" in library_build.log
    for name in ("golden_replay", "map_batch"):
        assert re.search(rf"Test +#\d+: {name} \.+ +Passed", library_build.log), name


def test_the_fp_flags_are_usage_requirements_of_the_library(library_build: Build) -> None:
    # A consumer's compile line (the C++ tests link bearing_core and set no flags of their
    # own) carries the library's floating-point flags: the inline arithmetic of its
    # headers compiles as the library's own does.
    ninja = (library_build.folder / "build" / "build.ninja").read_text(encoding="utf-8")
    consumer = re.search(r"build tests/cpp/CMakeFiles/test_map_batch\.dir/[^\n]*\n(.*?)\n\n",
                         ninja, re.S)  # fmt: skip
    assert consumer is not None
    flags = re.search(r"FLAGS = (.*)", consumer.group(1))
    assert flags is not None
    for flag in ("-ffp-contract=off", "-fno-tree-vectorize", "-fno-fast-math"):
        assert flag in flags.group(1).split(), flag


def test_the_install_holds_the_headers_the_library_and_the_cmake_package(
    library_build: Build,
) -> None:
    prefix = library_build.folder / "prefix"
    package = next(prefix.glob("lib*/cmake/bearing_core"))
    assert {p.name for p in package.iterdir()} >= {
        "bearing_coreConfig.cmake", "bearing_coreConfigVersion.cmake",
        "bearing_coreTargets.cmake"}  # fmt: skip
    assert (prefix / "include/bearing_core/slam/map_batch.hpp").is_file()
    assert next(prefix.glob("lib*/libbearing_core.a")).is_file()
    targets = (package / "bearing_coreTargets.cmake").read_text(encoding="utf-8")
    assert "bearing_core::bearing_core" in targets and "-ffp-contract=off" in targets


def _printed_regions(output: str) -> dict[int, list[complex]]:
    regions: dict[int, list[complex]] = {}
    for line in output.splitlines():
        if line.startswith("# landmark "):
            regions[int(line.split()[2])] = []
        elif line and not line.startswith("#"):
            j, x, y = line.split(",")
            regions[int(j)].append(complex(float(x), float(y)))
    return regions


def test_the_replay_prints_the_regions_python_computes_from_the_same_log(
    library_build: Build,
) -> None:
    (replay,) = page_commands(REPLAY)
    _, log, epsilon = shlex.split(replay)
    start, end = read_bearing_log(ROOT / log)
    assert start.shape == (10, 5) and np.isnan(start).sum() + np.isnan(end).sum() == 2
    maps = BatchedPolygonSLAM(1, start.shape[1], float(epsilon))
    for b1, b2 in zip(start, end, strict=True):
        maps.update(b1[None], b2[None])
    printed = _printed_regions(library_build.replay)
    assert sorted(printed) == [2, 3, 4]
    for j, region in printed.items():
        assert len(region) >= 3
        assert region == maps.polygon(0, j - 2).tolist(), j  # bit for bit
    areas = [float(line.split()[5].rstrip(",")) for line in library_build.replay.splitlines()
             if line.startswith("# landmark ")]  # fmt: skip
    assert areas == maps.areas[0].tolist()


def test_configuring_without_a_compiler_says_so_in_one_sentence(tmp_path: Path) -> None:
    # An sdist installed where there is no C++ compiler: CMake stops with the project's
    # own message, not a failed compiler test.
    result = subprocess.run(
        ["cmake", "-S", str(ROOT), "-B", str(tmp_path / "build"), "-G", "Ninja",
         "-DBEARING_ENV_PYTHON=OFF"],
        capture_output=True, text=True, timeout=120,
        env={**os.environ, "PATH": PATH, "CXX": str(tmp_path / "no-such-compiler")},
    )  # fmt: skip
    assert result.returncode != 0
    output = " ".join((result.stdout + result.stderr).split())
    assert "bearing_env needs a C++17 compiler to build from source, and found none" in output
    assert "is not able to compile a simple test program" not in output
