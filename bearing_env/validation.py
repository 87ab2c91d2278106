"""The checks of single values, one home for the world model, the simulator, the envs
and the agents: each returns the value normalised to a plain Python type, or raises a
``TypeError`` (wrong kind) or ``ValueError`` (out of range) that names it.

A real number here is an int or a float (numpy's included) but never a bool: ``True`` is
not a length.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

#: The bearing error bound the world model accepts, radians (exclusive): a cone of
#: +-epsilon is a proper wedge only below a right angle.
EPSILON_RANGE = (0.0, math.pi / 2)


def is_real(value: Any) -> bool:
    """A real number: int or float, numpy's included, bools excluded."""
    return not isinstance(value, (bool, np.bool_)) and isinstance(
        value, (int, float, np.integer, np.floating)
    )


def is_integer(value: Any) -> bool:
    """An int, numpy's included, bools excluded."""
    return not isinstance(value, (bool, np.bool_)) and isinstance(value, (int, np.integer))


def real(value: Any, name: str) -> float:
    """``value`` as a float, finite or not (TypeError unless a real number)."""
    if not is_real(value):
        raise TypeError(f"{name} must be a number, got {value!r}")
    return float(value)


def positive_float(value: Any, name: str) -> float:
    out = real(value, name)
    if not math.isfinite(out) or out <= 0.0:
        raise ValueError(f"{name} must be finite and > 0, got {value!r}")
    return out


def non_negative_float(value: Any, name: str) -> float:
    out = real(value, name)
    if not math.isfinite(out) or out < 0.0:
        raise ValueError(f"{name} must be finite and >= 0, got {value!r}")
    return out


def float_in(value: Any, name: str, low: float, high: float, closed_low: bool = True) -> float:
    """A number in ``[low, high]`` (``(low, high]`` when not ``closed_low``)."""
    out = real(value, name)
    inside = (low <= out if closed_low else low < out) and out <= high
    if not inside:
        bracket = "[" if closed_low else "("
        raise ValueError(f"{name} must be in {bracket}{low:g}, {high:g}], got {value!r}")
    return out


def int_at_least(value: Any, minimum: int, name: str, why: str = "") -> int:
    """An int ``>= minimum``; ``why`` follows the bound in the message."""
    if not is_integer(value):
        raise TypeError(f"{name} must be an int, got {value!r}")
    if value < minimum:
        suffix = f" {why}" if why else ""
        raise ValueError(f"{name} must be >= {minimum}{suffix}, got {value!r}")
    return int(value)


def int_at_most(value: int, maximum: int, name: str) -> int:
    if value > maximum:
        raise ValueError(f"{name} must be <= {maximum}, got {value!r}")
    return value


def flag(value: Any, name: str) -> bool:
    """A bool (numpy's included), as a Python bool; ints are not flags."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {value!r}")
    return bool(value)


def choice(value: Any, choices: Sequence[str], name: str) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a str, one of {tuple(choices)}, got {value!r}")
    if value not in choices:
        raise ValueError(f"unknown {name} {value!r}; expected one of {tuple(choices)}")
    return value


def epsilon_radians(epsilon: Any, name: str = "epsilon") -> float:
    """The bearing error bound as a float in :data:`EPSILON_RANGE` radians."""
    if not is_real(epsilon):
        raise TypeError(f"{name} must be a number of radians, got {epsilon!r}")
    value = float(epsilon)
    low, high = EPSILON_RANGE
    if not low < value < high:
        raise ValueError(f"{name} must be in (0, pi/2) radians, got {epsilon!r}")
    return value
