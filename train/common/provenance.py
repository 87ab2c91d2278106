"""Where a measured figure comes from: the command, the commit, the date and the machine.

A results file that ``bearing-env docs-tables`` writes a table from carries a
``"measured"`` record (:func:`measured_here`), and the table's caption says it
(:func:`measured_sentence`), so a page shows with each figure how to measure it again.

A record of figures measured before their command wrote results files has the same keys,
filled in from the page that showed them and the commit that published them, and a
``"transcribed"`` line that says so.
"""

from __future__ import annotations

import contextlib
import datetime
import os
import platform
import shlex
import subprocess
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any


def source_commit() -> str | None:
    """The git commit of the code measured (the checkout's HEAD, with ``+changes`` when
    its tracked files differ from it), or None outside a git checkout."""
    folder = Path(__file__).resolve().parent

    def git(*arguments: str) -> str:
        return subprocess.run(
            ["git", *arguments], cwd=folder, capture_output=True, text=True, check=True
        ).stdout.strip()

    try:
        head = git("rev-parse", "HEAD")
        changes = git("status", "--porcelain", "--untracked-files=no")
    except (OSError, subprocess.CalledProcessError):
        return None
    return f"{head}+changes" if changes else head


def machine_line() -> str:
    """This machine in one line: cores, processor, platform, Python, and the 1-minute
    load average (other jobs move timings, not the deterministic counts)."""
    line = (
        f"{os.cpu_count()}-core {platform.processor() or platform.machine()} machine "
        f"({platform.platform()}, Python {sys.version.split()[0]}"
    )
    with contextlib.suppress(OSError, AttributeError):
        line += f", load average {os.getloadavg()[0]:.2f}"
    return line + ")"


def measured_here(program: str, argv: Sequence[str]) -> dict[str, Any]:
    """The ``"measured"`` record of a run of ``program`` (``"bearing-env observability"``)
    with the arguments ``argv``, made now on this machine."""
    return {
        "command": " ".join([program, shlex.join(argv)]).strip(),
        "commit": source_commit(),
        "date": datetime.datetime.now(datetime.timezone.utc).date().isoformat(),
        "machine": machine_line(),
    }


def short_commit(commit: str | None) -> str:
    """A commit as the pages cite it: 7 hex digits, ``+changes`` kept."""
    if not commit:
        return "an unknown commit"
    head, plus, changes = commit.partition("+")
    return f"commit `{head[:7]}{plus}{changes}`"


def measured_sentence(measured: Mapping[str, Any], results_file: str) -> str:
    """One sentence for a table's caption: the command, date, commit, machine and file
    (and, for transcribed figures, where they were transcribed from)."""
    sentence = (
        f"Measured by `{measured['command']}` on {measured['date']}, "
        f"{short_commit(measured.get('commit'))}, on a {measured['machine']}; "
        f"file `{results_file}`."
    )
    if measured.get("transcribed"):
        sentence += f" {measured['transcribed']}"
    return sentence
