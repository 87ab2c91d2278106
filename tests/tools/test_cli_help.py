"""``bearing-env`` and every subcommand's ``--help``: each option says what it does and
its default, no reST markup shows, ``--version`` prints the version, and a bare
``bearing-env`` is a usage error."""

from __future__ import annotations

import argparse
import sys
from typing import Any

import pytest

import bearing_env
from bearing_env.train import cli
from bearing_env.train.common.cli_parser import DefaultsHelpFormatter, doc_summary
from tests.extras import needs


def help_of(
    argv: list[str], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> tuple[argparse.ArgumentParser, str]:
    """The parser that printed ``bearing-env ARGV --help`` and what it printed."""
    printed: list[argparse.ArgumentParser] = []
    print_help = argparse.ArgumentParser.print_help

    def recording(self: argparse.ArgumentParser, file: Any = None) -> None:
        printed.append(self)
        print_help(self, file)

    monkeypatch.setattr(argparse.ArgumentParser, "print_help", recording)
    monkeypatch.setattr(sys, "argv", ["bearing-env"])  # cli.main rewrites sys.argv
    with pytest.raises(SystemExit) as stopped:
        cli.main([*argv, "--help"])
    assert stopped.value.code in (0, None)
    (parser,) = printed
    return parser, capsys.readouterr().out


def option_help(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    """An option's help as ``--help`` prints it, before line wrapping."""
    formatter = parser._get_formatter()
    return formatter._expand_help(action) if action.help else ""


#: Subcommands whose --help itself needs an extra (the command checks for it first).
HELP_NEEDS = {"train": needs("train", "stable_baselines3", "torch")}


@pytest.mark.parametrize(
    "command",
    [
        pytest.param(c, marks=[HELP_NEEDS[c]] if c in HELP_NEEDS else [])
        for c in sorted(cli.SUBCOMMANDS)
    ],
)
def test_every_option_says_what_it_does_and_its_default(
    command: str, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    parser, text = help_of([command], capsys, monkeypatch)
    assert parser.prog == f"bearing-env {command}"
    assert parser.formatter_class is DefaultsHelpFormatter
    assert "``" not in text, text
    assert parser.description, "no description"
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        name = "/".join(action.option_strings) or action.dest
        shown = option_help(parser, action)
        assert shown.strip(), f"{name} has no description"
        takes_value = action.nargs != 0 and action.option_strings and not action.required
        if takes_value:
            assert "default" in shown.lower(), f"{name}: {shown!r} does not say its default"
            assert "(default: None)" not in shown, f"{name}: say what None means"


def test_top_level_help_lists_every_subcommand(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys, "argv", ["bearing-env"])
    cli.main(["--help"])
    text = capsys.readouterr().out
    assert "``" not in text
    for command in cli.SUBCOMMANDS:
        assert command in text


def test_version_prints_the_package_version(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys, "argv", ["bearing-env"])
    with pytest.raises(SystemExit) as stopped:
        cli.main(["--version"])
    assert stopped.value.code == 0
    assert capsys.readouterr().out.strip() == f"bearing-env {bearing_env.__version__}"


def test_bare_bearing_env_prints_the_usage_and_exits_2(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys, "argv", ["bearing-env"])
    with pytest.raises(SystemExit) as stopped:
        cli.main([])
    assert stopped.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: bearing-env") and "required: COMMAND" in err


def test_generalisation_is_a_subcommand() -> None:
    module, _ = cli.SUBCOMMANDS["generalisation"]
    assert module == "bearing_env.train.studies.generalisation"


def test_the_formatter_adds_a_default_only_where_the_help_has_none() -> None:
    parser = argparse.ArgumentParser(prog="p", formatter_class=DefaultsHelpFormatter)
    parser.add_argument("--count", type=int, default=3, help="how many")
    parser.add_argument("--seed", type=int, default=0, help="seed (default %(default)s)")
    parser.add_argument("--flag", action="store_true", help="a switch")
    parser.add_argument("--algo", required=True, help="which one")
    text = " ".join(parser.format_help().split())
    assert "--count COUNT how many (default: 3)" in text
    assert "seed (default 0)" in text and "(default: 0)" not in text
    assert "--flag a switch" in text and "--algo ALGO which one" in text


def test_doc_summary_is_the_first_paragraph_on_one_line() -> None:
    assert doc_summary("First line\nwraps here.\n\nMore.") == "First line wraps here."
    assert doc_summary(None) == ""


def test_top_level_help_groups_the_commands_users_first(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(sys, "argv", ["bearing-env"])
    cli.main(["--help"])
    lines = capsys.readouterr().out.splitlines()
    headings = [line for line in lines if line.endswith(":") and not line.startswith(" ")]
    assert headings[-3:] == ["Start here:", "Studies and scale-out:", "Maintainers' tools:"]
    listed = [line.split()[0] for line in lines if line.startswith("  ") and len(line.split()) > 1]
    order = [name for name in listed if name in cli.SUBCOMMANDS]
    assert order == list(cli.SUBCOMMANDS), "each command once, in its group's order"
    users = {"train", "evaluate", "compare", "play", "demo", "figures", "curves"}
    assert set(order[: len(users)]) == users, "the user's commands come first"
    for name in (
        "bench",
        "bench-callgrind",
        "region-search",
        "transfer-tightness",
        "soak",
        "docs-tables",
    ):
        assert name in cli.COMMAND_GROUPS["Maintainers' tools"]
    for line in lines:
        assert len(line) <= 100 or not line.startswith("  "), f"one short line each: {line!r}"
