"""One home per concept: single-value checks (``bearing_env.validation``) and angle
wrapping (``bearing_env.numerics``), and the package defines neither anywhere else."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pytest

from bearing_env import numerics, validation
from bearing_env.envs.config import EnvConfig
from bearing_env.slam import PolygonSLAM

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_FOLDERS = ("bearing_env", "agents", "train", "benchmarks")


@pytest.mark.parametrize("value", [1, 2.5, np.int64(3), np.float32(0.5), math.inf])
def test_real_numbers_are_real(value):
    assert validation.is_real(value)


@pytest.mark.parametrize("value", [True, np.bool_(False), "1", None, 1j, [1.0]])
def test_bools_strings_and_others_are_not_real(value):
    assert not validation.is_real(value)
    with pytest.raises(TypeError, match="must be a number"):
        validation.positive_float(value, "length")


def test_each_check_names_the_value_and_normalises_it():
    assert validation.positive_float(np.float32(0.5), "x") == 0.5
    assert type(validation.int_at_least(np.int64(4), 1, "n")) is int
    with pytest.raises(ValueError, match=r"n must be >= 3 \(L1, L2 and one more\), got 2"):
        validation.int_at_least(2, 3, "n", "(L1, L2 and one more)")
    with pytest.raises(TypeError, match="n must be an int, got True"):
        validation.int_at_least(True, 1, "n")
    with pytest.raises(ValueError, match=r"rate must be in \(0, 1\], got 0.0"):
        validation.float_in(0.0, "rate", 0.0, 1.0, closed_low=False)
    assert validation.float_in(0.0, "rate", 0.0, 1.0) == 0.0
    with pytest.raises(ValueError, match="finite and >= 0, got nan"):
        validation.non_negative_float(math.nan, "cost")
    with pytest.raises(ValueError, match="unknown fusion 'union'"):
        validation.choice("union", ("intersect", "relaxed"), "fusion")


def test_the_env_and_the_map_accept_the_same_epsilon():
    """The env's epsilon_deg range is the world model's (0, pi/2), in degrees."""
    inside, outside = 89.9, 90.0
    EnvConfig.create(epsilon_deg=inside)
    PolygonSLAM(3, math.radians(inside))
    with pytest.raises(ValueError, match="epsilon_deg"):
        EnvConfig.create(epsilon_deg=outside)
    with pytest.raises(ValueError, match="epsilon"):
        PolygonSLAM(3, math.radians(outside))


def test_wrap_agrees_with_wrap_angle_and_lands_in_range():
    angles = np.random.default_rng(0).uniform(-50.0, 50.0, 1000)
    wrapped = numerics.wrap_angle(angles)
    assert np.all((-math.pi <= wrapped) & (wrapped < math.pi))
    np.testing.assert_array_equal(wrapped, [numerics.wrap(a) for a in angles])
    np.testing.assert_allclose(np.exp(1j * wrapped), np.exp(1j * angles), atol=1e-12)


def package_functions() -> list[tuple[Path, ast.FunctionDef]]:
    found = []
    for folder in PACKAGE_FOLDERS:
        for path in sorted((ROOT / folder).rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.FunctionDef):
                    found.append((path.relative_to(ROOT), node))
    return found


def test_angle_wrapping_and_value_checks_have_one_home_each():
    wraps = [str(p) for p, f in package_functions() if ("wrap" in f.name and "angle" in f.name)
             or f.name == "wrap"]
    # wrap_angle (numpy) here; the scalar wrap is the native core's
    # (csrc/include/bearing_core/core/pymath.hpp), which numerics re-exports.
    assert sorted(wraps) == ["bearing_env/numerics.py"]
    from bearing_env import _core, numerics

    assert numerics.wrap is _core.wrap
    checks = {"is_real", "is_number", "is_integer", "int_at_least", "positive_float",
              "non_negative_float", "choice", "checked_epsilon", "epsilon_radians"}
    homes = {str(p) for p, f in package_functions() if f.name.lstrip("_") in checks}
    assert homes == {"bearing_env/validation.py"}
    # "a real number, not a bool" is spelled once, in validation.is_real/is_integer.
    spelled = [
        str(path) for folder in PACKAGE_FOLDERS for path in (ROOT / folder).rglob("*.py")
        if "isinstance(value, bool)" in path.read_text()
        or ", bool) or not isinstance(" in path.read_text()
    ]
    assert spelled == []


def test_the_simulator_imports_nothing_from_the_estimator():
    tree = ast.parse((ROOT / "bearing_env" / "world.py").read_text())
    imported = [
        node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and node.module
    ] + [alias.name for node in ast.walk(tree) if isinstance(node, ast.Import)
         for alias in node.names]
    assert not [name for name in imported if name.startswith("bearing_env.slam")]
