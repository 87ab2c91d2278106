"""Where a measured figure comes from: the command, the commit, the date and the machine.

A results file that ``bearing-env docs-tables`` writes a table from carries a
``"measured"`` record (:func:`measured_here`), and the table's caption says it
(:func:`measured_sentence`), so a page shows with each figure how to measure it again.

A record of figures measured before their command wrote results files has the same keys,
filled in from the page that showed them and the commit that published them, and a
``"transcribed"`` line that says so. A record whose run named no commit that exists (a
dirty tree's ``+changes``, before the records listed ``uncommitted`` files) takes its
commit and date from git history, the commit that added the file's figures, and a
``"provenance"`` line that says so.
"""

from __future__ import annotations

import contextlib
import datetime
import os
import platform
import re
import shlex
import subprocess
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any


def _git(*arguments: str) -> str:
    folder = Path(__file__).resolve().parent
    return subprocess.run(
        ["git", *arguments], cwd=folder, capture_output=True, text=True, check=True
    ).stdout


def source_commit() -> str | None:
    """The git commit of the code measured: the checkout's HEAD, always a commit that
    exists (never ``+changes``: :func:`uncommitted_files` says whether the tracked files
    differed from it), or None outside a git checkout."""
    try:
        return _git("rev-parse", "HEAD").strip()
    except (OSError, subprocess.CalledProcessError):
        return None


def uncommitted_files() -> list[str]:
    """The tracked files of the checkout that differ from its HEAD, sorted (empty for a
    clean tree, or outside a git checkout): a measurement's record lists them beside its
    commit, so the commit it names is one that exists."""
    try:
        lines = _git("status", "--porcelain", "--untracked-files=no").splitlines()
    except (OSError, subprocess.CalledProcessError):
        return []
    # "XY path" or "XY old -> new": the path the tree holds now.
    return sorted({line[3:].rpartition(" -> ")[2].strip('"') for line in lines if line.strip()})


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


def measured_record(command: str) -> dict[str, Any]:
    """The ``"measured"`` record of ``command`` (the whole command line), run now on this
    machine: the command, the commit (HEAD), the tracked files that differed from it
    (``uncommitted``, empty for a clean tree), the date and the machine."""
    return {
        "command": command,
        "commit": source_commit(),
        "uncommitted": uncommitted_files(),
        "date": datetime.datetime.now(datetime.timezone.utc).date().isoformat(),
        "machine": machine_line(),
    }


def measured_here(program: str, argv: Sequence[str]) -> dict[str, Any]:
    """The ``"measured"`` record (:func:`measured_record`) of a run of ``program``
    (``"bearing-env observability"``) with the arguments ``argv``, made now on this
    machine."""
    return measured_record(" ".join([program, shlex.join(argv)]).strip())


def short_commit(commit: str | None) -> str:
    """A commit as the pages cite it: ``commit `abc1234``` (7 hex digits). ValueError for
    anything but a commit's hex name (a dirty tree's ``+changes`` is no commit: the
    record lists its ``uncommitted`` files instead)."""
    if not commit:
        return "an unknown commit"
    if not re.fullmatch(r"[0-9a-f]{7,40}", commit):
        raise ValueError(
            f"not a commit: {commit!r} (record the clean commit and its uncommitted files)"
        )
    return f"commit `{commit[:7]}`"


def uncommitted_text(files: Sequence[str]) -> str:
    """How a caption names a run's uncommitted files: empty for a clean tree."""
    if not files:
        return ""
    shown = ", ".join(f"`{name}`" for name in files[:3])
    more = f" and {len(files) - 3} more" if len(files) > 3 else ""
    return f" with uncommitted changes to {shown}{more}"


def measured_sentence(measured: Mapping[str, Any], results_file: str) -> str:
    """One sentence for a table's caption: the command, date, commit (and the tracked
    files that differed from it), machine and file (and, for figures whose record was
    filled in afterwards, where from)."""
    sentence = (
        f"Measured by `{measured['command']}` on {measured['date']}, "
        f"{short_commit(measured.get('commit'))}"
        f"{uncommitted_text(measured.get('uncommitted', []))}, on a {measured['machine']}; "
        f"file `{results_file}`."
    )
    if measured.get("transcribed"):
        sentence += f" {measured['transcribed']}"
    if measured.get("provenance"):
        sentence += f" {measured['provenance']}"
    return sentence
