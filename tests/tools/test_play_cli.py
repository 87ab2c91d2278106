"""``bearing-env play``: its help, its refusals and its one-line error without pygame.

The window itself is tested in ``tests/envs/test_manual_control.py``; these tests call
the command line in this process and stop before a window opens.
"""

from __future__ import annotations

import sys

import pytest

from bearing_env.train.cli import main
from tests.extras import needs


def play(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    """``bearing-env play ARGV``: (exit status, stdout, stderr)."""
    with pytest.raises(SystemExit) as ended:
        main(["play", *argv])
    out, err = capsys.readouterr()
    return int(ended.value.code or 0), out, err


def one_error_line(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    status, _, err = play(argv, capsys)
    lines = [line for line in err.splitlines() if line.strip()]
    assert status == 2, err
    assert "Traceback" not in err
    assert lines[-1].startswith("bearing-env play: error: "), lines
    return lines[-1]


@pytest.fixture(autouse=True)
def _keep_argv(monkeypatch: pytest.MonkeyPatch) -> None:
    # The command line sets sys.argv for the subcommand's parser.
    monkeypatch.setattr(sys, "argv", list(sys.argv))


def test_help_names_the_options_their_defaults_and_the_keys(
    capsys: pytest.CaptureFixture[str],
) -> None:
    status, out, _ = play(["--help"], capsys)
    assert status == 0
    text = " ".join(out.split())
    assert text.startswith("usage: bearing-env play")
    for option in ("--env {BearingSLAM-v1,BearingSLAMDiscrete-v1}", "--env-kwargs", "--seed"):
        assert option in text
    assert "default BearingSLAM-v1" in text and "default: scenario=khepera" in text
    assert "(default 0)" in text
    assert "escape: quit" in text and "click: move toward the point" in text


def test_without_pygame_it_names_the_render_extra_in_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setitem(sys.modules, "pygame", None)  # as after a plain install
    status, _, err = play([], capsys)
    assert status == 2 and "Traceback" not in err
    assert err.strip().splitlines() == [
        "bearing-env play: error: bearing-env play needs the package 'pygame', which is not "
        'installed; install the render extra: pip install "bearing_env[render]"'
    ]


@needs("render")  # without pygame the command stops at the missing extra, before the settings
def test_bad_settings_are_one_line_errors_naming_the_value(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert "'fly'" in one_error_line(["--env-kwargs", "scenario=fly"], capsys)
    assert "'nope'" in one_error_line(["--env-kwargs", "nope"], capsys)
    assert "render_mode" in one_error_line(["--env-kwargs", "render_mode=human"], capsys)
    assert "'CartPole-v1'" in one_error_line(["--env", "CartPole-v1"], capsys)
    assert "-1" in one_error_line(["--seed", "-1"], capsys)
