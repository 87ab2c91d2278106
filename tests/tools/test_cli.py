"""The bearing-env command line: every subcommand resolves to a module with a main()."""

import importlib
import subprocess
import sys

import pytest

from bearing_env.train.cli import SUBCOMMANDS
from tests.extras import needs

#: Every subcommand; train's module imports stable-baselines3 at the top.
SUBCOMMAND_PARAMS = [
    pytest.param(command, marks=needs("train")) if command == "train" else command
    for command in sorted(SUBCOMMANDS)
]


@pytest.mark.parametrize("command", SUBCOMMAND_PARAMS)
def test_every_subcommand_has_a_main(command: str) -> None:
    module_name, _ = SUBCOMMANDS[command]
    assert callable(importlib.import_module(module_name).main)


@pytest.mark.parametrize("command", SUBCOMMAND_PARAMS)
def test_subcommand_help_runs(command: str) -> None:
    result = subprocess.run(
        [sys.executable, "-m", "bearing_env.train.cli", command, "--help"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert "usage:" in result.stdout


def test_unknown_subcommand_is_rejected() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "bearing_env.train.cli", "fly"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode != 0
    assert "invalid choice" in result.stderr


def hyperparams_command(algo: str, cwd) -> subprocess.CompletedProcess[str]:
    """``bearing-env hyperparams ALGO`` run from ``cwd`` (not the checkout)."""
    return subprocess.run(
        [sys.executable, "-m", "bearing_env.train.cli", "hyperparams", algo],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=cwd,
    )


def test_hyperparams_prints_the_shipped_file_from_any_folder(tmp_path) -> None:
    result = hyperparams_command("ppo", tmp_path)
    assert result.returncode == 0, result.stderr
    from pathlib import Path

    import bearing_env.train.sb3

    path = Path(result.stdout.strip())
    assert path.is_absolute() and path.name == "ppo.yml"
    assert path.parent.parent == Path(bearing_env.train.sb3.__file__).parent
    assert "BearingSLAM-v1:" in path.read_text()


def test_hyperparams_rejects_an_algorithm_without_a_file(tmp_path) -> None:
    result = hyperparams_command("td3", tmp_path)
    assert result.returncode == 2
    assert "'td3'" in result.stderr
    assert "dqn, ppo, ppo_attention, ppo_candidates, ppo_entities, ppo_shapes, sac" in result.stderr


def test_compare_help_names_every_policy_kind() -> None:
    from bearing_env.agents.registry import POLICY_CLASSES
    from bearing_env.train.compare.cli import build_parser

    epilog = " ".join((build_parser().epilog or "").split())
    # One name per kind: the shortest of the names that build the same class.
    shortest = {}
    for name, cls in POLICY_CLASSES.items():
        if cls not in shortest or len(name) < len(shortest[cls]):
            shortest[cls] = name
    missing = [name for name in shortest.values() if name not in epilog]
    assert missing == []
