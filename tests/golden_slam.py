"""Golden map updates: hashes of every map state after every movement, over fixed seeds.

The native core was ported from numba kernels that were compared with it bit for bit.
This corpus keeps that reference after the numba kernels are gone: each case runs a batch
of maps through seeded movement sequences with :class:`BatchedPolygonSLAM` (the public
API) and hashes every state array and every update result, as float64 bits (NaN
canonicalised: its payload carries no information), after every movement.
``tests/golden/slam_updates.json`` holds the hashes the numba kernels gave for the
``"paper"`` and ``"conservative_global"`` transfers (the latter recorded as
``"conservative"``, its name then), and the hashes of the local-bound ``"conservative"``
transfer from its first version; ``tests/slam/test_golden_slam.py`` compares.

    python -m tests.golden_slam              # print the hashes, and any changes
    python -m tests.golden_slam --update     # record them (only for a deliberate change)
    python -m tests.golden_slam --large      # the large corpus (slow test), same options

The cases cover the three transfers (several edge samples), the three fusions (the robust one
with and without the bound estimate, guaranteed and likely sets), both inconsistency
policies, 3 to 30 landmarks, epsilon from 0.5 to 10 degrees, noise beyond epsilon,
outlying and missed readings, and moves that barely change frames.
"""

from __future__ import annotations

import argparse
import hashlib
import itertools
import json
import sys
from collections import Counter
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from bearing_env.slam import BatchedPolygonSLAM
from bearing_env.slam.batch import FRAME_STATUSES, LANDMARK_STATUSES
from tests.slam_sim import random_episode, wrap

GOLDEN_FILE = Path(__file__).parent / "golden" / "slam_updates.json"


@dataclass(frozen=True)
class Case:
    """One corpus case: map settings and how its movements are drawn."""

    transfer: str
    fusion: str
    n_landmarks: int
    epsilon_deg: float
    edge_samples: int = 3
    on_inconsistency: str = "restart"
    robust_set: str = "guaranteed"
    noise_bound: str = "estimate"
    noise_factor: float = 1.0  #: the true noise bound, over epsilon
    outlier_rate: float = 0.0  #: readings replaced by a uniform angle
    missing_rate: float = 0.0  #: readings lost (NaN)
    maps: int = 6
    moves: int = 12
    length_range: tuple[float, float] = (0.1, 0.3)

    @property
    def name(self) -> str:
        parts = [self.transfer, self.fusion, f"n{self.n_landmarks}", f"e{self.epsilon_deg:g}",
                 f"s{self.edge_samples}", self.on_inconsistency]  # fmt: skip
        if self.fusion == "robust":
            parts += [self.robust_set, self.noise_bound]
        parts += [f"x{self.noise_factor:g}", f"o{self.outlier_rate:g}",
                  f"m{self.missing_rate:g}", f"L{self.length_range[0]:g}"]  # fmt: skip
        return "-".join(parts)


def _cases(large: bool) -> list[Case]:
    cases: list[Case] = []
    transfers = (
        ("conservative_global", 3),
        ("conservative_global", 2),
        ("paper", 3),
        ("conservative", 3),
        ("conservative", 2),
    )
    fusions = (
        ("intersect", {}),
        ("relaxed", {}),
        ("robust", {}),
        ("robust", {"robust_set": "likely"}),
        ("robust", {"noise_bound": "nominal"}),
    )
    noises = (
        {"noise_factor": 1.0},
        {"noise_factor": 1.6, "on_inconsistency": "keep"},
        {"noise_factor": 1.0, "outlier_rate": 0.05, "missing_rate": 0.05},
        {"noise_factor": 1.3, "missing_rate": 0.1, "length_range": (0.02, 0.08)},
    )
    shapes = ((3, 2.0), (5, 0.5), (8, 6.0), (30, 10.0)) if large else ((4, 2.0), (7, 5.0))
    for (transfer, samples), (fusion, extra), noise, (n, eps) in itertools.product(
        transfers, fusions, noises, shapes
    ):
        settings: dict[str, Any] = {**extra, **noise}
        cases.append(Case(transfer, fusion, n, eps, edge_samples=samples,
                          maps=16 if large else 4, moves=24 if large else 10,
                          **settings))  # fmt: skip
    return cases


def _feed(digest: Any, array: np.ndarray) -> None:
    array = np.ascontiguousarray(array)
    if array.dtype.kind == "c":
        array = np.ascontiguousarray(np.stack([array.real, array.imag], axis=-1))
    if array.dtype.kind == "f":
        array = np.where(np.isnan(array), np.nan, array)  # one NaN bit pattern
    digest.update(f"{array.dtype.str}{array.shape}".encode())
    digest.update(array.tobytes())


def new_maps(case: Case) -> BatchedPolygonSLAM:
    """The case's batch of empty maps."""
    return BatchedPolygonSLAM(
        case.maps, case.n_landmarks, np.deg2rad(case.epsilon_deg), transfer=case.transfer,
        edge_samples=case.edge_samples, on_inconsistency=case.on_inconsistency,
        fusion=case.fusion, robust_set=case.robust_set, noise_bound=case.noise_bound,
    )  # fmt: skip


def movements(case: Case, seed: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """The case's bearings, (maps, n_landmarks) at R1 and at R2, movement by movement
    (drawn from ``seed`` as they are fed, in this order)."""
    rng = np.random.default_rng(seed)
    epsilon = np.deg2rad(case.epsilon_deg)
    episodes = [
        random_episode(rng, case.n_landmarks, case.moves, length_range=case.length_range)
        for _ in range(case.maps)
    ]
    readings = [episode.readings(case.noise_factor * epsilon) for episode in episodes]
    for move in range(case.moves):
        b1 = np.array([readings[k][move][0] for k in range(case.maps)])
        b2 = np.array([readings[k][move][1] for k in range(case.maps)])
        for bearings in (b1, b2):
            outliers = rng.random(bearings.shape) < case.outlier_rate
            bearings[outliers] = wrap(rng.uniform(-np.pi, np.pi, int(outliers.sum())))
            bearings[rng.random(bearings.shape) < case.missing_rate] = np.nan
        yield b1, b2


def run_hash(
    maps: BatchedPolygonSLAM,
    moves: Iterable[tuple[np.ndarray, np.ndarray]],
    seen: Counter[str] | None = None,
) -> str:
    """The sha256 of ``maps``' run through ``moves`` (every update's result and every
    state array after every movement); ``seen`` counts the statuses met."""
    digest = hashlib.sha256()
    for b1, b2 in moves:
        result = maps.update(b1, b2)
        if seen is not None:
            seen.update(f"frame {FRAME_STATUSES[c]}" for c in result.frame_status)
            seen.update(f"landmark {LANDMARK_STATUSES[c]}" for c in result.landmark_status.ravel())
        for value in (result.frame_status, result.landmark_status, result.n_inconsistent):
            _feed(digest, np.asarray(value))
        for name in maps.state_names:
            _feed(digest, getattr(maps, name))
    return digest.hexdigest()


def case_hash(case: Case, seed: int, seen: Counter[str] | None = None) -> str:
    """The sha256 of a case's whole run (every state and result after every movement);
    ``seen`` counts the frame and landmark statuses met, and the robust bound's growths."""
    maps = new_maps(case)
    digest = run_hash(maps, movements(case, seed), seen)
    if seen is not None and case.fusion == "robust":
        seen["robust bound growths"] += int(np.sum(maps.bound_events > 0))
    return digest


def seeded_cases(large: bool = False) -> list[tuple[Case, int]]:
    """The corpus's cases, each with its seed (fixed by the case's place in the list)."""
    return [(case, 1000 + index) for index, case in enumerate(_cases(large))]


def corpus(large: bool = False, seen: Counter[str] | None = None) -> dict[str, str]:
    """Every case's hash."""
    return {case.name: case_hash(case, seed, seen=seen) for case, seed in seeded_cases(large)}


def recorded() -> dict[str, dict[str, str]]:
    return dict(json.loads(GOLDEN_FILE.read_text(encoding="utf-8")))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--update", action="store_true", help="record the current hashes")
    parser.add_argument("--large", action="store_true", help="the large corpus")
    args = parser.parse_args(argv)
    key = "large" if args.large else "small"
    hashes = corpus(args.large)
    old = recorded() if GOLDEN_FILE.exists() else {}
    changed = sorted(k for k, v in hashes.items() if old.get(key, {}).get(k) != v)
    print(f"{len(hashes)} cases, {len(changed)} differ from the recorded {key} corpus")
    for name in changed:
        print(f"  {name}")
    if args.update:
        GOLDEN_FILE.write_text(json.dumps({**old, key: hashes}, indent=1, sort_keys=True) + "\n")
        print(f"recorded in {GOLDEN_FILE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
