"""The test suite itself: every random source in a test has an explicit seed.

Gymnasium seeds an env's spaces apart from ``reset(seed=...)``, so a test that samples
an action space without seeding it draws different actions on every run; one such test
once failed on CI only, when its unseeded actions reached the success target early.
"""

from __future__ import annotations

import ast
import pathlib

import pytest
from hypothesis import settings

TESTS = pathlib.Path(__file__).parent


def _functions_sampling_unseeded_spaces(source: str) -> list[str]:
    tree = ast.parse(source)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
            body = ast.get_source_segment(source, node) or ""
            if ".sample()" in body and "space.seed(" not in body:
                found.append(node.name)
    return found


def test_the_check_finds_an_unseeded_sample() -> None:
    unseeded = "def f(env):\n    env.reset(seed=0)\n    env.step(env.action_space.sample())\n"
    seeded = "def g(env):\n    env.action_space.seed(0)\n    env.action_space.sample()\n"
    assert _functions_sampling_unseeded_spaces(unseeded + seeded) == ["f"]


@pytest.mark.parametrize(
    "path", sorted(TESTS.rglob("*.py")), ids=lambda path: path.relative_to(TESTS).as_posix()
)
def test_every_sampled_space_is_seeded(path: pathlib.Path) -> None:
    assert _functions_sampling_unseeded_spaces(path.read_text()) == []


def test_hypothesis_draws_the_same_examples_every_run() -> None:
    assert settings.default.derandomize
    assert settings.default.database is None
