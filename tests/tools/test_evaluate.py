# ruff: noqa: E402  (the imports below need the extra; the module skips without it)
"""``bearing-env train --seeds``, ``bearing-env curves`` and ``bearing-env evaluate``, end to
end on two tiny training seeds: one run folder per seed, resume without losing a finished
seed, a crashed seed leaving the others intact, learning curves, and an evaluation against
baselines with per-seed and aggregate figures."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.extras import skip_module_without

skip_module_without("train", "rliable")

from bearing_env.train.compare import evaluate
from bearing_env.train.compare.aggregate import probability_of_improvement
from bearing_env.train.sb3 import curves, multi_seed

TASK = "BearingSLAM-Khepera-v1"
TINY = [
    "--algo", "ppo", "--env", TASK, "--n-envs", "2", "--vec-env", "dummy",
    "--timesteps", "256", "--eval-freq", "128", "--eval-episodes", "2",
    "--hyperparams", "n_steps=64", "batch_size=64", "n_epochs=2",
    "policy_kwargs=dict(net_arch=[32, 32])",
]  # fmt: skip


def bearing_env(*arguments: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "bearing_env.train.cli", *arguments],
        capture_output=True,
        text=True,
        timeout=600,
        cwd=cwd,
    )


@pytest.fixture(scope="module")
def seeds_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two tiny PPO runs, seeds 0 and 1, trained at once (--workers 2)."""
    output = tmp_path_factory.mktemp("runs") / "ppo_tiny"
    result = bearing_env(
        "train", *TINY, "--seeds", "0", "1", "--workers", "2", "--output", str(output)
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "all 2 seeds finished" in result.stdout
    return output


def test_each_seed_gets_its_own_finished_run_folder(seeds_folder: Path) -> None:
    for seed in (0, 1):
        record = json.loads((seeds_folder / f"seed{seed}" / "run.json").read_text())
        assert record["seed"] == seed and record["status"] == "finished"
        assert (seeds_folder / f"seed{seed}" / "best" / "best_model.zip").is_file()
        assert multi_seed.seed_state(seeds_folder / f"seed{seed}") == "finished"
    assert multi_seed.seed_state(seeds_folder / "seed7") == "new"


def test_without_resume_existing_seeds_are_refused(seeds_folder: Path) -> None:
    result = bearing_env("train", *TINY, "--seeds", "0", "1", "--output", str(seeds_folder))
    assert result.returncode == 2
    assert "already holds runs of seeds [0, 1]" in result.stderr and "--resume" in result.stderr


def test_resume_skips_finished_seeds_and_a_crash_spares_the_others(
    seeds_folder: Path, tmp_path: Path
) -> None:
    output = tmp_path / "ppo_tiny"
    shutil.copytree(seeds_folder, output)
    # Seed 1 crashed while writing its record: its resume fails, and must fail alone.
    broken = output / "seed1"
    (broken / "run.json").write_text('{"status": "runn')
    assert multi_seed.seed_state(broken) == "unfinished"
    result = bearing_env(
        "train", *TINY, "--seeds", "0", "1", "2", "--workers", "2", "--resume",
        "--output", str(output),
    )  # fmt: skip
    assert result.returncode == 1, result.stdout + result.stderr
    assert "seeds [0]: already finished" in result.stdout
    assert "seed 2: finished" in result.stdout
    assert "seed 1: FAILED" in result.stdout and "--resume" in result.stderr
    assert multi_seed.seed_state(output / "seed2") == "finished"
    assert multi_seed.seed_state(output / "seed0") == "finished"


def test_seed_arguments_drop_what_each_seed_sets_itself() -> None:
    argv = ["--algo", "ppo", "--seeds", "0", "1", "2", "--workers=2", "--output", "x", "--resume",
            "--timesteps", "5", "--no-progress"]  # fmt: skip
    assert multi_seed.seed_arguments(argv) == ["--algo", "ppo", "--timesteps", "5"]
    with pytest.raises(ValueError, match="twice"):
        multi_seed.plan_seeds(Path("unused"), [1, 1], resume=False)


def test_curves_plot_the_seeds_with_a_band(seeds_folder: Path, tmp_path: Path) -> None:
    out, summary = tmp_path / "curves.png", tmp_path / "curves.json"
    curves.main([str(seeds_folder), "--out", str(out), "--json", str(summary), "--bootstrap", "50"])
    figures = json.loads(summary.read_text())
    assert out.stat().st_size > 0
    assert figures["timesteps"] == [128, 256]
    assert len(figures["runs"]) == 2 and len(figures["return"]["per_run"]) == 2
    band = (figures["return"][k] for k in ("ci_low", "iqm", "ci_high"))
    for low, value, high in zip(*band, strict=True):
        assert low <= value <= high
    with pytest.raises(SystemExit):
        curves.main([str(tmp_path / "nothing")])


@pytest.fixture(scope="module")
def evaluation(seeds_folder: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("eval") / "out"
    result = bearing_env(
        "evaluate", str(seeds_folder / "seed*"), "--episodes", "3", "--baselines", "random",
        "greedy", "--bootstrap", "50", "--out", str(out), "--no-progress",
    )  # fmt: skip
    assert result.returncode == 0, result.stdout + result.stderr
    return out


def model_runs(results: dict[str, object]) -> list[str]:
    model = results["model"]
    assert isinstance(model, dict)
    return list(model["runs"])


def test_evaluate_writes_the_json_the_table_and_both_plots(evaluation: Path) -> None:
    results = json.loads((evaluation / "evaluation.json").read_text())
    assert set(results["measured"]) >= {"command", "commit", "date", "machine"}
    assert "--no-progress" not in results["measured"]["command"]
    assert results["task"] == TASK and results["episodes"] == 3
    assert results["model"]["runs"] == ["ppo_tiny/seed0", "ppo_tiny/seed1"]
    assert results["baselines"] == ["random_polygonal", "greedy_one_step"]
    model = results["policies"]["ppo_tiny"]
    assert (model["runs"], model["episodes"]) == (2, 3)
    for label in ("ppo_tiny/seed0", "ppo_tiny/seed1", "random_polygonal", "greedy_one_step"):
        assert (results["policies"][label]["runs"], results["policies"][label]["episodes"]) == (
            1,
            3,
        )
    for baseline in results["baselines"]:
        for move in ("10", "20"):
            entry = results["probability_of_improvement"][baseline][move]
            assert entry["ci_low"] <= entry["value"] <= entry["ci_high"]
    runs_iqm = {
        r: results["policies"][r]["area_after"]["10"]["iqm"]["value"] for r in model_runs(results)
    }
    closest = min(
        runs_iqm, key=lambda r: abs(runs_iqm[r] - model["area_after"]["10"]["iqm"]["value"])
    )
    assert results["model"]["representative_run"] == closest
    iqm = model["area_after"]["10"]["iqm"]
    assert iqm["ci_low"] <= iqm["value"] <= iqm["ci_high"]
    table = (evaluation / "evaluation.md").read_text()
    assert "| ppo_tiny | 2 x 3 |" in table and "ppo_tiny/seed1" in table
    for plot in ("area_vs_moves.png", "performance_profile.png"):
        assert (evaluation / plot).stat().st_size > 0


def test_evaluate_figures_agree_with_the_episode_log(evaluation: Path) -> None:
    results = json.loads((evaluation / "evaluation.json").read_text())
    log = [
        json.loads(line)
        for line in (evaluation / "episodes" / "episodes.jsonl").read_text().splitlines()
    ]

    def area_after(label: str, move: int) -> list[float]:
        rows = sorted((r for r in log if r["policy"] == label), key=lambda r: r["seed"])
        return [r["area"][min(move, len(r["area"]) - 1)] for r in rows]

    import numpy as np

    model = np.array([area_after("ppo_tiny/seed0", 10), area_after("ppo_tiny/seed1", 10)])
    greedy = np.array([area_after("greedy_one_step", 10)])
    stated = results["probability_of_improvement"]["greedy_one_step"]["10"]["value"]
    assert stated == pytest.approx(probability_of_improvement(model, greedy))
    assert results["policies"]["ppo_tiny"]["area_after"]["10"]["median"] == pytest.approx(
        float(np.median(model))
    )


def test_evaluate_resumes_and_refuses_a_second_run_without_resume(
    evaluation: Path, seeds_folder: Path
) -> None:
    arguments = [
        str(seeds_folder / "seed*"), "--episodes", "3", "--baselines", "random", "greedy",
        "--bootstrap", "50", "--out", str(evaluation), "--no-progress",
    ]  # fmt: skip
    again = bearing_env("evaluate", *arguments)
    assert again.returncode == 2 and "--resume" in again.stderr
    before = json.loads((evaluation / "evaluation.json").read_text())
    resumed = bearing_env("evaluate", *arguments, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    after = json.loads((evaluation / "evaluation.json").read_text())
    assert after["policies"] == before["policies"]


def test_evaluate_refuses_models_of_another_task_and_missing_ones(seeds_folder: Path) -> None:
    other = bearing_env("evaluate", str(seeds_folder), "--env", "BearingSLAM-Random8-v1")
    assert other.returncode == 2
    assert "was trained on BearingSLAM-Khepera-v1, not on BearingSLAM-Random8-v1" in other.stderr
    missing = bearing_env("evaluate", str(seeds_folder / "nope*"))
    assert missing.returncode == 2 and "no model at" in missing.stderr
    assert "Traceback" not in other.stderr + missing.stderr


def test_models_resolve_from_a_parent_a_glob_and_a_zip(seeds_folder: Path, strict=True) -> None:
    from_parent = evaluate.resolve_models([str(seeds_folder)])
    from_glob = evaluate.resolve_models([str(seeds_folder / "seed*")])  # skips the .log files
    assert [r.path for r in from_parent] == [r.path for r in from_glob]
    assert [r.training_seed for r in from_parent] == [0, 1]
    single = evaluate.resolve_models([str(seeds_folder / "seed0" / "best" / "best_model.zip")])
    assert single[0].training_seed is None and single[0].env_id is None
    assert evaluate.run_labels("m", single) == ["m/run0"]
    with pytest.raises(evaluate.ModelError, match="given twice"):
        evaluate.resolve_models([str(seeds_folder / "seed0"), str(seeds_folder / "seed0")])


def test_a_card_shows_a_shipped_models_training_seeds(evaluation: Path, tmp_path: Path) -> None:
    from bearing_env.train.compare.config import CompareConfig
    from bearing_env.train.compare.task_cards import seeds_path, training_seeds_section

    docs = tmp_path / "docs" / "tasks"
    config = CompareConfig(
        policies={"greedy_one_step": "greedy", "ppo_khepera": "pretrained:name='ppo_khepera'"},
        env_id=f"bearing_env:{TASK}",
        env_kwargs={},
    )
    assert training_seeds_section(docs, config) == [], "no seeds file, no section"
    seeds_file = seeds_path(docs, "ppo_khepera")
    seeds_file.parent.mkdir(parents=True)
    shutil.copy(evaluation / "evaluation.json", seeds_file)
    text = "\n".join(training_seeds_section(docs, config))
    results = json.loads(seeds_file.read_text())
    shipped = results["model"]["representative_run"]
    assert text.startswith("## Training seeds") and "one of 2 training seeds" in text
    assert "| ppo_tiny, 2 seeds | 2 x 3 |" in text and f"| {shipped} (shipped) | 1 x 3 |" in text
    for baseline in ("random_polygonal", "greedy_one_step"):
        improvement = results["probability_of_improvement"][baseline]["10"]["value"]
        assert f"| {baseline} | 1 x 3 |" in text and f"| {improvement:.2g} [" in text
    assert "bearing-env evaluate" in text and "seeds_ppo_khepera.json" in text


def test_the_version_history_names_a_shipped_model_left_on_an_older_version() -> None:
    from bearing_env.agents import pretrained_record
    from bearing_env.tasks import TASKS_BY_ID
    from bearing_env.train.compare.config import CompareConfig
    from bearing_env.train.compare.task_cards import version_history

    task = TASKS_BY_ID["BearingSLAM-FurnishedRoom-v1"]
    spec = {"ppo_furnished_room": "pretrained:name='ppo_furnished_room'"}
    config = CompareConfig(policies=spec, env_id=f"bearing_env:{task.id}", env_kwargs={})
    lines = version_history(task, config)
    trained_on = pretrained_record("ppo_furnished_room")["env_id"]
    stays = [line for line in lines if "`ppo_furnished_room` stays" in line]
    assert (len(stays) == 1) == (trained_on != task.id), lines
    assert version_history(task) == [f"- {entry}" for entry in task.history]
