"""The shape of the code: no function outside the numba kernels is longer than 80 lines,
and no public function takes more than 12 parameters (``python -m tests.tools.code_shape``
prints the counts)."""

from __future__ import annotations

from pathlib import Path

from tests.tools.code_shape import (
    MAX_FUNCTION_LINES,
    MAX_PUBLIC_PARAMETERS,
    function_shapes,
    project_shapes,
    too_long,
    too_many_parameters,
)

#: Functions allowed over a limit for now, each with the reason (none today).
ALLOWED_WIDE: set[str] = set()


def test_no_function_outside_the_kernels_is_longer_than_80_lines() -> None:
    long_ones = [f"{s.key} ({s.lines} lines)" for s in too_long(project_shapes())]
    assert long_ones == [], f"over {MAX_FUNCTION_LINES} lines: {long_ones}"


def test_no_public_function_takes_more_than_12_parameters() -> None:
    wide = [s for s in too_many_parameters(project_shapes()) if s.key not in ALLOWED_WIDE]
    listed = [f"{s.key} ({s.parameters} parameters)" for s in wide]
    assert listed == [], f"over {MAX_PUBLIC_PARAMETERS} parameters: {listed}"


def test_the_allowances_are_still_needed() -> None:
    # An allowance whose function was fixed (or renamed) must go, or it hides the next one.
    wide = {s.key for s in too_many_parameters(project_shapes())}
    assert ALLOWED_WIDE <= wide, sorted(ALLOWED_WIDE - wide)


def test_the_checker_measures_lines_and_parameters_as_documented(tmp_path: Path) -> None:
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_FUNCTION_LINES))
    (tmp_path / "sample.py").write_text(
        "import numba\n"
        "from numba import njit\n\n\n"
        f"def long_one():\n{body}\n\n\n"
        f"@njit(cache=True)\ndef kernel():\n{body}\n\n\n"
        f"@numba.vectorize\ndef ufunc(x):\n{body}\n\n\n"
        "class Thing:\n"
        "    def method(self, a, b, /, c, *rest, d, e=1, **more):\n        pass\n\n"
        "    @classmethod\n    def build(cls, a):\n        pass\n\n"
        "    @staticmethod\n    def helper(self_like, b):\n        pass\n\n"
        "    def _private(self, a, b, c, d, e, f, g, h, i, j, k, l, m):\n        pass\n"
    )
    shapes = {s.name: s for s in function_shapes(tmp_path / "sample.py", tmp_path)}
    assert shapes["long_one"].lines == MAX_FUNCTION_LINES + 1
    assert not shapes["long_one"].kernel
    assert shapes["kernel"].kernel and shapes["ufunc"].kernel
    assert shapes["Thing.method"].parameters == 7  # a b c *rest d e **more, not self
    assert shapes["Thing.build"].parameters == 1
    assert shapes["Thing.helper"].parameters == 2  # a static method has no self to drop
    assert not shapes["Thing._private"].public and shapes["Thing._private"].parameters == 13
    assert [s.name for s in too_long(list(shapes.values()))] == ["long_one"]
    assert too_many_parameters(list(shapes.values())) == []
