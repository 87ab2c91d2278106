"""Bearing logs (bearing_env.slam.bearing_log): written and read back exactly, and a
malformed file refused with the line named."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bearing_env.slam.bearing_log import HEADER, read_bearing_log, write_bearing_log


def test_a_log_reads_back_bit_for_bit_with_its_missed_readings(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    start, end = rng.uniform(-np.pi, np.pi, (2, 6, 4))
    start[2, 3] = end[0, 0] = np.nan
    path = tmp_path / "log.csv"
    write_bearing_log(path, start, end)
    read_start, read_end = read_bearing_log(path)
    np.testing.assert_array_equal(read_start, start)
    np.testing.assert_array_equal(read_end, end)
    assert read_start.flags.c_contiguous and read_start.dtype == np.float64


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0,0,1,2\n", "the first line must be the header"),
        (f"{HEADER}\n0,0,1\n", "log.csv:2: expected movement,landmark"),
        (f"{HEADER}\n0,0,1,inf\n", "log.csv:2: four fields, bearings finite or nan"),
        (f"{HEADER}\n0,0,1,2\n0,1,1,2\n", "the same 3 or more landmarks"),
        (f"{HEADER}\n0,0,1,2\n0,2,1,2\n0,1,1,2\n", "row 2 is (movement, landmark) (0, 2)"),
    ],
)
def test_a_malformed_log_is_refused_naming_the_line(
    tmp_path: Path, text: str, message: str
) -> None:
    path = tmp_path / "log.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)")):
        read_bearing_log(path)
