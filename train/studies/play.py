"""``bearing-env play``: move the robot by hand in a pygame window.

The keys and the window are :mod:`bearing_env.envs.manual_control`'s (docs/play.md):
left/right turn the next move, up/down change its length, space or enter moves, a left
click on the field moves toward the point, ``r`` starts the next episode, escape quits.

    python -m bearing_env.train.studies.play [--env BearingSLAM-v1] [--env-kwargs K=V ...]
        [--seed 0]
"""

from __future__ import annotations

import argparse
import os
from typing import Any

import gymnasium as gym

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.envs.manual_control import KEY_HELP, TURN_STEP_DEG, ManualControl
from bearing_env.tasks import BASE_IDS
from bearing_env.train.common.cli_parser import command_parser
from bearing_env.train.common.cli_values import SEED, parse_key_values
from bearing_env.train.common.errors import exit_on_missing_extra, fail, require

PROG = "bearing-env play"
DEFAULT_ENV_ID = "BearingSLAM-v1"
#: The env settings without ``--env-kwargs``: the paper's real arena.
DEFAULT_ENV_KWARGS: dict[str, Any] = {"scenario": "khepera"}


def build_parser() -> argparse.ArgumentParser:
    keys = "; ".join(f"{keys}: {what}" for keys, what in KEY_HELP)
    parser = command_parser(
        PROG,
        "Move the robot by hand in a pygame window (the render extra), with "
        "the regions, their areas and the reward drawn live.",
        f"Keys: {keys}. The continuous env turns by {TURN_STEP_DEG:g} degrees a "
        "press; the discrete env steps through its own turn and length tables.",
    )
    parser.add_argument(
        "--env",
        default=DEFAULT_ENV_ID,
        choices=sorted(BASE_IDS.values()),
        help="env id (default %(default)s)",
    )
    parser.add_argument(
        "--env-kwargs",
        nargs="*",
        default=None,
        metavar="KEY=VALUE",
        help="env settings, e.g. n_landmarks=6 max_moves=30 (default: scenario=khepera)",
    )
    parser.add_argument(
        "--seed",
        type=SEED,
        default=0,
        help="seed of the first episode; each r (next episode) adds 1 (default %(default)s)",
    )
    return parser


def main(argv: list[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(argv)
    env_kwargs: dict[str, Any] = dict(DEFAULT_ENV_KWARGS)
    if args.env_kwargs is not None:
        try:
            env_kwargs = parse_key_values(args.env_kwargs, "--env-kwargs")
        except ValueError as error:
            parser.error(str(error))
    if "render_mode" in env_kwargs:
        parser.error("--env-kwargs: play shows the env in its own window; leave out render_mode")
    with exit_on_missing_extra(PROG):
        os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
        pygame = require("pygame", PROG, extra="render")
        try:
            env = gym.make(args.env, render_mode="rgb_array", **env_kwargs)
        except (TypeError, ValueError) as error:
            fail(PROG, f"--env-kwargs: {error}")
        try:
            control = ManualControl(env, seed=args.seed)
        except pygame.error as error:
            env.close()
            fail(PROG, f"cannot open a window: {error}")
        with control:
            control.run()


if __name__ == "__main__":
    main()
