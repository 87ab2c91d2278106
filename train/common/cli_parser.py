"""The subcommands' argument parsers: one help format, and the options several share.

Every ``bearing-env`` subcommand builds its parser with :func:`command_parser`, so its
``--help`` says each option's default (:class:`DefaultsHelpFormatter`) and shows no reST
markup (the descriptions are often a module docstring's first line). Options that mean the
same in several subcommands are added by one function each here (``--no-progress``,
``--json``), so they read alike everywhere.
"""

from __future__ import annotations

import argparse
from pathlib import Path


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """argparse's help, with ``(default: X)`` after the help of every option that takes
    a value, unless the help already says its default in its own words. Flags
    (``store_true``) are off unless given, and say nothing more."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        says_default = "default" in text.lower()
        takes_value = action.nargs != 0 and action.option_strings and not action.required
        if says_default or not takes_value or action.default is argparse.SUPPRESS:
            return text
        return f"{text} (default: %(default)s)"


def plain_text(text: str) -> str:
    """``text`` without reST's inline-literal backticks (``name`` -> name)."""
    return text.replace("``", "")


def doc_summary(docstring: str | None) -> str:
    """The first paragraph of a module's docstring, on one line: a parser's description."""
    paragraph = (docstring or "").strip().split("\n\n", 1)[0]
    return " ".join(paragraph.split())


def command_parser(
    prog: str, description: str, epilog: str | None = None
) -> argparse.ArgumentParser:
    """A subcommand's parser: ``prog`` as its usage names it, the description and epilog
    as plain text, every option's default in its help."""
    return argparse.ArgumentParser(
        prog=prog,
        description=plain_text(description),
        epilog=None if epilog is None else plain_text(epilog),
        formatter_class=DefaultsHelpFormatter,
    )


def add_no_progress(parser: argparse._ActionsContainer) -> None:
    """``--no-progress``: no progress bar (the bars come from
    :mod:`bearing_env.train.common.progress`)."""
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


def add_json_output(parser: argparse._ActionsContainer, what: str) -> None:
    """``--json PATH``: also write ``what`` there (none by default)."""
    parser.add_argument(
        "--json",
        type=Path,
        default=None,
        metavar="PATH",
        help=f"also write {what} to this JSON file (default: none)",
    )
