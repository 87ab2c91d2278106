"""The ``bearing-env`` command line: explore, compare, train and evaluate exploration
policies for bearing-only SLAM, and the maintainers' tools.

The commands, each with its module and one line of help, are :data:`COMMAND_GROUPS`;
``bearing-env --help`` prints them by group, in the order a newcomer meets them.
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

import argparse
import importlib
import sys

from bearing_env import __version__
from bearing_env.train.common.cli_parser import doc_summary, plain_text
from bearing_env.train.common.errors import exit_on_missing_extra, exit_quietly_on_broken_pipe

#: The commands by group, in the order a newcomer meets them: what to run first, the
#: studies and scale-out, then the maintainers' tools. Each: (module, one line of help).
COMMAND_GROUPS: dict[str, dict[str, tuple[str, str]]] = {
    "Start here": {
        "demo": (
            "bearing_env.train.studies.demo",
            "the paper's random polygonal exploration in the Khepera arena",
        ),
        "play": (
            "bearing_env.train.studies.play",
            "move the robot by hand in a pygame window",
        ),
        "compare": (
            "bearing_env.train.compare.cli",
            "exploration policies on the same evaluation episodes",
        ),
        "train": (
            "bearing_env.train.sb3.train_cli",
            "train PPO/SAC/DQN with stable-baselines3, one seed or several",
        ),
        "curves": (
            "bearing_env.train.sb3.curves",
            "learning curves of one run or several seeds, with CI bands",
        ),
        "evaluate": (
            "bearing_env.train.compare.evaluate",
            "your trained model against the task's baselines, over seeds",
        ),
        "figures": (
            "bearing_env.train.studies.figures",
            "the paper's Figs. 7, 10 and 11 in simulation",
        ),
    },
    "Studies and scale-out": {
        "suite": (
            "bearing_env.train.compare.suite",
            "the baselines on every registered task, and the task cards",
        ),
        "hyperparams": (
            "bearing_env.train.sb3.conf_files",
            "the path of a shipped rl-zoo3 hyperparameter file",
        ),
        "distill": (
            "bearing_env.train.sb3.distill",
            "DAgger: a model's actor trained on a planner's actions",
        ),
        "rllib": (
            "bearing_env.train.ray.rllib",
            "PPO with RLlib, on this machine or a Ray cluster",
        ),
        "sweep": (
            "bearing_env.train.ray.sweep",
            "a Ray Tune grid of RLlib PPO runs",
        ),
        "observability": (
            "bearing_env.train.studies.observability",
            "which movements can map a layout at all, whatever the policy",
        ),
        "generalisation": (
            "bearing_env.train.studies.generalisation",
            "a shipped random-layout policy across landmark counts",
        ),
        "robust-eval": (
            "bearing_env.train.studies.robust_eval",
            "the robust fusion against the strict one under outliers",
        ),
    },
    "Maintainers' tools": {
        "bench": (
            "bearing_env.benchmarks.bench_env",
            "env, vector env and PPO speed against CartPole-v1",
        ),
        "bench-slam": (
            "bearing_env.benchmarks.bench_slam",
            "world-model update() speed against CartPole-v1",
        ),
        "bench-callgrind": (
            "bearing_env.benchmarks.bench_callgrind",
            "instructions per map update and env step (valgrind)",
        ),
        "region-search": (
            "bearing_env.benchmarks.region_search",
            "a seeded search for regions that break the model's promises",
        ),
        "transfer-tightness": (
            "bearing_env.benchmarks.transfer_tightness",
            "transferred regions against the exact sets they bound",
        ),
        "soak": (
            "bearing_env.benchmarks.soak",
            "the envs over random configurations, containment every step",
        ),
        "docs-tables": (
            "bearing_env.train.common.doc_tables",
            "the docs' tables of measured figures, from the results files",
        ),
    },
}

#: Every command: (module, one line of help).
SUBCOMMANDS: dict[str, tuple[str, str]] = {
    name: entry for group in COMMAND_GROUPS.values() for name, entry in group.items()
}


def commands_help() -> str:
    """The commands, one line each, under their groups' headings."""
    width = max(len(name) for name in SUBCOMMANDS) + 2
    lines = []
    for heading, commands in COMMAND_GROUPS.items():
        lines += ["", f"{heading}:"]
        lines += [f"  {name:<{width}}{text}" for name, (_, text) in commands.items()]
    return "\n".join(lines[1:])


def main(argv: list[str] | None = None) -> None:
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = argparse.ArgumentParser(
        prog="bearing-env",
        description=plain_text(doc_summary(__doc__)),
        epilog=f"{commands_help()}\n\n'bearing-env COMMAND --help' shows a command's options.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument(
        "command", choices=list(SUBCOMMANDS), metavar="COMMAND", help="one of the commands below"
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
