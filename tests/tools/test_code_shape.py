"""The shape of the code: no function outside the numba kernels is longer than 80 lines,
and no public function takes more than 12 parameters; the C++ functions of csrc/, tests/cpp/
and examples/cpp/ follow the same 80-line rule, with named exceptions
(``python -m tests.tools.code_shape`` prints the counts)."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.tools.code_shape import (
    MAX_FUNCTION_LINES,
    MAX_PUBLIC_PARAMETERS,
    ROOT,
    function_shapes,
    project_shapes,
    too_long,
    too_many_parameters,
)
from tests.tools.cpp_shape import (
    ALLOWED_LONG,
    BINDINGS_FOLDER,
    MAX_BINDINGS_LINES,
    cpp_functions,
    project_cpp_functions,
    too_long_cpp,
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


def test_no_cpp_function_outside_the_allowances_is_longer_than_80_lines() -> None:
    long_ones = [
        f"{f.key} ({f.lines} lines, line {f.lineno})"
        for f in too_long_cpp(project_cpp_functions())
        if f.key not in ALLOWED_LONG
    ]
    assert long_ones == [], f"C++ over {MAX_FUNCTION_LINES} lines (split, or allow): {long_ones}"


def test_the_bindings_stay_thin() -> None:
    files = sorted((ROOT / BINDINGS_FOLDER).iterdir())
    lines = {f.name: len(f.read_text().splitlines()) for f in files}
    assert files and sum(lines.values()) <= MAX_BINDINGS_LINES, lines


def test_the_cpp_allowances_are_still_needed() -> None:
    # An allowance whose function was split (or renamed) must go, or it hides the next one.
    long_ones = {f.key for f in too_long_cpp(project_cpp_functions())}
    assert set(ALLOWED_LONG) <= long_ones, sorted(set(ALLOWED_LONG) - long_ones)
    assert all(reason.strip() for reason in ALLOWED_LONG.values())


# The synthetic C++ file: each function's expected (line of its name, length) is noted, and
# what must not be a function (the macro, the lambdas, the control blocks) is in it too.
CPP_SAMPLE = r"""// a comment with { braces } and a { lone one
#include <string>
#define BLOCK(x) \
    do {         \
        x;       \
    } while (0)

namespace demo::inner {

int free_function(int a,
                  int b) {  // free_function: line 10, 11 lines
    /* a } brace in a block comment */
    const char* text = "}{ \"}\" {";
    const char* raw = R"x({ ")" })x";
    const char brace = '}';
    for (int k = 0; k < 1'000; ++k) {
        a += k;
    }
    return a + b + text[0] + raw[0] + brace;
}

class Widget : public Base {
public:
    Widget(int a, int b)  // Widget::Widget: line 24, 6 lines
        : a_(a), b_{b}, c_{} {
        if (a_ > 0) {
            a_ = 0;
        }
    }
    int method() const noexcept { return a_; }  // line 30, 1 line
    auto trailing() const -> int {  // line 31, 3 lines
        return b_;
    }

private:
    int a_{0};
    int b_ = {1};
    int c_;
};

}  // namespace demo::inner

void with_lambda(std::vector<int>& v) {  // line 43, 9 lines
    auto keep = [](int x) {
        return x > 0;
    };
    for (int& x : v) {
        if (keep(x)) { x = 0; }
    }
    switch (v.size()) { default: break; }
}
auto not_a_function = [](int x) { return x; };
bool Widget::operator==(const Widget& other) const {  // line 53, 3 lines
    return true;
}
Widget::~Widget() {}  // line 56, 1 line
"""


def test_the_cpp_scanner_measures_as_documented(tmp_path: Path) -> None:
    long_body = "\n".join(f"    x += {i};" for i in range(MAX_FUNCTION_LINES - 1))
    sample = CPP_SAMPLE + f"void long_one(int x) {{\n{long_body}\n}}\n"
    (tmp_path / "sample.cpp").write_text(sample, encoding="utf-8")
    measured = {
        f.name: (f.lineno, f.lines) for f in cpp_functions(tmp_path / "sample.cpp", tmp_path)
    }
    assert measured == {
        "demo::inner::free_function": (10, 11),  # comments, strings and chars hold no brace
        "demo::inner::Widget::Widget": (24, 6),  # b_{b} and c_{} are not its body
        "demo::inner::Widget::method": (30, 1),
        "demo::inner::Widget::trailing": (31, 3),
        "with_lambda": (43, 9),  # the lambda, the for, the if and the switch are its lines
        "Widget::operator==": (53, 3),
        "Widget::~Widget": (56, 1),
        "long_one": (57, MAX_FUNCTION_LINES + 1),
    }  # and no BLOCK (the macro), keep or not_a_function (lambdas), if, for or switch
    functions = cpp_functions(tmp_path / "sample.cpp", tmp_path)
    assert functions[0].key == "sample.cpp:demo::inner::free_function"
    assert [f.name for f in too_long_cpp(functions)] == ["long_one"]


def test_a_control_statement_is_never_a_cpp_function(tmp_path: Path) -> None:
    # Even where the scanner looks for functions (at file scope), a keyword is no name.
    (tmp_path / "control.cpp").write_text(
        "if (ready) {\n}\nwhile (x) {\n}\nswitch (y) {\n}\nfor (;;) {\n}\ncatch (...) {\n}\n",
        encoding="utf-8",
    )
    assert cpp_functions(tmp_path / "control.cpp", tmp_path) == []


def test_the_cpp_scanner_refuses_what_it_cannot_balance(tmp_path: Path) -> None:
    # An #if with a brace in each branch would leave one unclosed: say so, not mismeasure.
    (tmp_path / "odd.cpp").write_text("void f() {\n    if (x) {\n}\n", encoding="utf-8")
    with pytest.raises(ValueError, match=r"odd\.cpp:1: unclosed"):
        cpp_functions(tmp_path / "odd.cpp", tmp_path)
