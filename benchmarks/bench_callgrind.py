"""``bearing-env bench-callgrind``: instructions per map update and per env step, counted
by valgrind's callgrind, a figure that does not drift with the machine's load.

Ratios to CartPole-v1 (``bearing-env bench``) move with whatever else the machine runs;
callgrind counts the instructions the native core executes, which are the same on every
run of the same build on the same inputs. Use it to compare two versions of a kernel.

    bearing-env bench-callgrind [--movements 400] [--steps 400] [--json out.json]

Runs of a small driver under ``valgrind --tool=callgrind``, each collecting only inside
one native entry point (``--toggle-collect``):

- ``update``: ``bearing::slam::update_maps``, called by ``PolygonSLAM.update``, per
  transfer, on the readings ``bench-slam`` replays: first those recorded from seeded
  BearingSLAM-Khepera-v1 episodes of the random polygonal trajectory (4 landmarks, the
  env's map settings, a fresh map per episode; recorded outside valgrind and handed to
  the driver in a file), then the synthetic readings (4 landmarks, epsilon 2 degrees,
  one layout in a 100 x 100 arena, repeated), a secondary figure;
- ``step``: ``bearing::env::step_rows``, the whole native env step (moves, readings, map
  update, rewards, observation and info arrays), on ``BearingSLAM-Khepera-v1`` with
  seeded random actions.

Each figure is the instruction count (callgrind's Ir) divided by the movements or steps,
and the functions with the largest inclusive share are listed: where the time goes.
"""

from __future__ import annotations

import dataclasses
import json
import re
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from bearing_env.benchmarks.bench_readings import SYNTHETIC_LABEL
from bearing_env.slam.transfer import TRANSFERS
from bearing_env.train.common.cli_parser import add_json_output, command_parser, doc_summary
from bearing_env.train.common.cli_values import at_least
from bearing_env.train.common.doc_tables import markdown_table
from bearing_env.train.common.errors import exit_on_output_errors
from bearing_env.train.common.files import atomic_write_text
from bearing_env.train.common.provenance import measured_here, measured_sentence

#: The native entry point each measurement collects inside.
ENTRY_POINTS = {"update": "bearing::slam::update_maps*", "step": "bearing::env::step_rows*"}
#: The step's entry functions (each holds the whole step), left out of the page's table.
ENTRY_NAMES = ("step_into", "step_rows")

#: The workloads of the update counts: (key, what the page calls them), the first primary.
UPDATE_WORKLOADS: tuple[tuple[str, str], ...] = (
    ("khepera", "recorded Khepera-v1 readings"),
    ("synthetic_4", SYNTHETIC_LABEL),
)

UPDATE_DRIVER = """
import dataclasses, json, sys
import numpy as np
from bearing_env.slam import MapSettings, PolygonSLAM
movements, transfer, path = int(sys.argv[1]), sys.argv[2], sys.argv[3]
data = np.load(path)
start, end, episodes = data["start"], data["end"], data["episodes"]
settings = MapSettings(**json.loads(str(data["settings"])))
slam = PolygonSLAM.from_settings(start.shape[1], dataclasses.replace(settings, transfer=transfer))
done = 0
while done < movements:
    for k in range(len(start)):
        if done == movements:
            break
        if k == 0 or episodes[k] != episodes[k - 1]:
            slam.reset()
        slam.update(start[k], end[k])
        done += 1
print(done)
"""


def save_workload(key: str, path: Path) -> None:
    """Write the readings of workload ``key`` (:data:`UPDATE_WORKLOADS`) to ``path`` for
    :data:`UPDATE_DRIVER`: recorded here, outside valgrind, whose count would otherwise
    take in the recording's env steps (which update maps too)."""
    from bearing_env.benchmarks import bench_slam

    workload = (
        bench_slam.recorded_workload("BearingSLAM-Khepera-v1")
        if key == "khepera"
        else bench_slam.synthetic_workload(int(key.rpartition("_")[2]))
    )
    pairs = [pair for episode in workload.episodes for pair in episode]
    episodes = [index for index, episode in enumerate(workload.episodes) for _ in episode]
    np.savez(
        path,
        start=np.array([b1 for b1, _ in pairs]),
        end=np.array([b2 for _, b2 in pairs]),
        episodes=np.array(episodes, dtype=np.int64),
        settings=json.dumps(dataclasses.asdict(workload.settings)),
    )


STEP_DRIVER = """
import sys
import gymnasium as gym
import numpy as np
import bearing_env
steps = int(sys.argv[1])
env = gym.make("BearingSLAM-Khepera-v1").unwrapped
env.reset(seed=0)
rng = np.random.default_rng(0)
for _ in range(steps):
    action = rng.uniform(-1.0, 1.0, 2).astype(np.float32)
    _, _, terminated, truncated, _ = env.step(action)
    if terminated or truncated:
        env.reset()
print(steps)
"""


def count(driver: str, entry: str, arguments: Sequence[str], top: int = 12) -> dict[str, Any]:
    """Run ``driver`` under callgrind collecting inside ``entry``; the total instructions
    and the ``top`` functions by inclusive instructions."""
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        raise SystemExit("bearing-env bench-callgrind: valgrind is not installed")
    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "callgrind.out"
        command = [
            valgrind, "--tool=callgrind", f"--callgrind-out-file={out}",
            f"--toggle-collect={entry}", sys.executable, "-c", driver, *arguments,
        ]  # fmt: skip
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            raise SystemExit(f"callgrind run failed:\n{result.stderr[-3000:]}")
        totals = re.search(r"^(?:totals|summary): (\d+)", out.read_text(), re.M)
        if totals is None:
            raise SystemExit(f"no totals in {out}")
        annotate = subprocess.run(
            ["callgrind_annotate", "--inclusive=yes", str(out)],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
    return {"instructions": int(totals[1]), "functions": functions_of(annotate, top)}


def functions_of(annotate: str, top: int) -> list[dict[str, Any]]:
    """The ``top`` functions of ``callgrind_annotate --inclusive=yes`` output, largest
    first: short name, inclusive instructions and share of the total."""
    functions: list[dict[str, Any]] = []
    for line in annotate.splitlines():
        # "count (share%) file:function [object]"; the file part has no colon.
        match = re.match(r"\s*([\d,]+)\s+\(\s*([\d.]+)%\)\s+[^\s:]+:(.+?)(?: \[(.*)\])?$", line)
        # The core's own functions and the maths library's: not the interpreter's frames
        # above the entry point nor nanobind's call wrappers, which hold every
        # instruction and say nothing.
        if match and _counted_object(match[4]) and not match[3].startswith(NANOBIND_WRAPPERS):
            if len(functions) == top:
                break
            instructions = int(match[1].replace(",", ""))
            functions.append(
                {"function": _short_name(match[3]), "instructions": instructions,
                 "share": float(match[2]) / 100}
            )  # fmt: skip
    return functions


#: nanobind's frames between the interpreter and a bound function, and the bindings' own
#: (``csrc/bindings``: argument parsing around each kernel, the lambdas of the module's
#: ``bind_*`` registration functions among them).
NANOBIND_WRAPPERS = ("nanobind::", "nb_func_", "func_create<", "bearing::bindings::", "bind_")


def _short_name(signature: str) -> str:
    """A function's qualified name without its parameter list or clone suffixes."""
    name = signature.strip().replace("(anonymous namespace)", "{anonymous}")
    return name.split("(", 1)[0]


def _counted_object(path: str | None) -> bool:
    """Whether a function of the shared object at ``path`` is listed: the native core's
    or the maths library's (``hypot``, ``atan2``)."""
    name = Path(path or "").name
    return name.startswith(("_core.", "libm.", "libm-"))


def main(argv: Sequence[str] | None = None) -> None:
    parser = command_parser("bearing-env bench-callgrind", doc_summary(__doc__))
    parser.add_argument("--movements", type=at_least(1), default=400,
                        help="map updates counted per transfer (default %(default)s)")  # fmt: skip
    parser.add_argument("--steps", type=at_least(1), default=400,
                        help="env steps counted (default %(default)s)")  # fmt: skip
    add_json_output(parser, "the counts")
    arguments = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(arguments)
    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory() as folder:
        for key, label in UPDATE_WORKLOADS:
            path = Path(folder) / f"{key}.npz"
            save_workload(key, path)
            for transfer in TRANSFERS:
                counted = count(UPDATE_DRIVER, ENTRY_POINTS["update"],
                                [str(args.movements), transfer, str(path)])  # fmt: skip
                per = counted["instructions"] / args.movements
                results[f"update_{transfer}_{key}"] = {
                    **counted,
                    "count": args.movements,
                    "per_call": per,
                    "readings": label,
                }
                print(f"PolygonSLAM.update, {label}, {transfer:>12}: {per:12,.0f} "
                      "instructions per movement")  # fmt: skip
    counted = count(STEP_DRIVER, ENTRY_POINTS["step"], [str(args.steps)])
    per = counted["instructions"] / args.steps
    results["step_khepera"] = {**counted, "count": args.steps, "per_call": per}
    print(f"BearingSLAM-Khepera-v1 env step (native part):   {per:12,.0f} instructions per step")
    if args.json is not None:
        record = {"measured": measured_here("bearing-env bench-callgrind", arguments),
                  "counts": results}  # fmt: skip
        with exit_on_output_errors(parser, args.json, "--json", refusals=()):
            atomic_write_text(args.json, json.dumps(record, indent=2))


#: The functions of a Khepera env step the performance page lists (the core's main parts).
PAGE_FUNCTIONS = 6


def markdown_callgrind(record: dict[str, Any]) -> str:
    """The performance page's instruction counts (``bearing-env docs-tables``), from
    :func:`main`'s ``--json`` file: per movement and per step, then where a Khepera env
    step's instructions go."""
    counts = record["counts"]
    step = counts["step_khepera"]
    sentence = (
        f"{measured_sentence(record['measured'], 'benchmarks/results/bench_callgrind.json')} "
        "Instructions per 4-landmark movement, "
        + "; ".join(
            f"on {label}: "
            + ", ".join(
                f"{counts[f'update_{transfer}_{key}']['per_call']:,.0f} {transfer}"
                for transfer in TRANSFERS
                if f"update_{transfer}_{key}" in counts
            )
            for key, label in UPDATE_WORKLOADS
            if any(f"update_{transfer}_{key}" in counts for transfer in TRANSFERS)
        )
        + "; per Khepera env "
        f"step (native part, {step['count']} steps): {step['per_call']:,.0f}, of which:"
    )
    names = [(entry["function"].rpartition("::")[2], entry) for entry in step["functions"]]
    # The entry point (its checked forms, step_into and step_rows, and the kernel) holds
    # every instruction, and the update's per-row loop (update_rows, update_row) holds
    # what update_maps holds.
    parts = [
        (name, entry)
        for name, entry in names
        if name not in ENTRY_NAMES and not name.startswith("update_row")
    ]
    rows = [(f"`{name}`", f"{entry['share']:.0%}") for name, entry in parts[:PAGE_FUNCTIONS]]
    return sentence + "\n\n" + markdown_table(("function (inclusive)", "share of a step"), rows)


if __name__ == "__main__":
    main()
