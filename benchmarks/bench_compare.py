"""``bearing-env compare`` on Ray against local worker processes: speed-up and overhead.

    python -m bearing_env.benchmarks.bench_compare                  # 200 episodes, 2 repeats
    python -m bearing_env.benchmarks.bench_compare --episodes 50 --repeats 1

Runs one comparison (``--policies``, ``--episodes`` each, the Khepera scenario) in these
ways, each ``--repeats`` times, and prints the wall times (min-max over the repeats):

- ``local, 1 process``: ``--workers 1``, in this process after an untimed first run
  (so its env and policies are built: the episodes alone); the baseline of every
  speed-up;
- ``local, 2 processes``: ``--workers 2`` (new worker processes each time, as a user
  runs it);
- ``ray, new instance``: ``--executor ray`` as a user runs it on one machine: the wall
  time includes starting a local Ray instance (all cores) and its workers;
- ``ray, running instance``: the same on a Ray instance started beforehand (its workers
  new: each builds its env and policies);
- ``ray, warm workers``: that instance's second run (workers already built them);
- ``ray, 1 CPU, warm``: a 1-CPU instance's second run;
- ``ray, 1 CPU, empty tasks``: as many tasks as episodes, submitted and collected as
  ``--executor ray`` does, each sending an episode's task and returning a real
  episode's record without playing it. Its time divided by the episodes is Ray's
  overhead per episode (scheduling, serialising the task and the record, the object
  store) on this machine.

Speed-ups and the overhead are computed within each repeat (the machine's load drifts
between repeats) and given as min-max over the repeats.

Every run must give the same ``summary.json`` (checked). The JSON (``--json``, default
``outputs/bench_compare.json``) holds every time. The machine is shared: quote ranges.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from bearing_env.extras import require
from bearing_env.train.compare.comparison import run_comparison
from bearing_env.train.compare.config import CompareConfig, policies_from_specs
from bearing_env.train.compare.log import LOG_NAME, EpisodeLog
from bearing_env.train.compare.runner import EpisodeTask, episode_tasks, executor_named

DEFAULT_POLICIES = ("random", "parallax", "greedy")


def _echo(task: EpisodeTask, record: dict[str, Any]) -> dict[str, Any]:
    """A Ray task that returns an episode's record without playing it."""
    return {**record, "policy": task.label, "seed": task.seed}


def _timed(run: Callable[[], Any]) -> float:
    started = time.perf_counter()
    run()
    return time.perf_counter() - started


def bench(
    config: CompareConfig, repeats: int, work: Path, progress: bool = False
) -> dict[str, list[float]]:
    """Wall seconds per way of running (see the module doc), ``repeats`` each."""
    ray = require("ray", "the Ray benchmark", extra="ray")
    times: dict[str, list[float]] = {}
    summaries: set[str] = set()
    counter = iter(range(1_000_000))

    def compare(name: str, **kwargs: Any) -> None:
        out = work / f"run{next(counter)}"
        seconds = _timed(
            lambda: run_comparison(config, out, progress=progress, plots=False, **kwargs)
        )
        times.setdefault(name, []).append(seconds)
        summaries.add((out / "summary.json").read_text())
        print(f"  {name:<24} {seconds:7.2f} s", flush=True)

    # This process builds its env and policies once and keeps them (as a Ray worker
    # does): an untimed first run, so that "local, 1 process" times the episodes alone.
    run_comparison(config, work / "warm-up", progress=False, plots=False)
    record = EpisodeLog(work / "warm-up" / LOG_NAME).load()[-1]
    tasks = episode_tasks(config, set())
    for repeat in range(repeats):
        print(f"repeat {repeat + 1} of {repeats}", flush=True)
        compare("local, 1 process", workers=1)
        compare("local, 2 processes", workers=2)
        compare("ray, new instance", executor=executor_named("ray"))
        started = time.perf_counter()
        ray.init(include_dashboard=False, log_to_driver=False)
        times.setdefault("ray start-up (ray.init)", []).append(time.perf_counter() - started)
        try:
            compare("ray, running instance", executor=executor_named("ray"))
            compare("ray, warm workers", executor=executor_named("ray"))
        finally:
            ray.shutdown()
        ray.init(num_cpus=1, include_dashboard=False, log_to_driver=False)
        try:
            compare("ray, 1 CPU", executor=executor_named("ray"))
            compare("ray, 1 CPU, warm", executor=executor_named("ray"))
            echo = ray.remote(num_cpus=1, max_retries=0)(_echo)

            def empty_tasks(echo: Any = echo) -> None:
                pending = [echo.remote(task, record) for task in tasks]
                while pending:
                    ready, pending = ray.wait(pending, num_returns=1)
                    ray.get(ready[0])

            seconds = _timed(empty_tasks)
            times.setdefault("ray, 1 CPU, empty tasks", []).append(seconds)
            print(f"  {'ray, 1 CPU, empty tasks':<24} {seconds:7.2f} s", flush=True)
        finally:
            ray.shutdown()
    if len(summaries) != 1:
        raise AssertionError("the runs gave different summaries")
    return times


def report(times: dict[str, list[float]], episodes: int) -> list[str]:
    """The table: each way's time range and its speed-up over one local process in the
    same repeat (min-max over the repeats), then Ray's overhead per episode."""
    base = times["local, 1 process"]
    lines = [f"{'run':<26} {'wall s (min-max)':>18} {'vs 1 process':>14} {'vs 2 processes':>16}"]

    def speed_up(name: str, over: str) -> str:
        if over not in times or name.startswith("ray start") or "empty" in name:
            return ""
        ratios = [ref / value for ref, value in zip(times[over], times[name], strict=True)]
        return f"{min(ratios):.2f}-{max(ratios):.2f}x"

    for name, values in times.items():
        low, high = min(values), max(values)
        lines.append(
            f"{name:<26} {f'{low:.2f}-{high:.2f}':>18} "
            f"{speed_up(name, 'local, 1 process'):>14} {speed_up(name, 'local, 2 processes'):>16}"
        )
    empty = [1000.0 * value / episodes for value in times["ray, 1 CPU, empty tasks"]]
    local = [1000.0 * value / episodes for value in base]
    lines.append(
        f"Ray's overhead per episode (1 CPU, empty tasks): {min(empty):.2f}-{max(empty):.2f} "
        f"ms; an episode takes {min(local):.2f}-{max(local):.2f} ms in one local process"
    )
    return lines


def main(argv: Sequence[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        prog="bench_compare", description=__doc__.splitlines()[0] if __doc__ else None
    )
    parser.add_argument("--episodes", type=int, default=200, help="per policy (%(default)s)")
    parser.add_argument("--policies", nargs="+", default=list(DEFAULT_POLICIES))
    parser.add_argument("--repeats", type=int, default=2, help="(default %(default)s)")
    parser.add_argument("--json", type=Path, default=Path("outputs/bench_compare.json"))
    args = parser.parse_args(argv)
    if args.episodes < 1 or args.repeats < 1:
        parser.error("--episodes and --repeats must be >= 1")
    config = CompareConfig(
        policies=policies_from_specs(args.policies),
        env_kwargs={"scenario": "khepera"},
        episodes=args.episodes,
        bootstrap=200,
    )
    total = args.episodes * len(config.policies)
    print(f"{total} episodes ({args.episodes} x {', '.join(config.policies)}), Khepera")
    with tempfile.TemporaryDirectory() as work:
        times = bench(config, args.repeats, Path(work))
    lines = report(times, total)
    print("\n".join(lines))
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(
        json.dumps(
            {"episodes": total, "policies": config.policies, "seconds": times, "report": lines},
            indent=1,
        )
        + "\n"
    )
    print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
