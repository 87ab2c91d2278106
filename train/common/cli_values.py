"""Values on their way in from the command line and out to JSON: counts, seeds and
seconds checked as argparse parses them, ``KEY=VALUE`` items parsed as Python literals,
and settings made JSON-safe.

Every subcommand's numeric options use the argparse types here (:func:`at_least`,
:data:`COUNT`, :data:`SEED`, :func:`seconds`), so a bad value, such as ``--episodes 0``,
``--seed -1`` or ``--seconds inf``, ends the command as an argparse usage error (exit
status 2) whose one error line names the option and the value:
``bearing-env compare: error: argument --episodes: must be >= 1, got 0``. Out-of-range
values are refused, never replaced by defaults. The checks are the env config's own
(:func:`bearing_env.envs.config.int_at_least`, :func:`~bearing_env.envs.config.positive_float`).

``KEY=VALUE`` items: ``bearing-env train`` (``--env-kwargs``, ``--hyperparams``),
``compare`` (``--env-kwargs``) and ``bench`` (``--env-kwargs``, ``--ppo-hyperparams``)
read them alike.
"""

from __future__ import annotations

import argparse
import ast
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from bearing_env.validation import int_at_least, int_at_most, positive_float

_T = TypeVar("_T")


def _checked(check: Callable[..., _T], *args: Any) -> _T:
    """``check(*args, "")`` (a validator of :mod:`bearing_env.envs.config`, whose last
    argument is the name to put in its message), its error as an argparse type error;
    argparse names the option."""
    try:
        return check(*args, "")
    except (TypeError, ValueError) as error:
        raise argparse.ArgumentTypeError(str(error).strip()) from None


def at_least(minimum: int, maximum: int | None = None) -> Callable[[str], int]:
    """An argparse ``type``: an integer ``>= minimum`` (and ``<= maximum`` if given)."""

    def integer(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        value = _checked(int_at_least, value, minimum)
        return value if maximum is None else _checked(int_at_most, value, maximum)

    integer.__name__ = f"integer >= {minimum}"
    return integer


#: argparse ``type`` of a count of things to do (episodes, workers, seeds, moves): >= 1.
COUNT = at_least(1)
#: argparse ``type`` of a count that may be 0 (0 documented as "none"/"never"): >= 0.
NON_NEGATIVE = at_least(0)
#: argparse ``type`` of a seed: an integer >= 0 (numpy refuses negative seeds).
SEED = at_least(0)


def seconds(text: str) -> float:
    """An argparse ``type``: a finite number of seconds > 0 (``inf`` would never end)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    return _checked(positive_float, value)


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


def registered_env_id(env_id: str) -> str:
    """``env_id`` (``"NAME-vN"`` or ``"module:NAME-vN"``, as ``gym.make`` reads it) when it
    names a registered env; ValueError naming it otherwise (Gymnasium's own message leaves
    out the version and the module)."""
    import importlib

    import gymnasium as gym

    module, _, name = env_id.rpartition(":")
    try:
        importlib.import_module(module or "bearing_env")  # registers the module's ids
    except ImportError as error:
        raise ValueError(f"unknown env id {env_id!r}: cannot import {module!r} ({error})") from None
    try:
        gym.spec(name)
    except gym.error.Error as error:
        raise ValueError(f"unknown env id {env_id!r}: {error}") from None
    return env_id
