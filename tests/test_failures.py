"""Clear failures instead of tracebacks: OSErrors while writing outputs, and a corrupt
episode log under ``compare --resume``."""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from bearing_env.train import compare, compare_log, compare_report
from bearing_env.train.compare_log import LOG_NAME, CorruptLogError, EpisodeLog
from bearing_env.train.errors import (
    EXIT_ERROR,
    exit_on_output_errors,
    os_error_message,
    with_path,
)

ROOT = Path(__file__).resolve().parents[1]

COMPARE_ARGS = [
    "--policies", "random", "--env-kwargs", "scenario=khepera", "max_moves=3",
    "--episodes", "3", "--no-progress", "--no-plots", "--bootstrap", "50",
]


def run_cli(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy"}
    return subprocess.run(
        [sys.executable, "-m", "bearing_env.train.cli", *args],
        capture_output=True, text=True, timeout=timeout, cwd=ROOT, env=env,
    )


def one_line_error(stderr: str, prog: str) -> str:
    """The single stderr line of a clean failure (no traceback, no usage)."""
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert "Traceback" not in stderr, stderr
    assert len(lines) == 1, stderr
    assert lines[0].startswith(f"{prog}: error: "), stderr
    return lines[0]


def compare_exit(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run ``compare.main`` expecting a clean failure; its one-line message."""
    with pytest.raises(SystemExit) as exit_info:
        compare.main(argv)
    assert exit_info.value.code == EXIT_ERROR
    return one_line_error(capsys.readouterr().err, "bearing-env compare")


@pytest.fixture
def a_file(tmp_path: Path) -> Path:
    """A regular file: a path below it cannot be created, even by root."""
    path = tmp_path / "not_a_folder"
    path.write_text("x")
    return path


# --------------------------------------------------------------------------------------
# The message itself
# --------------------------------------------------------------------------------------


class Refused(Exception):
    """A command's own refusal, such as a resume that does not match."""


@pytest.mark.parametrize(
    ("raised", "expected", "usage"),
    [
        (FileExistsError("out holds a run; pass --resume"), "out holds a run; pass --resume", True),
        (Refused("the log does not match"), "the log does not match", False),
        (OSError(errno.ENOSPC, "No space left on device", "out/x.json"),
         "cannot write out/x.json: No space left on device", False),
        (FileExistsError(errno.EEXIST, "File exists", "out/x"), "cannot write out/x: File exists",
         False),
    ],
)  # fmt: skip
def test_output_errors_end_the_command_with_status_2(
    raised: Exception, expected: str, usage: bool, capsys: pytest.CaptureFixture[str]
) -> None:
    import argparse

    parser = argparse.ArgumentParser(prog="bearing-env x")
    with pytest.raises(SystemExit) as exit_info:
        with exit_on_output_errors(parser, Path("out"), "--out", (Refused,)):
            raise raised
    assert exit_info.value.code == EXIT_ERROR
    err = capsys.readouterr().err
    assert ("usage: bearing-env x" in err) == usage
    assert expected in err and "Traceback" not in err


def test_output_errors_let_interrupts_and_other_errors_through() -> None:
    import argparse

    parser = argparse.ArgumentParser(prog="bearing-env x")
    for raised in (KeyboardInterrupt(), RuntimeError("a bug")):
        with pytest.raises(type(raised)):
            with exit_on_output_errors(parser, Path("out"), "--out"):
                raise raised



def test_the_message_names_the_path_and_the_reason() -> None:
    full = OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))  # as write() raises it: no path
    assert with_path(full, "/out/summary.json") is full
    assert full.filename == "/out/summary.json"
    assert os_error_message(full) == (
        "/out/summary.json: No space left on device (the disk is full)"
    )
    temporary = PermissionError(errno.EACCES, "Permission denied", "/out/.run.json.7.tmp")
    with_path(temporary, "/out/run.json")  # the final name, not the temporary one
    assert os_error_message(temporary).startswith("/out/run.json: Permission denied")
    named = OSError(errno.EROFS, "Read-only file system", "/elsewhere")
    assert with_path(named, "/out/x").filename == "/elsewhere"  # an error's own path stays


# --------------------------------------------------------------------------------------
# bearing-env compare
# --------------------------------------------------------------------------------------


def test_compare_into_a_folder_below_a_file_fails_in_one_line(a_file: Path) -> None:
    out = a_file / "out"
    result = run_cli("compare", *COMPARE_ARGS, "--out", str(out))
    assert result.returncode == EXIT_ERROR, result.stderr
    line = one_line_error(result.stderr, "bearing-env compare")
    assert str(out) in line and "Not a directory" in line and "--out" in line


def test_compare_on_a_full_disk_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def disk_full(fd: int) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", disk_full)
    out = tmp_path / "out"
    line = compare_exit([*COMPARE_ARGS, "--out", str(out)], capsys)
    assert str(out / "config.json") in line  # the first file written
    assert "No space left on device" in line and "free some space" in line
    assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]  # no temporary left


def test_compare_without_permission_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    write = compare_report.atomic_write_text

    def refuse_the_report(path: Path, text: str, newline: str | None = None) -> None:
        if path.name == "report.md":
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(path))
        write(path, text, newline)

    monkeypatch.setattr(compare_report, "atomic_write_text", refuse_the_report)
    out = tmp_path / "out"
    line = compare_exit([*COMPARE_ARGS, "--out", str(out)], capsys)
    assert str(out / "report.md") in line
    assert "Permission denied" in line and "make the folder writable" in line


def test_an_episode_log_that_cannot_be_appended_names_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def disk_full(fd: int) -> None:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", disk_full)
    log = EpisodeLog(tmp_path / LOG_NAME)
    with pytest.raises(OSError, match="No space left on device") as error:
        log.append({"policy": "x"})
    assert error.value.filename == str(log.path)


def _finished_log(out: Path) -> list[str]:
    compare.main([*COMPARE_ARGS, "--out", str(out)])
    return (out / LOG_NAME).read_text(encoding="utf-8").splitlines()


def test_a_corrupt_middle_line_is_reported_with_its_number_and_the_way_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    lines = _finished_log(out)
    expected = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert len(lines) == 3
    damaged = [lines[0], lines[1][: len(lines[1]) // 2], lines[2]]  # a cut-short line 2
    (out / LOG_NAME).write_text("\n".join(damaged) + "\n", encoding="utf-8")
    capsys.readouterr()

    line = compare_exit([*COMPARE_ARGS, "--out", str(out), "--resume"], capsys)
    assert f"{out / LOG_NAME}, line 2: not valid JSON" in line
    assert "delete that line" in line and "--overwrite" in line

    # The documented way out works: delete the line, resume, and get the same results.
    (out / LOG_NAME).write_text("\n".join([lines[0], lines[2]]) + "\n", encoding="utf-8")
    compare.main([*COMPARE_ARGS, "--out", str(out), "--resume"])
    resumed = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert resumed == expected


def test_a_valid_json_line_that_is_no_record_is_corrupt(tmp_path: Path) -> None:
    path = tmp_path / LOG_NAME
    good: dict[str, Any] = dict.fromkeys(compare_log.RECORD_KEYS, 0)
    path.write_text(json.dumps(good) + "\n[1, 2]\n" + json.dumps(good) + "\n")
    with pytest.raises(CorruptLogError, match=r"line 2: not an episode record") as error:
        EpisodeLog(path).load()
    assert error.value.line == 2


def test_a_corrupt_log_is_reported_on_the_command_line_without_a_traceback(
    tmp_path: Path,
) -> None:
    out = tmp_path / "out"
    lines = _finished_log(out)
    (out / LOG_NAME).write_text(lines[0] + "\n{oops\n" + lines[2] + "\n", encoding="utf-8")
    result = run_cli("compare", *COMPARE_ARGS, "--out", str(out), "--resume")
    assert result.returncode == EXIT_ERROR
    line = one_line_error(result.stderr, "bearing-env compare")
    assert "line 2" in line and "delete that line" in line


def test_a_corrupt_config_is_reported_under_resume(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out"
    _finished_log(out)
    (out / "config.json").write_text("{not json", encoding="utf-8")
    capsys.readouterr()
    line = compare_exit([*COMPARE_ARGS, "--out", str(out), "--resume"], capsys)
    assert "config.json is not valid JSON" in line and "--overwrite" in line


# --------------------------------------------------------------------------------------
# bearing-env train
# --------------------------------------------------------------------------------------

TRAIN_ARGS = [
    "--algo", "ppo", "--timesteps", "64", "--n-envs", "1", "--vec-env", "dummy",
    "--eval-freq", "0", "--no-progress", "--no-tensorboard",
    "--hyperparams", "n_steps=64", "batch_size=64",
]


def test_train_into_a_folder_below_a_file_fails_in_one_line(a_file: Path) -> None:
    pytest.importorskip("stable_baselines3")
    run = a_file / "run"
    result = run_cli("train", *TRAIN_ARGS, "--output", str(run))
    assert result.returncode == EXIT_ERROR, result.stderr
    line = one_line_error(result.stderr, "bearing-env train")
    assert str(run) in line and "Not a directory" in line and "--output" in line


def test_train_on_a_full_disk_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("stable_baselines3")
    from bearing_env.train import train_cli

    def disk_full(fd: int) -> None:  # the atomic writers fsync their temporary files
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "fsync", disk_full)
    run = tmp_path / "run"
    with pytest.raises(SystemExit) as exit_info:
        train_cli.main([*TRAIN_ARGS, "--output", str(run)])
    assert exit_info.value.code == EXIT_ERROR
    line = one_line_error(capsys.readouterr().err, "bearing-env train")
    assert str(run / "run.json") in line and "No space left on device" in line
    assert not [p for p in run.iterdir() if p.name.endswith(".tmp")]


# --------------------------------------------------------------------------------------
# The Python API: bad values are a TypeError or ValueError naming them
# --------------------------------------------------------------------------------------


def _make_discrete(**kwargs: Any) -> None:
    import gymnasium as gym

    gym.make("bearing_env:BearingSLAMDiscrete-v0", **kwargs)


def _replicate(count: Any) -> None:
    import numpy as np

    from bearing_env.slam import PolygonSLAM

    PolygonSLAM(4, np.deg2rad(2.0)).replicate(count)


def _fr_region(epsilon: float) -> None:
    from bearing_env.slam import fr_region

    fr_region(1.0, 1.2, epsilon)


@pytest.mark.parametrize(
    ("call", "error", "message"),
    [
        (lambda: _make_discrete(n_turns=10**8), ValueError,
         "n_turns must be <= 4096, got 100000000"),
        (lambda: _make_discrete(n_turns=10**9), ValueError, "n_turns must be <= 4096"),
        (lambda: _make_discrete(n_move_lengths=10**9, move_length=(0.1, 0.3)), ValueError,
         "n_move_lengths must be <= 4096, got 1000000000"),
        (lambda: _replicate(-1), ValueError, "replicate count must be >= 1, got -1"),
        (lambda: _replicate(0), ValueError, "replicate count must be >= 1, got 0"),
        (lambda: _replicate(2.5), TypeError, "replicate count must be an int, got 2.5"),
        (lambda: _fr_region(-0.1), ValueError, "epsilon must be in (0, pi/2) radians, got -0.1"),
        (lambda: _fr_region(0.0), ValueError, "epsilon must be in (0, pi/2) radians, got 0.0"),
        (lambda: _fr_region(2.0), ValueError, "epsilon must be in (0, pi/2) radians, got 2.0"),
    ],
    ids=[
        "n_turns=1e8", "n_turns=1e9", "n_move_lengths=1e9", "replicate(-1)", "replicate(0)",
        "replicate(2.5)", "fr_region(eps<0)", "fr_region(eps=0)", "fr_region(eps>pi/2)",
    ],
)  # fmt: skip
def test_api_values_out_of_range_are_refused_by_name(
    call: Any, error: type[Exception], message: str
) -> None:
    with pytest.raises(error) as raised:
        call()
    assert message in str(raised.value)


def test_the_largest_action_tables_are_accepted() -> None:
    _make_discrete(n_turns=4096, n_move_lengths=4096, move_length=(0.1, 0.3))


@pytest.mark.parametrize("dtype", ["float16", "longdouble", "int8", "float32", "float64"])
def test_continuous_actions_of_any_real_dtype_step_like_float64(dtype: str) -> None:
    import gymnasium as gym
    import numpy as np

    def first_step(action: Any) -> Any:
        env = gym.make("bearing_env:BearingSLAM-v0", scenario="khepera")
        env.reset(seed=3)
        return env.step(action)[0]

    values = [-1.0, 1.0]  # exact in every dtype (0.5 is not an int8)
    expected = first_step(np.array(values, dtype=np.float64))
    assert np.array_equal(first_step(np.array(values, dtype=dtype)), expected)


@pytest.mark.parametrize(
    "action", [["a", "b"], [1 + 1j, 0], [True, False], [None, 0.5]], ids=str
)
def test_non_numeric_continuous_actions_are_refused_by_value(action: list[Any]) -> None:
    import gymnasium as gym
    import numpy as np

    env = gym.make("bearing_env:BearingSLAM-v0", scenario="khepera")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="must be real numbers"):
        env.step(np.array(action))
