"""Every shell command in the README and the documentation pages runs, or at least
parses, as written.

The commands are read from the documents themselves (:data:`DOCUMENTS`: the README and
the pages of ``docs/``): every line of their ``bash`` blocks (with ``\\`` continuations
joined, comments dropped), and every inline `` `bearing-env ...` ``, `` `python -m ...` ``
and `` `make ...` ``. Each one must be listed in :data:`CHECKS`, which says how it is
checked; a document that gains a command the list lacks (or the documents losing one the
list still has) fails :func:`test_every_readme_command_has_a_check`.

How each kind is checked, cheaply:

- ``parse``: the arguments exactly as the README gives them go through the command's own
  argparse parser and its settings step (``config_from_args``, ``settings_from_args``),
  which reject unknown options, bad values and bad env kwargs; the command then does
  not run (these are the long runs: 200-episode comparisons, 600k-step training);
- ``run``: the command runs for real, with the extra arguments given (a smaller budget);
- ``make``: the Makefile defines the target, and ``make -n TARGET`` (a dry run) knows it;
- ``help``: the program's ``--help`` (with its subcommand) runs and names every option the
  command gives: Ray's own CLI, and the long benchmarks;
- ``copy``: a ``cp`` of a comparison plot, whose destination folder is in the repository
  and whose source is written by a documented ``compare`` command;
- ``zoo``: an rl-zoo3 command, which ``tests/tools/test_zoo_commands.py`` runs (briefly)
  as it reads it from the docs;
- ``pip``: a ``pip install`` of the package, whose extras are all in ``pyproject.toml``;
- ``cpp``: a command of the C++ library's build, which ``tests/tools/test_cpp_library.py``
  runs as it reads it from ``docs/cpp.md``.

CI's entry point, ``.ci/run``, runs exactly the README's test command
(:func:`test_ci_runs_the_readme_test_command`).
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
#: The README and the documentation pages (the generated task cards are left out: they
#: quote the suite command that wrote them, checked in tests/tools/test_suite.py).
DOCUMENTS = [README, *sorted((ROOT / "docs").glob("*.md"))]
BIN = Path(sys.executable).parent

#: Documented command -> (kind, extra arguments for a "run").
CHECKS: dict[str, tuple[str, tuple[str, ...]]] = {
    "pip install bearing_env": ("pip", ()),
    'pip install "bearing_env[render,train]"': ("pip", ()),
    "make test": ("make", ()),
    "make test-slow": ("make", ()),
    "make docs": ("make", ()),
    "make demo": ("make", ()),
    "make bench": ("make", ()),
    "make bench-slam": ("make", ()),
    "make lint": ("make", ()),
    "make native": ("make", ()),
    "make format": ("make", ()),
    "make wheel": ("make", ()),
    "make stubs": ("make", ()),
    "bearing-env train": ("parse", ("--algo", "ppo")),
    "bearing-env train --algo ppo --env BearingSLAM-Khepera-v1 --seeds 0 1 2 --workers 2 "
    "--eval-freq 250000 --output runs/ppo_khepera": ("parse", ()),
    "bearing-env curves": ("help", ()),
    "bearing-env evaluate": ("help", ()),
    "bearing-env curves runs/ppo_khepera --out outputs/ppo_khepera_curves.png": ("parse", ()),
    "bearing-env evaluate runs/ppo_khepera --workers 2 --out outputs/evaluate_ppo_khepera": (
        "parse",
        (),
    ),
    "bearing-env train --algo ppo --env BearingSLAM-Khepera-v1 --seeds 0 1 --timesteps 8192 "
    "--eval-freq 4096 --output runs/quick": ("parse", ()),
    "bearing-env evaluate runs/quick --episodes 20 --out outputs/evaluate_quick": ("parse", ()),
    "bearing-env figures": ("parse", ()),
    "bearing-env demo": ("run", ("--episodes", "1", "--moves", "3")),
    "bearing-env compare": ("parse", ()),
    "bearing-env compare --quick": ("parse", ()),
    "bearing-env play": ("parse", ()),
    "bearing-env play --env BearingSLAMDiscrete-v1 --env-kwargs scenario=khepera n_turns=12": (
        "parse",
        (),
    ),
    "bearing-env play --env-kwargs n_landmarks=6 max_moves=30 --seed 3": ("parse", ()),
    "bearing-env compare --policies greedy pretrained:ppo_generalist": ("parse", ()),
    "bearing-env bench": ("parse", ()),
    "bearing-env bench --sections startup": ("parse", ()),
    "bearing-env bench --sections slam": ("parse", ()),
    "bearing-env bench --sections throughput": ("parse", ()),
    "bearing-env figures --out docs/figures": ("parse", ()),
    "bearing-env hyperparams ppo": ("run", ()),
    "bearing-env hyperparams": ("run", ()),
    "bearing-env region-search --movements 2000000 --seed 2026": (
        "run",
        ("--movements", "300", "--no-progress"),
    ),
    "bearing-env soak --steps 1000000 --seed 2026": ("run", ("--steps", "30", "--no-progress")),
    "bearing-env region-search": ("run", ("--movements", "300", "--no-progress")),
    "bearing-env soak --steps 100000 --fusion robust": (
        "run",
        ("--steps", "30", "--fusion", "robust", "--no-progress"),
    ),
    "bearing-env soak": ("run", ("--steps", "30", "--no-progress")),
    "bearing-env soak --steps 100000 --task BearingSLAM-FurnishedRoom-v1": (
        "run",
        ("--steps", "30", "--no-progress"),
    ),
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
    "bearing-env compare --episodes 100 --workers 2 --env BearingSLAMDiscrete-v1 "
    "--out outputs/compare_khepera_discrete": ("parse", ()),
    "bearing-env compare --episodes 100 --workers 2 --env-kwargs scenario=random "
    "n_landmarks=6 --out outputs/compare_random6": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-Khepera-v1 --seed 0 --eval-freq 250000 "
    "--output runs/ppo_khepera": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-v0 --env-kwargs scenario=random "
    '"n_landmarks=(4,8)" max_landmarks=10 --hyperparams n_envs=8 batch_size=256 gamma=0.99 '
    "--timesteps 400000 --seed 1 --output runs/ppo_random": ("parse", ()),
    "bearing-env train --algo ppo --output runs/ppo_random --export "
    "agents/pretrained/ppo_random --export-only": ("parse", ()),
    "python -m bearing_env.train.studies.generalisation --model ppo_random --counts 3 4 6 8 10 "
    "--episodes 50": ("parse", ()),
    "python -m rl_zoo3.train --gym-packages bearing_env --algo ppo --env BearingSLAM-Khepera-v1 "
    '--conf-file "$(bearing-env hyperparams ppo)"': ("zoo", ()),
    "python -m rl_zoo3.enjoy --gym-packages bearing_env --algo ppo --env BearingSLAM-Khepera-v1 "
    "-f logs": ("zoo", ()),
    'bearing-env train --algo ppo --conf-file "$(bearing-env hyperparams ppo_entities)" '
    "--seed 0 --eval-freq 100000 --output runs/ppo_generalist": ("parse", ()),
    'bearing-env train --algo ppo --conf-file "$(bearing-env hyperparams ppo_attention)" '
    "--seed 0 --eval-freq 100000 --output runs/ppo_attention": ("parse", ()),
    'bearing-env train --algo ppo --conf-file "$(bearing-env hyperparams ppo_shapes)" '
    "--seed 0 --eval-freq 100000 --output runs/ppo_shapes": ("parse", ()),
    "bearing-env train --algo ppo --output runs/ppo_generalist --export "
    "agents/pretrained/ppo_generalist --export-only": ("parse", ()),
    "bearing-env compare --policies greedy oracle lookahead lookahead_oracle --episodes 200 "
    "--workers 2 --out outputs/compare_lookahead": ("parse", ()),
    "bearing-env figures --only robust --out docs/figures": ("parse", ()),
    "bearing-env robust-eval": ("parse", ()),
    "bearing-env robust-eval --episodes 200": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-Khepera-v1 "
    "--init-from pretrained:ppo_khepera --timesteps 2000000 "
    "--output runs/ppo_khepera_finetune": ("parse", ()),
    "bearing-env observability": ("parse", ()),
    # The learned designs on the planner features (docs/evaluation.md).
    "bearing-env train --algo ppo --env BearingSLAMDiscrete-Khepera-Planner-v1 --seeds 0 1 2 "
    "--workers 2 --timesteps 1000000 --eval-freq 250000 --output runs/ppo_planner_khepera": (
        "parse",
        (),
    ),
    'bearing-env train --algo ppo --conf-file "$(bearing-env hyperparams ppo_candidates)" '
    "--seeds 0 1 2 --timesteps 250000 --eval-freq 125000 "
    "--output runs/ppo_planner_scorer_khepera": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAMDiscrete-Khepera-Planner-v1 --timesteps 4096 "
    "--output runs/bc_init_khepera --export runs/bc_init_khepera/export/model": ("parse", ()),
    "bearing-env distill --student runs/bc_init_khepera/export/model.zip --teacher lookahead "
    "--iterations 4 --episodes 50 --output runs/bc_khepera": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAMDiscrete-Khepera-Planner-v1 --init-from "
    "runs/bc_khepera/model.zip --seeds 0 1 2 --timesteps 250000 --eval-freq 125000 "
    "--output runs/ppo_planner_bc_khepera": ("parse", ()),
    "bearing-env evaluate runs/ppo_planner_khepera --name ppo_planner_mlp "
    "--out outputs/evaluate_ppo_planner_mlp": ("parse", ()),
    "bearing-env evaluate runs/ppo_planner_scorer_khepera --name ppo_planner_scorer "
    "--out outputs/evaluate_ppo_planner_scorer": ("parse", ()),
    "bearing-env evaluate runs/ppo_planner_bc_khepera --name ppo_planner_bc "
    "--out outputs/evaluate_ppo_planner_bc": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAMDiscrete-Khepera-Planner-v1 --init-from "
    "runs/bc_khepera/model.zip --seeds 0 1 2 --workers 2 --timesteps 1000000 --eval-freq 250000 "
    "--output runs/ppo_planner_bc_khepera_1m": ("parse", ()),
    "bearing-env evaluate runs/ppo_planner_bc_khepera_1m --name ppo_planner_bc_1m "
    "--out outputs/evaluate_ppo_planner_bc_1m": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAMDiscrete-Random3to16-Planner-v1 --seeds 0 1 2 "
    "--workers 2 --timesteps 500000 --eval-freq 250000 --output runs/ppo_planner_random": (
        "parse",
        (),
    ),
    "bearing-env evaluate runs/ppo_planner_random --name ppo_planner_random "
    "--out outputs/evaluate_ppo_planner_random": ("parse", ()),
    "bearing-env evaluate runs/ppo_planner_random/seed0 runs/ppo_planner_random_b "
    "--name ppo_planner_random --out outputs/evaluate_ppo_planner_random": ("parse", ()),
    "bearing-env distill": ("help", ()),
    "bearing-env distill --student pretrained:ppo_khepera --teacher lookahead_oracle "
    "--iterations 4 --episodes 50 --output runs/distill_khepera": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-FurnishedRoom-v0 --seed 0 --eval-freq 250000 "
    "--output runs/ppo_furnished_room": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-Khepera-v1 --seeds 0 1 2 --workers 2 "
    "--timesteps 5000000 --eval-freq 250000 --output runs/ppo_khepera": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-Khepera-v1 --output runs/ppo_khepera/seed0 "
    "--export agents/pretrained/ppo_khepera --export-only": ("parse", ()),
    "bearing-env evaluate runs/ppo_khepera --out outputs/evaluate_ppo_khepera": ("parse", ()),
    "bearing-env curves runs/ppo_khepera --out docs/figures/ppo_khepera_curves.png --json "
    "docs/figures/ppo_khepera_curves.json": ("parse", ()),
    "bearing-env train --algo ppo --env BearingSLAM-FurnishedRoom-v0 --output "
    "runs/ppo_furnished_room --export agents/pretrained/ppo_furnished_room --export-only": (
        "parse",
        (),
    ),
    "bearing-env observability --env BearingSLAM-Khepera-v0 --fov 360 180 90 "
    "--oracle-episodes 20": ("parse", ()),
    "bearing-env observability --env BearingSLAM-Khepera-v1 --fov 360 180 90 --plot "
    "docs/figures/observability_khepera.png --json docs/figures/observability_khepera.json": (
        "parse",
        (),
    ),
    "bearing-env observability --env BearingSLAM-FurnishedRoom-v1 --fov 360 180 90 --plot "
    "docs/figures/observability_furnished_room.png --json "
    "docs/figures/observability_furnished_room.json": ("parse", ()),
    # The same, as the measured sentence of the table quotes them.
    "bearing-env observability --env BearingSLAM-Khepera-v1 --fov 360 180 90 --plot "
    "docs/figures/observability_khepera.png --json docs/figures/observability_khepera.json "
    "--no-progress": ("parse", ()),
    "bearing-env observability --env BearingSLAM-FurnishedRoom-v1 --fov 360 180 90 --plot "
    "docs/figures/observability_furnished_room.png --json "
    "docs/figures/observability_furnished_room.json --no-progress": ("parse", ()),
    "bearing-env suite": ("parse", ()),
    "bearing-env robust-eval --episodes 200 --json docs/figures/robust_eval.json": ("parse", ()),
    "bearing-env compare --episodes 200 --executor ray": ("parse", ()),
    "bearing-env compare --episodes 2000 --executor ray --ray-address auto "
    "--out outputs/compare_2000": ("parse", ()),
    "bearing-env rllib": ("parse", ()),
    "bearing-env rllib --env BearingSLAM-v1 --iterations 50 --output runs/rllib_ppo": (
        "parse",
        (),
    ),
    "bearing-env rllib --num-env-runners 3 --iterations 100 --ray-address auto "
    "--output runs/rllib_2node": ("parse", ()),
    "bearing-env sweep": ("parse", ()),
    "bearing-env sweep --grid lr=0.0001,0.0003 --env-grid scenario=khepera,random "
    "--num-env-runners 0 --iterations 20 --out runs/sweep": ("parse", ()),
    "python -m bearing_env.benchmarks.bench_compare": ("help", ()),
    "python -m bearing_env.benchmarks.bench_compare --repeats 3": ("help", ()),
    "ray start --head --port=6379": ("help", ()),
    "ray start --address=A_IP:6379": ("help", ()),
    "ray status": ("help", ()),
    "ray stop": ("help", ()),
    "bearing-env bench --help": ("help", ()),
    "bearing-env bench-callgrind --json benchmarks/results/bench_callgrind.json": ("help", ()),
    "bearing-env bench --json benchmarks/results/bench_env.json": ("parse", ()),
    "bearing-env compare --policies greedy oracle lookahead lookahead_oracle": ("parse", ()),
    "bearing-env docs-tables": ("parse", ()),
    "bearing-env generalisation": ("help", ()),
    "bearing-env suite --episodes 200": ("parse", ()),
    "bearing-env compare --policies random greedy --env bearing_env:BearingSLAM-Khepera-v0 "
    "--episodes 200": ("parse", ()),
    "bearing-env compare --policies random greedy --env bearing_env:BearingSLAM-Khepera-v1 "
    "--episodes 200": ("parse", ()),
    "bearing-env transfer-tightness --transfer T --json ...": ("help", ()),
    "bearing-env transfer-tightness --transfer conservative --no-progress --json "
    "benchmarks/results/transfer_tightness_conservative.json": ("help", ()),
    "bearing-env transfer-tightness --transfer conservative_global --no-progress --json "
    "benchmarks/results/transfer_tightness_conservative_global.json": ("help", ()),
    "bearing-env suite --tasks BearingSLAM-FurnishedRoom-v1 --workers 2": ("parse", ()),
    "bearing-env suite --tasks BearingSLAM-Khepera-v1 --workers 2": ("parse", ()),
    "python -m bearing_env.train.studies.generalisation --model ppo_generalist --counts 3 8 12 "
    "16 --episodes 200 --out outputs/generalisation_generalist": ("parse", ()),
    "python -m rl_zoo3.train --algo ppo --env BearingSLAM-Random3to16-Entities-v1 "
    '--gym-packages bearing_env --conf-file "$(bearing-env hyperparams ppo_entities)"': (
        "zoo",
        (),
    ),
    "bearing-env suite --episodes 200 --workers 2": ("parse", ()),
    "bearing-env docs-tables --check": ("parse", ()),
    "cp outputs/compare_khepera_25cm/summary.json docs/compare/results/khepera_25cm.json": (
        "copy",
        (),
    ),
    "cp outputs/compare_khepera_discrete/summary.json "
    "docs/compare/results/settings_discrete.json": ("copy", ()),
    "cp outputs/compare_random6/summary.json docs/compare/results/settings_random6.json": (
        "copy",
        (),
    ),
    "cp outputs/compare_lookahead/summary.json docs/compare/results/lookahead.json": ("copy", ()),
    "cmake -S . -B build/cpp -G Ninja -DBEARING_ENV_PYTHON=OFF": ("cpp", ()),
    "cmake --build build/cpp": ("cpp", ()),
    "ctest --test-dir build/cpp --output-on-failure": ("cpp", ()),
    "cmake --install build/cpp --prefix /opt/bearing_core": ("cpp", ()),
    "cmake -S examples/cpp -B build/replay -G Ninja -DCMAKE_PREFIX_PATH=/opt/bearing_core": (
        "cpp",
        (),
    ),
    "cmake --build build/replay": ("cpp", ()),
    "build/replay/replay examples/cpp/bearing_log.csv 0.0349": ("cpp", ()),
}


def readme_commands(text: str) -> list[str]:
    """The shell commands of a Markdown document, in order, without duplicates."""
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
    inline = re.findall(r"`((?:bearing-env|python -m|make) [^`]+)`", text)
    commands += [" ".join(command.split()) for command in inline]  # one line each
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


def documented_commands() -> set[str]:
    return {
        command
        for document in DOCUMENTS
        for command in readme_commands(document.read_text(encoding="utf-8"))
    }


def test_every_readme_command_has_a_check() -> None:
    commands = documented_commands()
    assert sorted(commands - CHECKS.keys()) == [], "documented commands without a check"
    assert sorted(CHECKS.keys() - commands) == [], "checks of commands the documents lost"


def test_the_readme_gives_the_two_make_commands_and_ci_runs_its_test_command() -> None:
    readme = readme_commands(README.read_text(encoding="utf-8"))
    assert {"make test", "make demo"} <= set(readme)
    ci_lines = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    commands = [line.strip() for line in ci_lines if line.strip()]
    commands = [line for line in commands if not line.startswith(("#", "set ", "cd "))]
    assert commands == ["make test"]


def _parse(argv: list[str]) -> None:
    """Parse a command's arguments with its own parser and settings step."""
    program, rest = argv[0], argv[1:]
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
    elif command == "suite":
        from bearing_env.train.compare import suite

        suite.suite_configs(suite.build_parser().parse_args(arguments))
    elif command == "play":
        from bearing_env.train.studies import play

        play.build_parser().parse_args(arguments)
    elif command == "train":
        from bearing_env.train.sb3 import train_cli

        train_cli.settings_from_args(train_cli.build_parser().parse_args(arguments))
    elif command in ("evaluate", "curves"):
        from bearing_env.train.compare import evaluate
        from bearing_env.train.sb3 import curves

        module = evaluate if command == "evaluate" else curves
        module.build_parser().parse_args(arguments)
    elif command == "distill":
        from bearing_env.train.sb3 import distill

        distill.settings_from_args(distill.build_parser().parse_args(arguments))
    elif command == "figures":
        from bearing_env.train.studies import figures

        figures.build_parser().parse_args(arguments)
    elif command == "observability":
        from bearing_env.train.studies import observability

        observability.build_parser().parse_args(arguments)
    elif command == "robust-eval":
        from bearing_env.train.studies import robust_eval

        robust_eval.build_parser().parse_args(arguments)
    elif command == "bench":
        from bearing_env.benchmarks import bench_env

        parser = bench_env.build_parser()
        bench_env.settings_from_args(parser.parse_args(arguments), parser)
    elif command == "docs-tables":
        from bearing_env.train.common import doc_tables

        doc_tables.build_parser().parse_args(arguments)
    elif command == "rllib":
        from bearing_env.train.ray import rllib

        rllib.settings_from_args(rllib.build_parser().parse_args(arguments))
    elif command == "sweep":
        from bearing_env.train.ray import sweep

        sweep.build_parser().parse_args(arguments)
    else:
        pytest.fail(f"no parser check for bearing-env {command}")


def documented_options(argv: list[str]) -> set[str]:
    """The options a command gives (``--port=6379`` gives ``--port``)."""
    return {arg.split("=", 1)[0] for arg in argv if arg.startswith("--")}


def command_extra(command: str) -> str | None:
    """The extra a README command needs to run or parse: training (and rl-zoo3's trainer)
    needs ``train``, Ray's own command line ``ray``."""
    if command.startswith(
        ("bearing-env train", "bearing-env distill", "bearing-env evaluate", "python -m rl_zoo3")
    ):
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
        makefile = (ROOT / "Makefile").read_text(encoding="utf-8")
        assert re.search(rf"^{re.escape(argv[1])}:", makefile, re.MULTILINE), argv[1]
        result = subprocess.run(
            ["make", "-n", *argv[1:]], cwd=ROOT, capture_output=True, text=True, timeout=60
        )
        assert result.returncode == 0, result.stderr
        assert result.stdout.strip()
    elif kind == "pip":
        tomllib = pytest.importorskip("tomllib")  # Python 3.11+
        extras = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
        optional = extras["project"]["optional-dependencies"]
        requirement = re.fullmatch(r"bearing_env(?:\[([\w,]+)\])?", argv[-1])
        assert argv[:2] == ["pip", "install"] and requirement is not None, argv
        named = (requirement.group(1) or "").split(",")
        assert sorted(set(filter(None, named)) - optional.keys()) == []
    elif kind == "copy":
        source, destination = Path(argv[1]), Path(argv[2])
        assert (ROOT / destination.parent).is_dir()
        out_option = f"--out {source.parent}"
        writers = ("bearing-env compare", "python -m bearing_env.train.studies.generalisation")
        producers = [c for c in CHECKS if c.startswith(writers) and out_option in c]
        assert producers, f"no documented command writes {source}"
    elif kind == "cpp":
        # The C++ build's commands: tests/tools/test_cpp_library.py runs them as it reads
        # them from docs/cpp.md.
        from tests.tools.test_cpp_library import page_commands

        assert command in page_commands()
    elif kind == "zoo":
        from tests.tools.test_zoo_commands import COMMANDS

        assert command in {zoo.command for zoo in COMMANDS}
    elif kind == "parse":
        _parse(argv + list(extra))
    elif kind == "help":
        # A command of another program (Ray's CLI) or a long benchmark: its --help runs,
        # so the program and the subcommand exist.
        if argv[0] == "python":
            program = [sys.executable, *argv[1:3]]
        else:
            program = [str(BIN / argv[0]), argv[1]]
        result = subprocess.run([*program, "--help"], capture_output=True, text=True, timeout=120)
        assert result.returncode == 0, result.stderr[-3000:]
        assert documented_options(argv) <= set(re.findall(r"--[\w-]+", result.stdout))
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
