"""``bearing-env soak``: random valid configurations, the guarantee checked at every step."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

from bearing_env.benchmarks import soak


def test_random_configurations_are_valid_and_vary():
    rng = np.random.default_rng(3)
    drawn = [soak.random_configuration(rng) for _ in range(30)]
    assert {env_id for env_id, _ in drawn} == set(soak.IDS)
    assert len({kwargs["scenario"] for _, kwargs in drawn}) >= 2
    for env_id, kwargs in drawn[:6]:
        gym.make(env_id, **kwargs).close()


def test_a_short_soak_counts_steps_and_checks_and_finds_nothing(capsys):
    soak.main(["--steps", "150", "--seed", "4", "--no-progress"])
    out = capsys.readouterr().out
    assert "misses 0, nonfinite 0, exceptions 0" in out
    report = soak.run(150, seed=4, episodes=5)
    assert report.steps >= 150 and report.containment_checks > 0 and report.defects == 0


class LosesTheTruth(gym.Wrapper):
    def step(self, action):
        observation, reward, terminated, truncated, info = self.env.step(action)
        info["landmark_contains_truth"] = np.zeros_like(info["landmark_contains_truth"])
        return observation, reward, terminated, truncated, info


def test_a_robust_soak_draws_the_same_configurations_with_the_robust_fusion(capsys):
    strict_rng, robust_rng = np.random.default_rng(7), np.random.default_rng(7)
    strict = [soak.random_configuration(strict_rng) for _ in range(5)]
    robust = [soak.random_configuration(robust_rng, "robust") for _ in range(5)]
    assert len({str(kwargs) for _, kwargs in strict}) == 5
    for (strict_id, strict_kwargs), (robust_id, robust_kwargs) in zip(strict, robust, strict=True):
        assert robust_id == strict_id and robust_kwargs["fusion"] == "robust"
        assert {**robust_kwargs, "fusion": "intersect"} == strict_kwargs
    report = soak.run(150, seed=4, episodes=5, fusion="robust")
    assert report.steps >= 150 and report.containment_checks > 0 and report.defects == 0
    soak.main(["--steps", "30", "--fusion", "robust", "--no-progress"])
    assert "seed 0, robust: steps" in capsys.readouterr().out


def test_the_soak_counts_misses_and_exceptions_and_exits_1(monkeypatch, capsys):
    make = gym.make
    monkeypatch.setattr(soak.gym, "make", lambda *a, **k: LosesTheTruth(make(*a, **k)))
    report = soak.run(60, seed=5, episodes=2)
    assert report.misses > 0 and report.failures[0]["what"].startswith("truth outside")

    def broken(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(soak.gym, "make", broken)
    with pytest.raises(SystemExit) as exit_info:  # and ends although no step ever runs
        soak.main(["--steps", "3", "--no-progress"])
    assert exit_info.value.code == 1
    assert "exceptions 3" in (out := capsys.readouterr().out) and "RuntimeError: boom" in out


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["--steps", "0"], "--steps"),
        (["--episodes", "-1"], "--episodes"),
        (["--seed", "-2"], "--seed"),
        (["--json", "{a_file}/x.json"], "--json"),
        (["--fusion", "relaxed"], "--fusion"),
        (["--fusion", "robust", "--task", "BearingSLAM-Khepera-v1"], "--fusion"),
    ],
)
def test_the_soak_refuses_bad_values_in_one_line(argv, named, capsys, tmp_path):
    a_file = tmp_path / "a_file"
    a_file.write_text("")
    with pytest.raises(SystemExit) as exit_info:
        soak.main([arg.format(a_file=a_file) for arg in argv])
    assert exit_info.value.code == 2
    assert named in capsys.readouterr().err.strip().splitlines()[-1]


def test_a_task_soak_runs_that_task_only(capsys):
    import pytest

    report = soak.run(120, seed=2, episodes=2, task="BearingSLAM-FurnishedRoom-v1")
    assert report.steps >= 120 and report.defects == 0 and report.containment_checks > 0
    soak.main(["--steps", "40", "--task", "BearingSLAM-Khepera-Camera90-v1", "--no-progress"])
    assert "BearingSLAM-Khepera-Camera90-v1" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        soak.main(["--steps", "10", "--task", "Nope-v0"])
