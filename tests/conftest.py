"""Test collection: the modules that need the ``train`` extra are collected only with it.

``make test`` installs every extra, so all modules run there. A plain install of the
sdist (``tests/test_install.py``) has no torch or stable-baselines3; these modules import
them at the top, so they are left out of collection, and the report header says so.
"""

from __future__ import annotations

import pytest

from bearing_env.extras import available, install_command

#: Test modules that import the ``train`` extra (torch, stable-baselines3) at the top.
NEEDS_TRAIN_EXTRA = (
    "test_bench.py",
    "test_extractors.py",
    "test_lost_work.py",
    "test_train.py",
    "test_vec_env.py",
)
TRAIN_EXTRA_INSTALLED = available("stable_baselines3", "torch")

collect_ignore = [] if TRAIN_EXTRA_INSTALLED else list(NEEDS_TRAIN_EXTRA)


def pytest_report_header(config: pytest.Config) -> str | None:
    if TRAIN_EXTRA_INSTALLED:
        return None
    return (
        f"not collected, they need the train extra ({install_command('train')}): "
        + " ".join(NEEDS_TRAIN_EXTRA)
    )
