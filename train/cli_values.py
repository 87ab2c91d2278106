"""Values on their way in from the command line and out to JSON: ``KEY=VALUE`` items
parsed as Python literals, and settings made JSON-safe.

Used by ``bearing-env train`` (``--env-kwargs``, ``--hyperparams``), ``compare``
(``--env-kwargs``) and ``bench`` (``--env-kwargs``, ``--ppo-hyperparams``), so the three
read ``KEY=VALUE`` alike.
"""

from __future__ import annotations

import ast
from collections.abc import Sequence
from typing import Any


def parse_literal(text: str) -> Any:
    """A Python literal when ``text`` is one (``4``, ``0.25``, ``(0.1, 0.3)``, ``0.05,0.3``
    (a tuple), ``None``), else ``text`` itself."""
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def parse_key_values(pairs: Sequence[str], option: str) -> dict[str, Any]:
    """``["k=v", ...]`` -> ``{"k": parse_literal(v)}``; ValueError naming ``option`` and
    the item that is not ``KEY=VALUE``."""
    parsed: dict[str, Any] = {}
    for pair in pairs:
        key, separator, value = pair.partition("=")
        if not separator or not key.strip():
            raise ValueError(f"{option} expects KEY=VALUE (key=value) items, got {pair!r}")
        parsed[key.strip()] = parse_literal(value.strip())
    return parsed


def format_key_values(values: dict[str, Any]) -> list[str]:
    """``{"k": v}`` -> ``["k=v", ...]``, which ``parse_key_values`` reads back to ``values``
    (strings bare when they are not literals, everything else as its repr)."""
    return [
        f"{key}={value}"
        if isinstance(value, str) and parse_literal(value) == value
        else f"{key}={value!r}"
        for key, value in values.items()
    ]


def json_safe(value: Any) -> Any:
    """Settings as JSON: dicts (string keys) and lists kept, tuples as lists, numbers,
    strings, bools and None as they are, anything else (a schedule, a class) as its repr."""
    if isinstance(value, dict):
        return {str(key): json_safe(item) for key, item in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(item) for item in value]
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return repr(value)
