"""``bearing-env train``'s command line: the arguments, the run folder they name, the
:class:`~bearing_env.train.sb3.train.TrainSettings` they give, ``--export``/``--export-only``,
and failures as one line with exit status 2 (130 after an interruption). What training
does, and the files it writes: :mod:`bearing_env.train.sb3.train`.

    bearing-env train --algo ppo [--output runs/ppo_khepera] [--resume] [--export DIR/NAME]
    python -m bearing_env.train.sb3.train_cli ...          # the same
"""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path

from bearing_env.train.common.cli_parser import add_no_progress, command_parser
from bearing_env.train.common.cli_values import (
    COUNT,
    NON_NEGATIVE,
    SEED,
    at_least,
    parse_key_values,
    registered_env_id,
)
from bearing_env.train.common.errors import fail, write_error_message
from bearing_env.train.common.seeds import MAX_VALIDATION_EPISODES
from bearing_env.train.sb3.export import ExportedModel, export_run
from bearing_env.train.sb3.train import (
    DEFAULT_CHECKPOINT_FREQ,
    DEFAULT_EVAL_EPISODES,
    DEFAULT_EVAL_FREQ,
    DEFAULT_KEEP_CHECKPOINTS,
    DEFAULT_RUNS_DIR,
    TrainSettings,
    train,
)
from bearing_env.train.sb3.training_envs import VEC_ENV_CHOICES
from bearing_env.train.sb3.zoo import DEFAULT_ENV_IDS, default_env_id, hyperparams_key

#: How ``--init-from`` names a shipped model.
PRETRAINED_PREFIX = "pretrained:"
#: The exit status after Ctrl-C or SIGTERM stopped training (a checkpoint was saved).
EXIT_INTERRUPTED = 130


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env train",
        "Train PPO/SAC (BearingSLAM-Khepera-v1) or DQN (BearingSLAMDiscrete-Khepera-v1) with "
        "stable-baselines3; hyperparameters from the shipped <algo>.yml (rl-zoo3 format; "
        "bearing-env hyperparams ALGO prints its path). "
        "Ctrl-C saves a checkpoint; --resume continues from it.",
    )
    _add_experiment_options(parser.add_argument_group("what is trained"))
    _add_run_folder_options(parser.add_argument_group("the run folder"))
    _add_evaluation_options(parser.add_argument_group("evaluation and checkpoints"))
    _add_process_options(parser.add_argument_group("this process"))
    return parser


def _add_experiment_options(group: argparse._ArgumentGroup) -> None:
    """The algorithm, the env, the hyperparameters, the length and the seed."""
    add = group.add_argument
    add(
        "--algo",
        required=True,
        choices=sorted(DEFAULT_ENV_IDS),
        help="the algorithm; it picks the default env id and the shipped <algo>.yml",
    )
    add(
        "--env",
        help="env id: the key of the YAML entry and the env (default: a file's one entry's "
        "id, else BearingSLAM-Khepera-v1; for dqn BearingSLAMDiscrete-Khepera-v1)",
    )
    add(
        "--env-kwargs",
        nargs="*",
        default=[],
        metavar="K=V",
        help="merged over the YAML's (default: none)",
    )
    add(
        "--hyperparams",
        nargs="*",
        default=[],
        metavar="K=V",
        help="override YAML entries (default: none)",
    )
    add("--conf-file", type=Path, help="hyperparameter file (default: the shipped <algo>.yml)")
    add(
        "--timesteps",
        type=COUNT,
        help="total env steps of the run (default the YAML's n_timesteps); PPO trains in "
        "whole rollouts of n_steps x n_envs steps, so it may train a little more: it says "
        "so before it starts",
    )
    add("--seed", type=SEED, default=0, help="seed of the run (default %(default)s)")
    add(
        "--seeds",
        type=SEED,
        nargs="+",
        metavar="SEED",
        help="train one run per seed, each in --output/seed<SEED> (default: one run, --seed)",
    )
    add(
        "--workers",
        type=COUNT,
        default=1,
        help="with --seeds: seeds trained at once, each in its own process (at most one per "
        "core pays off)",
    )
    add("--n-envs", type=COUNT, help="parallel envs (default the YAML's n_envs)")
    add(
        "--vec-env",
        choices=VEC_ENV_CHOICES,
        default="auto",
        help="batched: one Gymnasium vector env in this process (the id's batched "
        "vector_entry_point, else a SyncVectorEnv); subproc: a process per env (spawn); "
        "dummy: all in this process; auto (default): batched when the id registers a "
        "batched vector env, else subproc",
    )


def _add_run_folder_options(group: argparse._ArgumentGroup) -> None:
    """Where the run is written, continued from, and exported to."""
    add = group.add_argument
    add("--output", type=Path, help="run folder (default runs/<algo>_<env>_seed<seed>)")
    add("--resume", action="store_true", help="continue the run in --output from its checkpoint")
    add(
        "--init-from",
        metavar="MODEL",
        help="start a new run from the weights of MODEL (a .zip, a run folder, or "
        "pretrained:NAME for a shipped model) and the VecNormalize statistics saved beside "
        "it, for fine-tuning; its networks must fit the run's (default: none, new weights)",
    )
    add(
        "--export",
        type=Path,
        metavar="DIR/NAME",
        help="after training, copy the best model to DIR/NAME.zip (+ _vecnormalize.pkl, "
        ".json) (default: no export)",
    )
    add("--export-only", action="store_true", help="export the run in --output without training")


def _add_evaluation_options(group: argparse._ArgumentGroup) -> None:
    """How often the run is evaluated and checkpointed."""
    add = group.add_argument
    add(
        "--eval-freq",
        type=NON_NEGATIVE,
        default=DEFAULT_EVAL_FREQ,
        help="env steps between evaluations (0: never; default %(default)s)",
    )
    add(
        "--eval-episodes",
        type=at_least(1, MAX_VALIDATION_EPISODES),
        default=DEFAULT_EVAL_EPISODES,
        help="episodes per evaluation (default %(default)s)",
    )
    add(
        "--checkpoint-freq",
        type=COUNT,
        default=DEFAULT_CHECKPOINT_FREQ,
        help="env steps between checkpoints (default %(default)s)",
    )
    add(
        "--keep-checkpoints",
        type=COUNT,
        default=DEFAULT_KEEP_CHECKPOINTS,
        help="checkpoints kept on disk (default %(default)s)",
    )


def _add_process_options(group: argparse._ArgumentGroup) -> None:
    """What this process shows, logs and computes on."""
    add = group.add_argument
    add_no_progress(group)
    add("--no-tensorboard", action="store_true", help="no TensorBoard logs")
    add(
        "--device",
        default="cpu",
        help="torch device: cpu, cuda, cuda:N, mps or auto; refused when this machine "
        "lacks it (default %(default)s)",
    )
    add(
        "--torch-threads",
        type=NON_NEGATIVE,
        default=1,
        help="0: torch's default (default %(default)s)",
    )
    add(
        "--verbose",
        type=int,
        choices=(-1, 0, 1, 2),
        default=0,
        help="1: SB3 training tables; -1: no evaluation lines",
    )


def default_output(algo: str, env_id: str, seed: int | None) -> Path:
    """``runs/<algo>_<env>_seed<seed>``, or ``runs/<algo>_<env>`` for several seeds."""
    stem = f"{algo}_{hyperparams_key(env_id)}"
    return DEFAULT_RUNS_DIR / (stem if seed is None else f"{stem}_seed{seed}")


def settings_from_args(args: argparse.Namespace) -> TrainSettings:
    env_id = registered_env_id(args.env or default_env_id(args.algo, args.conf_file))
    return TrainSettings(
        algo=args.algo,
        env_id=env_id,
        output=args.output or default_output(args.algo, env_id, args.seed),
        env_kwargs=parse_key_values(args.env_kwargs, "--env-kwargs"),
        hyperparam_overrides=parse_key_values(args.hyperparams, "--hyperparams"),
        conf_file=args.conf_file,
        timesteps=args.timesteps,
        seed=args.seed,
        n_envs=args.n_envs,
        vec_env=args.vec_env,
        resume=args.resume,
        init_from=init_model_path(args.init_from),
        eval_freq=args.eval_freq,
        eval_episodes=args.eval_episodes,
        checkpoint_freq=args.checkpoint_freq,
        keep_checkpoints=args.keep_checkpoints,
        progress_bar=not args.no_progress,
        tensorboard=not args.no_tensorboard,
        device=args.device,
        torch_threads=args.torch_threads or None,
        verbose=args.verbose,
    )


def init_model_path(spec: str | None, option: str = "--init-from") -> Path | None:
    """``--init-from``'s model (or another ``option``'s): ``pretrained:NAME`` is a shipped
    model's ``.zip``."""
    if spec is None:
        return None
    if spec.startswith(PRETRAINED_PREFIX):
        from bearing_env.agents.sb3 import PRETRAINED_DIR, pretrained_names

        name = spec.removeprefix(PRETRAINED_PREFIX)
        if name not in pretrained_names():
            raise ValueError(
                f"{option}: no pretrained model named {name!r}; available: {pretrained_names()}"
            )
        return PRETRAINED_DIR / f"{name}.zip"
    return Path(spec)


def _output_of(args: argparse.Namespace) -> Path:
    """The run folder the arguments name (``--output`` or its default)."""
    env_id = args.env or default_env_id(args.algo, args.conf_file)
    return Path(args.output or default_output(args.algo, env_id, args.seed))


def _print_export(exported: ExportedModel) -> None:
    print(f"exported the {exported.source} model to {exported.model_path}")
    if exported.vecnormalize_path is not None:
        print(f"  VecNormalize statistics: {exported.vecnormalize_path}")
    print(f"  description: {exported.metadata_path}")


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else list(argv))
    if args.export_only and args.export is None:
        parser.error("--export-only needs --export DIR/NAME")
    if args.seeds is not None:
        _train_seeds(parser, args, sys.argv[1:] if argv is None else list(argv))
        return
    if args.workers != 1:
        parser.error("--workers needs --seeds")
    with _clear_errors(args):
        settings = settings_from_args(args)
        if args.export_only:
            _print_export(export_run(settings.output, args.export))
            return
        result = train(settings)
    speed = (
        f", {result.steps_per_second:.0f} env steps/s over {result.wall_seconds:.1f} s"
        if math.isfinite(result.steps_per_second) and result.wall_seconds > 0.01
        else ""
    )
    print(f"{result.run_dir}: {result.num_timesteps}/{result.target_timesteps} timesteps{speed}")
    if result.interrupted:
        where = result.checkpoint.model_path if result.checkpoint is not None else "?"
        print(f"interrupted: checkpoint {where}; continue with --resume", file=sys.stderr)
        raise SystemExit(EXIT_INTERRUPTED)
    if args.export is not None:
        with _clear_errors(args):
            _print_export(export_run(settings.output, args.export))


def _train_seeds(
    parser: argparse.ArgumentParser, args: argparse.Namespace, argv: list[str]
) -> None:
    """``--seeds``: one run per seed (:mod:`bearing_env.train.sb3.multi_seed`)."""
    from bearing_env.train.sb3.multi_seed import train_seeds

    if any(argument.split("=", 1)[0] == "--seed" for argument in argv):
        parser.error("--seed and --seeds exclude each other")
    if args.export is not None:
        parser.error(
            "--export takes one run: export a seed with --export-only --output DIR/seed<S>"
        )
    env_id = registered_env_id(args.env or default_env_id(args.algo, args.conf_file))
    output = args.output or default_output(args.algo, env_id, None)
    try:
        status = train_seeds(
            argv, output, args.seeds, args.workers, args.resume, not args.no_progress
        )
    except (FileExistsError, ValueError) as error:
        parser.error(str(error))
    raise SystemExit(status)


@contextlib.contextmanager
def _clear_errors(args: argparse.Namespace) -> Iterator[None]:
    """Bad settings and files, and OSErrors while writing (disk full, no permission, a
    parent that is a file), end the command with one line and exit status 2."""
    try:
        yield
    except (FileNotFoundError, FileExistsError, ValueError, TypeError) as error:
        print(f"bearing-env train: error: {error}", file=sys.stderr)
        raise SystemExit(2) from error
    except OSError as error:
        output = _output_of(args)
        in_run = str(error.filename or output).startswith(str(output))
        option = "--export" if args.export is not None and not in_run else "--output"
        fail("bearing-env train", write_error_message(error, output, option))


if __name__ == "__main__":
    main()
