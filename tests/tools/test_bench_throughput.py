"""``bearing-env bench --sections throughput``: the EnvPool/gymnax-style table of env
steps/s against CartPole-v1 and the PPO pair, at tiny sizes. The structure of the JSON
and the table is checked, never the speed."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import gymnasium as gym
import pytest
from gymnasium.vector import AutoresetMode

from bearing_env.benchmarks import bench_env, bench_report, bench_throughput
from tests.extras import needs
from tests.tools.test_bench import check_common, check_figure

TINY = ["--sections", "throughput", "--seconds", "0.05", "--counts", "1", "4"]
TINY_PPO = ["--ppo-envs", "2", "--ppo-steps", "16", "--ppo-rounds", "2"]
TINY_HYPERPARAMS = ["--ppo-hyperparams", "n_steps=8", "n_epochs=1", "batch_size=16"]


def run_tiny(tmp_path: Path, *arguments: str) -> dict[str, Any]:
    path = tmp_path / "throughput.json"
    bench_env.main([*TINY, "--json", str(path), *arguments])
    results: dict[str, Any] = json.loads(path.read_text())
    return results


def check_env_steps(results: dict[str, Any]) -> None:
    section = results["throughput"]
    assert results["settings"]["counts"] == section["counts"] == [1, 4]
    assert section["cartpole_vectorization_mode"] == "vector_entry_point"  # gymnasium 1.x
    labels = {ref["label"] for ref in results["cartpole_references"]}
    assert "throughput" in labels
    assert [row["num_envs"] for row in section["env_steps"]] == [1, 4]
    for row in section["env_steps"]:
        for name in ("cartpole", "bearing_slam"):
            figure = row[name]
            check_figure(figure, labels)
            assert figure["vectorization_mode"] == "vector_entry_point"
            assert figure["autoreset_mode"] == "NextStep"
            assert figure["step_calls"] >= 2
            # Reset-only sub-steps are timed but not counted.
            assert figure["steps"] <= row["num_envs"] * figure["step_calls"]
        assert row["ratio_to_cartpole_vector"] == pytest.approx(
            row["bearing_slam"]["steps_per_s"] / row["cartpole"]["steps_per_s"]
        )


def test_env_steps_without_sb3(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without stable-baselines3 the table has the env-step rows and says PPO was skipped."""
    monkeypatch.setattr(bench_throughput, "available", lambda *modules: False)
    results = run_tiny(tmp_path)
    check_common(results, {"throughput"})
    check_env_steps(results)
    section = results["throughput"]
    assert section["ppo"] is None and "stable-baselines3" in section["ppo_note"]
    target = {t["id"]: t for t in results["targets"]}["h"]
    assert target["met"] is None and target["value"] is None
    out = capsys.readouterr().out
    lines = out.splitlines()
    header = next(i for i, line in enumerate(lines) if line.startswith("sub-envs"))
    assert all(name in lines[header] for name in bench_report.THROUGHPUT_HEADER)
    assert lines[header + 2].split()[0] == "1" and lines[header + 3].split()[0] == "4"
    assert lines[header + 4] == ""  # no PPO row
    assert section["ppo_note"] in out


@needs("train", "stable_baselines3", "torch")
def test_throughput_with_the_ppo_pair(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    results = run_tiny(tmp_path, *TINY_PPO, *TINY_HYPERPARAMS)
    check_common(results, {"throughput"})
    check_env_steps(results)
    ppo = results["throughput"]["ppo"]
    bearing, cartpole = ppo["bearing_slam"], ppo["cartpole"]
    labels = {ref["label"] for ref in results["cartpole_references"]}
    assert {"ppo/batched", "ppo/CartPole-v1 dummy", "throughput/round 2"} <= labels
    assert (bearing["kind"], bearing["env_id"]) == ("batched", "BearingSLAM-v1")
    assert (cartpole["kind"], cartpole["env_id"]) == ("dummy", "CartPole-v1")
    assert bearing["env_kwargs"] == {"scenario": "khepera"} and cartpole["env_kwargs"] == {}
    for row in (bearing, cartpole):
        check_figure(row, labels)
        assert row["n_envs"] == ppo["n_envs"] == 2
        assert len(row["rounds"]) == 2 and row["normalize"] is True
        assert row["steps"] % row["rollout_steps"] == 0
    # The same hyperparameters on both envs: n_steps, batch_size, n_epochs, policy net.
    assert bearing["hyperparams"] == cartpole["hyperparams"]
    assert (bearing["hyperparams"]["n_steps"], bearing["hyperparams"]["n_epochs"]) == (8, 1)
    ratios = sorted(
        mine["steps_per_s"] / theirs["steps_per_s"]
        for mine, theirs in zip(bearing["rounds"], cartpole["rounds"], strict=True)
    )
    assert ppo["ratio_to_cartpole_ppo"] == pytest.approx(sum(ratios) / 2)  # median of two
    target = {t["id"]: t for t in results["targets"]}["h"]
    assert target["value"] == ppo["ratio_to_cartpole_ppo"]
    assert bench_report.TARGET_THRESHOLDS["h"] == 0.7
    assert target["met"] == (target["value"] >= 0.7)
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.startswith("PPO, 2 envs"))
    assert row.split()[-3:] == [
        f"{cartpole['steps_per_s']:,.0f}",
        f"{bearing['steps_per_s']:,.0f}",
        f"{ppo['ratio_to_cartpole_ppo']:.3f}",
    ]


def test_quick_takes_one_and_four_sub_envs() -> None:
    parser = bench_env.build_parser()
    quick = bench_env.settings_from_args(parser.parse_args(["--quick"]), parser)
    assert quick.counts == bench_throughput.QUICK_THROUGHPUT_COUNTS == (1, 4)
    full = bench_env.settings_from_args(parser.parse_args([]), parser)
    assert full.counts == (1, 64, 256, 1024) and "throughput" in full.sections


def test_presampled_steps_count_transitions_not_reset_sub_steps() -> None:
    venv = gym.make_vec("CartPole-v1", num_envs=4, vectorization_mode="vector_entry_point")
    actions = bench_throughput.presampled_actions(venv, seed=0)
    assert len(actions) == bench_throughput.ACTION_BATCHES and actions[0].shape == (4,)
    venv.reset(seed=0)
    transitions, _, calls = bench_throughput.step_presampled(venv, actions, 0.0, min_calls=60)
    venv.close()
    # Random CartPole episodes end within 60 steps, so some sub-steps were resets.
    assert calls == 60 and 0 < transitions < 4 * 60


def test_presampled_steps_refuse_a_vector_env_without_autoreset() -> None:
    venv = gym.make_vec(
        "CartPole-v1",
        num_envs=2,
        vectorization_mode="sync",
        vector_kwargs={"autoreset_mode": AutoresetMode.DISABLED},
    )
    actions = bench_throughput.presampled_actions(venv, seed=0)
    with pytest.raises(ValueError, match="autoresetting"):
        bench_throughput.step_presampled(venv, actions, 0.0)
    venv.close()


@pytest.mark.parametrize("counts", [["0"], ["4", "x"]])
def test_bad_counts_are_rejected(counts: list[str], capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        bench_env.main(["--sections", "throughput", "--counts", *counts, "--no-json"])
    assert "--counts" in capsys.readouterr().err
