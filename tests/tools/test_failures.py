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

from bearing_env.train.common.errors import (
    EXIT_ERROR,
    exit_on_output_errors,
    os_error_message,
    with_path,
)
from bearing_env.train.compare import cli as compare
from bearing_env.train.compare import log as compare_log
from bearing_env.train.compare import report as compare_report
from bearing_env.train.compare.log import LOG_NAME, CorruptLogError, EpisodeLog
from tests.extras import import_or_skip

ROOT = Path(__file__).resolve().parents[2]

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
    import_or_skip("stable_baselines3")
    run = a_file / "run"
    result = run_cli("train", *TRAIN_ARGS, "--output", str(run))
    assert result.returncode == EXIT_ERROR, result.stderr
    line = one_line_error(result.stderr, "bearing-env train")
    assert str(run) in line and "Not a directory" in line and "--output" in line


def test_train_on_a_full_disk_names_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import_or_skip("stable_baselines3")
    from bearing_env.train.sb3 import train_cli

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

    gym.make("bearing_env:BearingSLAMDiscrete-v1", **kwargs)


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
        env = gym.make("bearing_env:BearingSLAM-v1", scenario="khepera")
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

    env = gym.make("bearing_env:BearingSLAM-v1", scenario="khepera")
    env.reset(seed=0)
    with pytest.raises(ValueError, match="must be real numbers"):
        env.step(np.array(action))


# --------------------------------------------------------------------------------------
# Bad values on the command line: an argparse usage error, one error line, status 2
# --------------------------------------------------------------------------------------


def usage_error(stderr: str, prog: str) -> str:
    """The one error line of a usage error: argparse's usage lines may come first, then
    exactly one ``<prog>: error: ...`` line, and no traceback."""
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert "Traceback" not in stderr, stderr
    errors = [line for line in lines if line.startswith(f"{prog}: error: ")]
    assert len(errors) == 1 and lines[-1] == errors[0], stderr
    assert all(line.startswith(("usage:", " ")) for line in lines[:-1]), stderr
    return errors[0]


def cli_exit(
    argv: list[str], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> tuple[int | str | None, str]:
    """Run ``bearing-env ARGV`` in this process; its exit status and its stderr."""
    from bearing_env.train import cli

    monkeypatch.setattr(sys, "argv", ["bearing-env", *argv])  # cli.main sets it: restore
    capsys.readouterr()
    with pytest.raises(SystemExit) as exit_info:
        cli.main(argv)
    return exit_info.value.code, capsys.readouterr().err


def closed_port() -> int:
    """A port on 127.0.0.1 that nothing listens on (bound, then released)."""
    import socket

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


_QUICK = ["--policies", "random", "--env-kwargs", "scenario=khepera", "max_moves=2"]
_TRAIN = ["train", "--algo", "ppo", "--no-progress", "--no-tensorboard", "--eval-freq", "0"]

#: (argv, text of the error line). ``{tmp}``: a fresh folder; ``{a_file}``: a regular file;
#: ``{port}``: a closed port on 127.0.0.1.
BAD_VALUES: list[tuple[list[str], str]] = [
    # compare
    (["compare", "--env", "NoSuch-v0", *_QUICK], "unknown env id 'NoSuch-v0'"),
    (["compare", "--seed-start", "-5"], "argument --seed-start: must be >= 0, got -5"),
    (["compare", "--bootstrap-seed", "-1"], "argument --bootstrap-seed: must be >= 0, got -1"),
    (["compare", "--episodes", "0"], "argument --episodes: must be >= 1, got 0"),
    (["compare", "--episodes", "x"], "argument --episodes: expected an integer, got 'x'"),
    (["compare", "--workers", "0"], "argument --workers: must be >= 1, got 0"),
    (["compare", "--workers", "-1"], "argument --workers: must be >= 1, got -1"),
    (["compare", "--bootstrap", "-1"], "argument --bootstrap: must be >= 1, got -1"),
    (["compare", "--stop-after", "-1"], "argument --stop-after: must be >= 0, got -1"),
    (["compare", *_QUICK, "--resume", "--out", "{tmp}/none"], "holds no comparison"),
    (["compare", "--resume", "--overwrite"],
     "argument --overwrite: not allowed with argument --resume"),
    (["compare", *_QUICK, "--executor", "ray", "--ray-address", "127.0.0.1:{port}"],
     "Ray address '127.0.0.1:{port}' does not answer"),
    (["compare", *_QUICK, "--executor", "ray", "--ray-address", "nowhere"],
     "Ray address 'nowhere': expected HOST:PORT"),
    # train
    ([*_TRAIN, "--hyperparams", "n_steps=-1", "--output", "{tmp}/run"],
     "hyperparameter n_steps must be >= 1, got -1"),
    ([*_TRAIN, "--hyperparams", "batch_size=0", "--output", "{tmp}/run"],
     "hyperparameter batch_size must be >= 2, got 0"),
    ([*_TRAIN, "--torch-threads", "-1"], "argument --torch-threads: must be >= 0, got -1"),
    ([*_TRAIN, "--env", "NoSuch-v0", "--output", "{tmp}/run"], "unknown env id 'NoSuch-v0'"),
    ([*_TRAIN, "--timesteps", "0"], "argument --timesteps: must be >= 1, got 0"),
    ([*_TRAIN, "--seed", "-1"], "argument --seed: must be >= 0, got -1"),
    ([*_TRAIN, "--n-envs", "0"], "argument --n-envs: must be >= 1, got 0"),
    ([*_TRAIN, "--eval-episodes", "0"], "argument --eval-episodes: must be >= 1, got 0"),
    ([*_TRAIN, "--checkpoint-freq", "0"], "argument --checkpoint-freq: must be >= 1, got 0"),
    ([*_TRAIN, "--keep-checkpoints", "0"], "argument --keep-checkpoints: must be >= 1, got 0"),
    ([*_TRAIN, "--eval-freq", "-1"], "argument --eval-freq: must be >= 0, got -1"),
    # bench
    (["bench", "--landmarks", "2"], "argument --landmarks: must be >= 3, got 2"),
    (["bench", "--num-envs", "0"], "argument --num-envs: must be >= 1, got 0"),
    (["bench", "--env-kwargs", "foo=1"], "--env-kwargs: "),
    (["bench", "--json", "{a_file}/b.json"], "cannot write {a_file}: File exists"),
    (["bench", "--seconds", "inf"], "argument --seconds: must be finite and > 0, got inf"),
    (["bench", "--seconds", "nan"], "argument --seconds: must be finite and > 0, got nan"),
    (["bench", "--seconds", "0"], "argument --seconds: must be finite and > 0, got 0.0"),
    (["bench", "--ppo-envs", "0"], "argument --ppo-envs: must be >= 1, got 0"),
    (["bench", "--profile-num-envs", "0"], "argument --profile-num-envs: must be >= 1, got 0"),
    # bench-slam
    (["bench-slam", "--seconds", "-1"], "argument --seconds: must be finite and > 0, got -1.0"),
    (["bench-slam", "--seconds", "inf"], "argument --seconds: must be finite and > 0, got inf"),
    # figures
    (["figures", "--seeds", "-1"], "argument --seeds: must be >= 1, got -1"),
    (["figures", "--seeds", "0"], "argument --seeds: must be >= 1, got 0"),
    (["figures", "--seed-start", "-1"], "argument --seed-start: must be >= 0, got -1"),
    (["figures", "--fig7-seed", "-1"], "argument --fig7-seed: must be >= 0, got -1"),
    (["figures", "--only", "7", "--out", "{a_file}/figs"],
     "cannot write {a_file}/figs: Not a directory"),
    # demo
    (["demo", "--episodes", "0"], "argument --episodes: must be >= 1, got 0"),
    (["demo", "--episodes", "-1"], "argument --episodes: must be >= 1, got -1"),
    (["demo", "--moves", "0"], "argument --moves: must be >= 1, got 0"),
    (["demo", "--moves", "-1"], "argument --moves: must be >= 1, got -1"),
    (["demo", "--seed", "-1"], "argument --seed: must be >= 0, got -1"),
    # rllib and sweep share their options
    (["rllib", "--iterations", "0"], "argument --iterations: must be >= 1, got 0"),
    (["rllib", "--checkpoint-every", "0"], "argument --checkpoint-every: must be >= 1, got 0"),
    (["rllib", "--stop-after", "-1"], "argument --stop-after: must be >= 0, got -1"),
    (["sweep", "--seed", "-1"], "argument --seed: must be >= 0, got -1"),
]


@pytest.mark.parametrize(
    ("argv", "expected"), BAD_VALUES, ids=[" ".join(argv) for argv, _ in BAD_VALUES]
)
def test_a_bad_value_ends_in_one_line_naming_it_with_status_2(
    argv: list[str],
    expected: str,
    tmp_path: Path,
    a_file: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    if "train" in argv:
        import_or_skip("stable_baselines3")
    if "ray" in argv:  # the executor's checks run after `import ray`
        import_or_skip("ray")
    if argv[0] == "figures" and "--only" in argv:  # it gets as far as plotting
        import_or_skip("matplotlib")
    port = closed_port()
    fill = {"tmp": str(tmp_path), "a_file": str(a_file), "port": str(port)}
    argv = [arg.format(**fill) for arg in argv]
    code, err = cli_exit(argv, capsys, monkeypatch)
    assert code == EXIT_ERROR, err
    line = usage_error(err, f"bearing-env {argv[0]}")
    assert expected.format(**fill) in line


def test_train_on_a_missing_cuda_device_fails_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    torch = import_or_skip("torch")
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    code, err = cli_exit([*_TRAIN, "--device", "cuda", "--output", str(tmp_path / "r")],
                         capsys, monkeypatch)
    assert code == EXIT_ERROR
    line = usage_error(err, "bearing-env train")
    assert "device 'cuda': CUDA is not available" in line
    assert not (tmp_path / "r").exists()  # refused before anything was written


def test_ppo_says_up_front_that_it_trains_whole_rollouts() -> None:
    import_or_skip("stable_baselines3")
    from bearing_env.train.sb3.train import rollout_notice

    notice = rollout_notice({"n_steps": 256}, 16, 0, 100)
    assert notice is not None and "\n" not in notice
    assert "whole rollouts of 4096 env steps" in notice and "to 4096 timesteps, not 100" in notice
    assert rollout_notice({"n_steps": 256}, 16, 0, 8192) is None  # whole rollouts: no note
    assert "to 8192 timesteps, not 5000" in (rollout_notice({"n_steps": 256}, 16, 4096, 5000) or "")
    assert rollout_notice({"train_freq": 1}, 4, 0, 100) is None  # off-policy: exact
    with pytest.raises(ValueError, match="n_steps \\* n_envs must be >= 2"):
        rollout_notice({"n_steps": 1}, 1, 0, 100)


def test_a_ray_address_that_does_not_answer_is_refused() -> None:
    from bearing_env.train.ray.ray_executor import RayAddressError, check_ray_address

    port = closed_port()
    with pytest.raises(RayAddressError, match=f"'127.0.0.1:{port}' does not answer"):
        check_ray_address(f"127.0.0.1:{port}", timeout=1.0)
    with pytest.raises(RayAddressError, match="does not answer"):
        check_ray_address(f"ray://127.0.0.1:{port}", timeout=1.0)
    for malformed in ("127.0.0.1", "http://127.0.0.1:6379", "127.0.0.1:port"):
        with pytest.raises(RayAddressError, match="expected HOST:PORT"):
            check_ray_address(malformed)
    check_ray_address("auto")  # left to Ray


def test_bench_slam_into_a_closed_pipe_ends_quietly(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    from bearing_env.train.common.errors import EXIT_BROKEN_PIPE

    read_end, write_end = os.pipe()
    os.close(read_end)  # `| head` has gone: every write is EPIPE
    with open(write_end, "w", buffering=1) as closed_pipe:
        monkeypatch.setattr(sys, "stdout", closed_pipe)
        code, err = cli_exit(["bench-slam", "--seconds", "0.01"], capsys, monkeypatch)
        monkeypatch.undo()
    assert code == EXIT_BROKEN_PIPE
    assert err == ""


# --------------------------------------------------------------------------------------
# bearing-env figures and bench: a read-only or full disk ends in one line
# --------------------------------------------------------------------------------------


class _OsWith:
    """``os`` with some functions replaced: patched into the project's atomic writers
    only, so that numba's cache (which renames files too, when a test compiles a kernel
    for the first time) keeps the real ones."""

    def __init__(self, **replaced: Any) -> None:
        self.__dict__.update(replaced)

    def __getattr__(self, name: str) -> Any:
        return getattr(os, name)


def _read_only(*args: Any, **kwargs: Any) -> None:
    raise OSError(errno.EROFS, os.strerror(errno.EROFS))


def _disk_full(fd: int) -> None:
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


@pytest.mark.parametrize(
    ("command", "patch", "written", "reason"),
    [
        (["figures", "--only", "7"], ("replace", _read_only), "fig7_polygons.png",
         "Read-only file system"),
        (["figures", "--only", "7"], ("fsync", _disk_full), "figures.json",
         "No space left on device"),
        (["bench", "--sections", "slam", "--seconds", "0.01"], ("replace", _read_only), "b.json",
         "Read-only file system"),
        (["bench", "--sections", "slam", "--seconds", "0.01"], ("fsync", _disk_full), "b.json",
         "No space left on device"),
        (["bench-slam", "--seconds", "0.01"], ("replace", _read_only), "b.json",
         "Read-only file system"),
        (["bench-slam", "--seconds", "0.01"], ("fsync", _disk_full), "b.json",
         "No space left on device"),
    ],
    ids=["figures-read-only", "figures-full", "bench-read-only", "bench-full",
         "bench-slam-read-only", "bench-slam-full"],
)  # fmt: skip
def test_figures_and_bench_on_a_bad_disk_name_the_file(
    command: list[str],
    patch: tuple[str, Any],
    written: str,
    reason: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The atomic writers' rename fails on a read-only file system, their fsync on a full
    disk; either way the message names the file."""
    from bearing_env.train.common import files

    if command[0] == "figures":
        import_or_skip("matplotlib")
    out = tmp_path / "out"
    where = ["--out", str(out)] if command[0] == "figures" else ["--json", str(out / "b.json")]
    name, replacement = patch
    monkeypatch.setattr(files, "os", _OsWith(**{name: replacement}))
    code, err = cli_exit([*command, *where], capsys, monkeypatch)
    assert code == EXIT_ERROR, err
    lines = [line for line in err.splitlines() if line.strip()]
    errors = [line for line in lines if line.startswith(f"bearing-env {command[0]}: error: ")]
    assert "Traceback" not in err and errors == lines[-1:], err  # after bench's progress log
    assert str(out / written) in errors[0] and reason in errors[0]
