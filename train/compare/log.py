"""The episode log of a comparison, ``episodes.jsonl``: one JSON line per finished
episode, appended and fsynced as soon as it ends, read back on ``--resume``.

A torn last line (the run was killed mid-write) is dropped and the file repaired; any
other line that is not a valid record is a :class:`CorruptLogError` naming its line
number, with the way to recover.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from bearing_env.train.common.errors import (
    with_path,
)
from bearing_env.train.common.files import atomic_write_text

LOG_NAME = "episodes.jsonl"

#: What every record of the episode log must hold (``run_task``'s record).
RECORD_KEYS = ("policy", "seed", "moves", "max_moves", "area", "error", "contained")


class CorruptLogError(ValueError):
    """A line of ``episodes.jsonl`` other than the last is not a valid episode record."""

    def __init__(self, path: Path, line: int, problem: str) -> None:
        self.path, self.line = path, line
        super().__init__(
            f"{path}, line {line}: {problem}. To recover, delete that line (its episode "
            "runs again with --resume), or rerun with --overwrite instead of --resume to "
            "start the comparison again"
        )


class EpisodeLog:
    """The append-only JSON-lines log of finished episodes."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def load(self) -> list[dict[str, Any]]:
        """All complete records. A torn last line (the run was killed mid-write) is
        dropped and the file repaired; any other unreadable line is a
        :class:`CorruptLogError` naming its line number."""
        if not self.path.exists():
            return []
        text = self.path.read_text(encoding="utf-8")
        lines = text.split("\n")
        records, torn = [], False
        for index, line in enumerate(lines):
            if not line.strip():
                continue
            try:
                record = json.loads(line)
            except json.JSONDecodeError as error:
                if index == len(lines) - 1:
                    torn = True  # no newline after it: the write was cut short
                    break
                raise CorruptLogError(self.path, index + 1, f"not valid JSON ({error})") from None
            if not isinstance(record, dict) or any(key not in record for key in RECORD_KEYS):
                needed = ", ".join(RECORD_KEYS)
                raise CorruptLogError(
                    self.path, index + 1, f"not an episode record (it needs {needed})"
                )
            records.append(record)
        if torn:
            atomic_write_text(
                self.path, "".join(json.dumps(r, allow_nan=False) + "\n" for r in records)
            )
        return records

    def append(self, record: dict[str, Any]) -> None:
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            with open(self.path, "a", encoding="utf-8") as handle:
                handle.write(json.dumps(record, allow_nan=False) + "\n")
                handle.flush()
                os.fsync(handle.fileno())
        except OSError as error:
            raise with_path(error, self.path) from None

    def clear(self) -> None:
        if self.path.exists():
            self.path.unlink()
