"""Behaviour is kept: every golden trace hashes as recorded (``tests/golden_traces.py``).

A deliberate change of behaviour re-records the hashes with
``python -m tests.golden_traces --update`` and says why in its commit.
"""

from __future__ import annotations

import pytest

from tests.extras import needs
from tests.golden_traces import TRACES, feed, recorded, trace_hash

#: Every trace; the shipped model's policy loads with stable-baselines3.
TRACE_PARAMS = [
    pytest.param(name, marks=needs("train")) if "pretrained" in name else name
    for name in sorted(TRACES)
]


@pytest.mark.parametrize("name", TRACE_PARAMS)
def test_the_trace_hashes_as_recorded(name):
    assert trace_hash(name) == recorded()[name], f"{name} changed behaviour"


def test_the_hash_sees_every_value_and_its_place():
    import hashlib

    import numpy as np

    def digest(value):
        h = hashlib.sha256()
        feed(h, value)
        return h.hexdigest()

    base = {"obs": np.zeros(3, np.float32), "info": {"area": np.array([1.0, np.inf])}}
    variants = [
        {"obs": np.array([0, 0, 1e-6], np.float32), "info": base["info"]},
        {"obs": base["obs"], "info": {"area": np.array([1.0, np.nan])}},
        {"obs": base["obs"], "info": {"areas": np.array([1.0, np.inf])}},
        {"obs": base["obs"].reshape(1, 3), "info": base["info"]},
        {"obs": base["obs"], "info": {"area": np.array([1.0, np.inf]), "extra": None}},
    ]
    assert len({digest(v) for v in [base, *variants]}) == 1 + len(variants)
    assert digest(base) == digest({"info": base["info"], "obs": base["obs"].copy()})
