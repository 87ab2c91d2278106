"""Skips for tests that need an optional extra: the reason names the extra and its
``pip install`` line (``bearing_env.extras.install_command``).

A plain install (``pip install bearing_env`` plus pytest and hypothesis) runs every core
test and skips the rest cleanly; ``make test`` installs every extra, so nothing skips
there. Use the narrowest form that fits: :func:`needs` on one test (or a parameter),
:func:`import_or_skip` at the point of need, :func:`skip_module_without` for a module
that is wholly about an extra.
"""

from __future__ import annotations

import importlib
import importlib.util
from types import ModuleType

import pytest

from bearing_env.extras import MODULE_EXTRAS, available, install_command


def extra_modules(extra: str) -> tuple[str, ...]:
    """The import names an extra provides (``bearing_env.extras.MODULE_EXTRAS``)."""
    modules = tuple(module for module, owner in MODULE_EXTRAS.items() if owner == extra)
    if not modules:
        raise ValueError(f"unknown extra {extra!r}; known: {sorted(set(MODULE_EXTRAS.values()))}")
    return modules


def missing(extra: str, *modules: str) -> str | None:
    """Why a test cannot run without ``extra`` (its ``modules``, all of the extra's by
    default), or None when they are installed."""
    wanted = modules or extra_modules(extra)
    absent = [module for module in wanted if not available(module)]
    if not absent:
        return None
    return f"needs the {extra} extra ({', '.join(absent)} not installed): {install_command(extra)}"


def needs(extra: str, *modules: str) -> pytest.MarkDecorator:
    """Skip the test (or a parameter, through ``pytest.param(marks=...)``) without the extra."""
    reason = missing(extra, *modules)
    return pytest.mark.skipif(reason is not None, reason=reason or "")


def skip_module_without(extra: str, *modules: str) -> None:
    """At the top of a module that is wholly about an extra: skip all of it without it."""
    reason = missing(extra, *modules)
    if reason is not None:
        pytest.skip(reason, allow_module_level=True)


def import_or_skip(module: str) -> ModuleType:
    """Import an extra's module at the point of need, or skip naming its extra."""
    reason = missing(MODULE_EXTRAS[module.split(".")[0]], module.split(".")[0])
    if reason is not None:
        pytest.skip(reason)
    return importlib.import_module(module)


def build_backend_missing() -> str | None:
    """Why the distributions cannot be built here (pyproject.toml's build backend,
    scikit-build-core with nanobind, is not installed; the ``dev`` extra installs it), or
    None."""
    missing_tools = [
        name
        for name in ("scikit_build_core", "nanobind")
        if importlib.util.find_spec(name) is None
    ]
    if not missing_tools:
        return None
    return (
        f"needs the dev extra ({', '.join(missing_tools)} build the distributions): "
        f"{install_command('dev')}"
    )
