"""The native extension's type stub names exactly what the built module has.

``bearing_env/_core.pyi`` is hand-written (mypy reads it; the compiled module has no
Python source): a name bound in C++ but missing from the stub, or left in the stub after
the binding went away, fails here.
"""

from __future__ import annotations

import ast
import importlib.resources

from bearing_env import _core

#: The stub as installed with the package (the source tree is absent when the installed
#: package's tests run, e.g. from the sdist).
STUB = importlib.resources.files("bearing_env") / "_core.pyi"


def _stub_names() -> set[str]:
    names: set[str] = set()
    for node in ast.parse(STUB.read_text(encoding="utf-8")).body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
        elif isinstance(node, ast.Assign):
            names.update(t.id for t in node.targets if isinstance(t, ast.Name))
    return {name for name in names if not name.startswith("_")}


def test_the_stub_names_every_public_name_of_the_module_and_no_other() -> None:
    module = {name for name in dir(_core) if not name.startswith("_")}
    assert sorted(module - _stub_names()) == []
    assert sorted(_stub_names() - module) == []


def test_capacity_errors_are_runtime_errors() -> None:
    assert issubclass(_core.CapacityError, RuntimeError)
