"""``bearing-env hyperparams ALGO``: where the shipped rl-zoo3 hyperparameter files are.

The files are package data of ``bearing_env.train.sb3`` (``hyperparams/<algo>.yml``, found
through :mod:`bearing_env.shipped`), so they exist in site-packages as well as in a
checkout. ``bearing-env hyperparams ppo`` prints the path of ``ppo.yml``, for rl-zoo3::

    python -m rl_zoo3.train --gym-packages bearing_env --algo ppo --env BearingSLAM-Khepera-v1 \\
        --conf-file "$(bearing-env hyperparams ppo)"

(rl-zoo3 gives an entry's ``env_kwargs`` to its training envs only and makes its
evaluation env from the id alone, so every entry is keyed by the id it trains on and
holds no ``env_kwargs``: the id's registered kwargs carry the settings. Each file's
header shows its command.)

``bearing-env hyperparams`` without an algorithm lists the shipped files. Nothing here
needs an optional extra.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

from bearing_env.shipped import shipped_dir
from bearing_env.train.common.cli_parser import command_parser

#: The shipped rl-zoo3 hyperparameter files: ``<algo>.yml``, one entry per env id.
HYPERPARAMS_DIR = shipped_dir("bearing_env.train.sb3", "hyperparams")


def shipped_algorithms() -> list[str]:
    """The algorithms with a shipped hyperparameter file, sorted (``["dqn", "ppo", "sac"]``)."""
    return sorted(path.stem for path in HYPERPARAMS_DIR.glob("*.yml"))


def default_conf_file(algo: str) -> Path:
    """The shipped hyperparameter file of ``algo`` (which need not exist)."""
    return HYPERPARAMS_DIR / f"{algo.lower()}.yml"


def main(argv: Sequence[str] | None = None) -> None:
    parser = command_parser(
        "bearing-env hyperparams",
        "Print the path of a shipped rl-zoo3 hyperparameter file "
        "(for rl_zoo3.train --conf-file); without ALGO, list them.",
    )
    parser.add_argument(
        "algo",
        nargs="?",
        help=f"one of {', '.join(shipped_algorithms())} (default: list them all)",
    )
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if args.algo is None:
        for algo in shipped_algorithms():
            print(f"{algo}\t{default_conf_file(algo)}")
        return
    path = default_conf_file(args.algo)
    if not path.is_file():
        parser.error(
            f"no shipped hyperparameter file for {args.algo!r}; "
            f"expected one of {', '.join(shipped_algorithms())}"
        )
    print(path)


if __name__ == "__main__":
    main()
