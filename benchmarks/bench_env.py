"""``bearing-env bench``, the command line: env, vector env and PPO throughput of
BearingSLAM-v1 against CartPole-v1, in one run. The figures are measured by
:mod:`~bearing_env.benchmarks.bench_timing` and reported (targets, JSON, table) by
:mod:`~bearing_env.benchmarks.bench_report`.

    python benchmarks/bench_env.py [--seconds 2] [--sections single,vector,ppo] [--quick]
    bearing-env bench --sections throughput      # EnvPool/gymnax-style table vs CartPole-v1
    bearing-env bench [...]                      # the same
    bearing-env bench --profile single           # cProfile of the single-env loop
    bearing-env bench --slam [--seconds 2]       # the world-model benchmark (bench_slam.py)

Absolute rates drift on shared machines, so every figure is also given as a ratio to
Gymnasium's CartPole-v1 ``env.step`` rate (``gym.make("CartPole-v1")`` with its default
wrappers, :func:`bearing_env.benchmarks.bench_slam.cartpole_steps_per_second`). The reference is
measured at the start, again before each section (before each PPO variant), and at the
end; each figure is divided by the reference measured closest to it in time, and also by
the start reference.

Sections:

- ``single``: one env, ``gym.make("BearingSLAM-v1", ...).unwrapped``, seeded random
  actions sampled ahead of the timed loop (a block of 4,096, cycled), ``reset()`` at the
  end of each episode (resets count in the time, not as steps). The Khepera scenario,
  and the random scenario with 4, 16 and 64 landmarks
  (``max_landmarks = n``). One more row steps the Khepera env through ``gym.make``'s
  wrappers, as a user (or SB3's DummyVecEnv) does, and one the Khepera env made with
  ``robot_map_info=False`` (no ``info["robot_map"]``). The limited sensor's rows: the
  furnished room with its obstacles and without them (its panoramic, empty reference),
  and Khepera with a 90 degree camera; ``step_cost_ratio`` is a step's time over its
  reference's (target: <= 1.5 for the furnished room).
- ``vector``: ``gym.make_vec`` with ``vectorization_mode="vector_entry_point"`` (the
  batched ``BearingSLAMVectorEnv``; also with ``robot_map_info=False``) and with
  ``"sync"`` (a SyncVectorEnv of single envs, the baseline) for each ``--num-envs``.
  Rates are env transitions per second summed over the sub-envs; in NEXT_STEP autoreset
  mode the reset-only sub-steps that follow an episode's end count in the time but not
  as transitions.
- ``slam``: ``PolygonSLAM.update`` alone (:mod:`bearing_env.benchmarks.bench_slam`), both
  transfers: first on the readings of the random polygonal trajectory recorded from
  seeded BearingSLAM-Khepera-v1 (4 landmarks) and BearingSLAM-Random8-v1 (8) episodes,
  then, as secondary rows, on the synthetic readings (one layout in a 100 x 100 arena,
  repeated) with 4 and 64 landmarks. The median, min and max over 5 runs, each figure
  against its run's CartPole-v1 rate.
- ``startup``: whole fresh processes, timed from before their start to their exit: one
  imports bearing_env, makes ``BearingSLAM-Khepera-v1``, resets and steps it once; the
  other runs the same script on CartPole-v1 without importing bearing_env. They run
  alternately, five timed pairs after an untimed one (which writes the bytecode caches),
  with empty HOME and XDG_CACHE_HOME folders; the figure is the ratio of the medians. The
  first bearing_env process is kept as the cold figure, and whether numba was imported
  (it must not be: the core is compiled when the package is built).
- ``planning``: ``agents.GreedyOneStep``'s planning time per move (its ``act()``, which
  scores 16 candidate moves on copies of the map), Khepera scenario, the median over the
  moves of several episodes. Seconds, not a ratio.
- ``ppo``: SB3 ``PPO`` with the shipped ``ppo.yml``'s settings for BearingSLAM-v1
  (VecNormalize included) on ``--ppo-envs`` envs built by
  ``bearing_env.train.sb3.training_envs.make_training_env``
  for each vec env kind (batched, subproc with spawn, dummy). The rate is env steps per
  second of wall time of ``model.learn()``, measured after a warm-up ``learn()`` of one
  rollout, so process start-up and torch initialisation are excluded. PPO always finishes
  the rollout it starts, so ``--ppo-steps`` is rounded up to whole rollouts. All kinds
  are built first, then timed in ``--ppo-rounds`` interleaved rounds (each round times
  every kind once, in turn): a kind's rate is its median round and its ratio to
  SubprocVecEnv the median of the per-round ratios, so that a machine whose speed drifts
  during the run favours no kind.
- ``throughput``: the table in EnvPool's and gymnax's format, rows = ``--counts`` sub-envs
  (default 1, 64, 256, 1024), columns = CartPole-v1 steps/s, BearingSLAM-v1 steps/s (the
  batched env) and their ratio, random actions sampled up front, each pair measured back
  to back; then PPO on ``--ppo-envs`` batched envs against the same SB3 PPO (the same
  hyperparameters) on CartPole-v1 in a DummyVecEnv, in ``--ppo-rounds`` interleaved rounds.
  Details: :mod:`bearing_env.benchmarks.bench_throughput`.

Targets (printed as met / not met and stored in the JSON;
:data:`~bearing_env.benchmarks.bench_report.TARGETS` holds them):

a. single env, Khepera scenario: ``env.step`` >= 20% of CartPole-v1's step rate;
b. batched env, 64 sub-envs (Khepera, 4 landmarks): total env steps/s >= 50% of
   CartPole-v1's single-env step rate; i. with 256 sub-envs: >= 60%;
c. 64 landmarks at >= 1/16 of the 4-landmark single-env rate;
d. PPO on the batched env >= 2x the env steps/s of PPO on SubprocVecEnv, same n_envs;
e. ``PolygonSLAM.update`` on the recorded Khepera-v1 readings, conservative: >= 60% of
   CartPole-v1's step rate;
f. a fresh process that imports bearing_env, makes BearingSLAM-Khepera-v1 and steps once
   takes <= 1.5x the same script on CartPole-v1 (no bearing_env import), side by side;
g. ``GreedyOneStep`` plans a move in <= 0.5 ms (median);
h. PPO on 16 batched envs >= 0.7x the env steps/s of the same SB3 PPO on CartPole-v1,
   same n_envs (the throughput section).
"""

from __future__ import annotations

import argparse
import datetime as _dt
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from bearing_env.benchmarks.bench_report import (
    DEFAULT_JSON,
    JSON_FORMAT,
    evaluate_targets,
    machine_info,
    print_table,
    write_json,
)
from bearing_env.benchmarks.bench_throughput import (
    DEFAULT_THROUGHPUT_COUNTS,
    QUICK_THROUGHPUT_COUNTS,
    bench_throughput,
)
from bearing_env.benchmarks.bench_timing import (
    DEFAULT_NUM_ENVS,
    DEFAULT_PPO_ENVS,
    DEFAULT_PPO_ROUNDS,
    DEFAULT_PPO_STEPS,
    DEFAULT_SECONDS,
    DEFAULT_SINGLE_LANDMARKS,
    PLANNING_EPISODES,
    PPO_KINDS,
    QUICK_PPO_OVERRIDES,
    QUICK_STARTUP_RUNS,
    SECTIONS,
    STARTUP_RUNS,
    Bench,
    bench_planning,
    bench_ppo,
    bench_single,
    bench_slam_updates,
    bench_startup,
    bench_vector,
    log,
    profile,
)
from bearing_env.envs.config import MAX_N_LANDMARKS
from bearing_env.train.common.cli_parser import command_parser
from bearing_env.train.common.cli_values import (
    COUNT,
    at_least,
    json_safe,
    parse_key_values,
    seconds,
)
from bearing_env.train.common.errors import exit_on_output_errors

# --------------------------------------------------------------------------------------
# Command line
# --------------------------------------------------------------------------------------


def _split_list(values: Sequence[str]) -> list[str]:
    return [item for value in values for item in value.replace(",", " ").split()]


def _int_list(
    values: Sequence[str], option: str, minimum: int = 1, maximum: int | None = None
) -> list[int]:
    """The integers of ``values`` (comma or space separated), each checked by
    ``cli_values.at_least(minimum, maximum)``; ArgumentTypeError naming ``option``."""
    check = at_least(minimum, maximum)
    items = _split_list(values)
    if not items:
        raise argparse.ArgumentTypeError(f"argument {option}: expected integers")
    try:
        return [check(item) for item in items]
    except argparse.ArgumentTypeError as error:
        raise argparse.ArgumentTypeError(f"argument {option}: {error}") from None


def _check_env_kwargs(env_kwargs: dict[str, Any]) -> None:
    """Build (and close) one BearingSLAM-v1 env with ``env_kwargs``: an unknown or bad
    kwarg fails now, in one line, not after minutes of measurements."""
    import gymnasium as gym

    try:
        gym.make("BearingSLAM-v1", **env_kwargs).close()
    except (TypeError, ValueError) as error:
        raise ValueError(f"--env-kwargs: {error}") from None


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env bench",
        "BearingSLAM-v1 single-env, vector-env and PPO throughput, each as a ratio "
        "to CartPole-v1 steps/s measured in the same run; printed as a table and written to "
        "JSON. (The world-model update() benchmark: bearing-env bench --slam.)",
    )
    _add_run_options(parser.add_argument_group("the run"))
    _add_env_options(parser.add_argument_group("single and vector env sections"))
    _add_ppo_options(parser.add_argument_group("PPO section (and the throughput section's PPO)"))
    _add_throughput_options(parser.add_argument_group("throughput section"))
    _add_profile_options(parser.add_argument_group("profiling"))
    return parser


def _add_run_options(group: argparse._ArgumentGroup) -> None:
    """What is measured, how long, and where the figures go."""
    add = group.add_argument
    add(
        "--seconds",
        type=seconds,
        default=None,
        help=f"time per measurement, finite and > 0 (default {DEFAULT_SECONDS:g})",
    )
    add("--json", type=Path, default=DEFAULT_JSON, help="output JSON (default %(default)s)")
    add("--no-json", action="store_true", help="do not write the JSON")
    add(
        "--sections",
        nargs="+",
        default=[",".join(SECTIONS)],
        metavar="SECTION",
        help=f"comma/space separated subset of {','.join(SECTIONS)} (default all)",
    )
    add(
        "--quick",
        action="store_true",
        help="tiny settings for tests: 0.05 s, 1 and 4 envs (and sub-envs), PPO on 2 envs, "
        "8-step rollouts, one timed pair of start-up processes",
    )
    add(
        "--slam",
        action="store_true",
        help="run the world-model benchmark (bench_slam.py) instead, with the other arguments",
    )


def _add_env_options(group: argparse._ArgumentGroup) -> None:
    """The envs of the single and vector sections."""
    add = group.add_argument
    add(
        "--num-envs",
        nargs="+",
        default=None,
        metavar="N",
        help="vector env sizes (default " + ",".join(map(str, DEFAULT_NUM_ENVS)) + ")",
    )
    add(
        "--landmarks",
        nargs="+",
        default=None,
        metavar="N",
        help=f"landmark counts of the single-env random scenario, 3 to {MAX_N_LANDMARKS} "
        "(default " + ",".join(map(str, DEFAULT_SINGLE_LANDMARKS)) + ")",
    )
    add(
        "--env-kwargs",
        nargs="*",
        default=[],
        metavar="K=V",
        help="env kwargs of the vector and PPO sections (default scenario=khepera)",
    )


def _add_ppo_options(group: argparse._ArgumentGroup) -> None:
    """The PPO section: its envs, steps, rounds, vec env kinds and hyperparameters."""
    add = group.add_argument
    add("--ppo-envs", type=COUNT, default=None, help=f"PPO n_envs (default {DEFAULT_PPO_ENVS})")
    add(
        "--ppo-steps",
        type=COUNT,
        default=None,
        help=f"timed PPO env steps, rounded up to whole rollouts (default {DEFAULT_PPO_STEPS})",
    )
    add(
        "--ppo-rounds",
        type=COUNT,
        default=None,
        help=f"interleaved timed rounds per PPO kind; the median counts "
        f"(default {DEFAULT_PPO_ROUNDS}; --quick 1)",
    )
    add(
        "--ppo-kinds",
        nargs="+",
        default=[",".join(PPO_KINDS)],
        metavar="KIND",
        help=f"subset of {','.join(PPO_KINDS)} (default all)",
    )
    add(
        "--ppo-hyperparams",
        nargs="*",
        default=[],
        metavar="K=V",
        help="override ppo.yml entries (e.g. n_steps=128 batch_size=256; default: none)",
    )


def _add_throughput_options(group: argparse._ArgumentGroup) -> None:
    """The sub-env counts of the throughput table (its PPO pair takes the PPO options)."""
    group.add_argument(
        "--counts",
        nargs="+",
        default=None,
        metavar="N",
        help="sub-env counts of the throughput table (default "
        + ",".join(map(str, DEFAULT_THROUGHPUT_COUNTS))
        + "; --quick "
        + ",".join(map(str, QUICK_THROUGHPUT_COUNTS))
        + ")",
    )


def _add_profile_options(group: argparse._ArgumentGroup) -> None:
    """``--profile``: a cProfile of one loop instead of the benchmark."""
    group.add_argument(
        "--profile",
        choices=("single", "vector"),
        help="cProfile that loop for --seconds, print the top 25 functions by tottime, exit "
        "(default: no profile, the benchmark)",
    )
    group.add_argument(
        "--profile-num-envs", type=COUNT, default=64, help="vector env size for --profile vector"
    )


@dataclass(frozen=True)
class Settings:
    seconds: float
    sections: tuple[str, ...]
    num_envs: tuple[int, ...]
    landmarks: tuple[int, ...]
    env_kwargs: dict[str, Any]
    ppo_envs: int
    ppo_steps: int
    ppo_rounds: int
    ppo_kinds: tuple[str, ...]
    ppo_overrides: dict[str, Any]
    quick: bool
    json_path: Path | None
    counts: tuple[int, ...] = DEFAULT_THROUGHPUT_COUNTS


def settings_from_args(args: argparse.Namespace, parser: argparse.ArgumentParser) -> Settings:
    sections = tuple(_split_list(args.sections))
    unknown = sorted(set(sections) - set(SECTIONS))
    if unknown or not sections:
        parser.error(f"--sections: unknown {unknown}; choose from {','.join(SECTIONS)}")
    kinds = tuple(_split_list(args.ppo_kinds))
    if not kinds or set(kinds) - set(PPO_KINDS):
        parser.error(f"--ppo-kinds: choose from {','.join(PPO_KINDS)}")
    try:
        num_envs = _int_list(args.num_envs, "--num-envs") if args.num_envs else None
        counts = _int_list(args.counts, "--counts") if args.counts else None
        landmarks = (
            _int_list(args.landmarks, "--landmarks", 3, MAX_N_LANDMARKS) if args.landmarks else None
        )
        env_kwargs = {"scenario": "khepera", **parse_key_values(args.env_kwargs, "--env-kwargs")}
        _check_env_kwargs(env_kwargs)
        overrides = parse_key_values(args.ppo_hyperparams, "--ppo-hyperparams")
    except (argparse.ArgumentTypeError, ValueError) as error:
        parser.error(str(error))
    quick = bool(args.quick)
    measure = args.seconds if args.seconds is not None else (0.05 if quick else DEFAULT_SECONDS)
    ppo_envs = args.ppo_envs if args.ppo_envs is not None else (2 if quick else DEFAULT_PPO_ENVS)
    ppo_steps = args.ppo_steps
    if ppo_steps is None:
        ppo_steps = 16 if quick else DEFAULT_PPO_STEPS
    ppo_rounds = args.ppo_rounds
    if ppo_rounds is None:
        ppo_rounds = 1 if quick else DEFAULT_PPO_ROUNDS
    if ppo_envs < 1 or ppo_steps < 1 or ppo_rounds < 1:
        parser.error("--ppo-envs, --ppo-steps and --ppo-rounds must be >= 1")
    if quick:
        quick_overrides = {**QUICK_PPO_OVERRIDES}
        quick_overrides["batch_size"] = int(overrides.get("n_steps", 8)) * ppo_envs
        overrides = {**quick_overrides, **overrides}
    return Settings(
        seconds=float(measure),
        sections=tuple(section for section in SECTIONS if section in sections),
        num_envs=tuple(num_envs or ((1, 4) if quick else DEFAULT_NUM_ENVS)),
        landmarks=tuple(landmarks or DEFAULT_SINGLE_LANDMARKS),
        env_kwargs=env_kwargs,
        ppo_envs=ppo_envs,
        ppo_steps=ppo_steps,
        ppo_rounds=ppo_rounds,
        ppo_kinds=tuple(kind for kind in PPO_KINDS if kind in kinds),
        ppo_overrides=overrides,
        quick=quick,
        json_path=None if args.no_json else args.json,
        counts=tuple(counts or (QUICK_THROUGHPUT_COUNTS if quick else DEFAULT_THROUGHPUT_COUNTS)),
    )


def run(settings: Settings) -> dict[str, Any]:
    """Run the selected sections; the results dict that is printed and written to JSON."""
    bench = Bench(settings.seconds)
    started = _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")
    log(f"bench_env: sections {','.join(settings.sections)}, {settings.seconds:g} s per figure")
    bench.measure_reference("start")
    results: dict[str, Any] = {}
    if "single" in settings.sections:
        log("[single] one env, random actions, resets included")
        results["single"] = bench_single(bench, settings.landmarks)
    if "vector" in settings.sections:
        log(f"[vector] gym.make_vec, {settings.env_kwargs}, num_envs {settings.num_envs}")
        results["vector"] = bench_vector(bench, settings.num_envs, settings.env_kwargs)
    if "slam" in settings.sections:
        log("[slam] PolygonSLAM.update alone")
        results["slam"] = bench_slam_updates(bench)
    if "startup" in settings.sections:
        log("[startup] fresh processes, start to exit: BearingSLAM-Khepera-v1 vs CartPole-v1")
        results["startup"] = bench_startup(QUICK_STARTUP_RUNS if settings.quick else STARTUP_RUNS)
    if "planning" in settings.sections:
        log("[planning] GreedyOneStep.act on Khepera")
        episodes = 2 if settings.quick else PLANNING_EPISODES
        results["planning"] = bench_planning(episodes)
    if "ppo" in settings.sections:
        log(
            f"[ppo] SB3 PPO on {settings.ppo_envs} envs, {settings.ppo_rounds} interleaved "
            f"rounds of {settings.ppo_steps} timed steps"
        )
        results["ppo"] = bench_ppo(
            bench,
            settings.ppo_kinds,
            settings.ppo_envs,
            settings.ppo_steps,
            settings.env_kwargs,
            settings.ppo_overrides,
            settings.ppo_rounds,
        )
    if "throughput" in settings.sections:
        log(
            f"[throughput] random actions, {settings.counts} sub-envs vs CartPole-v1; PPO on "
            f"{settings.ppo_envs} batched envs vs CartPole-v1"
        )
        results["throughput"] = bench_throughput(
            bench,
            settings.counts,
            settings.env_kwargs,
            settings.ppo_envs,
            settings.ppo_steps,
            settings.ppo_overrides,
            settings.ppo_rounds,
        )
    bench.measure_reference("end")
    return {
        "format": JSON_FORMAT,
        "benchmark": "bench_env",
        "started": started,
        "total_seconds": bench.now(),
        "machine": machine_info(),
        "settings": {
            "seconds": settings.seconds,
            "sections": list(settings.sections),
            "num_envs": list(settings.num_envs),
            "landmarks": list(settings.landmarks),
            "env_kwargs": settings.env_kwargs,
            "ppo_envs": settings.ppo_envs,
            "ppo_steps": settings.ppo_steps,
            "ppo_rounds": settings.ppo_rounds,
            "ppo_kinds": list(settings.ppo_kinds),
            "ppo_overrides": json_safe(settings.ppo_overrides),
            "quick": settings.quick,
            "counts": list(settings.counts),
        },
        "cartpole_references": [
            {"label": ref.label, "steps_per_s": ref.steps_per_s, "time_s": ref.time_s}
            for ref in bench.references
        ],
        **results,
        "targets": evaluate_targets(results),
    }


def main(argv: Sequence[str] | None = None) -> dict[str, Any] | None:
    arguments = sys.argv[1:] if argv is None else list(argv)
    if "--slam" in arguments:  # forward to the world-model benchmark, which has its own options
        from bearing_env.benchmarks import bench_slam

        bench_slam.main([arg for arg in arguments if arg != "--slam"])
        return None
    parser = build_parser()
    args = parser.parse_args(arguments)
    settings = settings_from_args(args, parser)
    if args.profile is not None:
        profile(args.profile, settings.seconds, args.profile_num_envs, settings.env_kwargs)
        return None
    json_path = settings.json_path
    if json_path is not None:
        # A --json that cannot be written (a parent that is a file, a read-only folder)
        # fails before the measurements; a full disk at the end: one line naming it.
        with exit_on_output_errors(parser, json_path, "--json", refusals=()):
            json_path.parent.mkdir(parents=True, exist_ok=True)
    results = run(settings)
    print_table(results)
    if json_path is not None:
        with exit_on_output_errors(parser, json_path, "--json", refusals=()):
            write_json(json_path, results)
        print(f"\nJSON: {json_path}")
    return results


if __name__ == "__main__":
    main()
