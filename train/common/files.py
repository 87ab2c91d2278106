"""Atomic file writes: a reader sees the old file or the new one, never a part of it.

Every output of ``train``, ``compare`` and ``bench`` is written to a temporary file in
the same folder and renamed over the target (``os.replace``). An ``OSError`` (disk full,
no permission) names the target, not the temporary (``errors.with_path``).
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from bearing_env.train.common.errors import with_path


@contextmanager
def atomic_path(final_path: Path, suffix: str = "") -> Iterator[Path]:
    """A temporary path beside ``final_path``, renamed to it if the block succeeds.
    ``suffix`` ends the temporary name (``".png"`` for writers that choose a format by it)."""
    temporary = final_path.with_name(f".{final_path.name}.{os.getpid()}.tmp{suffix}")
    try:
        final_path.parent.mkdir(parents=True, exist_ok=True)
        yield temporary
        os.replace(temporary, final_path)
    except OSError as error:
        # Disk full, no permission, ...: name the file being written, not its temporary.
        if error.filename is not None and str(error.filename) == str(temporary):
            error.filename = None
        raise with_path(error, final_path) from None
    finally:
        if temporary.exists():
            temporary.unlink()


def atomic_write_text(path: Path, text: str, newline: str | None = None) -> None:
    """Write ``text`` to ``path`` atomically, fsynced before the rename. ``newline`` is
    :func:`open`'s (``""`` for CSV: no line-end translation)."""
    with atomic_path(path) as temporary:
        with open(temporary, "w", encoding="utf-8", newline=newline) as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())


def write_json_atomically(path: Path, payload: dict[str, Any]) -> None:
    """``payload`` as indented JSON with sorted keys, written atomically."""
    atomic_write_text(path, json.dumps(payload, indent=2, sort_keys=True) + "\n")


def atomic_save_figure(figure: Any, path: Path, **kwargs: Any) -> None:
    """``figure.savefig(path, **kwargs)`` (matplotlib), written atomically."""
    with atomic_path(path, suffix=path.suffix) as temporary:
        figure.savefig(temporary, **kwargs)
