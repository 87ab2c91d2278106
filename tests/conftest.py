"""Test collection: the modules that need the ``train`` extra are collected only with it.

``make test`` installs every extra, so all modules run there. A plain install of the
sdist (``tests/test_install.py``) has no torch or stable-baselines3; these modules import
them at the top, so they are left out of collection, and the report header says so.
"""

from __future__ import annotations

import pytest
from hypothesis import settings

from bearing_env.extras import available, install_command

# Every run draws the same examples, and no example database carries state between runs.
settings.register_profile("deterministic", derandomize=True, database=None)
settings.load_profile("deterministic")

#: Test modules (paths below ``tests/``) that import the ``train`` extra (torch,
#: stable-baselines3, rl-zoo3) at the top, or load the shipped models in every test.
NEEDS_TRAIN_EXTRA = (
    "test_bench.py",
    "test_extractors.py",
    "test_lost_work.py",
    "test_train.py",
    "test_vec_env.py",
    "agents/test_model_task.py",
    "tools/test_compare_tasks.py",
    "tools/test_zoo_commands.py",
)
TRAIN_EXTRA_INSTALLED = available("stable_baselines3", "torch")
#: Test modules that import the ``ray`` extra at the top.
NEEDS_RAY_EXTRA = ("test_ray.py",)
RAY_EXTRA_INSTALLED = available("ray")

collect_ignore = [
    *([] if TRAIN_EXTRA_INSTALLED else NEEDS_TRAIN_EXTRA),
    *([] if RAY_EXTRA_INSTALLED else NEEDS_RAY_EXTRA),
]


def pytest_report_header(config: pytest.Config) -> str | None:
    lines = [
        f"not collected, they need the {extra} extra ({install_command(extra)}): "
        + " ".join(modules)
        for extra, modules, installed in (
            ("train", NEEDS_TRAIN_EXTRA, TRAIN_EXTRA_INSTALLED),
            ("ray", NEEDS_RAY_EXTRA, RAY_EXTRA_INSTALLED),
        )
        if not installed
    ]
    return "\n".join(lines) or None
