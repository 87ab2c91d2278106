"""One-line failures for the command line, instead of tracebacks.

- An ``OSError`` while writing outputs (disk full, no permission, a parent that is a
  file, a read-only file system) ends the command with ``<prog>: error: <path>: <reason>``
  and exit status :data:`EXIT_ERROR`.
- A command or call that needs an optional extra that is not installed
  (``render``: pygame; ``train``: stable-baselines3, torch, matplotlib, ...) raises
  :class:`MissingExtraError`, which names the extra and the ``pip install`` line; the
  command line prints it and exits with :data:`EXIT_ERROR`.
"""

from __future__ import annotations

import errno
import importlib
import sys
from pathlib import Path
from types import ModuleType
from typing import NoReturn

#: Exit status of a command that failed with a clear message (argparse's, for usage errors).
EXIT_ERROR = 2

#: The optional extra (``pyproject.toml``) that provides each importable module.
MODULE_EXTRAS: dict[str, str] = {
    "pygame": "render",
    "moviepy": "video",
    "stable_baselines3": "train",
    "torch": "train",
    "matplotlib": "train",
    "tqdm": "train",
    "rich": "train",
    "tensorboard": "train",
    "yaml": "train",
    "rl_zoo3": "train",
}
#: The pip distribution name of a module, where it differs.
_DISTRIBUTIONS = {"stable_baselines3": "stable-baselines3", "yaml": "pyyaml"}

_HINTS = {
    getattr(errno, name): hint
    for name, hint in (
        ("ENOSPC", "the disk is full"),
        ("EDQUOT", "the disk quota is exceeded"),
        ("EACCES", "no permission to write there"),
        ("EPERM", "no permission to write there"),
        ("EROFS", "the file system is read-only"),
        ("ENOTDIR", "a parent of that path is a file, not a folder"),
    )
    if hasattr(errno, name)
}


def install_command(extra: str) -> str:
    return f'pip install "bearing_env[{extra}]"'


class MissingExtraError(ImportError):
    """An optional dependency is missing; the message says which extra installs it."""

    def __init__(self, module: str, purpose: str, extra: str | None = None) -> None:
        top = module.split(".")[0]
        self.extra = extra or MODULE_EXTRAS.get(top, "train")
        distribution = _DISTRIBUTIONS.get(top, top)
        super().__init__(
            f"{purpose} needs the package '{distribution}', which is not installed: "
            f"{install_command(self.extra)}",
            name=top,
        )


def require(module: str, purpose: str, extra: str | None = None) -> ModuleType:
    """Import ``module``, or raise :class:`MissingExtraError` naming the extra to install."""
    try:
        return importlib.import_module(module)
    except ImportError as error:
        missing = (error.name or module).split(".")[0]
        if missing != module.split(".")[0] and missing not in MODULE_EXTRAS:
            raise  # something else is broken inside the installed package
        raise MissingExtraError(missing, purpose, extra) from error


def missing_extra(error: ImportError) -> MissingExtraError | None:
    """The :class:`MissingExtraError` an import error amounts to, or None when the
    missing module is not one of an optional extra's."""
    if isinstance(error, MissingExtraError):
        return error
    name = getattr(error, "name", None)
    if not isinstance(error, ModuleNotFoundError) or not name:
        return None
    top = name.split(".")[0]
    if top not in MODULE_EXTRAS:
        return None
    return MissingExtraError(top, "this command")


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
