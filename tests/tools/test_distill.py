"""``bearing-env distill``: DAgger from a planner into a shipped model.

The student is the shipped ``ppo_khepera`` and the teacher ``GreedyOneStep`` (2 ms a
move), on a few episodes: the runs check that the student's actions move towards the
teacher's, that the output is a model ``compare`` and ``train --init-from`` read, that an
interrupted run finishes with ``--resume`` exactly as an uninterrupted one, and that bad
settings end in one clear line.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests.extras import skip_module_without

skip_module_without("train")

import torch  # noqa: E402

import bearing_env.train.sb3.distill as distill_module  # noqa: E402
from bearing_env.agents import SB3Policy, pretrained_record  # noqa: E402
from bearing_env.agents.sb3 import PRETRAINED_DIR, find_vecnormalize  # noqa: E402
from bearing_env.train.sb3.callbacks import StopRequest  # noqa: E402
from bearing_env.train.sb3.distill import (  # noqa: E402
    DATASET_NAME,
    MODEL_NAME,
    STATE_NAME,
    Dataset,
    DistillResult,
    DistillSettings,
    action_error,
    distill,
)
from bearing_env.train.sb3.train import start_from  # noqa: E402


def settings(output: Path, **changes: Any) -> DistillSettings:
    base = DistillSettings(
        student="pretrained:ppo_khepera",
        output=output,
        teacher="greedy",
        iterations=2,
        episodes=2,
        epochs=15,
        batch_size=64,
        learning_rate=1e-3,
        seed=3,
        progress=False,
    )
    return replace(base, **changes)


def parameters(path: Path) -> dict[str, torch.Tensor]:
    return {k: v.clone() for k, v in SB3Policy(None, path).model.policy.state_dict().items()}


@pytest.fixture(scope="module")
def whole_run(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, DistillResult]:
    """Two iterations of two episodes, uninterrupted."""
    output = tmp_path_factory.mktemp("distill") / "whole"
    return output, distill(settings(output))


def test_the_students_actions_move_towards_the_teachers_and_only_the_actor_changes(
    whole_run: tuple[Path, DistillResult],
) -> None:
    output, result = whole_run
    first, second = result.iterations
    assert (first["actor"], second["actor"]) == ("teacher", "student")
    for entry in result.iterations:
        assert entry["loss_after"] < 0.7 * entry["loss_before"], entry
    assert 0 < first["labels"] < second["labels"] == result.labels
    state = json.loads((output / STATE_NAME).read_text())
    assert state["labels"] == result.labels
    dataset = Dataset.load(output / DATASET_NAME)
    assert len(dataset) == result.labels
    assert sorted(np.unique(dataset.episode_seed)) == [600_000, 600_001, 600_002, 600_003]
    # The value network and the exploration noise are the shipped model's.
    before = parameters(PRETRAINED_DIR / "ppo_khepera.zip")
    after = parameters(output / MODEL_NAME)
    changed = {k for k in before if not torch.equal(before[k], after[k])}
    actor = ("mlp_extractor.policy_net", "action_net")
    assert changed and all(k.startswith(actor) for k in changed)


def test_the_output_is_a_model_that_compare_and_init_from_read(tmp_path: Path) -> None:
    distill(settings(tmp_path / "run", iterations=1, episodes=1, epochs=1))
    model = tmp_path / "run" / MODEL_NAME
    stats = find_vecnormalize(model)
    assert stats is not None
    assert stats.read_bytes() == (PRETRAINED_DIR / "ppo_khepera_vecnormalize.pkl").read_bytes()
    policy = SB3Policy(None, model)  # its record gives its task
    env = policy.make_env()
    observation, info = env.reset(seed=1)
    assert env.action_space.contains(policy.act(observation, info))
    record, student = (
        json.loads(model.with_suffix(".json").read_text()),
        pretrained_record("ppo_khepera"),
    )
    assert (record["env_id"], record["env_kwargs"]) == (student["env_id"], student["env_kwargs"])
    fresh = SB3Policy.pretrained("ppo_khepera").model
    start_from(fresh, model, "cpu")
    expected = parameters(model)
    assert all(torch.equal(v, expected[k]) for k, v in fresh.policy.state_dict().items())


def test_an_interrupted_run_resumes_to_the_same_result(
    whole_run: tuple[Path, DistillResult], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    whole_output, whole = whole_run

    class StopAtTheThirdCheck(StopRequest):
        """Ctrl-C, as the run sees it, from its third check on. The run checks after
        every episode and every training step: the third check follows iteration 0's
        training."""

        checks = 0

        def __bool__(self) -> bool:
            StopAtTheThirdCheck.checks += 1
            return StopAtTheThirdCheck.checks >= 3

    monkeypatch.setattr(distill_module, "StopRequest", StopAtTheThirdCheck)
    stopped = distill(settings(tmp_path / "parts"))
    assert stopped.interrupted and len(stopped.iterations) == 1
    monkeypatch.undo()
    finished = distill(settings(tmp_path / "parts"), resume=True)
    assert not finished.interrupted and finished.labels == whole.labels
    a, b = (Dataset.load(folder / DATASET_NAME) for folder in (whole_output, tmp_path / "parts"))
    np.testing.assert_array_equal(a.actions, b.actions)
    np.testing.assert_array_equal(a.observations[""], b.observations[""])
    first, second = (
        parameters(whole_output / MODEL_NAME),
        parameters(tmp_path / "parts" / MODEL_NAME),
    )
    assert all(torch.equal(first[k], second[k]) for k in first)


def test_a_turn_error_is_the_angle_between_the_turns() -> None:
    mean = torch.tensor([[0.95, 0.5], [0.2, -1.0]])
    target = torch.tensor([[-0.95, 0.5], [-0.1, 0.0]])
    error = action_error(mean, target)
    assert error[0].item() == pytest.approx(0.1**2, abs=1e-6)  # across +-pi, not 1.9
    assert error[1].item() == pytest.approx(0.3**2 + 1.0, abs=1e-6)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"episodes": 0}, "episodes must be >= 1, got 0"),
        ({"learning_rate": 0.0}, "learning_rate must be > 0, got 0.0"),
        ({"seed_start": 899_999}, "must stay in the training range"),
    ],
)
def test_bad_settings_are_refused_by_name(
    tmp_path: Path, changes: dict[str, Any], message: str
) -> None:
    with pytest.raises(ValueError, match=message):
        settings(tmp_path, **changes)


def test_the_command_refuses_to_mix_runs_and_names_what_changed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    output = tmp_path / "run"
    base = [
        "--student", "pretrained:ppo_khepera", "--teacher", "greedy", "--output", str(output),
        "--iterations", "1", "--episodes", "1", "--epochs", "1", "--no-progress",
    ]  # fmt: skip
    distill_module.main(base)
    assert "iteration 0 (teacher acted)" in capsys.readouterr().out
    for extra, expected in (
        ([], "holds a distillation already: pass --resume"),
        (["--resume", "--episodes", "2"], "other settings than the run's: episodes 1 -> 2"),
        (["--resume", "--teacher", "parallax"], "teacher 'greedy' -> 'parallax'"),
        (["--resume", "--iterations", "2"], "iterations 1 -> 2"),
    ):
        with pytest.raises(SystemExit) as stopped:
            distill_module.main([*base, *extra])
        assert stopped.value.code == 2
        (line,) = capsys.readouterr().err.strip().splitlines()
        assert line.startswith("bearing-env distill: error: ") and expected in line, line
    for student, expected in (
        (str(tmp_path / "missing.zip"), "missing.zip"),
        ("pretrained:nope", "--student: no pretrained model named 'nope'"),
    ):
        with pytest.raises(SystemExit):
            distill_module.main(["--student", student, "--output", str(tmp_path / "o")])
        assert expected in capsys.readouterr().err


def test_a_discrete_student_learns_the_teachers_choices(tmp_path: Path) -> None:
    """The planner-features id's PPO student (``Discrete(16)``), freshly trained for one
    rollout and exported, learns the teacher's candidate indices (cross-entropy)."""
    from bearing_env.train.sb3 import train_cli

    run = tmp_path / "init"
    train_cli.main(
        [
            "--algo", "ppo", "--env", "BearingSLAMDiscrete-Khepera-Planner-v1",
            "--output", str(run), "--vec-env", "dummy", "--n-envs", "2", "--timesteps", "64",
            "--hyperparams", "n_steps=32", "batch_size=32", "n_epochs=1",
            "--eval-freq", "0", "--no-progress", "--no-tensorboard",
            "--export", str(run / "export" / "model"),
        ]
    )  # fmt: skip
    output = tmp_path / "distilled"
    result = distill(settings(output, student=str(run / "export" / "model.zip"), epochs=30))
    for entry in result.iterations:
        assert entry["loss_after"] < 0.7 * entry["loss_before"], entry
    dataset = Dataset.load(output / DATASET_NAME)
    labels = dataset.actions[:, 0]
    assert dataset.actions.shape[1] == 1 and np.array_equal(labels, np.round(labels))
    assert labels.min() >= 0 and labels.max() < 16 and np.unique(labels).size > 1
    student = SB3Policy(None, output / MODEL_NAME)
    env = student.make_env()
    observation, info = env.reset(seed=1)
    assert env.action_space.contains(student.act(observation, info))
