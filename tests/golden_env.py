"""Golden env steps at full precision, recorded from the numba env step before the switch.

``tests/golden_traces.py`` hashes floats as float32; this corpus hashes the env traces
(not the policies') with every float64 bit (NaN canonicalised), so the native env step is
held to the numba step's exact numbers. ``tests/golden/env_steps.json`` holds the hashes;
``tests/envs/test_golden_env.py`` compares.

    python -m tests.golden_env [--update] [NAME ...]

``--update`` records the hashes of the traces run (all, or the names given) and keeps
the others' as they were.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

from tests.golden_traces import TRACES, feed

GOLDEN_FILE = Path(__file__).parent / "golden" / "env_steps.json"
#: The traces of the envs themselves (the policies' traces need the train extra).
NAMES = sorted(name for name in TRACES if not name.startswith("policy-"))


def exact_hash(name: str) -> str:
    digest = hashlib.sha256()
    for item in TRACES[name]():
        feed(digest, item, exact=True)
    return digest.hexdigest()


def recorded() -> dict[str, str]:
    return dict(json.loads(GOLDEN_FILE.read_text(encoding="utf-8")))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--update", action="store_true", help="record the current hashes")
    parser.add_argument("names", nargs="*", help="traces to run (default: all)")
    args = parser.parse_args(argv)
    names = args.names or NAMES
    unknown = sorted(set(names) - set(NAMES))
    if unknown:
        parser.error(f"unknown traces {unknown}; the traces are {NAMES}")
    current = {name: exact_hash(name) for name in names}
    old = recorded() if GOLDEN_FILE.exists() else {}
    changed = [name for name in names if old.get(name) != current[name]]
    print(f"{len(names)} traces, {len(changed)} differ: {changed}")
    if args.update:
        GOLDEN_FILE.write_text(json.dumps({**old, **current}, indent=1, sort_keys=True) + "\n")
    return 1 if changed and not args.update else 0


if __name__ == "__main__":
    sys.exit(main())
