"""A seeded search for regions that break the world model's promises.

Fresh maps go through random movements (random layouts in the unit square, uniform
headings, log-uniform move lengths, epsilon uniform in degrees, bearing noise uniform
within +-epsilon), and every region after every movement is checked by
:mod:`bearing_env.slam.audit`: simple and strictly convex, its area equal to shapely's,
finite, and, for the conservative transfer, holding the truth.

    python -m bearing_env.benchmarks.region_search --movements 2000000
    bearing-env region-search --movements 100000 --moves 10 --fusion relaxed

Prints one row per transfer and exits with status 1 if any check failed, listing the
first counter-examples as ``(epsilon, bearings_start, bearings_end)`` for single
movements, ready to replay with ``PolygonSLAM(n, epsilon).update(b1, b2)``. Ctrl-C stops
early and prints what was checked so far.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

from bearing_env.slam import FUSIONS, TRANSFERS
from bearing_env.slam.audit import SearchReport, SearchSettings, search
from bearing_env.train.common.cli_parser import (
    add_json_output,
    add_no_progress,
    command_parser,
    doc_summary,
)
from bearing_env.train.common.cli_values import COUNT, SEED
from bearing_env.train.common.errors import exit_on_output_errors
from bearing_env.train.common.files import write_json_atomically
from bearing_env.train.common.progress import progress_bar

COLUMNS = (
    "movements", "regions", "not_simple_convex", "shapely_invalid", "area_mismatches",
    "nonfinite", "containment_checks", "misses",
)


def run(
    settings: SearchSettings, movements: int, batch: int, seed: int, progress: bool = False
) -> SearchReport:
    """Check at least ``movements`` movements, ``batch`` maps at a time, from ``seed``."""
    rng = np.random.default_rng(seed)
    report = SearchReport()
    with progress_bar(movements, desc=settings.transfer, unit="mv", enabled=progress) as bar:
        try:
            while report.movements < movements:
                maps = min(batch, -(-(movements - report.movements) // settings.moves))
                report.add(search(settings, maps, rng))
                bar.update(maps * settings.moves)
        except KeyboardInterrupt:
            print("interrupted: the figures cover what was checked so far", file=sys.stderr)
    return report


def format_rows(reports: dict[str, SearchReport]) -> list[str]:
    """One row per count, one column per transfer."""
    rows = [f"{'':<20}" + "".join(f"{transfer:>16}" for transfer in reports)]
    for column in COLUMNS:
        counts = "".join(f"{getattr(report, column):>16,}" for report in reports.values())
        rows.append(f"{column:<20}{counts}")
    return rows


def make_parser() -> argparse.ArgumentParser:
    parser = command_parser("bearing-env region-search", doc_summary(__doc__))
    parser.add_argument(
        "--movements", type=COUNT, default=2_000_000,
        help="movements to check per transfer (default %(default)s)",
    )
    parser.add_argument(
        "--transfers", nargs="+", choices=TRANSFERS, default=list(TRANSFERS),
        help="transfers to search (default: both)",
    )
    parser.add_argument("--fusion", choices=FUSIONS, default="intersect", help="map fusion")
    parser.add_argument(
        "--moves", type=COUNT, default=1,
        help="movements per map before a fresh one (default 1: single movements)",
    )
    parser.add_argument(
        "--batch", type=COUNT, default=4096, help="maps per batch (default %(default)s)"
    )
    parser.add_argument("--seed", type=SEED, default=0, help="search seed (default %(default)s)")
    parser.add_argument(
        "--noise-fraction", type=float, default=1.0,
        help="noise bound as a fraction of epsilon; containment is checked when <= 1 "
        "(default %(default)s)",
    )
    add_json_output(parser, "the counts")
    add_no_progress(parser)
    return parser


def parse_args(argv: list[str] | None = None) -> tuple[argparse.ArgumentParser, argparse.Namespace]:
    parser = make_parser()
    args = parser.parse_args(argv)
    if not (math.isfinite(args.noise_fraction) and args.noise_fraction >= 0.0):
        parser.error(f"--noise-fraction must be finite and >= 0, got {args.noise_fraction!r}")
    return parser, args


def main(argv: list[str] | None = None) -> None:
    parser, args = parse_args(argv)
    if args.json:  # an unwritable --json fails before the search, in one line
        with exit_on_output_errors(parser, Path(args.json), "--json", refusals=()):
            Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    base = SearchSettings(fusion=args.fusion, moves=args.moves, noise_fraction=args.noise_fraction)
    reports: dict[str, SearchReport] = {}
    for transfer in args.transfers:
        settings = replace(base, transfer=transfer)
        progress = not args.no_progress
        reports[transfer] = run(settings, args.movements, args.batch, args.seed, progress)
    print(
        f"seed {args.seed}, fusion {args.fusion}, {args.moves} movement(s) per map, "
        f"epsilon {base.epsilon_deg[0]:g}-{base.epsilon_deg[1]:g} deg, "
        f"noise within {args.noise_fraction:g} x epsilon"
    )
    print("\n".join(format_rows(reports)))
    for transfer, report in reports.items():
        for example in report.examples:
            print(f"counter-example ({transfer}): {example!r}")
    if args.json:
        payload = {"settings": asdict(base), "seed": args.seed, "reports": {
            name: {c: getattr(r, c) for c in COLUMNS} | {"examples": r.examples}
            for name, r in reports.items()
        }}
        with exit_on_output_errors(parser, Path(args.json), "--json", refusals=()):
            write_json_atomically(Path(args.json), payload)
    if any(report.defects for report in reports.values()):
        sys.exit(1)


if __name__ == "__main__":
    main()
