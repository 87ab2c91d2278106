"""The shape of the project's functions: how long each is and how many parameters it takes.

    python -m tests.tools.code_shape        # the counts, and every function over a limit

(The C++ functions' lengths, held to the same MAX_FUNCTION_LINES, are measured by the
sibling module ``tests/tools/cpp_shape.py``; this module's summary lists them too.)

A function's length is ``end_lineno - lineno + 1`` of its ``def`` (decorators not counted);
its parameters are the positional, keyword-only and ``*args``/``**kwargs`` ones, without a
method's ``self``/``cls``. Numba kernels (``@njit``, ``@jit``, ``@vectorize``,
``@guvectorize``, plain or called) are exempt: a kernel is one compiled loop whose
arguments are its arrays, and splitting it costs calls in the hot path.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: The folders the limits hold in: the package and the three installed beside it.
CHECKED_FOLDERS: tuple[str, ...] = ("bearing_env", "agents", "train", "benchmarks")
MAX_FUNCTION_LINES = 80
MAX_PUBLIC_PARAMETERS = 12
NUMBA_DECORATORS = frozenset({"njit", "jit", "vectorize", "guvectorize"})


@dataclass(frozen=True)
class FunctionShape:
    """One function or method: where it is, how long, how many parameters."""

    path: str  # relative to the repository
    name: str  # qualified within its module: Class.method, outer.inner
    lineno: int
    lines: int
    parameters: int
    public: bool  # no part of the qualified name starts with an underscore
    kernel: bool  # decorated with a numba compiler

    @property
    def key(self) -> str:
        return f"{self.path}:{self.name}"


def decorator_name(decorator: ast.expr) -> str:
    """The last name of a decorator: ``njit`` for ``@njit``, ``@numba.njit(cache=True)``."""
    target = decorator.func if isinstance(decorator, ast.Call) else decorator
    if isinstance(target, ast.Attribute):
        return target.attr
    return target.id if isinstance(target, ast.Name) else ""


def parameter_count(function: ast.FunctionDef | ast.AsyncFunctionDef, method: bool) -> int:
    """Positional, keyword-only and starred parameters, without a method's self/cls."""
    arguments = function.args
    names = [a.arg for a in (*arguments.posonlyargs, *arguments.args)]
    static = any(decorator_name(d) == "staticmethod" for d in function.decorator_list)
    if method and not static and names and names[0] in ("self", "cls", "mcs"):
        names = names[1:]
    starred = (arguments.vararg is not None) + (arguments.kwarg is not None)
    return len(names) + len(arguments.kwonlyargs) + starred


def function_shapes(path: Path, root: Path = ROOT) -> Iterator[FunctionShape]:
    """Every function and method defined in the Python file ``path``, nested ones too."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    relative = path.relative_to(root).as_posix()

    def visit(node: ast.AST, prefix: str, in_class: bool) -> Iterator[FunctionShape]:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef):
                yield from visit(child, f"{prefix}{child.name}.", in_class=True)
            elif isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef):
                name = f"{prefix}{child.name}"
                assert child.end_lineno is not None
                yield FunctionShape(
                    path=relative,
                    name=name,
                    lineno=child.lineno,
                    lines=child.end_lineno - child.lineno + 1,
                    parameters=parameter_count(child, method=in_class),
                    public=not any(part.startswith("_") for part in name.split(".")),
                    kernel=any(decorator_name(d) in NUMBA_DECORATORS for d in child.decorator_list),
                )
                yield from visit(child, f"{name}.", in_class=False)
            else:
                yield from visit(child, prefix, in_class)

    yield from visit(tree, "", in_class=False)


def project_shapes(root: Path = ROOT) -> list[FunctionShape]:
    """The shapes of every function in the checked folders under ``root``."""
    files = sorted(p for folder in CHECKED_FOLDERS for p in (root / folder).rglob("*.py"))
    return [shape for path in files for shape in function_shapes(path, root)]


def too_long(shapes: list[FunctionShape]) -> list[FunctionShape]:
    """The non-kernel functions longer than MAX_FUNCTION_LINES."""
    return [s for s in shapes if not s.kernel and s.lines > MAX_FUNCTION_LINES]


def too_many_parameters(shapes: list[FunctionShape]) -> list[FunctionShape]:
    """The public non-kernel functions with more than MAX_PUBLIC_PARAMETERS parameters."""
    return [s for s in shapes if s.public and not s.kernel and s.parameters > MAX_PUBLIC_PARAMETERS]


def main() -> None:
    shapes = project_shapes()
    long_ones, wide_ones = too_long(shapes), too_many_parameters(shapes)
    kernels = sum(s.kernel for s in shapes)
    print(f"{len(shapes)} functions in {', '.join(CHECKED_FOLDERS)} ({kernels} numba kernels)")
    print(f"longer than {MAX_FUNCTION_LINES} lines (kernels exempt): {len(long_ones)}")
    for shape in long_ones:
        print(f"  {shape.key} ({shape.lines} lines, line {shape.lineno})")
    print(f"public, more than {MAX_PUBLIC_PARAMETERS} parameters: {len(wide_ones)}")
    for shape in wide_ones:
        print(f"  {shape.key} ({shape.parameters} parameters, line {shape.lineno})")
    # Imported here: cpp_shape takes its limit and root from this module.
    from tests.tools.cpp_shape import iter_report, project_cpp_functions

    for line in iter_report(project_cpp_functions()):
        print(line)


if __name__ == "__main__":
    main()
