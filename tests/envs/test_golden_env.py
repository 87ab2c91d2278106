"""The env steps give, at full float64 precision, what the numba env step gave
(``tests/golden_env.py``): observations, rewards, episode ends and infos."""

from __future__ import annotations

import pytest

from tests.golden_env import NAMES, exact_hash, recorded


@pytest.mark.parametrize("name", NAMES)
def test_the_trace_hashes_as_recorded_at_full_precision(name: str) -> None:
    assert exact_hash(name) == recorded()[name], f"{name} changed"
