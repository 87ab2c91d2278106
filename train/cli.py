"""The ``bearing-env`` command line.

    bearing-env demo [...]        the random polygonal demo in the Khepera scenario (make demo)
    bearing-env bench [...]       env, vector env, throughput and PPO steps/s against
                                  CartPole-v1, as tables and JSON (benchmarks/bench_env.py,
                                  make bench)
    bearing-env bench-slam [...]  world-model update() throughput against CartPole-v1
                                  (benchmarks/bench_slam.py; also ``bearing-env bench --slam``)
    bearing-env bench-callgrind [...]  instructions per map update and per env step,
                                  counted by valgrind (benchmarks/bench_callgrind.py)
    bearing-env region-search [...]  a seeded search for regions that break the world
                                  model's promises (benchmarks/region_search.py)
    bearing-env soak [...]        the envs over random configurations, checking the
                                  conservative guarantee at every step (benchmarks/soak.py)
    bearing-env compare [...]     exploration policies on the same evaluation episodes
    bearing-env suite [...]       the baselines on every registered task, with the task
                                  cards in docs/tasks/ (compare once per task)
    bearing-env figures [...]     the paper's Figs. 7, 10 and 11 in simulation
    bearing-env robust-eval [...]  the robust fusion against the strict one under outliers
                                  and an underestimated noise bound
    bearing-env observability [...]  which movements can map a layout with a task's sensor,
                                  whatever the policy (train/studies/observability.py)
    bearing-env generalisation [...]  a policy trained on random layouts, across landmark
                                  counts (train/studies/generalisation.py)
    bearing-env play [...]        move the robot by hand in a pygame window (the render extra)
    bearing-env train [...]       PPO/SAC/DQN with stable-baselines3 (shipped rl-zoo3 files)
    bearing-env distill [...]     DAgger from a planner (LookaheadOracle) into an SB3 model
                                  (train/sb3/distill.py)
    bearing-env hyperparams ALGO  the path of a shipped rl-zoo3 hyperparameter file
    bearing-env docs-tables [...]  the docs' tables of measured figures, from the results
                                  files in the repo (train/common/doc_tables.py)
    bearing-env rllib [...]       PPO with RLlib, locally or on a Ray cluster (train/ray/rllib.py)
    bearing-env sweep [...]       a Ray Tune grid of RLlib PPO runs (train/ray/sweep.py)

``bearing-env --version`` prints the package's version; ``bearing-env`` alone prints the
usage and exits with status 2. Each subcommand forwards its remaining arguments to the
module that implements it, so ``bearing-env demo --help`` shows that module's options,
each with its default. A subcommand that needs an
optional extra that is not installed (``train``: stable-baselines3, torch, matplotlib, ...;
``render``: pygame; ``ray``: ray, RLlib, Ray Tune) says which one to install,
``pip install "bearing_env[train]"``, and exits with status 2. A bad option value ends
as an argparse usage error (status 2) whose one error line names the option and the value
(``bearing_env.train.common.cli_values``); output into a closed pipe (``... | head``) ends quietly.
"""

from __future__ import annotations

import importlib
import sys

from bearing_env import __version__
from bearing_env.train.common.cli_parser import command_parser, doc_summary
from bearing_env.train.common.errors import exit_on_missing_extra, exit_quietly_on_broken_pipe

SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "demo": (
        "bearing_env.train.studies.demo",
        "random polygonal exploration in the Khepera scenario",
    ),
    "bench": (
        "bearing_env.benchmarks.bench_env",
        "env, vector env, throughput and PPO steps/s vs CartPole-v1",
    ),
    "bench-slam": (
        "bearing_env.benchmarks.bench_slam",
        "world-model update() throughput vs CartPole-v1",
    ),
    "bench-callgrind": (
        "bearing_env.benchmarks.bench_callgrind",
        "instructions per map update and per env step, counted by valgrind (load-independent)",
    ),
    "region-search": (
        "bearing_env.benchmarks.region_search",
        "a seeded search for world-model regions that are not simple, convex or conservative",
    ),
    "transfer-tightness": (
        "bearing_env.benchmarks.transfer_tightness",
        "single-movement regions against the exact transferred sets they bound (area, containment)",
    ),
    "soak": (
        "bearing_env.benchmarks.soak",
        "a soak of the envs over random configurations, checking containment every step",
    ),
    "train": (
        "bearing_env.train.sb3.train_cli",
        "train PPO/SAC/DQN agents with stable-baselines3 (rl-zoo3 hyperparameter files)",
    ),
    "distill": (
        "bearing_env.train.sb3.distill",
        "DAgger: train a model's actor on a planner's actions at the states it visits",
    ),
    "docs-tables": (
        "bearing_env.train.common.doc_tables",
        "write the docs' tables of measured figures from the results files in the repo",
    ),
    "hyperparams": (
        "bearing_env.train.sb3.conf_files",
        "print the path of a shipped rl-zoo3 hyperparameter file (for --conf-file)",
    ),
    "compare": (
        "bearing_env.train.compare.cli",
        "compare exploration policies on fixed evaluation episodes",
    ),
    "suite": (
        "bearing_env.train.compare.suite",
        "run the baselines (random, parallax, greedy, lookahead, matching shipped models) "
        "on every registered task, 50 episodes each by default, and write the task cards",
    ),
    "rllib": (
        "bearing_env.train.ray.rllib",
        "train PPO with RLlib on this machine or a Ray cluster (the ray extra)",
    ),
    "sweep": (
        "bearing_env.train.ray.sweep",
        "a Ray Tune grid of RLlib PPO runs over hyperparameters or env kwargs",
    ),
    "figures": (
        "bearing_env.train.studies.figures",
        "reproduce the paper's Figs. 7, 10 and 11 in simulation",
    ),
    "robust-eval": (
        "bearing_env.train.studies.robust_eval",
        "the robust fusion against the strict one: containment, area and step time",
    ),
    "observability": (
        "bearing_env.train.studies.observability",
        "which movements can map a layout at all with a task's sensor, whatever the policy",
    ),
    "generalisation": (
        "bearing_env.train.studies.generalisation",
        "a shipped policy trained on random layouts, across landmark counts",
    ),
    "play": (
        "bearing_env.train.studies.play",
        "move the robot by hand in a pygame window (keys or mouse clicks)",
    ),
}


def main(argv: list[str] | None = None) -> None:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = command_parser("bearing-env", doc_summary(__doc__))
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument(
        "command",
        choices=sorted(SUBCOMMANDS),
        help="; ".join(f"{name}: {text}" for name, (_, text) in SUBCOMMANDS.items()),
    )
    if argv[:1] in (["-h"], ["--help"]):
        parser.print_help()
        return
    args = parser.parse_args(argv[:1])  # no command: the usage, and exit status 2
    command, rest = args.command, argv[1:]
    if command == "bench" and "--slam" in rest:  # bearing-env bench --slam == bench-slam
        command, rest = "bench-slam", [arg for arg in rest if arg != "--slam"]
    module_name, _ = SUBCOMMANDS[command]
    sys.argv = [f"bearing-env {command}", *rest]
    # A subcommand whose optional extra is not installed says which one, in one line.
    with exit_quietly_on_broken_pipe(), exit_on_missing_extra(f"bearing-env {command}"):
        module = importlib.import_module(module_name)
        module.main()


if __name__ == "__main__":
    main()
