"""Every shell command in the README runs, or at least parses, as written.

The commands are read from the README itself: every line of its ``bash`` blocks (with
``\\`` continuations joined, comments dropped), and every inline `` `bearing-env ...` ``,
`` `python -m ...` `` and `` `make ...` ``. Each one must be listed in :data:`CHECKS`,
which says how it is checked; a README that gains a command the list lacks (or loses one
the list still has) fails :func:`test_every_readme_command_has_a_check`.

How each kind is checked, cheaply:

- ``parse``: the arguments exactly as the README gives them go through the command's own
  argparse parser and its settings step (``config_from_args``, ``settings_from_args``),
  which reject unknown options, bad values and bad env kwargs; the command then does
  not run (these are the long runs: 200-episode comparisons, 600k-step training);
- ``run``: the command runs for real, with the extra arguments given (a smaller budget);
- ``make``: ``make -n TARGET`` (a dry run) knows the target;
- ``help``: the program's ``--help`` (with its subcommand) runs: Ray's own CLI, and the
  long benchmark;
- ``copy``: a ``cp`` of a comparison plot, whose destination folder is in the repository
  and whose source is written by a README ``compare`` command.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from tests.extras import needs

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
BIN = Path(sys.executable).parent

#: README command -> (kind, extra arguments for a "run").
CHECKS: dict[str, tuple[str, tuple[str, ...]]] = {
    "make test": ("make", ()),
    "make demo": ("make", ()),
    "make bench": ("make", ()),
    "make bench-slam": ("make", ()),
    "make lint": ("make", ()),
    "bearing-env train": ("parse", ("--algo", "ppo")),
    "bearing-env figures": ("parse", ()),
    "bearing-env demo": ("run", ("--episodes", "1", "--moves", "3")),
    "bearing-env compare": ("parse", ()),
    "bearing-env compare --quick": ("parse", ()),
    "bearing-env bench": ("parse", ()),
    "bearing-env bench --sections startup": ("parse", ()),
    "bearing-env bench --sections slam,planning --seconds 1": ("parse", ()),
    "bearing-env bench --profile vector": ("parse", ()),
    "bearing-env bench --sections single,vector,slam,startup,planning": ("parse", ()),
    "bearing-env figures --out docs/figures": ("parse", ()),
    "bearing-env hyperparams ppo": ("run", ()),
    "bearing-env hyperparams": ("run", ()),
    "bearing-env region-search --movements 2000000 --seed 2026": (
        "run",
        ("--movements", "300", "--no-progress"),
    ),
    "bearing-env soak --steps 1000000 --seed 2026": ("run", ("--steps", "30", "--no-progress")),
    "python -m bearing_env.train.studies.demo": ("run", ("--episodes", "1", "--moves", "3")),
    "bearing-env compare --episodes 200 --workers 2 --out outputs/compare_khepera": (
        "parse",
        (),
    ),
    "bearing-env compare --episodes 200 --workers 2 --env-kwargs scenario=khepera "
    "move_length=0.25 --out outputs/compare_khepera_25cm": ("parse", ()),
    "cp outputs/compare_khepera/area_vs_moves.png docs/compare/khepera_area_vs_moves.png": (
        "copy",
        (),
    ),
    "cp outputs/compare_khepera/error_vs_moves.png docs/compare/khepera_error_vs_moves.png": (
        "copy",
        (),
    ),
    "bearing-env compare --episodes 100 --workers 2 --env BearingSLAMDiscrete-v0 "
    "--out outputs/compare_khepera_discrete": ("parse", ()),
    "bearing-env compare --episodes 100 --workers 2 --env-kwargs scenario=random "
    "n_landmarks=6 --out outputs/compare_random6": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-v0 --seed 0 --eval-freq 250000 "
    "--output runs/ppo_khepera": ("parse", ()),
    "bearing-env train --algo ppo --output runs/ppo_khepera --export "
    "agents/pretrained/ppo_khepera --export-only": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-v0 --env-kwargs scenario=random "
    '"n_landmarks=(4,8)" max_landmarks=10 --hyperparams n_envs=8 batch_size=256 gamma=0.99 '
    "--timesteps 400000 --seed 1 --output runs/ppo_random": ("parse", ()),
    "bearing-env train --algo ppo --output runs/ppo_random --export "
    "agents/pretrained/ppo_random --export-only": ("parse", ()),
    "python -m bearing_env.train.studies.generalisation --model ppo_random --counts 3 4 6 8 10 "
    "--episodes 50": ("parse", ()),
    "python -m rl_zoo3.train --gym-packages bearing_env --algo ppo --env BearingSLAM-v0 "
    '--conf-file "$(bearing-env hyperparams ppo)"': ("parse", ()),
    "python -m rl_zoo3.train --gym-packages bearing_env --algo ppo --env BearingSLAM-v0 "
    '--conf-file "$(bearing-env hyperparams ppo_entities)"': ("parse", ()),
    'bearing-env train --algo ppo --conf-file "$(bearing-env hyperparams ppo_entities)" '
    "--seed 0 --eval-freq 100000 --output runs/ppo_generalist": ("parse", ()),
    "bearing-env train --algo ppo --output runs/ppo_generalist --export "
    "agents/pretrained/ppo_generalist --export-only": ("parse", ()),
    "python -m bearing_env.train.studies.generalisation --model ppo_generalist --counts 3 8 12 16 "
    "--episodes 200 --out outputs/generalisation_generalist": ("parse", ()),
    "cp outputs/generalisation_generalist/generalisation.png "
    "docs/compare/generalisation_generalist.png": ("copy", ()),
    "bearing-env compare --policies greedy oracle lookahead lookahead_oracle --episodes 200 "
    "--workers 2 --out outputs/compare_lookahead": ("parse", ()),
    "bearing-env figures --only robust --out docs/figures": ("parse", ()),
    "bearing-env compare --episodes 200 --executor ray": ("parse", ()),
    "bearing-env compare --episodes 2000 --executor ray --ray-address auto "
    "--out outputs/compare_2000": ("parse", ()),
    "bearing-env rllib": ("parse", ()),
    "bearing-env rllib --env BearingSLAM-v0 --iterations 50 --output runs/rllib_ppo": (
        "parse",
        (),
    ),
    "bearing-env rllib --num-env-runners 3 --iterations 100 --ray-address auto "
    "--output runs/rllib_2node": ("parse", ()),
    "bearing-env sweep": ("parse", ()),
    "bearing-env sweep --grid lr=0.0001,0.0003 --env-grid scenario=khepera,random "
    "--num-env-runners 0 --iterations 20 --out runs/sweep": ("parse", ()),
    "python -m bearing_env.benchmarks.bench_compare": ("help", ()),
    "ray start --head --port=6379": ("help", ()),
    "ray start --address=A_IP:6379": ("help", ()),
    "ray status": ("help", ()),
    "ray stop": ("help", ()),
}


def readme_commands(text: str) -> list[str]:
    """The shell commands of a README, in order, without duplicates."""
    commands: list[str] = []
    for block in re.findall(r"```(?:bash|sh|shell)\n(.*?)```", text, re.S):
        pending = ""
        for line in block.splitlines():
            pending = f"{pending} {line.strip()}".strip()
            if pending.endswith("\\"):
                pending = pending[:-1].rstrip()
                continue
            command = re.sub(r"\s+#.*$", "", pending).strip()
            if command and not command.startswith("#"):
                commands.append(command)
            pending = ""
    commands += re.findall(r"`((?:bearing-env|python -m|make) [^`]+)`", text)
    return list(dict.fromkeys(commands))


def test_the_extractor_reads_blocks_continuations_comments_and_inline_commands() -> None:
    text = (
        "Run `bearing-env demo` or `make demo`.\n\n```bash\n# a comment\n"
        "bearing-env compare --episodes 2 \\\n    --out o   # why\nmake test\n```\n"
        "```python\nprint('not a shell command')\n```\n"
    )
    assert readme_commands(text) == [
        "bearing-env compare --episodes 2 --out o",
        "make test",
        "bearing-env demo",
        "make demo",
    ]


def test_every_readme_command_has_a_check() -> None:
    commands = set(readme_commands(README.read_text(encoding="utf-8")))
    assert sorted(commands - CHECKS.keys()) == [], "README commands without a check"
    assert sorted(CHECKS.keys() - commands) == [], "checks of commands the README lost"


def _parse(argv: list[str]) -> None:
    """Parse a command's arguments with its own parser and settings step."""
    program, rest = argv[0], argv[1:]
    if program == "python" and rest[:2] == ["-m", "rl_zoo3.train"]:
        # rl-zoo3 builds its parser inside train(), so the run itself is in test_train
        # (test_rl_zoo3_trains_with_the_shipped_yaml, with this substitution's path); here
        # the module imports and the substituted path exists.
        from bearing_env.train.sb3.zoo import rl_zoo3_module

        assert callable(rl_zoo3_module("rl_zoo3.train").train)
        conf = rest.index("--conf-file") + 1
        shipped = re.fullmatch(r"\$\(bearing-env hyperparams (\w+)\)", rest[conf])
        assert shipped is not None, rest[conf]
        from bearing_env.train.sb3.conf_files import default_conf_file

        assert default_conf_file(shipped.group(1)).is_file()
        return
    if program == "python":
        assert rest[:2] == ["-m", "bearing_env.train.studies.generalisation"]
        result = subprocess.run(
            [sys.executable, "-m", "bearing_env.train.studies.generalisation", "--help"],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert result.returncode == 0, result.stderr
        options = set(re.findall(r"--[\w-]+", result.stdout))
        assert {arg for arg in rest[2:] if arg.startswith("--")} <= options
        return
    assert program == "bearing-env"
    command, arguments = rest[0], rest[1:]
    if command == "compare":
        from bearing_env.train.compare import cli as compare

        compare.config_from_args(compare.build_parser().parse_args(arguments))
    elif command == "train":
        from bearing_env.train.sb3 import train_cli

        train_cli.settings_from_args(train_cli.build_parser().parse_args(arguments))
    elif command == "figures":
        from bearing_env.train.studies import figures

        figures.build_parser().parse_args(arguments)
    elif command == "bench":
        from bearing_env.benchmarks import bench_env

        parser = bench_env.build_parser()
        bench_env.settings_from_args(parser.parse_args(arguments), parser)
    elif command == "rllib":
        from bearing_env.train.ray import rllib

        rllib.settings_from_args(rllib.build_parser().parse_args(arguments))
    elif command == "sweep":
        from bearing_env.train.ray import sweep

        sweep.build_parser().parse_args(arguments)
    else:
        pytest.fail(f"no parser check for bearing-env {command}")


def command_extra(command: str) -> str | None:
    """The extra a README command needs to run or parse: training (and rl-zoo3's trainer)
    needs ``train``, Ray's own command line ``ray``."""
    if command.startswith(("bearing-env train", "python -m rl_zoo3")):
        return "train"
    if command.startswith("ray "):
        return "ray"
    return None


#: Every checked command, each marked with the extra it needs.
COMMAND_PARAMS = [
    pytest.param(command, marks=needs(extra)) if (extra := command_extra(command)) else command
    for command in sorted(CHECKS)
]


@pytest.mark.parametrize("command", COMMAND_PARAMS)
def test_readme_command_runs_or_parses(command: str, tmp_path: Path) -> None:
    kind, extra = CHECKS[command]
    argv = shlex.split(command)
    if kind == "make":
        result = subprocess.run(
            ["make", "-n", *argv[1:]], cwd=ROOT, capture_output=True, text=True, timeout=60
        )
        assert result.returncode == 0, result.stderr
        assert result.stdout.strip()
    elif kind == "copy":
        source, destination = Path(argv[1]), Path(argv[2])
        assert (ROOT / destination.parent).is_dir()
        out_option = f"--out {source.parent}"
        writers = ("bearing-env compare", "python -m bearing_env.train.studies.generalisation")
        producers = [c for c in CHECKS if c.startswith(writers) and out_option in c]
        assert producers, f"no README command writes {source}"
    elif kind == "parse":
        _parse(argv + list(extra))
    elif kind == "help":
        # A command of another program (Ray's CLI) or a long benchmark: its --help runs,
        # so the program and the subcommand exist.
        if argv[0] == "python":
            program = [sys.executable, *argv[1:3]]
        else:
            program = [str(BIN / argv[0]), argv[1]]
        result = subprocess.run(
            [*program, "--help"], capture_output=True, text=True, timeout=120
        )
        assert result.returncode == 0, result.stderr[-3000:]
    else:
        assert kind == "run"
        program = [str(BIN / "bearing-env")] if argv[0] == "bearing-env" else [sys.executable]
        result = subprocess.run(
            [*program, *argv[1:], *extra],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=300,
            env={**os.environ, "SDL_VIDEODRIVER": "dummy"},
        )
        assert result.returncode == 0, result.stderr[-3000:]
        assert "Traceback" not in result.stderr
