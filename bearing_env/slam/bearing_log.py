"""Bearing logs: a robot's bearings, movement by movement, as a CSV file.

The format (the same the C++ example ``examples/cpp/replay`` reads; ``docs/cpp.md``):

* a header line ``movement,landmark,bearing_start,bearing_end``;
* one row per movement and landmark: the movement's number (0, 1, ... in order), the
  landmark's (0 is L1, 1 is L2, then the mapped landmarks L3, L4, ...), and its bearings
  at the start and at the end of the movement, in radians counter-clockwise from the
  direction of motion, ``nan`` for a missed reading;
* every movement lists every landmark, in order; lines starting with ``#`` are comments.

:func:`read_bearing_log` gives the arrays :meth:`BatchedPolygonSLAM.update` takes, one row
per movement; :func:`write_bearing_log` writes them.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: The header line of a bearing log.
HEADER = "movement,landmark,bearing_start,bearing_end"


def read_bearing_log(path: str | Path) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The bearings of the log at ``path``: (start, end), each (movements, landmarks).

    Raises:
        ValueError: on a missing header, a malformed row, movements or landmarks out of
            order or missing, or an infinite bearing, naming the line.
    """
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    rows = [(number, line) for number, line in enumerate(lines, 1)
            if line.strip() and not line.startswith("#")]  # fmt: skip
    if not rows or rows[0][1].strip() != HEADER:
        raise ValueError(f"{path}: the first line must be the header {HEADER!r}")
    table: list[tuple[int, int, float, float]] = []
    for number, line in rows[1:]:
        fields = line.split(",")
        try:
            movement, landmark = int(fields[0]), int(fields[1])
            start, end = float(fields[2]), float(fields[3])
        except (ValueError, IndexError):
            raise ValueError(f"{path}:{number}: expected {HEADER}, got {line!r}") from None
        if len(fields) != 4 or math.isinf(start) or math.isinf(end):
            raise ValueError(f"{path}:{number}: four fields, bearings finite or nan: {line!r}")
        table.append((movement, landmark, start, end))
    return _arrays(table, path)


def _arrays(
    table: list[tuple[int, int, float, float]], path: str | Path
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    n_landmarks = 1 + max((row[1] for row in table), default=-1)
    if n_landmarks < 3 or len(table) % n_landmarks:
        raise ValueError(f"{path}: every movement must list the same 3 or more landmarks")
    moves = len(table) // n_landmarks
    expected = [(m, j) for m in range(moves) for j in range(n_landmarks)]
    got = [(row[0], row[1]) for row in table]
    if got != expected:
        first = next(k for k, pair in enumerate(got) if pair != expected[k])
        raise ValueError(f"{path}: row {first + 1} is (movement, landmark) {got[first]}, "
                         f"expected {expected[first]}")  # fmt: skip
    values = np.array([(row[2], row[3]) for row in table]).reshape(moves, n_landmarks, 2)
    return np.ascontiguousarray(values[..., 0]), np.ascontiguousarray(values[..., 1])


def write_bearing_log(path: str | Path, start: ArrayLike, end: ArrayLike) -> None:
    """Write bearings (movements, landmarks) at the start and end of each movement to
    ``path`` as a bearing log (exact: each number as Python's shortest round-trip repr)."""
    b1, b2 = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    if b1.ndim != 2 or b1.shape != b2.shape:
        raise ValueError(f"start and end must be (movements, landmarks), got {b1.shape}, "
                         f"{b2.shape}")  # fmt: skip
    lines = [HEADER]
    for move in range(b1.shape[0]):
        for landmark in range(b1.shape[1]):
            lines.append(f"{move},{landmark},{float(b1[move, landmark])!r},"
                         f"{float(b2[move, landmark])!r}")  # fmt: skip
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


__all__ = ["HEADER", "read_bearing_log", "write_bearing_log"]
