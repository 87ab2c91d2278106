"""The golden map corpus's inputs and hashes as a data file, for the C++ replay.

The corpus (:mod:`tests.golden_slam`) draws its bearings with numpy from fixed seeds;
C++ cannot draw the same ones. So this module writes cases of the small corpus to
``tests/golden/slam_replay.txt``: each case's settings, every movement's bearings (exact:
Python's shortest round-trip repr, which ``strtod`` reads back bit for bit) and the
sha256 the corpus records for it. ``tests/cpp/test_golden_replay.cpp`` (ctest) replays
them through the library's own map batch and hashes the same bytes;
``tests/slam/test_golden_replay.py`` checks that the file agrees with the recorded
corpus, so the two cannot drift apart.

Only cases whose run here hashes as recorded are written (a guard: the corpus's inputs
take their angles from the C library's scalar functions, ``tests/slam_sim.py``, so every
case should), up to :data:`MAX_CASES`, spread over the corpus's settings.

    python -m tests.golden_replay --update    # write the file (a deliberate change only)

Format, one record per line, ``#`` lines are comments::

    case NAME SHA256
    settings EPSILON TRANSFER EDGE_SAMPLES ON_INCONSISTENCY FUSION MAX_OUTLIERS WINDOW RISK
             LIKELY ESTIMATE_BOUND        (one line: codes as bearing_env.slam.kernels's)
    shape MAPS LANDMARKS MOVES
    start B...   then   end B...          (per movement: MAPS * LANDMARKS bearings, map
                                           by map, radians; nan: a missed reading)
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bearing_env.slam import BatchedPolygonSLAM
from bearing_env.slam.settings import FUSIONS, INCONSISTENCY_POLICIES, ROBUST_SETS
from bearing_env.slam.transfer import TRANSFERS
from tests.golden_slam import GOLDEN_FILE, Case, movements, new_maps, run_hash, seeded_cases

REPLAY_FILE = Path(__file__).parent / "golden" / "slam_replay.txt"
#: Most cases written (round robin over the transfers and fusions).
MAX_CASES = 24


@dataclass
class ReplayCase:
    """One case of the file: its name and hash, settings and bearings."""

    name: str
    sha256: str
    settings: dict[str, float | int | bool]
    bearings: np.ndarray  #: (moves, 2, maps, landmarks): at R1, then at R2

    def new_maps(self) -> BatchedPolygonSLAM:
        s = self.settings
        return BatchedPolygonSLAM(
            self.bearings.shape[2], self.bearings.shape[3], float(s["epsilon"]),
            transfer=TRANSFERS[int(s["transfer"])], edge_samples=int(s["edge_samples"]),
            on_inconsistency=INCONSISTENCY_POLICIES[int(s["on_inconsistency"])],
            fusion=FUSIONS[int(s["fusion"])], max_outliers=int(s["max_outliers"]),
            window=int(s["window"]), risk=float(s["risk"]),
            robust_set="likely" if s["likely"] else "guaranteed",
            noise_bound="estimate" if s["estimate_bound"] else "nominal",
        )  # fmt: skip

    def replay_hash(self) -> str:
        """The hash of this case's run through the Python package."""
        return run_hash(self.new_maps(), ((b[0], b[1]) for b in self.bearings))


SETTINGS = ("epsilon", "transfer", "edge_samples", "on_inconsistency", "fusion",
            "max_outliers", "window", "risk", "likely", "estimate_bound")  # fmt: skip


def settings_of(maps: BatchedPolygonSLAM) -> dict[str, float | int | bool]:
    """A batch's settings as the file writes them (the kernels' codes)."""
    return {
        "epsilon": maps.epsilon, "transfer": TRANSFERS.index(maps.transfer),
        "edge_samples": maps.edge_samples,
        "on_inconsistency": INCONSISTENCY_POLICIES.index(maps.on_inconsistency),
        "fusion": FUSIONS.index(maps.fusion), "max_outliers": maps.max_outliers,
        "window": maps.window, "risk": maps.risk, "likely": maps.robust_set == ROBUST_SETS[1],
        "estimate_bound": maps.noise_bound == "estimate",
    }  # fmt: skip


def _number(value: float | int | bool) -> str:
    return str(int(value)) if isinstance(value, (bool, int, np.integer)) else repr(float(value))


def _case_lines(case: Case, seed: int, sha256: str) -> list[str]:
    moves = list(movements(case, seed))
    settings = settings_of(new_maps(case))
    lines = [f"case {case.name} {sha256}",
             "settings " + " ".join(_number(settings[name]) for name in SETTINGS),
             f"shape {case.maps} {case.n_landmarks} {case.moves}"]  # fmt: skip
    for b1, b2 in moves:
        lines.append("start " + " ".join(repr(float(v)) for v in b1.ravel()))
        lines.append("end " + " ".join(repr(float(v)) for v in b2.ravel()))
    return lines


def selected_cases() -> list[tuple[Case, int, str]]:
    """Cases whose run here hashes as recorded, round robin over transfer and fusion."""
    recorded = json.loads(GOLDEN_FILE.read_text(encoding="utf-8"))["small"]
    groups: dict[tuple[str, str], list[tuple[Case, int, str]]] = {}
    for case, seed in seeded_cases():
        if run_hash(new_maps(case), movements(case, seed)) == recorded[case.name]:
            groups.setdefault((case.transfer, case.fusion), []).append(
                (case, seed, recorded[case.name])
            )
    chosen: list[tuple[Case, int, str]] = []
    while len(chosen) < MAX_CASES and any(groups.values()):
        for group in groups.values():
            if group and len(chosen) < MAX_CASES:
                chosen.append(group.pop(0))
    return chosen


def write(path: Path = REPLAY_FILE) -> int:
    lines = ["# The golden map corpus's inputs and recorded hashes (tests/golden_replay.py).",
             "# Written by `python -m tests.golden_replay --update`; the C++ test",
             "# tests/cpp/test_golden_replay.cpp replays it."]  # fmt: skip
    chosen = selected_cases()
    for case, seed, sha256 in chosen:
        lines += _case_lines(case, seed, sha256)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return len(chosen)


def read(path: Path = REPLAY_FILE) -> list[ReplayCase]:
    """The file's cases."""
    cases: list[ReplayCase] = []
    rows: list[np.ndarray] = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line or line.startswith("#"):
            continue
        kind, *fields = line.split()
        if kind == "case":
            name, sha256 = fields
            cases.append(ReplayCase(name, sha256, {}, np.zeros(0)))
            rows = []
        elif kind == "settings":
            values = [float(v) if "." in v or "e" in v else int(v) for v in fields]
            cases[-1].settings = dict(zip(SETTINGS, values, strict=True))
        elif kind == "shape":
            maps, landmarks, moves = map(int, fields)
            cases[-1].bearings = np.empty((moves, 2, maps, landmarks))
        elif kind in ("start", "end"):
            rows.append(np.array([float(v) for v in fields]))
            bearings = cases[-1].bearings
            flat = np.stack(rows) if len(rows) == 2 * bearings.shape[0] else None
            if flat is not None:
                bearings[...] = flat.reshape(bearings.shape)
        else:
            raise ValueError(f"{path}: unknown record {kind!r}")
    return cases


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--update", action="store_true", help="write the file")
    args = parser.parse_args(argv)
    if args.update:
        print(f"{write()} cases written to {REPLAY_FILE}")
        return 0
    cases = read()
    differ = [case.name for case in cases if case.replay_hash() != case.sha256]
    print(f"{len(cases)} cases, {len(differ)} replay with another hash: {differ}")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
