"""The comparison harness: determinism, resume, atomic outputs, statistics, command line."""

from __future__ import annotations

import csv
import json
import os
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from bearing_env.train import cli
from bearing_env.train.common.cli_values import format_key_values, parse_key_values
from bearing_env.train.common.seeds import EVAL_SEED_START
from bearing_env.train.compare.cli import main
from bearing_env.train.compare.comparison import RunMismatchError, run_comparison
from bearing_env.train.compare.config import CompareConfig, policies_from_specs
from bearing_env.train.compare.log import LOG_NAME, EpisodeLog
from bearing_env.train.compare.report import area_tail_rows, csv_text
from bearing_env.train.compare.runner import EpisodeTask, episode_tasks, run_locally
from bearing_env.train.compare.stats import bootstrap_mean_ci, worst_share_mean
from tests.extras import needs

SMALL_ENV = {"scenario": "khepera", "max_moves": 4}
OUTPUT_FILES = (
    "config.json",
    LOG_NAME,
    "episodes.csv",
    "summary.json",
    "summary.csv",
    "report.md",
    "timing.json",
    "area_vs_moves.png",
    "error_vs_moves.png",
)


def small_config(episodes: int = 4, **overrides: Any) -> CompareConfig:
    settings: dict[str, Any] = {
        "policies": policies_from_specs(["random", "greedy"]),
        "env_id": "BearingSLAM-v1",
        "env_kwargs": dict(SMALL_ENV),
        "episodes": episodes,
        "bootstrap": 200,
    }
    settings.update(overrides)
    return CompareConfig(**settings)


def run(config: CompareConfig, out: Path, **kwargs: Any) -> Any:
    kwargs.setdefault("progress", False)
    kwargs.setdefault("plots", False)
    return run_comparison(config, out, **kwargs)


def episode_results(out: Path) -> list[dict[str, Any]]:
    """The logged episodes without their timings, in a canonical order."""
    records = EpisodeLog(out / LOG_NAME).load()
    for record in records:
        record.pop("policy_seconds")
    return sorted(records, key=lambda r: (r["policy"], r["seed"]))


def test_seeds_are_the_documented_evaluation_range() -> None:
    config = small_config(episodes=3)
    assert config.seeds == [EVAL_SEED_START, EVAL_SEED_START + 1, EVAL_SEED_START + 2]
    assert EVAL_SEED_START == 1_000_000


@needs("train", "matplotlib")
def test_a_run_writes_every_output(tmp_path: Path) -> None:
    result = run(small_config(), tmp_path, plots=True, command="bearing-env compare ...")
    assert result.complete
    for name in OUTPUT_FILES:
        assert (tmp_path / name).stat().st_size > 0, name
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp") or ".tmp." in p.name]
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert set(summary["policies"]) == {"random_polygonal", "greedy_one_step"}
    greedy = summary["policies"]["greedy_one_step"]
    assert greedy["episodes"] == 4
    assert set(greedy["area_after"]) == {"1", "3"}  # only counts <= max_moves = 4
    assert len(greedy["curves"]["area_mean"]) == 5
    report = (tmp_path / "report.md").read_text()
    assert "greedy_one_step" in report and "bearing-env compare ..." in report
    csv_lines = (tmp_path / "episodes.csv").read_text().strip().splitlines()
    assert len(csv_lines) == 1 + 2 * 4


@needs("train", "matplotlib")
def test_plots_are_written_when_no_landmark_is_ever_mapped(tmp_path: Path) -> None:
    """A 90-degree camera maps nothing in a few episodes: every error is missing and every
    area at the cap, and the error plot (no positive value for a log axis) still draws."""
    config = small_config(
        episodes=2, env_id="bearing_env:BearingSLAM-Khepera-Camera90-v1", env_kwargs={}
    )
    result = run(config, tmp_path, plots=True)
    curves = result.summary["policies"]["greedy_one_step"]["curves"]
    assert set(curves["error_mean"]) == {None}
    for name in ("area_vs_moves.png", "error_vs_moves.png"):
        assert (tmp_path / name).stat().st_size > 0, name


def test_the_harness_is_deterministic(tmp_path: Path) -> None:
    config = small_config()
    run(config, tmp_path / "a")
    run(config, tmp_path / "b")
    assert (tmp_path / "a/summary.json").read_text() == (tmp_path / "b/summary.json").read_text()
    assert episode_results(tmp_path / "a") == episode_results(tmp_path / "b")


def test_parallel_workers_give_the_same_results(tmp_path: Path) -> None:
    config = small_config(episodes=3)
    run(config, tmp_path / "serial", workers=1)
    run(config, tmp_path / "parallel", workers=2)
    assert (tmp_path / "serial/summary.json").read_text() == (
        tmp_path / "parallel/summary.json"
    ).read_text()

    # The executor yields in task order (seed-major), so both logs hold the same lines.
    def logged(out: Path) -> list[dict[str, Any]]:
        records = EpisodeLog(out / LOG_NAME).load()
        return [{k: v for k, v in r.items() if k != "policy_seconds"} for r in records]

    tasks = episode_tasks(config, set())
    assert [(r["policy"], r["seed"]) for r in logged(tmp_path / "parallel")] == [
        (task.label, task.seed) for task in tasks
    ]
    assert logged(tmp_path / "parallel") == logged(tmp_path / "serial")


def test_an_executor_gets_only_the_missing_episodes_and_its_records_are_logged(
    tmp_path: Path,
) -> None:
    config = small_config(episodes=3)
    run(config, tmp_path, stop_after=2)
    given: list[list[tuple[str, int]]] = []

    def recording_executor(tasks: Sequence[EpisodeTask], workers: int) -> Iterator[dict[str, Any]]:
        given.append([(task.label, task.seed) for task in tasks])
        return run_locally(tasks, workers)

    result = run(config, tmp_path, resume=True, executor=recording_executor)
    assert result.complete
    assert given == [[(t.label, t.seed) for t in episode_tasks(config, set())][2:]]
    assert len(EpisodeLog(tmp_path / LOG_NAME).load()) == 6


def test_a_resumed_run_reproduces_the_uninterrupted_one(tmp_path: Path) -> None:
    config = small_config(episodes=5)
    run(config, tmp_path / "whole")
    partial = run(config, tmp_path / "resumed", stop_after=3)
    assert not partial.complete
    assert len(EpisodeLog(tmp_path / "resumed" / LOG_NAME).load()) == 3
    resumed = run(config, tmp_path / "resumed", resume=True)
    assert resumed.complete
    assert (tmp_path / "whole/summary.json").read_text() == (
        tmp_path / "resumed/summary.json"
    ).read_text()
    assert episode_results(tmp_path / "whole") == episode_results(tmp_path / "resumed")


def test_a_torn_last_line_is_dropped_and_rerun(tmp_path: Path) -> None:
    config = small_config(episodes=3)
    run(config, tmp_path / "whole")
    out = tmp_path / "killed"
    run(config, out, stop_after=4)
    log = out / LOG_NAME
    text = log.read_text()
    log.write_text(text + text.splitlines()[0][:40])  # killed in the middle of a write
    run(config, out, resume=True)
    assert len(EpisodeLog(log).load()) == 6
    assert log.read_text().endswith("\n")
    assert (tmp_path / "whole/summary.json").read_text() == (out / "summary.json").read_text()


def test_a_finished_run_is_not_overwritten_by_accident(tmp_path: Path) -> None:
    config = small_config(episodes=2)
    run(config, tmp_path)
    with pytest.raises(FileExistsError, match="--resume"):
        run(config, tmp_path)
    other_env = small_config(episodes=2, env_kwargs={"scenario": "khepera", "max_moves": 3})
    with pytest.raises(RunMismatchError, match="env_kwargs"):
        run(other_env, tmp_path, resume=True)
    renamed = small_config(episodes=2, policies={"random_polygonal": "parallax"})
    with pytest.raises(RunMismatchError, match="random_polygonal"):
        run(renamed, tmp_path, resume=True)
    run(other_env, tmp_path, overwrite=True)
    assert json.loads((tmp_path / "config.json").read_text())["env_kwargs"]["max_moves"] == 3


def test_resume_can_add_episodes_and_policies(tmp_path: Path) -> None:
    run(small_config(episodes=2), tmp_path)
    bigger = small_config(
        episodes=3, policies=policies_from_specs(["random", "greedy", "parallax"])
    )
    result = run(bigger, tmp_path, resume=True)
    assert result.complete and len(result.records) == 9
    assert run(bigger, tmp_path / "fresh").summary == result.summary


def test_bootstrap_ci_is_seeded_and_sensible() -> None:
    values = np.random.default_rng(0).exponential(size=200)
    low, high = bootstrap_mean_ci(values, np.random.default_rng(1), 2000)
    assert low < values.mean() < high
    assert (low, high) == bootstrap_mean_ci(values, np.random.default_rng(1), 2000)
    assert 0.1 < high - low < 0.5  # ~ 2 * 1.96 / sqrt(200) for a unit exponential


def test_env_kwargs_and_policy_labels_parse() -> None:
    assert parse_key_values(
        ["scenario=khepera", "move_length=0.25", "noise=gaussian"], "--env-kwargs"
    ) == {
        "scenario": "khepera",
        "move_length": 0.25,
        "noise": "gaussian",
    }
    assert parse_key_values(["move_length=0.05,0.3"], "--env-kwargs") == {
        "move_length": (0.05, 0.3)
    }
    with pytest.raises(ValueError, match=r"--env-kwargs expects KEY=VALUE.*'khepera'"):
        parse_key_values(["khepera"], "--env-kwargs")
    labels = policies_from_specs(["random", "random", "random:length=0.25"])
    assert list(labels) == [
        "random_polygonal",
        "random_polygonal#2",
        "random_polygonal[length=0.25]",
    ]


def test_env_kwargs_format_back_to_what_parses() -> None:
    values = {"scenario": "random", "n_landmarks": [3, 12], "move_length": (0.05, 0.3),
              "label": "4", "noise": {"outlier_rate": 0.05}, "flag": None}  # fmt: skip
    items = format_key_values(values)
    assert items[0] == "scenario=random" and items[3] == "label='4'"
    assert parse_key_values(items, "--env-kwargs") == values


def test_command_line_runs_and_resumes(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    args = [
        "--policies",
        "random",
        "parallax",
        "--env",
        "BearingSLAMDiscrete-v1",
        "--env-kwargs",
        "scenario=khepera",
        "max_moves=3",
        "--episodes",
        "2",
        "--out",
        str(tmp_path),
        "--no-progress",
        "--no-plots",
        "--bootstrap",
        "100",
        "--stop-after",
        "1",
    ]
    main(args)
    assert "INCOMPLETE" in capsys.readouterr().out
    main([*args[:-2], "--resume"])
    printed = capsys.readouterr().out
    assert "complete" in printed and "parallax" in printed
    with pytest.raises(SystemExit):
        main(["--policies", "nonsense", "--out", str(tmp_path / "x"), "--no-progress"])
    assert "unknown policy" in capsys.readouterr().err


def test_the_report_quotes_the_command_that_reproduces_the_results() -> None:
    from bearing_env.train.compare.cli import reproducing_command

    argv = ["--episodes", "9", "--resume", "--stop-after", "3", "--no-progress", "--out", "o"]
    assert reproducing_command(argv) == "bearing-env compare --episodes 9 --out o"


@needs("train", "matplotlib")
def test_bearing_env_dispatches_compare(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    cli.main(
        [
            "compare",
            "--quick",
            "--episodes",
            "2",
            "--policies",
            "random",
            "greedy",
            "--no-progress",
            "--bootstrap",
            "50",
        ]
    )
    out = tmp_path / "outputs" / "compare_quick"
    assert (out / "report.md").exists() and (out / "area_vs_moves.png").exists()
    config = json.loads((out / "config.json").read_text())
    assert config["env_kwargs"] == {"scenario": "khepera", "max_moves": 10}
    assert "Median total area" in capsys.readouterr().out
    # --quick starts afresh each time (make demo reruns it).
    cli.main(
        [
            "compare",
            "--quick",
            "--episodes",
            "2",
            "--policies",
            "random",
            "--no-progress",
            "--no-plots",
            "--bootstrap",
            "50",
        ]
    )
    assert list(json.loads((out / "config.json").read_text())["policies"]) == ["random_polygonal"]


def test_atomic_outputs_leave_no_partial_files(tmp_path: Path) -> None:
    from bearing_env.train.common.files import atomic_write_text

    target = tmp_path / "deep" / "file.json"
    atomic_write_text(target, "{}\n")
    atomic_write_text(target, '{"a": 1}\n')
    assert target.read_text() == '{"a": 1}\n'
    assert os.listdir(target.parent) == ["file.json"]


@pytest.mark.slow
def test_ctrl_c_then_resume_reproduces_the_uninterrupted_run(tmp_path: Path) -> None:
    """A real SIGINT to a parallel run: finished episodes survive, --resume finishes."""
    import signal
    import subprocess
    import sys
    import time

    args = [
        "--policies", "random", "greedy", "--env-kwargs", "scenario=khepera", "max_moves=5",
        "--episodes", "16", "--workers", "2", "--no-progress", "--no-plots",
        "--bootstrap", "100",
    ]  # fmt: skip
    root = Path(__file__).resolve().parents[2]

    def command(out: Path, *extra: str) -> list[str]:
        module = "bearing_env.train.compare.cli"
        return [sys.executable, "-m", module, *args, "--out", str(out), *extra]

    interrupted = tmp_path / "interrupted"
    process = subprocess.Popen(
        command(interrupted),
        cwd=root,
        start_new_session=True,  # its own process group, like a terminal's Ctrl-C
        # A shell's background jobs ignore SIGINT; a terminal's foreground job does not.
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    log = interrupted / LOG_NAME
    deadline = time.monotonic() + 60
    while not (log.exists() and len(log.read_text().splitlines()) >= 6):
        assert time.monotonic() < deadline and process.poll() is None
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130, stderr
    assert "--resume" in stderr
    finished = len(EpisodeLog(log).load())
    assert 6 <= finished < 32
    subprocess.run(command(interrupted, "--resume"), cwd=root, check=True, capture_output=True)
    subprocess.run(command(tmp_path / "whole"), cwd=root, check=True, capture_output=True)
    assert (interrupted / "summary.json").read_text() == (
        tmp_path / "whole" / "summary.json"
    ).read_text()


#: A label that hand-written CSV quoting corrupts: a quote, a comma, a quoted comma.
AWKWARD_LABEL = 'say "hi", x'


def read_csv(path: Path) -> list[list[str]]:
    with open(path, encoding="utf-8", newline="") as handle:
        return list(csv.reader(handle))


def test_csv_text_round_trips_quotes_commas_and_line_breaks() -> None:
    cells = [AWKWARD_LABEL, '"quoted"', "a,b", "two\nlines", "", None, 0.1, 3, True]
    text = csv_text(["h1", "h,2", 'h"3', "h4", "h5", "h6", "h7", "h8", "h9"], [cells])
    header, row = list(csv.reader(text.splitlines(keepends=True)))
    assert header == ["h1", "h,2", 'h"3', "h4", "h5", "h6", "h7", "h8", "h9"]
    assert row == [AWKWARD_LABEL, '"quoted"', "a,b", "two\nlines", "", "", "0.1", "3", "True"]


def test_compare_csv_files_round_trip_an_awkward_label(tmp_path: Path) -> None:
    """Through the real writer: a run whose policy label holds quotes and commas writes
    summary.csv and episodes.csv that read back, cell for cell, with the stdlib reader."""
    config = small_config(episodes=2, policies={AWKWARD_LABEL: "random", "plain": "greedy"})
    run(config, tmp_path)
    summary = read_csv(tmp_path / "summary.csv")
    width = len(summary[0])
    assert all(len(row) == width for row in summary)
    assert [row[:2] for row in summary[1:]] == [[AWKWARD_LABEL, "random"], ["plain", "greedy"]]
    episodes = read_csv(tmp_path / "episodes.csv")
    width = len(episodes[0])
    assert all(len(row) == width for row in episodes)
    assert [row[0] for row in episodes[1:]] == [AWKWARD_LABEL] * 2 + ["plain"] * 2
    assert [int(row[1]) for row in episodes[1:]] == config.seeds * 2
    logged = json.loads((tmp_path / "summary.json").read_text(encoding="utf-8"))
    assert float(summary[1][3]) == logged["policies"][AWKWARD_LABEL]["area_after"]["1"]["median"]


def test_worst_share_mean_is_the_mean_of_the_largest_values() -> None:
    values = np.arange(1.0, 41.0)  # 40 episodes: the worst 5% are the 2 largest
    assert worst_share_mean(values) == pytest.approx((39.0 + 40.0) / 2)
    assert worst_share_mean(np.array([3.0, 1.0, 2.0])) == 3.0  # at least one episode
    assert worst_share_mean(values, share=0.5) == pytest.approx(np.arange(21.0, 41.0).mean())
    assert np.isnan(worst_share_mean(np.array([])))


@given(
    arrays(
        np.float64,
        st.integers(1, 60),
        elements=st.floats(0.0, 1e3, allow_nan=False, allow_infinity=False),
    )
)
@settings(max_examples=60, deadline=None)
def test_the_worst_case_figures_bound_the_median(values: np.ndarray) -> None:
    assert np.median(values) <= np.percentile(values, 90) + 1e-9
    assert np.percentile(values, 90) <= worst_share_mean(values) + 1e-9
    assert worst_share_mean(values) <= values.max() + 1e-9


def test_the_report_gives_the_worst_case_from_the_logged_episodes(tmp_path: Path) -> None:
    config = small_config(episodes=6, env_kwargs={"scenario": "khepera", "max_moves": 10})
    run(config, tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text())
    records = EpisodeLog(tmp_path / LOG_NAME).load()
    for label, stats in summary["policies"].items():
        # An episode that ended early keeps its last area (as the statistics carry it).
        finals = np.array(
            [r["area"][min(10, len(r["area"]) - 1)] for r in records if r["policy"] == label]
        )
        entry = stats["area_after"]["10"]
        assert entry["p90"] == pytest.approx(np.percentile(finals, 90))
        assert entry["worst5_mean"] == pytest.approx(finals.max())  # 6 episodes: the worst one
    header, rows = area_tail_rows(summary, config)
    assert header == ["policy", "median, 10", "90th pct, 10", "worst 5% mean, 10"]
    assert [row[0] for row in rows] == list(summary["policies"])
    report = (tmp_path / "report.md").read_text()
    assert "mean of the worst 5%" in report and "90th pct, 10" in report
    assert "area10_p90" in (tmp_path / "summary.csv").read_text().splitlines()[0]


ROOM = "bearing_env:BearingSLAM-FurnishedRoom-v1"


@pytest.mark.parametrize(
    ("env", "arguments", "expected", "scenario"),
    [
        (ROOM, [], {}, "furnished_room"),
        ("bearing_env:BearingSLAM-Khepera-Camera180-v1", [], {}, "khepera"),
        ("bearing_env:BearingSLAM-v1", [], {"scenario": "khepera"}, "khepera"),
        (ROOM, ["--env-kwargs", "max_moves=5"], {"max_moves": 5}, "furnished_room"),
    ],
)
def test_a_task_id_keeps_its_own_arena(
    env: str, arguments: list[str], expected: dict[str, Any], scenario: str
) -> None:
    """The Khepera default of the base ids must not replace a task's own scenario."""
    import gymnasium as gym

    from bearing_env.train.compare.cli import build_parser, config_from_args

    args = build_parser().parse_args(["--env", env, "--policies", "random", *arguments])
    config, _ = config_from_args(args)
    assert config.env_kwargs == expected
    made = gym.make(config.env_id, **config.env_kwargs)
    assert made.unwrapped.config.scenario == scenario
    made.close()


def test_worker_processes_release_the_native_objects_they_cache(tmp_path: Path) -> None:
    """Workers keep an env and policies per comparison; they close them at exit, so the
    native core's objects are freed before the interpreter ends (nanobind would otherwise
    report leaked instances on stderr)."""
    import subprocess
    import sys

    result = subprocess.run(
        [sys.executable, "-m", "bearing_env.train.compare.cli", "--policies", "random",
         "greedy", "--env-kwargs", "scenario=khepera", "max_moves=3", "--episodes", "2",
         "--workers", "2", "--no-progress", "--no-plots", "--bootstrap", "10",
         "--out", str(tmp_path / "out")],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "leaked" not in result.stderr, result.stderr
