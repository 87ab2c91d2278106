"""``bearing-env bench-callgrind``: instruction counts, and where they go by function."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from bearing_env.benchmarks import bench_callgrind

#: Lines as ``callgrind_annotate --inclusive=yes`` prints them (shortened signatures):
#: the interpreter's frames, nanobind's wrappers, the core's functions and libm's.
ANNOTATE = """\
--------------------------------------------------------------------------------
Ir                    file:function
--------------------------------------------------------------------------------
521,467,662 (100.0%)  ./csu/../csu/libc-start.c:__libc_start_main@@GLIBC_2.34 [/usr/lib/x86_64-linux-gnu/libc.so.6]
521,467,662 (100.0%)  /tmp/python-build/Python-3.11.7/Python/ceval.c:_PyEval_EvalFrameDefault [/usr/bin/python3.11]
521,467,662 (100.0%)  ???:nanobind::detail::nb_func_vectorcall_medium(_object*, _object* const*) [/x/bearing_env/_core.cpython-311-x86_64-linux-gnu.so]
521,467,662 (100.0%)  ???:bearing::env::step_rows(bearing::View<long const, 1>, bearing::env::Inputs const&) [/x/bearing_env/_core.cpython-311-x86_64-linux-gnu.so]
480,225,014 (92.09%)  ???:bearing::slam::(anonymous namespace)::update_rows(long, long) [/x/bearing_env/_core.cpython-311-x86_64-linux-gnu.so]
232,410,091 (44.57%)  ???:bearing::slam::transfer_region(bearing::cplx const*, long) [/x/bearing_env/_core.cpython-311-x86_64-linux-gnu.so]
 24,410,544 ( 4.68%)  ./math/../sysdeps/ieee754/dbl-64/e_hypot.c:hypot@@GLIBC_2.35 [/usr/lib/x86_64-linux-gnu/libm.so.6]
 19,026,744 ( 3.65%)  ???:bearing::env::observe(bearing::View<long const, 1>) [/x/bearing_env/_core.cpython-311-x86_64-linux-gnu.so]
"""  # noqa: E501


def test_the_listed_functions_are_the_cores_and_libms_by_short_name() -> None:
    functions = bench_callgrind.functions_of(ANNOTATE, top=4)
    assert [f["function"] for f in functions] == [
        "bearing::env::step_rows",
        "bearing::slam::{anonymous}::update_rows",
        "bearing::slam::transfer_region",
        "hypot@@GLIBC_2.35",
    ]
    assert functions[1]["instructions"] == 480_225_014
    assert functions[1]["share"] == pytest.approx(0.9209)
    assert len(bench_callgrind.functions_of(ANNOTATE, top=12)) == 5


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("valgrind") is None, reason="needs valgrind")
def test_the_command_counts_the_update_and_the_step(tmp_path: Path) -> None:
    out = tmp_path / "callgrind.json"
    bench_callgrind.main(["--movements", "20", "--steps", "20", "--json", str(out)])
    record = json.loads(out.read_text())
    assert record["measured"]["command"] == (
        "bearing-env bench-callgrind --movements 20 --steps 20 --json " + str(out)
    )
    results = record["counts"]
    transfers = ("conservative", "paper", "conservative_global")
    assert set(results) == {
        *(f"update_{t}_{key}" for key in ("khepera", "synthetic_4") for t in transfers),
        "step_khepera",
    }
    assert results["update_paper_khepera"]["readings"] == "recorded Khepera-v1 readings"
    for counted in results.values():
        assert counted["per_call"] == counted["instructions"] / counted["count"] > 1000
        names = [f["function"] for f in counted["functions"]]
        assert names and all(not n.startswith(bench_callgrind.NANOBIND_WRAPPERS) for n in names)
    # The conservative transfer costs more than the paper's, per movement.
    for key in ("khepera", "synthetic_4"):
        assert (
            results[f"update_conservative_{key}"]["per_call"]
            > results[f"update_paper_{key}"]["per_call"]
        )
    # The entry point first: the library's step_into (the outputs held), its checked
    # step_rows, then the kernel.
    entries = tuple(f["function"] for f in results["step_khepera"]["functions"][:3])
    assert entries == (
        "bearing::env::checked::step_into",
        "bearing::env::checked::step_rows",
        "bearing::env::step_rows",
    )


def test_the_update_driver_replays_the_recorded_readings_episode_by_episode(
    tmp_path: Path,
) -> None:
    # The driver, run here without valgrind, on the saved Khepera-v1 workload: as many
    # updates as asked, a fresh map at each episode, the env's map settings.
    import subprocess
    import sys

    import numpy as np

    path = tmp_path / "khepera.npz"
    bench_callgrind.save_workload("khepera", path)
    data = np.load(path)
    assert data["start"].shape == data["end"].shape == (160, 4)
    assert data["episodes"].tolist() == [k // 20 for k in range(160)]
    assert json.loads(str(data["settings"]))["epsilon"] == pytest.approx(np.deg2rad(2.0))
    out = subprocess.run(
        [sys.executable, "-c", bench_callgrind.UPDATE_DRIVER, "170", "paper", str(path)],
        capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    assert out.strip() == "170"


def test_the_page_table_lists_the_steps_functions_below_the_step_itself() -> None:
    step = {"count": 400, "per_call": 140_335.0, "functions": [
        {"function": "bearing::env::step_rows", "share": 1.0},
        {"function": "bearing::slam::{anonymous}::update_rows", "share": 0.95},
        *({"function": f"bearing::slam::part{k}", "share": 0.9 - 0.1 * k} for k in range(8)),
    ]}  # fmt: skip
    record = {
        "measured": {"command": "bearing-env bench-callgrind", "commit": "abc1234def",
                     "date": "2026-12-03", "machine": "2-core x86_64 machine"},
        "counts": {"update_conservative_khepera": {"per_call": 81_168.3},
                   "update_paper_khepera": {"per_call": 36_694.4},
                   "update_conservative_synthetic_4": {"per_call": 61_168.3},
                   "update_paper_synthetic_4": {"per_call": 26_694.4}, "step_khepera": step},
    }  # fmt: skip
    text = bench_callgrind.markdown_callgrind(record)
    assert (
        "on recorded Khepera-v1 readings: 81,168 conservative, 36,694 paper; on synthetic" in text
    )
    assert "repeated layout): 61,168 conservative, 26,694 paper" in text
    assert "(native part, 400 steps): 140,335" in text
    rows = [line for line in text.splitlines() if line.startswith("| `")]
    assert rows[0] == "| `part0` | 90% |" and len(rows) == bench_callgrind.PAGE_FUNCTIONS
    assert "step_rows" not in "".join(rows) and "update_rows" not in "".join(rows)
