"""The golden corpus's replay file (``tests/golden/slam_replay.txt``, which the C++ test
``tests/cpp/test_golden_replay.cpp`` replays) agrees with the recorded corpus: its
settings are the named corpus cases', its hashes the recorded ones, and its bearings,
replayed through the Python package, give those hashes."""

from __future__ import annotations

import json

import pytest

from tests import golden_replay
from tests.golden_slam import GOLDEN_FILE, new_maps, seeded_cases

CASES = golden_replay.read()
CORPUS = {case.name: case for case, _ in seeded_cases()}


def test_the_file_covers_every_transfer_and_fusion() -> None:
    assert len(CASES) >= 10
    transfers = {case.name.split("-")[0] for case in CASES}
    fusions = {case.name.split("-")[1] for case in CASES}
    assert transfers == {"conservative", "conservative_global", "paper"}
    assert fusions == {"intersect", "relaxed", "robust"}


@pytest.mark.parametrize("case", CASES, ids=lambda case: case.name)
def test_a_case_is_the_recorded_corpus_case_and_replays_to_its_hash(
    case: golden_replay.ReplayCase,
) -> None:
    recorded = json.loads(GOLDEN_FILE.read_text(encoding="utf-8"))["small"]
    assert case.sha256 == recorded[case.name]
    corpus_case = CORPUS[case.name]
    assert case.settings == golden_replay.settings_of(new_maps(corpus_case))
    assert case.bearings.shape == (corpus_case.moves, 2, corpus_case.maps,
                                   corpus_case.n_landmarks)  # fmt: skip
    assert case.replay_hash() == case.sha256
