"""The map update gives, bit for bit, the states its numba reference gave
(``tests/golden_slam.py``): every state array and update result after every movement of
the corpus, for both transfers, the three fusions and both inconsistency policies.
"""

from __future__ import annotations

from collections import Counter

import pytest

from tests.golden_slam import corpus, recorded


def test_the_small_corpus_hashes_as_recorded_and_covers_every_outcome() -> None:
    seen: Counter[str] = Counter()
    hashes = corpus(large=False, seen=seen)
    expected = recorded()["small"]
    assert hashes.keys() == expected.keys()
    assert sorted(name for name in hashes if hashes[name] != expected[name]) == []
    # The corpus reaches every path worth guarding: frames changed and refused, landmarks
    # fused, found inconsistent, unbounded and missed, and the robust bound grown.
    for outcome in ("frame ok", "frame l1_unbounded", "frame l1_missing", "frame rejected",
                    "landmark updated", "landmark inconsistent", "landmark unbounded",
                    "landmark missing", "robust bound growths"):  # fmt: skip
        assert seen[outcome] > 0, (outcome, seen)


@pytest.mark.slow
def test_the_large_corpus_hashes_as_recorded() -> None:
    hashes = corpus(large=True)
    expected = recorded()["large"]
    assert sorted(name for name in hashes if hashes[name] != expected[name]) == []
