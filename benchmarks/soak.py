"""A soak of the envs over random valid configurations, checking the conservative
guarantee at every step.

Each configuration draws an id (continuous or discrete), a scenario (random layouts of 3
to 30 landmarks, Khepera, the paper's simulation), epsilon in 0.5-10 degrees, a move
length range, the observation kind, the reward and the episode length; the transfer is
conservative, the fusion the paper's intersection (or, with ``--fusion robust``, the
robust fusion with its defaults: its noise-bound estimate only ever grows the bound, so
the guarantee holds for it too), and the noise uniform within +-epsilon, so every
initialised region must hold its landmark. Episodes run on random actions from a seeded
action space.

    python -m bearing_env.benchmarks.soak --steps 1000000
    bearing-env soak --steps 20000 --seed 3
    bearing-env soak --steps 100000 --task BearingSLAM-FurnishedRoom-v1
    bearing-env soak --steps 100000 --fusion robust

With ``--task`` every configuration is that registered task as it is (its noise must be
within +-epsilon and its mapping conservative for the check to hold: the tasks without a
fault are), each with seeds of its own.

It counts steps, exceptions, non-finite values (NaN anywhere in the observation, reward
or areas; an uninitialised area is inf by design) and containment misses, prints them,
and exits with status 1 if any is non-zero. Ctrl-C stops early and prints the counts so
far.
"""

from __future__ import annotations

import argparse
import math
import sys
import traceback
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import bearing_env  # noqa: F401  (registers the ids)
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

IDS = ("BearingSLAM-v1", "BearingSLAMDiscrete-v1")


@dataclass
class SoakReport:
    steps: int = 0
    episodes: int = 0
    configurations: int = 0
    containment_checks: int = 0
    misses: int = 0
    nonfinite: int = 0
    exceptions: int = 0
    #: The first failures: the configuration and what went wrong.
    failures: list[dict[str, Any]] = field(default_factory=list)

    @property
    def defects(self) -> int:
        return self.misses + self.nonfinite + self.exceptions

    def note(self, kwargs: dict[str, Any], seed: int, what: str, limit: int = 10) -> None:
        if len(self.failures) < limit:
            self.failures.append({"env_kwargs": kwargs, "seed": seed, "what": what})


#: The fusions a soak of random configurations may run (``--fusion``).
SOAK_FUSIONS = ("intersect", "robust")


def random_configuration(
    rng: np.random.Generator, fusion: str = "intersect"
) -> tuple[str, dict[str, Any]]:
    """An env id and valid keyword arguments with ``fusion``, drawn from ``rng`` (the
    draws do not depend on ``fusion``)."""
    env_id = str(rng.choice(IDS))
    kwargs: dict[str, Any] = {
        "scenario": str(rng.choice(["random", "random", "khepera", "paper_sim"])),
        "epsilon_deg": float(rng.uniform(0.5, 10.0)),
        "observation": str(rng.choice(["flat", "entities", "shapes"])),
        "reward": str(rng.choice(["log_area", "area"])),
        "max_moves": int(rng.integers(5, 41)),
        "transfer": "conservative",
        "fusion": fusion,
    }
    if kwargs["scenario"] == "random":
        kwargs["n_landmarks"] = int(rng.integers(3, 31))
    if rng.uniform() < 0.5:
        low = float(rng.uniform(0.01, 0.1))
        kwargs["move_length"] = (low, float(rng.uniform(low, 0.5)))
    return env_id, kwargs


def finite(value: Any) -> bool:
    """No NaN or inf in an observation (a Box array or a dict of them)."""
    if isinstance(value, dict):
        return all(finite(item) for item in value.values())
    return bool(np.isfinite(value).all())


def soak_configuration(
    env_id: str, kwargs: dict[str, Any], seed: int, episodes: int, report: SoakReport
) -> None:
    """Run ``episodes`` episodes of one configuration into ``report``."""
    report.configurations += 1
    env: gym.Env[Any, Any] | None = None
    try:
        env = gym.make(
            env_id, disable_env_checker=True, **kwargs
        )
        env.action_space.seed(seed)
        for episode in range(episodes):
            observation, _ = env.reset(seed=seed + episode)
            report.episodes += 1
            done = False
            while not done:
                observation, reward, terminated, truncated, info = env.step(
                    env.action_space.sample()
                )
                done = terminated or truncated
                report.steps += 1
                area = np.asarray(info["landmark_area"])
                if not (finite(observation) and math.isfinite(reward)) or np.isnan(area).any():
                    report.nonfinite += 1
                    report.note(kwargs, seed + episode, f"non-finite value at step {report.steps}")
                initialised = np.isfinite(area)
                missed = initialised & ~np.asarray(info["landmark_contains_truth"])
                report.containment_checks += int(initialised.sum())
                if missed.any():
                    report.misses += int(missed.sum())
                    what = f"truth outside {int(missed.sum())} region(s) at step {report.steps}"
                    report.note(kwargs, seed + episode, what)
    except Exception as error:  # a soak counts every failure and goes on
        report.exceptions += 1
        report.note(kwargs, seed, "".join(traceback.format_exception_only(error)).strip())
    finally:
        if env is not None:
            env.close()


def run(
    steps: int,
    seed: int,
    episodes: int,
    progress: bool = False,
    task: str | None = None,
    fusion: str = "intersect",
) -> SoakReport:
    """Soak at least ``steps`` env steps over configurations drawn from ``seed`` with
    ``fusion`` (or of the registered ``task`` only, as it is).

    Every configuration that runs steps at least one, so at most ``steps`` are drawn:
    configurations that all fail before their first step end the soak too."""
    rng = np.random.default_rng(seed)
    report = SoakReport()
    with progress_bar(steps, desc="soak", unit="step", enabled=progress) as bar:
        try:
            while report.steps < steps and report.configurations < steps:
                before = report.steps
                env_id, kwargs = (
                    random_configuration(rng, fusion) if task is None else (task, {})
                )
                soak_configuration(env_id, kwargs, int(rng.integers(2**31)), episodes, report)
                bar.update(report.steps - before)
        except KeyboardInterrupt:
            print("interrupted: the counts cover what ran so far", file=sys.stderr)
    return report


def _task_id(value: str) -> str:
    """A registered task's id (argparse: an unknown one is refused, naming the tasks)."""
    from bearing_env.tasks import task_named

    try:
        return task_named(value).id
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def make_parser() -> argparse.ArgumentParser:
    parser = command_parser("bearing-env soak", doc_summary(__doc__))
    parser.add_argument(
        "--steps", type=COUNT, default=1_000_000, help="env steps (default %(default)s)"
    )
    parser.add_argument(
        "--seed", type=SEED, default=0, help="seed of the configurations (default %(default)s)"
    )
    parser.add_argument(
        "--episodes", type=COUNT, default=5, help="episodes per configuration (default %(default)s)"
    )
    parser.add_argument(
        "--task",
        type=_task_id,
        default=None,
        help="soak this registered task only, e.g. BearingSLAM-FurnishedRoom-v1 "
        "(default: random configurations)",
    )
    parser.add_argument(
        "--fusion",
        choices=SOAK_FUSIONS,
        default="intersect",
        help="the fusion of the random configurations (default %(default)s; a --task keeps "
        "its own)",
    )
    add_json_output(parser, "the counts")
    add_no_progress(parser)
    return parser


def main(argv: list[str] | None = None) -> None:
    parser = make_parser()
    args = parser.parse_args(argv)
    if args.json:  # an unwritable --json fails before the soak, in one line
        with exit_on_output_errors(parser, Path(args.json), "--json", refusals=()):
            Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    if args.task is not None and args.fusion != "intersect":
        parser.error("--fusion applies to random configurations; a --task keeps its own")
    report = run(
        args.steps, args.seed, args.episodes, not args.no_progress, args.task, args.fusion
    )
    counts = {name: value for name, value in asdict(report).items() if name != "failures"}
    label = f"seed {args.seed}, {args.task or args.fusion}"
    print(f"{label}: " + ", ".join(f"{name} {value:,}" for name, value in counts.items()))
    for failure in report.failures:
        print(f"failure: {failure}")
    if args.json:
        with exit_on_output_errors(parser, Path(args.json), "--json", refusals=()):
            write_json_atomically(Path(args.json), {"seed": args.seed, **asdict(report)})
    if report.defects:
        sys.exit(1)


if __name__ == "__main__":
    main()
