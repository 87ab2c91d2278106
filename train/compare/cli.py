"""``bearing-env compare``: the command line that runs exploration policies on the same
evaluation episodes. This module only reads the arguments, builds the
:class:`~bearing_env.train.compare.config.CompareConfig` and reports; the work is done by

- :mod:`~bearing_env.train.compare.comparison`: one comparison from start to finish (resume, log,
  outputs);
- :mod:`~bearing_env.train.compare.runner`: the episodes and the local worker pool;
- :mod:`~bearing_env.train.compare.log`: ``episodes.jsonl``;
- :mod:`~bearing_env.train.compare.stats` and :mod:`~bearing_env.train.compare.report`:
  the numbers and the files that show them;
- :mod:`~bearing_env.train.common.seeds`: the seed ranges.

Every policy plays the same episodes: episode ``i`` resets the env with seed
``seed_start + i`` (default ``EVAL_SEED_START = 1_000_000``). Training code keeps its
seeds below ``TRAINING_SEED_LIMIT`` (``bearing_env.train.common.seeds``), so evaluation episodes
are never trained on. The policy's own randomness is seeded from the same episode seed
through a separate stream (``bearing_env.agents.base.policy_rng``).

A ``pretrained:NAME`` model runs on the task it was trained on (its record, see
:mod:`bearing_env.agents.model_task`): without ``--env-kwargs`` the comparison runs on
that task, in its id's current version (a model trained on ``BearingSLAM-v0`` runs on
``BearingSLAM-v1`` with its env kwargs, :func:`~bearing_env.tasks.current_id`); env
kwargs of another task (or models of different tasks) are refused in one line naming
the settings that differ, with exit status 2.

Outputs (in ``--out``):

- ``config.json``: what was run (env id and kwargs, policy specs, seeds);
- ``episodes.jsonl``: one JSON line per finished episode, appended and fsynced as soon as
  the episode ends, so an interrupted run loses no logged episode; ``--resume`` runs
  only the missing ones and gives the same summary as an uninterrupted run;
- ``episodes.csv``, ``summary.json``, ``summary.csv``, ``report.md``: written atomically
  (temporary file + ``os.replace``) from the log;
- ``area_vs_moves.png``, ``error_vs_moves.png``;
- ``timing.json``: policy time per decision (the only output that is not reproducible).

With ``--workers N`` the episodes run in a pool of spawned processes that exit with the
command (see :mod:`~bearing_env.train.compare.runner`).

An ``OSError`` while writing (disk full, no permission) ends the command with a one-line
message naming the file and exit status 2. A line of ``episodes.jsonl`` that is not a
valid record, other than a torn last line, is a :class:`CorruptLogError` naming its line
number: delete that line and rerun with ``--resume``, or start again with ``--overwrite``.

Metrics per policy. **Total area** is the sum over landmarks L3, L4, ... of the region
areas (FL units squared), each capped at the env's ``area_cap`` (default 10), which is
also the value of a landmark not yet initialised, exactly as in the reward. An episode
that succeeds early keeps its final map, so its area is carried forward to later move
counts. Reported after 1, 3, 5, 10 and 20 moves (those <= max_moves): the median, and the
mean with a 95% percentile-bootstrap CI (2000 resamples, seeded). Also: success rate
(the env's termination: every region below ``target_area``), moves to success (median
over successful episodes), final landmark error (per episode the mean distance from
centroid to truth over initialised landmarks, FL units; median over episodes),
containment (the fraction of initialised landmarks whose final region holds the truth),
and path length (metres per episode, mean).

    bearing-env compare --env-kwargs scenario=khepera --episodes 200 --workers 2
    bearing-env compare --quick                   # 20 short episodes of the heuristics
"""

from __future__ import annotations

import argparse
import contextlib
import sys
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from bearing_env.agents.model_task import ModelTask, TaskMismatchError, setting_differences
from bearing_env.extras import DISTRIBUTIONS, install_command
from bearing_env.tasks import REGISTERED_TASKS_BY_ID, current_id
from bearing_env.train.common.cli_parser import add_no_progress, command_parser
from bearing_env.train.common.cli_values import (
    COUNT,
    NON_NEGATIVE,
    SEED,
    parse_key_values,
    registered_env_id,
)
from bearing_env.train.common.errors import (
    available,
    exit_on_output_errors,
    fail,
    missing_extra,
    require,
)
from bearing_env.train.common.seeds import EVAL_SEED_START
from bearing_env.train.compare.comparison import RunMismatchError, run_comparison
from bearing_env.train.compare.config import (
    DEFAULT_BOOTSTRAP,
    DEFAULT_BOOTSTRAP_SEED,
    DEFAULT_ENV_ID,
    DEFAULT_ENV_KWARGS,
    DEFAULT_EPISODES,
    CompareConfig,
    policies_from_specs,
)
from bearing_env.train.compare.log import LOG_NAME, CorruptLogError
from bearing_env.train.compare.report import print_tables
from bearing_env.train.compare.runner import EXECUTORS, executor_named, make_env
from bearing_env.train.ray.ray_executor import (
    RAY_CONNECT_TIMEOUT,
    RayAddressError,
    check_ray_address,
)

DEFAULT_POLICIES: tuple[str, ...] = ("random", "parallax", "greedy", "oracle", "lookahead")

QUICK_POLICIES: tuple[str, ...] = ("random", "parallax", "greedy")

QUICK_EPISODES = 20

QUICK_MAX_MOVES = 10


def build_parser() -> argparse.ArgumentParser:
    parser = command_parser(
        "bearing-env compare",
        "Compare exploration policies on the same evaluation episodes.",
        epilog=(
            "Policy specs: random, parallax, greedy, oracle, lookahead, lookahead_oracle, "
            "pretrained:NAME, sb3:path=MODEL.zip, with options as NAME:key=value,... "
            "(e.g. random:length=0.25, greedy:n_turns=16, lookahead:depth=3). "
            f"Evaluation seeds start at {EVAL_SEED_START:,}; training seeds stay below."
        ),
    )
    _add_episode_options(parser.add_argument_group("policies and episodes"))
    _add_executor_options(parser.add_argument_group("where the episodes run"))
    _add_output_options(parser.add_argument_group("outputs"))
    _add_statistics_options(parser.add_argument_group("statistics"))
    return parser


def _add_episode_options(group: argparse._ArgumentGroup) -> None:
    """What is compared: the policies, the env, the episodes and their seeds."""
    group.add_argument(
        "--policies",
        nargs="+",
        default=None,
        metavar="SPEC",
        help=f"policy specs (default: {' '.join(DEFAULT_POLICIES)}, and every model shipped "
        "in agents/pretrained/ that was trained on this env id and env kwargs)",
    )
    group.add_argument("--env", default=DEFAULT_ENV_ID, help="env id (default %(default)s)")
    group.add_argument(
        "--env-kwargs",
        nargs="*",
        default=None,
        metavar="KEY=VALUE",
        help="env kwargs (default: the task of the pretrained:NAME models in --policies, "
        "else none for a task id such as BearingSLAM-FurnishedRoom-v1, else scenario=khepera)",
    )
    group.add_argument(
        "--episodes",
        type=COUNT,
        default=None,
        help=f"evaluation episodes per policy (default {DEFAULT_EPISODES}; --quick "
        f"{QUICK_EPISODES})",
    )
    group.add_argument(
        "--seed-start",
        type=SEED,
        default=EVAL_SEED_START,
        help="seed of the first evaluation episode (default %(default)s)",
    )
    group.add_argument(
        "--quick",
        action="store_true",
        help=f"a short run: {QUICK_EPISODES} episodes of {QUICK_MAX_MOVES} moves, "
        f"policies {' '.join(QUICK_POLICIES)}, Khepera; overwrites its output",
    )


def _add_executor_options(group: argparse._ArgumentGroup) -> None:
    """Where the episodes run: this process, a local pool, or Ray."""
    group.add_argument(
        "--workers",
        type=COUNT,
        default=1,
        help="processes to run episodes in, >= 1 (default %(default)s)",
    )
    group.add_argument(
        "--executor",
        choices=EXECUTORS,
        default="local",
        help="local: this process, or --workers processes (default); ray: Ray tasks on a "
        "local Ray instance or the cluster of --ray-address (the ray extra)",
    )
    group.add_argument(
        "--ray-address",
        default=None,
        metavar="ADDRESS",
        help="with --executor ray: the running cluster to join (HOST:PORT, or auto); a "
        f"HOST:PORT that does not answer within {RAY_CONNECT_TIMEOUT:g} s is refused "
        "(default: a new local Ray instance)",
    )


def _add_output_options(group: argparse._ArgumentGroup) -> None:
    """Where the outputs go, what happens to a comparison already there, and what is shown."""
    group.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output folder (default outputs/compare; with --quick outputs/compare_quick)",
    )
    again = group.add_mutually_exclusive_group()
    again.add_argument(
        "--resume",
        action="store_true",
        help="finish the comparison already in --out (refused if --out holds none)",
    )
    again.add_argument(
        "--overwrite", action="store_true", help="discard the comparison already in --out"
    )
    group.add_argument(
        "--stop-after",
        type=NON_NEGATIVE,
        default=None,
        metavar="N",
        help="run at most N new episodes, then write the outputs (resume later; "
        "default: run them all)",
    )
    add_no_progress(group)
    group.add_argument("--no-plots", action="store_true", help="skip the PNG plots")


def _add_statistics_options(group: argparse._ArgumentGroup) -> None:
    """The bootstrap behind the confidence intervals."""
    group.add_argument(
        "--bootstrap",
        type=COUNT,
        default=DEFAULT_BOOTSTRAP,
        help="bootstrap resamples for the CIs, >= 1 (default %(default)s)",
    )
    group.add_argument(
        "--bootstrap-seed",
        type=SEED,
        default=DEFAULT_BOOTSTRAP_SEED,
        help="seed of the bootstrap resampling (default %(default)s)",
    )


def task_of(env_id: str, kwargs: Mapping[str, Any]) -> tuple[bool, object] | None:
    """What makes two tasks the same: the action kind and the resolved settings of
    ``env_id`` (in its current version) with ``kwargs``, ``max_moves`` aside; None when
    they do not make an env (the comparison says what is wrong when it makes one)."""
    import gymnasium as gym

    settings = {key: value for key, value in kwargs.items() if key != "max_moves"}
    task = ModelTask(current_id(env_id.rpartition(":")[2]), settings)
    try:
        return task.discrete, task.config
    except (ValueError, TypeError, gym.error.Error):
        return None


def matching_pretrained(env_id: str, env_kwargs: dict[str, Any]) -> list[str]:
    """Specs of the shipped models trained on this env's task: the same action kind and the
    same resolved settings (the id's registered kwargs, then the env kwargs), so a model
    trained on ``BearingSLAM-Khepera-v1`` matches ``BearingSLAM-v1`` with
    ``scenario="khepera"``.

    ``max_moves`` is ignored: it only sets how long an episode runs. An id of an older
    version counts as its current one (:func:`~bearing_env.tasks.current_id`), on both
    sides: a model trained on ``BearingSLAM-v0`` with ``scenario="khepera"`` matches
    ``BearingSLAM-Khepera-v1``.
    """
    from bearing_env.agents import pretrained_names, pretrained_record

    wanted = task_of(env_id, env_kwargs)
    if wanted is None:
        return []
    specs = []
    for name in pretrained_names():
        record = pretrained_record(name)
        trained_on = task_of(str(record.get("env_id", "")), dict(record.get("env_kwargs", {})))
        if trained_on == wanted:
            specs.append(f"pretrained:{name}")
    return specs


def shipped_policies(env_id: str, env_kwargs: dict[str, Any]) -> list[str]:
    """The shipped models to compare by default: :func:`matching_pretrained`, or none,
    with a note on stderr, when stable-baselines3 (the ``train`` extra) is missing."""
    return installed_models(matching_pretrained(env_id, env_kwargs))


def installed_models(specs: list[str]) -> list[str]:
    """The ``pretrained:NAME`` specs, or none, with a note on stderr, when
    stable-baselines3 (the ``train`` extra) is missing."""
    if specs and not available("stable_baselines3", "torch"):
        missing = "stable_baselines3" if not available("stable_baselines3") else "torch"
        names = ", ".join(spec.split(":", 1)[1] for spec in specs)
        package = DISTRIBUTIONS.get(missing, missing)
        print(
            f"note: skipped the shipped models ({names}): they need the package "
            f"'{package}', which is not installed; install the train extra: "
            f"{install_command('train')}",
            file=sys.stderr,
        )
        return []
    return specs


def models_task(specs: Sequence[str]) -> ModelTask | None:
    """The task of the ``pretrained:NAME`` models among ``specs`` (the first one's), or
    None when there are none.

    Raises:
        TaskMismatchError: two of them were trained on different tasks (the one-line
            message names the settings that differ).
    """
    from bearing_env.agents.registry import parse_policy_spec
    from bearing_env.agents.sb3 import pretrained_task

    tasks = [
        pretrained_task(str(parsed.options["name"]))
        for parsed in map(parse_policy_spec, specs)
        if parsed.kind == "pretrained"
    ]
    for other in tasks[1:]:
        differences = setting_differences(tasks[0].settings(), other.settings(), other.model)
        if differences:
            raise TaskMismatchError(
                f"models {tasks[0].model!r} and {other.model!r} were trained on different "
                f"tasks: {', '.join(differences)}; compare them one at a time"
            )
    return tasks[0] if tasks else None


def config_from_args(args: argparse.Namespace) -> tuple[CompareConfig, Path]:
    """The comparison the arguments describe, and its output folder. Without
    ``--env-kwargs``, pretrained models run on their own task (:func:`models_task`)."""
    registered_env_id(args.env)
    # A task id carries its own settings (scenario included): the Khepera default is
    # for the base ids only, or it would silently replace a task's arena.
    is_task = args.env.rpartition(":")[2] in REGISTERED_TASKS_BY_ID
    env_id, env_kwargs = args.env, {} if is_task else dict(DEFAULT_ENV_KWARGS)
    task = None if args.env_kwargs is not None else models_task(args.policies or [])
    if args.env_kwargs is not None:
        env_kwargs = parse_key_values(args.env_kwargs, "--env-kwargs")
    elif task is not None:
        env_kwargs = dict(task.env_kwargs)
        env_id = current_id(task.env_id) if args.env == DEFAULT_ENV_ID else args.env
    if args.quick:
        env_kwargs.setdefault("max_moves", QUICK_MAX_MOVES)
    policies = args.policies or [
        *(QUICK_POLICIES if args.quick else DEFAULT_POLICIES),
        *shipped_policies(env_id, env_kwargs),
    ]
    episodes = args.episodes
    if episodes is None:
        episodes = QUICK_EPISODES if args.quick else DEFAULT_EPISODES
    out = (
        args.out
        if args.out is not None
        else Path("outputs/compare_quick" if args.quick else "outputs/compare")
    )
    config = CompareConfig(
        policies=policies_from_specs(policies),
        env_id=env_id,
        env_kwargs=env_kwargs,
        episodes=episodes,
        seed_start=args.seed_start,
        bootstrap=args.bootstrap,
        bootstrap_seed=args.bootstrap_seed,
    )
    return config, out


#: Options that change how a run proceeds but not its results: left out of the command
#: the report quotes (a resumed run regenerates with the plain command).
_PROCESS_ONLY_FLAGS = ("--resume", "--overwrite", "--no-progress")

_PROCESS_ONLY_OPTIONS = ("--stop-after", "--executor", "--ray-address")


def result_arguments(
    argv: Sequence[str],
    process_flags: Sequence[str] = _PROCESS_ONLY_FLAGS,
    process_options: Sequence[str] = _PROCESS_ONLY_OPTIONS,
) -> list[str]:
    """The arguments that determine the results: ``argv`` less the ``process_flags`` and
    the ``process_options`` with their values."""
    kept: list[str] = []
    skip_value = False
    for arg in argv:
        if skip_value:
            skip_value = False
        elif arg in process_flags:
            pass
        elif arg in process_options:
            skip_value = True
        elif not arg.startswith(tuple(f"{option}=" for option in process_options)):
            kept.append(arg)
    return kept


def reproducing_command(
    argv: Sequence[str],
    prog: str = "bearing-env compare",
    process_flags: Sequence[str] = _PROCESS_ONLY_FLAGS,
    process_options: Sequence[str] = _PROCESS_ONLY_OPTIONS,
) -> str:
    """``prog ...`` with the arguments that determine the results
    (:func:`result_arguments`)."""
    return " ".join([prog, *result_arguments(argv, process_flags, process_options)])


def main(argv: Sequence[str] | None = None) -> None:
    parser = build_parser()
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    if args.executor != "ray" and args.ray_address is not None:
        parser.error("--ray-address needs --executor ray")
    if args.executor == "ray" and args.workers != 1:
        parser.error(
            "--workers is for --executor local; Ray runs as many episodes as the cluster has CPUs"
        )
    try:
        if args.executor == "ray":
            require("ray", "--executor ray", extra="ray")
            if args.ray_address is not None:
                check_ray_address(args.ray_address)
        config, out = config_from_args(args)
        # Fail fast on a bad env or policy spec, before any worker starts.
        from bearing_env.agents.registry import make_policy

        with contextlib.closing(make_env(config.env_id, config.env_kwargs)) as env:
            for spec in config.policies.values():
                make_policy(spec, env)
    except TaskMismatchError as error:  # one line, with no usage: the arguments parse
        fail(parser.prog, str(error))
    except (ValueError, TypeError, FileNotFoundError) as error:
        parser.error(str(error))
    except ImportError as error:  # an sb3: policy without stable-baselines3, ...
        clear = missing_extra(error, "this comparison")
        if clear is None:
            raise
        fail(parser.prog, str(clear))
    command = reproducing_command(sys.argv[1:] if argv is None else list(argv))
    started = time.perf_counter()
    try:
        refusals = (RunMismatchError, CorruptLogError, RayAddressError)
        with exit_on_output_errors(parser, out, "--out", refusals):
            result = run_comparison(
                config,
                out,
                workers=args.workers,
                resume=args.resume,
                overwrite=args.overwrite or (args.quick and not args.resume),
                stop_after=args.stop_after,
                progress=not args.no_progress,
                plots=not args.no_plots,
                command=command,
                executor=executor_named(args.executor, args.ray_address),
            )
    except KeyboardInterrupt:
        print(
            f"\ninterrupted: finished episodes are saved in {out / LOG_NAME}; "
            "rerun the same command with --resume to finish",
            file=sys.stderr,
        )
        raise SystemExit(130) from None
    print_tables(result.summary, config, result.timing)
    status = "complete" if result.complete else "INCOMPLETE (rerun with --resume)"
    print(
        f"{status}: {len(result.records)} episodes in {out} "
        f"({time.perf_counter() - started:.0f} s); report: {out / 'report.md'}"
    )


if __name__ == "__main__":
    main()
