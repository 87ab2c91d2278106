"""benchmarks/bench_env.py and ``bearing-env bench``: quick runs write complete JSON and print
the table. Nothing here asserts on speed."""

from __future__ import annotations

import json
import math
import os
import sys
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

from bearing_env.benchmarks import bench_env, bench_readings, bench_report, bench_timing
from bearing_env.train import cli
from tests.extras import needs

MACHINE_KEYS = {"platform", "cpu_count", "numpy", "python", "gymnasium"}
FIGURE_KEYS = {
    "steps",
    "seconds",
    "steps_per_s",
    "cartpole_reference",
    "cartpole_steps_per_s",
    "ratio_to_cartpole",
    "ratio_to_cartpole_start",
}


def positive_finite(value: Any) -> bool:
    return isinstance(value, (int, float)) and math.isfinite(value) and value > 0


def run_quick(tmp_path: Path, *arguments: str) -> tuple[dict[str, Any], Path]:
    path = tmp_path / "results" / "bench.json"  # the folder does not exist yet
    bench_env.main(["--quick", "--json", str(path), *arguments])
    return json.loads(path.read_text()), path


def check_common(results: dict[str, Any], sections: set[str]) -> None:
    assert results["format"] == bench_report.JSON_FORMAT
    assert MACHINE_KEYS <= results["machine"].keys()
    assert results["machine"]["cpu_count"] >= 1
    assert set(results["settings"]["sections"]) == sections
    references = results["cartpole_references"]
    labels = [ref["label"] for ref in references]
    assert labels[0] == "start" and labels[-1] == "end"
    assert all(positive_finite(ref["steps_per_s"]) for ref in references)
    assert {section for section in bench_timing.SECTIONS if section in results} == sections
    targets = {target["id"]: target for target in results["targets"]}
    assert set(targets) == set(bench_report.TARGETS)
    for target in targets.values():
        assert target["met"] in (True, False, None)
        assert (target["met"] is None) == (target["value"] is None)


def check_figure(figure: dict[str, Any], labels: set[str]) -> None:
    assert FIGURE_KEYS <= figure.keys()
    assert figure["steps"] > 0
    for key in ("seconds", "steps_per_s", "ratio_to_cartpole", "ratio_to_cartpole_start"):
        assert positive_finite(figure[key]), (key, figure[key])
    assert figure["cartpole_reference"] in labels


def test_quick_single_and_vector(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    results, path = run_quick(tmp_path, "--sections", "single,vector")
    check_common(results, {"single", "vector"})
    labels = {ref["label"] for ref in results["cartpole_references"]}

    single = {row["name"]: row for row in results["single"]}
    assert set(single) == {
        "khepera",
        "random_4",
        "random_16",
        "random_64",
        "khepera_wrapped",
        "khepera_no_robot_map",
        "furnished_room",
        "furnished_room_empty",
        "khepera_camera90",
    }
    assert single["khepera_no_robot_map"]["env_kwargs"]["robot_map_info"] is False
    assert positive_finite(single["furnished_room"]["step_cost_ratio"])
    assert single["furnished_room_empty"]["step_cost_ratio"] is None
    for row in single.values():
        check_figure(row, labels)
    assert single["random_4"]["ratio_to_4_landmarks"] == pytest.approx(1.0)
    assert positive_finite(single["random_64"]["ratio_to_4_landmarks"])

    vector = results["vector"]
    assert {(row["kind"], row["num_envs"]) for row in vector} == {
        (kind, n) for kind in ("batched", "batched_no_robot_map", "sync") for n in (1, 4)
    }
    for row in vector:
        check_figure(row, labels)
        assert row["step_calls"] >= 2
        if row["kind"] != "sync":
            assert positive_finite(row["ratio_to_sync"])
            assert row["vectorization_mode"] == "vector_entry_point"
        has_map = row["kind"] != "batched_no_robot_map"
        assert row["env_kwargs"].get("robot_map_info", True) == has_map
    targets = {target["id"]: target for target in results["targets"]}
    # The batched env always exists: no row or target says what it fell back to.
    for row in [*vector, *results["single"], *results["targets"]]:
        assert "fallback" not in row and "measured_with" not in row
    assert targets["a"]["met"] is not None and targets["c"]["met"] is not None
    assert targets["b"]["met"] is None  # --quick measures 1 and 4 envs, not 64
    assert targets["d"]["met"] is None

    assert {row["actions"] for row in results["single"]} == {"sampled ahead"}
    out = capsys.readouterr().out
    assert "CartPole-v1" in out and "khepera, 4 landmarks" in out and "Targets:" in out
    assert "single: seeded random actions sampled ahead of the timed loop" in out
    assert str(path) in out
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temp file left


class CountingEnv(gym.Env[Any, Any]):
    """Steps instantly; records each action and how many draws the bench's generator had
    made when it came."""

    action_space = gym.spaces.Box(-1.0, 1.0, (2,), dtype=np.float32)
    observation_space = gym.spaces.Box(-1.0, 1.0, (1,), dtype=np.float32)

    def __init__(self, draws: list[int]) -> None:
        self.draws, self.seen, self.actions = draws, [], []

    def reset(self, *, seed: int | None = None, options: Any = None) -> tuple[Any, dict]:
        return np.zeros(1, np.float32), {}

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict]:
        self.seen.append(len(self.draws))
        self.actions.append(np.array(action))
        return np.zeros(1, np.float32), 0.0, len(self.actions) % 97 == 0, False, {}


def test_single_env_actions_are_sampled_ahead_of_the_timed_loop(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    draws: list[int] = []
    real_rng = np.random.default_rng

    class Counting:
        def __init__(self, seed: int) -> None:
            self.rng = real_rng(seed)

        def uniform(self, *args: Any, **kwargs: Any) -> Any:
            draws.append(1)
            return self.rng.uniform(*args, **kwargs)

    monkeypatch.setattr(bench_timing.np.random, "default_rng", Counting)
    env = CountingEnv(draws)
    block = bench_timing.SINGLE_ACTION_BLOCK
    steps, _, resets = bench_timing.run_single_env(env, 0.0, min_steps=2 * block + 10)
    assert steps == 2 * block + 10 and resets == steps // 97
    assert set(env.seen) == {1}  # one draw, before the first (warm-up) step
    timed = np.array(env.actions[1:])  # after the warm-up step
    np.testing.assert_array_equal(timed[:block], timed[block : 2 * block])
    expected = real_rng(0).uniform(-1.0, 1.0, (block, 2)).astype(np.float32)
    np.testing.assert_array_equal(timed[:block], expected)


@needs("train", "stable_baselines3", "torch")
def test_quick_ppo_in_process_kinds(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    results, _ = run_quick(tmp_path, "--sections", "ppo", "--ppo-kinds", "batched,dummy")
    check_common(results, {"ppo"})
    labels = {ref["label"] for ref in results["cartpole_references"]}
    assert {"ppo/batched", "ppo/dummy"} <= labels
    rows = {row["kind"]: row for row in results["ppo"]}
    assert set(rows) == {"batched", "dummy"}
    for row in rows.values():
        check_figure(row, labels)
        assert row["n_envs"] == 2
        assert row["steps"] >= row["requested_steps"]
        assert row["steps"] % row["rollout_steps"] == 0
        assert row["ratio_to_subproc"] is None
        assert row["hyperparams"]["n_steps"] == 8
    assert "PPO" in capsys.readouterr().out


@needs("train", "stable_baselines3", "torch")
def test_quick_ppo_subproc(tmp_path: Path) -> None:
    results, _ = run_quick(
        tmp_path, "--sections", "ppo", "--ppo-kinds", "subproc", "--ppo-envs", "1"
    )
    (row,) = results["ppo"]
    assert row["kind"] == "subproc" and "fallback" not in row
    check_figure(row, {ref["label"] for ref in results["cartpole_references"]})
    assert row["ratio_to_subproc"] == pytest.approx(1.0)


def stand_in_vector_env(num_envs: int, **env_kwargs: Any) -> Any:
    """A vector entry point for the test (SAME_STEP autoreset, unlike the default)."""
    factories = [lambda: gym.make(bench_timing.ENV_ID, **env_kwargs)] * num_envs
    return gym.vector.SyncVectorEnv(factories, autoreset_mode=AutoresetMode.SAME_STEP)


def test_batched_rows_in_same_step_mode_count_every_sub_step(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The vector rows count transitions by the env's autoreset mode."""
    monkeypatch.setattr(gym.spec(bench_timing.ENV_ID), "vector_entry_point", stand_in_vector_env)
    results, _ = run_quick(tmp_path, "--sections", "vector", "--num-envs", "2")
    (batched, batched_no_map, sync) = results["vector"]
    assert batched["kind"] == "batched" and batched["vectorization_mode"] == "vector_entry_point"
    assert batched_no_map["kind"] == "batched_no_robot_map"
    for row in (batched, batched_no_map):
        assert row["autoreset_mode"] == "SameStep"
        assert row["steps"] == 2 * row["step_calls"]  # SAME_STEP: every sub-step counts
    assert sync["autoreset_mode"] == "NextStep"


def fake_figure(rate: float, **extra: Any) -> dict[str, Any]:
    return {"steps_per_s": rate, "ratio_to_cartpole": rate / 1000.0, **extra}


def test_the_targets_are_the_current_ones() -> None:
    thresholds = bench_report.TARGET_THRESHOLDS
    assert thresholds == pytest.approx(
        {
            "a": 0.20,
            "b": 0.50,
            "i": 0.60,
            "c": 1 / 16,
            "e": 0.60,
            "f": 1.5,
            "g": 0.5e-3,
            "h": 0.7,
            "d": 2.0,
        }
    )
    assert set(bench_report.TARGETS) == set(thresholds)  # no compile-time target (j)
    assert bench_report.UPPER_BOUND_TARGETS == {"f", "g"}
    for key, threshold in [("a", "20%"), ("e", "60%"), ("h", "0.7x"), ("f", "1.5x")]:
        assert threshold in bench_report.TARGETS[key]
    assert "BearingSLAM-Khepera-v1" in bench_report.TARGETS["f"]
    assert "compil" not in " ".join(bench_report.TARGETS.values())


def test_targets_from_results() -> None:
    # Each value lies between a target's old threshold and its current one.
    results = {
        "single": [
            fake_figure(180.0, name="khepera"),  # 18%: the 15% target was met, 20% is not
            fake_figure(400.0, name="random_4"),
            fake_figure(20.0, name="random_64"),
        ],
        "vector": [
            fake_figure(1500.0, kind="batched", num_envs=64),
            fake_figure(550.0, kind="batched", num_envs=256),
        ],
        "slam": [
            fake_figure(450.0, readings="khepera", transfer="conservative", n_landmarks=4),
            fake_figure(900.0, readings="khepera", transfer="paper", n_landmarks=4),
            fake_figure(700.0, readings="synthetic_4", transfer="conservative", n_landmarks=4),
        ],
        "startup": {"ratio_to_cartpole": 1.4},
        "planning": {"median_s": 0.4e-3},
        "ppo": [fake_figure(300.0, kind="batched"), fake_figure(100.0, kind="subproc")],
        "throughput": {"ppo": {"ratio_to_cartpole_ppo": 0.6}},
    }
    targets = {target["id"]: target for target in bench_report.evaluate_targets(results)}
    assert targets["a"]["met"] is False and targets["a"]["value"] == pytest.approx(0.18)
    assert targets["b"]["met"] is True and targets["b"]["note"] is None
    assert targets["i"]["met"] is False and targets["i"]["value"] == pytest.approx(0.55)
    assert targets["c"]["met"] is False and targets["c"]["value"] == pytest.approx(0.05)
    assert targets["d"]["met"] is True and targets["d"]["value"] == pytest.approx(3.0)
    # the conservative row on recorded Khepera-v1 readings, not the paper one (90%) nor
    # the synthetic one (70%)
    assert targets["e"]["met"] is False and targets["e"]["value"] == pytest.approx(0.45)
    assert targets["f"]["met"] is True and targets["f"]["value"] == 1.4
    assert targets["g"]["met"] is True
    assert targets["h"]["met"] is False and targets["h"]["value"] == 0.6
    results["startup"] = {"ratio_to_cartpole": 1.6}
    results["single"][0] = fake_figure(210.0, name="khepera")
    targets = {target["id"]: target for target in bench_report.evaluate_targets(results)}
    assert targets["f"]["met"] is False and targets["a"]["met"] is True
    assert all(target["met"] is None for target in bench_report.evaluate_targets({}))


def test_write_json_is_atomic_and_finite(tmp_path: Path) -> None:
    path = tmp_path / "a" / "b.json"
    bench_report.write_json(path, {"x": float("nan"), "y": [1.5, float("inf")]})
    assert json.loads(path.read_text()) == {"x": None, "y": [1.5, None]}
    bench_report.write_json(path, {"x": 2})
    assert json.loads(path.read_text()) == {"x": 2}
    assert [p.name for p in path.parent.iterdir()] == ["b.json"]


def test_bad_arguments_are_rejected() -> None:
    for arguments in (["--sections", "fast"], ["--num-envs", "0"], ["--ppo-kinds", "async"]):
        with pytest.raises(SystemExit):
            bench_env.main([*arguments, "--no-json"])


def test_profile_prints_the_top_functions(capsys: pytest.CaptureFixture[str]) -> None:
    assert bench_env.main(["--profile", "single", "--seconds", "0.05"]) is None
    out = capsys.readouterr().out
    assert "tottime" in out and "step" in out


def test_cli_bench_runs_bench_env(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(sys, "argv", ["bearing-env"])  # cli.main rewrites sys.argv
    assert cli.SUBCOMMANDS["bench"][0] == "bearing_env.benchmarks.bench_env"
    path = tmp_path / "cli.json"
    cli.main(["bench", "--quick", "--sections", "single", "--landmarks", "4", "--json", str(path)])
    results = json.loads(path.read_text())
    assert [row["name"] for row in results["single"]] == [
        "khepera",
        "random_4",
        "khepera_wrapped",
        "khepera_no_robot_map",
        "furnished_room",
        "furnished_room_empty",
        "khepera_camera90",
    ]
    out = capsys.readouterr().out
    assert "Targets:" in out and "furnished room, 4 obstacles" in out


@pytest.mark.parametrize("argv", [["bench", "--slam"], ["bench-slam"]])
def test_cli_reaches_the_world_model_bench(
    argv: list[str], monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(sys, "argv", ["bearing-env"])
    cli.main([*argv, "--seconds", "0.01"])
    out = capsys.readouterr().out
    assert "update()" in out and "CartPole-v1" in out


@needs("train", "stable_baselines3", "torch")
def test_ppo_rounds_are_interleaved_and_the_median_counts(tmp_path: Path) -> None:
    results, _ = run_quick(
        tmp_path, "--sections", "ppo", "--ppo-kinds", "batched,dummy", "--ppo-rounds", "3"
    )
    assert results["settings"]["ppo_rounds"] == 3
    labels = [ref["label"] for ref in results["cartpole_references"]]
    assert {"ppo/round 2", "ppo/round 3"} <= set(labels)
    for row in results["ppo"]:
        rounds = row["rounds"]
        assert len(rounds) == 3
        assert row["steps"] == sum(figure["steps"] for figure in rounds)
        rates = sorted(figure["steps_per_s"] for figure in rounds)
        assert row["steps_per_s"] == pytest.approx(rates[1])


def test_quick_slam(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    results, _ = run_quick(tmp_path, "--sections", "slam")
    check_common(results, {"slam"})
    rows = results["slam"]
    transfers = ("conservative", "paper")
    # The recorded readings first, then the synthetic ones (secondary).
    assert [(row["readings"], row["transfer"]) for row in rows] == [
        *((readings, t) for t in transfers for readings in ("khepera", "random8")),
        *((readings, t) for t in transfers for readings in ("synthetic_4", "synthetic_64")),
    ]
    assert [row["primary"] for row in rows] == [True] * 4 + [False] * 4
    assert {row["env_id"] for row in rows[:4]} == set(bench_readings.RECORDED_TASKS)
    assert [row["n_landmarks"] for row in rows[:2]] == [4, 8]
    assert {row["label"] for row in rows[4:]} == {bench_readings.SYNTHETIC_LABEL}
    for row in rows:
        assert row["runs"] == bench_timing.SLAM_RUNS == len(row["run_steps_per_s"])
        for name in ("steps_per_s", "ratio_to_cartpole"):
            low, median, high = (row[f"{name}{end}"] for end in ("_min", "", "_max"))
            assert positive_finite(low) and low <= median <= high
        assert row["cartpole_reference"] == "slam"
    assert "slam" in {ref["label"] for ref in results["cartpole_references"]}
    targets = {target["id"]: target for target in results["targets"]}
    assert targets["e"]["value"] == rows[0]["ratio_to_cartpole"]  # Khepera-v1, conservative
    out = capsys.readouterr().out
    lines = [line for line in out.splitlines() if line.startswith("slam ")]
    assert "update(), conservative, Khepera-v1 readings, 4 landmarks" in lines[0]
    assert "Random8-v1 readings, 8 landmarks" in lines[1]
    assert all("[secondary]" in line and "synthetic readings" in line for line in lines[4:])
    assert not any("[secondary]" in line for line in lines[:4])
    assert "5 runs:" in lines[0] and "actions sampled ahead" not in out


def test_an_older_results_files_update_rows_do_not_stand_for_the_recorded_readings() -> None:
    results = {"format": 3, "slam": [fake_figure(500.0, transfer="conservative", n_landmarks=4)]}
    (target,) = [t for t in bench_report.evaluate_targets(results) if t["id"] == "e"]
    assert target["met"] is None and "synthetic readings" in target["note"]
    old_row = {**results["slam"][0], "cartpole_reference": "slam", "ratio_to_cartpole_start": 0.5}
    (row,) = bench_report.table_rows({**results, "slam": [old_row]})
    assert row[1] == "update(), conservative, 4 landmarks" and row[-1] == ""


STARTUP_KEYS = {
    "env_id",
    "runs",
    "bearing_env_runs_s",
    "cartpole_runs_s",
    "bearing_env_median_s",
    "cartpole_median_s",
    "ratio_to_cartpole",
    "cold_bearing_env_s",
    "numba_imported",
}


def check_startup(results: dict[str, Any], runs: int) -> dict[str, Any]:
    """The startup section's figures and the target read from them (f)."""
    check_common(results, {"startup"})
    startup: dict[str, Any] = results["startup"]
    assert set(startup) == STARTUP_KEYS
    assert startup["env_id"] == "BearingSLAM-Khepera-v1"
    assert startup["runs"] == runs
    assert len(startup["bearing_env_runs_s"]) == len(startup["cartpole_runs_s"]) == runs
    for key in ("bearing_env", "cartpole"):
        assert startup[f"{key}_median_s"] == pytest.approx(
            float(np.median(startup[f"{key}_runs_s"]))
        )
    assert startup["ratio_to_cartpole"] == pytest.approx(
        startup["bearing_env_median_s"] / startup["cartpole_median_s"]
    )
    target = {target["id"]: target for target in results["targets"]}["f"]
    assert target["value"] == startup["ratio_to_cartpole"]
    assert target["met"] == (startup["ratio_to_cartpole"] <= 1.5)
    return startup


def test_quick_startup_times_whole_processes_alternately_after_an_untimed_pair(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # The fresh processes are replaced (the test below runs real ones): what is checked is
    # which script runs when, in which environment, and where each figure goes.
    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")
    monkeypatch.setattr(bench_timing, "STARTUP_RUNS", 3)
    monkeypatch.setattr(bench_timing, "QUICK_STARTUP_RUNS", 3)
    monkeypatch.setattr(bench_env, "QUICK_STARTUP_RUNS", 3)
    calls: list[tuple[str, dict[str, str]]] = []
    seconds = iter([0.9, 0.3, 0.5, 0.4, 0.7, 0.2, 0.6, 0.5])
    imported = iter([False, False, False, False, True, False, False, False])
    scripts = {script: name for name, script in bench_timing.STARTUP_SCRIPTS.items()}

    def process_seconds(script: str, environment: dict[str, str]) -> tuple[float, bool]:
        if not calls:  # the first process starts with empty folders
            assert not any(Path(environment["HOME"]).iterdir())
            assert not any(Path(environment["XDG_CACHE_HOME"]).iterdir())
        calls.append((scripts[script], environment))
        return next(seconds), next(imported)

    monkeypatch.setattr(bench_timing, "process_seconds", process_seconds)
    startup = check_startup(run_quick(tmp_path, "--sections", "startup")[0], 3)
    assert [name for name, _ in calls] == ["bearing_env", "cartpole"] * 4
    for _, environment in calls:
        assert "PYTHONDONTWRITEBYTECODE" not in environment
        assert environment["HOME"] == calls[0][1]["HOME"] != environment["XDG_CACHE_HOME"]
        assert environment["XDG_CACHE_HOME"] == calls[0][1]["XDG_CACHE_HOME"]
        assert environment["PATH"] == os.environ["PATH"]
    assert not Path(calls[0][1]["HOME"]).exists()  # temporary folders, removed after
    assert startup == {
        "env_id": "BearingSLAM-Khepera-v1",
        "runs": 3,
        "bearing_env_runs_s": [0.5, 0.7, 0.6],  # the untimed pair's 0.9 and 0.3 left out
        "cartpole_runs_s": [0.4, 0.2, 0.5],
        "bearing_env_median_s": 0.6,
        "cartpole_median_s": 0.4,
        "ratio_to_cartpole": pytest.approx(1.5),
        "cold_bearing_env_s": 0.9,
        "numba_imported": True,  # one run of the three imported it
    }
    out = capsys.readouterr().out
    assert "fresh process" in out and "1.50x CartPole-v1" in out and "0.90 s" in out
    assert "numba imported: yes" in out and "compil" not in out


def test_startup_scripts_make_and_step_the_env_and_report_numba() -> None:
    bearing, cartpole = (bench_timing.STARTUP_SCRIPTS[k] for k in ("bearing_env", "cartpole"))
    assert 'gym.make("BearingSLAM-Khepera-v1")' in bearing and "import bearing_env" in bearing
    assert 'gym.make("CartPole-v1")' in cartpole and "bearing_env" not in cartpole
    for script in (bearing, cartpole):
        assert "env.reset(seed=0)" in script and "env.step(" in script
        assert script.rstrip().endswith('print("numba" in sys.modules)')


def test_startup_children_get_their_folders_and_write_bytecode(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PYTHONDONTWRITEBYTECODE", "1")
    environment = bench_timing.startup_environment(str(tmp_path), str(tmp_path / "cache"))
    script = (
        "import os, sys\n"
        "print(os.getcwd() == os.environ['HOME'] and not sys.flags.dont_write_bytecode\n"
        "      and os.environ['XDG_CACHE_HOME'].endswith('cache'))\n"
    )
    elapsed, answer = bench_timing.process_seconds(script, environment)
    assert answer is True and 0 < elapsed < 60
    with pytest.raises(RuntimeError, match="status 3"):
        bench_timing.process_seconds("raise SystemExit(3)", environment)
    with pytest.raises(RuntimeError, match="status 0"):
        bench_timing.process_seconds("print('maybe')", environment)


def test_quick_startup_runs_real_processes_without_numba(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    startup = check_startup(run_quick(tmp_path, "--sections", "startup")[0], 1)
    assert startup["numba_imported"] is False
    for value in (
        startup["cold_bearing_env_s"],
        *startup["bearing_env_runs_s"],
        *startup["cartpole_runs_s"],
    ):
        assert 0 < value < 120
    out = capsys.readouterr().out
    assert "numba imported: no" in out and "x CartPole-v1" in out


def test_quick_planning(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    results, _ = run_quick(tmp_path, "--sections", "planning")
    check_common(results, {"planning"})
    planning = results["planning"]
    assert planning["moves"] == 2 * 20  # two timed Khepera episodes of 20 moves
    assert 0 < planning["median_s"] <= planning["p90_s"]
    target = {t["id"]: t for t in results["targets"]}["g"]
    assert target["value"] == planning["median_s"]
    assert target["met"] == (planning["median_s"] <= 0.5e-3)
    assert "GreedyOneStep.act" in capsys.readouterr().out


def test_bench_slam_warms_everything_it_times_before_timing(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # Its first row used to read "0.0% of CartPole" (the first update() compiled its
    # kernels inside the timed window) and the next "172.96 x the 4-landmark rate".
    from bearing_env.benchmarks import bench_slam

    events: list[str] = []
    updates: list[tuple[str, int]] = []
    real_update = bench_slam.PolygonSLAM.update

    def update(self: Any, *args: Any, **kwargs: Any) -> Any:
        updates.append((self.transfer, self.n_landmarks))
        return real_update(self, *args, **kwargs)

    real_warm_up, real_cartpole = bench_slam.warm_up, bench_slam.cartpole_steps_per_second
    real_rate = bench_slam.updates_per_second
    monkeypatch.setattr(bench_slam.PolygonSLAM, "update", update)
    monkeypatch.setattr(
        bench_slam, "warm_up", lambda *a: (events.append("warm_up"), real_warm_up(*a))[1]
    )
    monkeypatch.setattr(
        bench_slam,
        "cartpole_steps_per_second",
        lambda s: (events.append("cartpole"), real_cartpole(s))[1],
    )
    monkeypatch.setattr(
        bench_slam,
        "updates_per_second",
        lambda w, t, s: (events.append(f"{t} {w.key}"), real_rate(w, t, s))[1],
    )
    bench_slam.main(["--seconds", "0.02", "--runs", "2"])
    assert events[0] == "warm_up"
    keys = ["khepera", "random8", *(f"synthetic_{n}" for n in bench_slam.LANDMARK_COUNTS)]
    transfers = bench_slam.MEASURED_TRANSFERS
    one_run = [
        "cartpole",
        *(f"{t} {key}" for t in transfers for key in keys[:2]),
        *(f"{t} {key}" for t in transfers for key in keys[2:]),
    ]
    assert events[1:] == one_run * 2  # each run: CartPole-v1, then every figure once
    # The warm-up's untimed pass updated every measured map before anything was timed.
    counts = [4, 8, *bench_slam.LANDMARK_COUNTS]
    measured = {(t, n) for t in transfers for n in counts}
    per_transfer = sum(workload.movements for workload in bench_slam.workloads())
    warm_up_updates = updates[: len(transfers) * per_transfer]
    assert set(warm_up_updates) == measured
    out = capsys.readouterr().out
    assert "update()" in out and "median of 2 runs" in out


def test_targets_print_in_their_own_units() -> None:
    results = {
        "vector": [fake_figure(550.0, kind="batched", num_envs=256)],
        "startup": {"ratio_to_cartpole": 1.625},
        "planning": {"median_s": 0.45e-3},
    }
    shown = {
        target["id"]: bench_report.format_target(target)
        for target in bench_report.evaluate_targets(results)
    }
    assert set(shown) == set(bench_report.TARGETS)
    assert "55.00% (need 60%) -> NOT MET" in shown["i"]
    assert "1.62x (need <= 1.5x) -> NOT MET" in shown["f"]
    assert "0.450 ms (need <= 0.5 ms) -> MET" in shown["g"]


def new_startup(ratio: float = 1.25, numba: bool = False) -> dict[str, Any]:
    return {
        "env_id": "BearingSLAM-Khepera-v1",
        "runs": 3,
        "bearing_env_runs_s": [0.5, 0.6, 0.4],
        "cartpole_runs_s": [0.4, 0.3, 0.5],
        "bearing_env_median_s": 0.5,
        "cartpole_median_s": 0.4,
        "ratio_to_cartpole": ratio,
        "cold_bearing_env_s": 0.75,
        "numba_imported": numba,
    }


def test_the_docs_state_the_startup_ratio_and_numba() -> None:
    results = {"format": bench_report.JSON_FORMAT, "startup": new_startup()}
    text = bench_report.markdown_startup(results)
    assert "fresh process" in text and "`BearingSLAM-Khepera-v1`" in text
    assert "0.50 s, 1.25x CartPole-v1 (0.40 s" in text
    assert "0.50 / 0.60 / 0.40 s; CartPole-v1 0.40 / 0.30 / 0.50 s" in text
    assert "empty HOME and cache folders: 0.75 s" in text
    assert "numba imported: no." in text and "compil" not in text
    results["startup"] = new_startup(numba=True)
    assert "numba imported: **yes**" in bench_report.markdown_startup(results)
    goals = bench_report.markdown_goals(results)
    (row,) = [line for line in goals.splitlines() if "fresh process" in line]
    assert "| 1.25x | ≤ 1.5x | yes |" in row
    assert "empty cache" not in goals  # no compile-time goal (j)


def test_an_older_results_file_says_its_startup_is_an_older_format() -> None:
    # Formats 1 and 2 (benchmarks/results/bench_env.json until it is measured again)
    # timed the first step alone, in seconds.
    results = {
        "format": 2,
        "startup": {
            "cold_first_step_s": 0.53,
            "warm_first_step_s": 0.47,
            "warm_runs_s": [0.42, 0.6, 0.47],
        },
    }
    (target,) = [t for t in bench_report.evaluate_targets(results) if t["id"] == "f"]
    assert target["value"] is None and target["met"] is None
    assert "older results file (format 2)" in target["note"]
    text = bench_report.markdown_startup(results)
    assert "older results file (format 2)" in text and "0.47 s" in text
    assert "older results file (format 2)" in bench_report.format_table(
        {**results, "cartpole_references": [], "settings": {"seconds": 2}, "targets": [target]}
    )
    goals = bench_report.markdown_goals(results)
    assert "- (older results file (format 2)" in goals
    assert "older results file" not in bench_report.markdown_startup(
        {"format": bench_report.JSON_FORMAT, "startup": new_startup()}
    )
