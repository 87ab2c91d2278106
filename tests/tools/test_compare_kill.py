"""A SIGKILLed ``bearing-env compare --workers 2`` takes its workers and multiprocessing's
resource tracker with it: nothing of its process group survives, and a reader of its
stdout gets EOF."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from bearing_env.train.compare.log import LOG_NAME

REPO_ROOT = Path(__file__).resolve().parents[2]


def live_members(pgid: int) -> list[str]:
    """The processes of group ``pgid`` that are not zombies (``/proc``)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except OSError:  # it ended meanwhile
            continue
        # pid (comm) state ppid pgrp ...: comm may hold spaces, so split after its ")".
        state, _ppid, pgrp = stat.rsplit(")", 1)[1].split()[:3]
        if int(pgrp) == pgid and state != "Z":
            found.append(f"{entry.name} {state} {cmdline.strip()[:120]}")
    return found


@pytest.mark.skipif(not Path("/proc/self/stat").is_file(), reason="needs /proc (Linux)")
def test_sigkill_of_compare_ends_its_workers_and_closes_its_stdout(tmp_path: Path) -> None:
    out = tmp_path / "killed"
    command = [
        sys.executable, "-m", "bearing_env.train.compare.cli", "--policies", "random", "greedy",
        "--env-kwargs", "scenario=khepera", "max_moves=5", "--episodes", "500",
        "--workers", "2", "--no-progress", "--no-plots", "--out", str(out),
    ]  # fmt: skip
    process = subprocess.Popen(
        command,
        cwd=REPO_ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,  # its own process group: pgid == pid
    )
    pgid = process.pid
    received: list[bytes] = []
    reader = threading.Thread(target=lambda: received.append(process.stdout.read()), daemon=True)
    reader.start()
    try:
        log = out / LOG_NAME
        deadline = time.monotonic() + 60
        while not (log.exists() and len(log.read_text().splitlines()) >= 2):
            assert process.poll() is None, process.stderr.read().decode()
            assert time.monotonic() < deadline, "no episode within 60 s"
            time.sleep(0.05)
        assert len(live_members(pgid)) >= 4  # compare, 2 workers, resource tracker
        os.kill(process.pid, signal.SIGKILL)  # the parent only, as an OOM killer would
        process.wait(timeout=10)
        deadline = time.monotonic() + 5
        while live_members(pgid) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert live_members(pgid) == []
        reader.join(timeout=5)
        assert not reader.is_alive(), "stdout still open"
        assert received == [b""]  # EOF (--no-progress: nothing was printed yet)
    finally:
        if live_members(pgid):
            os.killpg(pgid, signal.SIGKILL)
        if process.poll() is None:
            process.wait()
        process.stdout.close()
        process.stderr.close()
