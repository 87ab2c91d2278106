"""Test settings shared by every test folder.

Tests that need an optional extra skip without it, naming the extra and its install
command (``tests/extras.py``), so a plain install runs the core tests and ``make test``
(every extra installed) runs them all.
"""

from __future__ import annotations

from hypothesis import settings

# Every run draws the same examples, and no example database carries state between runs.
settings.register_profile("deterministic", derandomize=True, database=None)
settings.load_profile("deterministic")
