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
    results = json.loads(out.read_text())
    assert set(results) == {"update_conservative_4", "update_paper_4", "step_khepera"}
    for counted in results.values():
        assert counted["per_call"] == counted["instructions"] / counted["count"] > 1000
        names = [f["function"] for f in counted["functions"]]
        assert names and all(not n.startswith(bench_callgrind.NANOBIND_WRAPPERS) for n in names)
    # The conservative transfer costs more than the paper's, per movement.
    assert results["update_conservative_4"]["per_call"] > results["update_paper_4"]["per_call"]
    assert results["step_khepera"]["functions"][0]["function"] == "bearing::env::step_rows"
