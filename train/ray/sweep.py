"""``bearing-env sweep``: a Ray Tune grid of RLlib PPO runs (``bearing-env rllib``'s).

    bearing-env sweep --grid lr=0.0001,0.0003 --iterations 20
    bearing-env sweep --env-grid scenario=khepera,random --grid gamma=0.9,0.99 \\
        --num-env-runners 0 --ray-address HEAD_IP:6379

Every combination of the ``--grid`` values (hyperparameters: :data:`SWEEPABLE`) and the
``--env-grid`` values (env kwargs, over ``--env-kwargs``) is one Tune trial, trained for
``--iterations`` iterations with the rest of the settings of ``bearing-env rllib``. A
trial takes one CPU for its learner and one per env runner: with ``--num-env-runners 0``
(sampling in the learner's process) a machine of N cores runs N trials at once.

Outputs (``--out``, default ``runs/sweep``): Tune's experiment folder ``tune/`` (a
folder, result logs and a checkpoint per trial), and ``sweep.json``/``sweep.csv``, one
row per trial: the swept values, the final mean episode return, env steps and the
trial's checkpoint, best first. An interrupted sweep (Ctrl-C) keeps its finished trials;
``--resume`` restores the experiment with Tune and runs the unfinished ones.
"""

from __future__ import annotations

import argparse
import itertools
import json
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from bearing_env.train.common.cli_parser import command_parser
from bearing_env.train.common.cli_values import parse_literal
from bearing_env.train.common.errors import exit_on_output_errors, fail, require
from bearing_env.train.common.files import atomic_write_text
from bearing_env.train.compare.report import csv_text
from bearing_env.train.ray.ray_executor import check_ray_address, ray_session
from bearing_env.train.ray.rllib import (
    RLlibSettings,
    add_settings_arguments,
    ppo_config,
    settings_from_args,
)

#: Hyperparameters a grid may sweep: the :class:`RLlibSettings` field and the
#: ``PPOConfig.training`` argument it sets.
SWEEPABLE: dict[str, str] = {
    "lr": "lr",
    "gamma": "gamma",
    "train_batch_size": "train_batch_size_per_learner",
    "minibatch_size": "minibatch_size",
    "epochs": "num_epochs",
}
TUNE_NAME = "tune"
SUMMARY_NAME = "sweep.json"


@dataclass(frozen=True)
class SweepSettings:
    """A grid: ``base`` with each combination of ``grid`` (hyperparameters) and
    ``env_grid`` (env kwargs) values."""

    base: RLlibSettings
    grid: dict[str, list[Any]]
    env_grid: dict[str, list[Any]]

    def __post_init__(self) -> None:
        unknown = sorted(set(self.grid) - set(SWEEPABLE))
        if unknown:
            raise ValueError(f"cannot sweep {unknown}; --grid takes {sorted(SWEEPABLE)}")
        for key, values in {**self.grid, **self.env_grid}.items():
            if not values:
                raise ValueError(f"grid {key!r} has no values")
        for combination in self.combinations():  # every trial's settings are valid
            self.settings_of(combination)

    def combinations(self) -> list[dict[str, Any]]:
        """Each trial's swept values (``env.KEY`` for env kwargs), in grid order."""
        keys = [*self.grid, *(f"env.{key}" for key in self.env_grid)]
        values = [*self.grid.values(), *self.env_grid.values()]
        return [dict(zip(keys, chosen, strict=True)) for chosen in itertools.product(*values)]

    def settings_of(self, combination: Mapping[str, Any]) -> RLlibSettings:
        """The :class:`RLlibSettings` of one trial (ValueError on a bad value)."""
        env_kwargs = dict(self.base.env_kwargs)
        fields: dict[str, Any] = {}
        for key, value in combination.items():
            if key.startswith("env."):
                env_kwargs[key[4:]] = value
            else:
                fields[key] = value
        return replace(self.base, env_kwargs=env_kwargs, **fields)


def tune_param_space(sweep: SweepSettings) -> Any:
    """The ``PPOConfig`` with ``tune.grid_search`` at each swept value."""
    tune = require("ray.tune", "a Ray Tune sweep", extra="ray")
    config = ppo_config(sweep.base)
    if sweep.grid:
        config = config.training(
            **{SWEEPABLE[key]: tune.grid_search(values) for key, values in sweep.grid.items()}
        )
    if sweep.env_grid:
        env_config = {
            **dict(sweep.base.env_kwargs),
            **{key: tune.grid_search(values) for key, values in sweep.env_grid.items()},
        }
        config = config.environment(env_config=env_config)
    return config


def _swept_values(config: Mapping[str, Any], sweep: SweepSettings) -> dict[str, Any]:
    """A trial's values of the swept keys, read back from its resolved config."""
    values: dict[str, Any] = {key: config[SWEEPABLE[key]] for key in sweep.grid}
    env_config = config.get("env_config", {})
    values.update({f"env.{key}": env_config[key] for key in sweep.env_grid})
    return values


def _row(result: Any, sweep: SweepSettings) -> dict[str, Any]:
    metrics = result.metrics or {}
    runners = metrics.get("env_runners", {})
    checkpoint = getattr(result, "checkpoint", None)
    mean_return = runners.get("episode_return_mean")
    return {
        **_swept_values(result.config, sweep),
        "iterations": metrics.get("training_iteration"),
        "env_steps": metrics.get("num_env_steps_sampled_lifetime"),
        "episode_return_mean": None if mean_return is None else float(mean_return),
        "error": None if result.error is None else f"{type(result.error).__name__}",
        "checkpoint": None if checkpoint is None else str(checkpoint.path),
        "path": str(result.path),
    }


def _best_first(row: Mapping[str, Any]) -> tuple[bool, float]:
    value = row["episode_return_mean"]
    return (value is None, -float(value) if value is not None else 0.0)


def run_sweep(
    sweep: SweepSettings,
    out: Path,
    resume: bool = False,
    address: str | None = None,
    verbose: int = 1,
) -> list[dict[str, Any]]:
    """Run (or finish) the grid; the rows of ``sweep.json``, best mean return first.

    Raises:
        FileExistsError: ``out`` holds a sweep and ``resume`` is False.
        ValueError: ``resume`` without a sweep to restore.
    """
    out = Path(out).resolve()
    experiment = out / TUNE_NAME
    with ray_session(address):
        tune = require("ray.tune", "a Ray Tune sweep", extra="ray")
        param_space = tune_param_space(sweep)
        # The class, not the name "PPO": resolving a name makes RLlib import every
        # algorithm, and DreamerV3's module builds a debugging env that warns.
        ppo = require("ray.rllib.algorithms.ppo", "a Ray Tune sweep", extra="ray").PPO
        if resume:
            if not tune.Tuner.can_restore(str(experiment)):
                raise ValueError(f"cannot resume: {out} holds no sweep; drop --resume")
            tuner = tune.Tuner.restore(
                str(experiment), trainable=ppo, param_space=param_space, resume_errored=True
            )
        else:
            if experiment.exists():
                raise FileExistsError(f"{out} already holds a sweep; pass --resume to finish it")
            tuner = tune.Tuner(
                ppo,
                param_space=param_space,
                run_config=tune.RunConfig(
                    name=TUNE_NAME,
                    storage_path=str(out),
                    stop={"training_iteration": sweep.base.iterations},
                    checkpoint_config=tune.CheckpointConfig(checkpoint_at_end=True),
                    verbose=verbose,
                ),
            )
        grid = tuner.fit()
        rows = sorted((_row(result, sweep) for result in grid), key=_best_first)
    summary = {
        "settings": sweep.base.to_json(),
        "grid": sweep.grid,
        "env_grid": sweep.env_grid,
        "trials": rows,
    }
    atomic_write_text(out / SUMMARY_NAME, json.dumps(summary, indent=1) + "\n")
    header = list(rows[0]) if rows else []
    atomic_write_text(
        out / "sweep.csv", csv_text(header, ([row[k] for k in header] for row in rows)), ""
    )
    return rows


def parse_grid(items: Sequence[str], option: str) -> dict[str, list[Any]]:
    """``["lr=0.0001,0.0003"]`` -> ``{"lr": [0.0001, 0.0003]}``: each value a Python
    literal when it parses as one, else a string (a comma always separates values)."""
    grid: dict[str, list[Any]] = {}
    for item in items:
        key, sep, text = item.partition("=")
        if not sep or not key.strip() or not text.strip():
            raise ValueError(f"{option} {item!r} is not KEY=VALUE[,VALUE...]")
        grid[key.strip()] = [parse_literal(value) for value in text.split(",")]
    return grid


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env sweep",
        "A Ray Tune grid of RLlib PPO runs over hyperparameters or env kwargs.",
    )
    add_settings_arguments(parser)
    add = parser.add_argument
    add(
        "--grid",
        nargs="*",
        default=[],
        metavar="KEY=V1,V2",
        help=f"hyperparameter values to sweep; KEY in {', '.join(SWEEPABLE)} (default: none)",
    )
    add(
        "--env-grid",
        nargs="*",
        default=[],
        metavar="KEY=V1,V2",
        help="env kwarg values to sweep (e.g. scenario=khepera,random; default: none)",
    )
    add("--out", type=Path, default=Path("runs/sweep"), help="output folder (default %(default)s)")
    add("--resume", action="store_true", help="finish the sweep in --out")
    return parser


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        require("ray.tune", "a Ray Tune sweep", extra="ray")
        sweep = SweepSettings(
            base=settings_from_args(args),
            grid=parse_grid(args.grid, "--grid"),
            env_grid=parse_grid(args.env_grid, "--env-grid"),
        )
        if args.ray_address is not None:
            check_ray_address(args.ray_address)
    except (ValueError, TypeError) as error:
        parser.error(str(error))
    except ImportError as error:
        fail(parser.prog, str(error))
    started = time.perf_counter()
    with exit_on_output_errors(parser, args.out, "--out"):
        rows = run_sweep(
            sweep,
            args.out,
            resume=args.resume,
            address=args.ray_address,
            verbose=0 if args.no_progress else 1,
        )
    for row in rows:
        swept = ", ".join(f"{key}={row[key]}" for key in sweep.combinations()[0])
        print(f"{swept}: mean episode return {row['episode_return_mean']}")
    print(
        f"{len(rows)} trials in {args.out} ({time.perf_counter() - started:.0f} s); "
        f"summary: {args.out / SUMMARY_NAME}"
    )


if __name__ == "__main__":
    main()
