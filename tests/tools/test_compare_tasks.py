"""``bearing-env compare`` runs a pretrained model on its own task, or refuses in one line."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from bearing_env.agents import pretrained_record
from bearing_env.tasks import current_id
from bearing_env.train.compare import cli as compare
from bearing_env.train.compare.cli import QUICK_MAX_MOVES
from tests.extras import skip_module_without

skip_module_without("train")


def run_compare(*arguments: str) -> subprocess.CompletedProcess[str]:
    """``bearing-env compare`` as a user runs it (its own process: output, exit status)."""
    return subprocess.run(
        [sys.executable, "-m", "bearing_env.train.compare.cli", *arguments],
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_a_pretrained_model_is_compared_on_its_own_task(tmp_path: Path) -> None:
    out = tmp_path / "quick"
    compare.main(
        ["--quick", "--policies", "greedy", "pretrained:ppo_generalist", "--episodes", "1",
         "--out", str(out), "--no-progress", "--no-plots"]
    )  # fmt: skip
    config = json.loads((out / "config.json").read_text())
    record = pretrained_record("ppo_generalist")
    # Trained on BearingSLAM-v0: compared on the current version of that id.
    assert record["env_id"] == "BearingSLAM-v0" and config["env_id"] == "BearingSLAM-v1"
    assert config["env_id"] == current_id(record["env_id"])
    assert config["env_kwargs"] == {**record["env_kwargs"], "max_moves": QUICK_MAX_MOVES}
    episodes = (out / "episodes.jsonl").read_text().splitlines()
    assert sorted(json.loads(line)["policy"] for line in episodes) == [
        "greedy_one_step",
        "ppo_generalist",
    ]


@pytest.mark.parametrize(
    ("arguments", "expected"),
    [
        (
            ("--env-kwargs", "scenario=khepera"),
            "bearing-env compare: error: model 'ppo_generalist' was trained on another task "
            "than this env: observation 'entities' (env: 'flat'), max_landmarks 16 (env: 8), "
            "scenario 'random' (env: 'khepera'); its task (ppo_generalist.json): "
            "BearingSLAM-v0 with max_landmarks=16, n_landmarks=[3, 16], "
            "observation='entities', scenario='random'",
        ),
        (
            ("--policies", "pretrained:ppo_khepera", "pretrained:ppo_generalist"),
            "bearing-env compare: error: models 'ppo_khepera' and 'ppo_generalist' were "
            "trained on different tasks: observation 'flat' (ppo_generalist: 'entities'), "
            "max_landmarks 8 (ppo_generalist: 16), scenario 'khepera' "
            "(ppo_generalist: 'random'); compare them one at a time",
        ),
    ],
)
def test_a_model_on_another_task_is_refused_in_one_line(
    arguments: tuple[str, ...], expected: str, tmp_path: Path
) -> None:
    policies = () if "--policies" in arguments else ("--policies", "pretrained:ppo_generalist")
    result = run_compare("--quick", *policies, *arguments, "--out", str(tmp_path / "c"))
    assert result.returncode == 2
    assert result.stdout == ""
    assert result.stderr.splitlines() == [expected]
    assert not (tmp_path / "c").exists()
