"""One-line failures for the command line, instead of tracebacks.

- An ``OSError`` while writing outputs (disk full, no permission, a parent that is a
  file, a read-only file system) ends the command with ``<prog>: error: <path>: <reason>``
  and exit status :data:`EXIT_ERROR`.
- Output into a closed pipe (``bearing-env bench-slam | head -3``) ends the command
  quietly (:func:`exit_quietly_on_broken_pipe`), as Python's documentation recommends.
- A command or call that needs an optional extra that is not installed
  (``render``: pygame; ``train``: stable-baselines3, torch, matplotlib, ...; ``ray``:
  Ray, RLlib, Ray Tune) raises
  :class:`~bearing_env.extras.MissingExtraError`, which names the extra and the
  ``pip install`` line; the command line prints it and exits with :data:`EXIT_ERROR`.
"""

from __future__ import annotations

import errno
import os
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

if TYPE_CHECKING:
    import argparse

from bearing_env.extras import (
    MODULE_EXTRAS,
    MissingExtraError,
    available,
    install_command,
    missing_extra,
    require,
)

__all__ = [
    "EXIT_BROKEN_PIPE",
    "EXIT_ERROR",
    "MODULE_EXTRAS",
    "MissingExtraError",
    "available",
    "exit_on_missing_extra",
    "exit_on_output_errors",
    "exit_quietly_on_broken_pipe",
    "fail",
    "install_command",
    "missing_extra",
    "os_error_message",
    "require",
    "with_path",
    "write_error_message",
]

#: Exit status of a command that failed with a clear message (argparse's, for usage errors).
EXIT_ERROR = 2
#: Exit status when the reader of stdout went away (Python's own status on EPIPE).
EXIT_BROKEN_PIPE = 1

_HINTS = {
    getattr(errno, name): hint
    for name, hint in (
        ("ENOSPC", "the disk is full"),
        ("EDQUOT", "the disk quota is exceeded"),
        ("EACCES", "no permission to write there"),
        ("EPERM", "no permission to write there"),
        ("EROFS", "the file system is read-only"),
        ("ENOTDIR", "a parent of that path is a file, not a folder"),
        ("EEXIST", "something of that name is in the way"),
    )
    if hasattr(errno, name)
}


def with_path(error: OSError, path: str | Path) -> OSError:
    """Give an ``OSError`` raised while writing ``path`` that path, when it names none or
    only a temporary file beside it; returns the error, for ``raise``."""
    if error.filename is None or str(error.filename).endswith(".tmp"):
        error.filename = str(path)
    return error


def os_error_message(error: OSError, path: str | Path | None = None) -> str:
    """``<path>: <reason> (<hint>)`` for an ``OSError``, on one line."""
    where = error.filename if error.filename is not None else path
    reason = error.strerror or str(error) or type(error).__name__
    hint = _HINTS.get(error.errno) if error.errno is not None else None
    text = f"{where}: {reason}" if where is not None else reason
    if hint and hint.lower() != reason.lower():
        text += f" ({hint})"
    return " ".join(text.split())


def write_error_message(error: OSError, path: str | Path | None, option: str) -> str:
    """``cannot write <path>: <reason> (<hint>); <what to do>`` for an ``OSError`` raised
    while writing a command's outputs into the folder given by ``option``."""
    if error.errno in (errno.ENOSPC, getattr(errno, "EDQUOT", None)):
        advice = f"free some space, or choose another {option}"
    elif error.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        advice = f"make the folder writable, or choose another {option}"
    else:
        advice = f"choose another {option}"
    return f"cannot write {os_error_message(error, path)}; {advice}"


def fail(prog: str, message: str, status: int = EXIT_ERROR) -> NoReturn:
    """Print ``<prog>: error: <message>`` on one line to stderr and exit with ``status``."""
    print(f"{prog}: error: {' '.join(message.split())}", file=sys.stderr)
    raise SystemExit(status)


@contextmanager
def exit_on_output_errors(
    parser: argparse.ArgumentParser,
    folder: Path,
    option: str,
    refusals: tuple[type[Exception], ...] = (ValueError,),
) -> Iterator[None]:
    """How a command that writes into ``folder`` (given by ``option``) ends on errors
    inside the block.

    A ``FileExistsError`` without an errno (the command's own refusal: the folder holds a
    run already) is a usage error; a ``refusals`` error (a resume that does not match, a
    damaged log) is one line; any other ``OSError`` (disk full, no permission, a parent
    that is a file) is one line naming the file. Each exits with status 2.
    """
    try:
        yield
    except FileExistsError as error:
        if error.errno is None:
            parser.error(str(error))
        fail(parser.prog, write_error_message(error, folder, option))
    except refusals as error:
        fail(parser.prog, str(error))
    except OSError as error:
        fail(parser.prog, write_error_message(error, folder, option))


@contextmanager
def exit_on_missing_extra(prog: str) -> Iterator[None]:
    """Turn an import error of an optional extra's module, inside the block, into
    ``<prog>: error: ... pip install "bearing_env[<extra>]"`` and exit status 2."""
    try:
        yield
    except ImportError as error:
        clear = missing_extra(error, "this command")
        if clear is None:
            raise
        fail(prog, str(clear))


@contextmanager
def exit_quietly_on_broken_pipe() -> Iterator[None]:
    """End the command quietly, with :data:`EXIT_BROKEN_PIPE`, when the reader of its
    stdout goes away (``bearing-env bench-slam | head -3``): no traceback, and no second
    error when Python flushes stdout at exit, because stdout then points at
    ``os.devnull`` (the recipe of Python's ``signal`` documentation)."""
    try:
        yield
        sys.stdout.flush()  # inside the try: the last lines may fail only now
    except BrokenPipeError:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        raise SystemExit(EXIT_BROKEN_PIPE) from None
