"""Every rl-zoo3 command the docs show runs, briefly, as written.

The commands are read from the text: the README, the pages under ``docs/``, the header
comments of the shipped hyperparameter files (``train/sb3/hyperparams/*.yml``) and the
package's docstrings, so a command that changes there is the command tested here. Each
runs in ``bash`` from a fresh folder, with ``bearing-env`` on the PATH (for its
``$(bearing-env hyperparams ...)``), and with arguments appended that make it short: a
few dozen timesteps, an evaluation every 16 steps of one episode, tiny buffers.
``enjoy`` runs on the output of the training command before it in the same document.

What is checked, through :mod:`tests.tools.zoo_probe`, which records the settings of every
env rl-zoo3 builds: the training envs are the YAML entry's ``env_kwargs``, and the
evaluation env (and ``enjoy``'s env) has exactly the training envs' settings. rl-zoo3
gives a YAML's ``env_kwargs`` to its training envs only, so an entry with settings of its
own evaluated on the id's defaults without ``--eval-env-kwargs`` and failed here, as the
``ppo_entities`` command did (``norm_obs_keys`` on a Box observation). Every shipped
entry is keyed by a registered id whose kwargs carry its settings (``ppo.yml``:
``BearingSLAM-Khepera-v1``; ``ppo_entities.yml``: ``BearingSLAM-Random3to16-Entities-v1``),
so no command needs that flag: rl-zoo3 makes the evaluation env from the id;
:func:`test_the_plain_command_trains_and_evaluates_each_task_keyed_file` runs that plain
form for every single-entry file, whatever the docs show, and
``tests/tools/test_hyperparams_files.py`` runs every entry of every file in process.

The ``ppo`` and ``ppo_entities`` runs and ``enjoy`` are in the default run; the other
algorithms' commands are ``slow``.
"""

# ruff: noqa: E402  (imports of the extra follow its skip)
from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.extras import skip_module_without

skip_module_without("train")

import yaml

from bearing_env.envs.config import EnvConfig
from bearing_env.train.sb3.conf_files import default_conf_file
from bearing_env.train.sb3.zoo import hyperparams_key
from tests.tools.zoo_probe import PROBE_VARIABLE

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(sys.executable).parent

#: rl-zoo3's command line: ``python -m rl_zoo3.train`` or ``python -m rl_zoo3.enjoy``.
ZOO_COMMAND = re.compile(r"^python -m rl_zoo3\.(train|enjoy)\b")

#: Timesteps of a test run: PPO's single rollout of 2 envs x 32 steps, an episode and a half.
TIMESTEPS = 64
#: rl-zoo3 evaluates every ``--eval-freq // n_envs`` calls: here at 32 and 64 steps.
EVAL_FREQ = 32
#: The hyperparameters that make each algorithm's run short (rl-zoo3's ``--hyperparams``).
TINY_HYPERPARAMS: dict[str, tuple[str, ...]] = {
    "ppo": ("n_envs:2", "n_steps:32", "batch_size:32", "n_epochs:1"),
    "sac": ("n_envs:2", "learning_starts:16", "buffer_size:1000", "batch_size:16"),
    "dqn": (
        "n_envs:2",
        "learning_starts:16",
        "buffer_size:1000",
        "batch_size:16",
        "target_update_interval:8",
    ),
}
#: The algorithms whose commands run in the default test run (the others are ``slow``).
DEFAULT_RUN_ALGOS = ("ppo",)
#: The gym packages of a test run: the project's, and the probe that records the envs.
PROBED_PACKAGES = ("--gym-packages", "bearing_env", "tests.tools.zoo_probe")


def documents() -> list[Path]:
    """The files whose text shows rl-zoo3 commands, in a fixed order: the README, the
    docs pages, the hyperparameter files and the docstrings of the package's modules."""
    modules = [ROOT / folder for folder in ("bearing_env", "agents", "train", "benchmarks")]
    return [
        ROOT / "README.md",
        *sorted((ROOT / "docs").rglob("*.md")),
        *sorted((ROOT / "train" / "sb3" / "hyperparams").glob("*.yml")),
        *sorted(
            path
            for folder in modules
            for path in folder.rglob("*.py")
            if "python -m rl_zoo3." in path.read_text(encoding="utf-8")
        ),
    ]


def zoo_commands(text: str, kind: str = ".md") -> list[str]:
    """The rl-zoo3 commands of a text, in order: lines (``\\`` continuations joined,
    shell comments dropped) that start with ``python -m rl_zoo3.``, and in Markdown
    inline ``python -m rl_zoo3.`` code. ``kind`` is the file's suffix: a ``.yml`` file
    shows its commands in ``#`` comments, a ``.py`` file in docstrings (where the
    continuation is an escaped ``\\\\``)."""
    commands: list[str] = []
    pending = ""
    for raw in text.splitlines():
        line = raw.strip()
        if kind == ".yml":
            if not line.startswith("#"):
                pending = ""
                continue
            line = line.lstrip("#").strip()
        pending = f"{pending} {line}".strip()
        if pending.endswith("\\"):
            pending = pending.rstrip("\\").rstrip()
            continue
        command = re.sub(r"\s+#.*$", "", pending)  # a shell comment after the command
        if ZOO_COMMAND.match(command):
            commands.append(command)
        pending = ""
    if kind == ".md":
        commands += re.findall(r"`(python -m rl_zoo3\.[^`]+)`", text)
    return commands


@dataclass(frozen=True)
class DocumentedCommand:
    """A command as a document shows it, and the training command ``enjoy`` plays."""

    command: str
    source: str
    trained_by: str | None = None

    @property
    def verb(self) -> str:
        match = ZOO_COMMAND.match(self.command)
        assert match is not None
        return match.group(1)

    @property
    def argv(self) -> list[str]:
        return shlex.split(self.command)

    def option(self, name: str) -> str:
        argv = self.argv
        assert name in argv, f"{self.command!r} has no {name}"
        return argv[argv.index(name) + 1]

    @property
    def algo(self) -> str:
        return self.option("--algo")

    @property
    def label(self) -> str:
        conf = re.search(r"hyperparams (\w+)\)", self.command)
        return f"{self.verb}-{self.algo}-{conf.group(1) if conf else self.option('--env')}"


def documented_commands() -> list[DocumentedCommand]:
    """Every distinct rl-zoo3 command of :func:`documents`, each ``enjoy`` with the
    training command before it in its document (same ``--algo`` and ``--env``)."""
    found: dict[str, DocumentedCommand] = {}
    for path in documents():
        source = str(path.relative_to(ROOT))
        earlier: list[DocumentedCommand] = []
        for text in zoo_commands(path.read_text(encoding="utf-8"), path.suffix):
            command = DocumentedCommand(text, source)
            if command.verb == "enjoy":
                trainers = [
                    c.command
                    for c in earlier
                    if c.verb == "train"
                    and (c.algo, c.option("--env")) == (command.algo, command.option("--env"))
                ]
                assert trainers, f"{source}: {text!r} follows no training command it can play"
                command = DocumentedCommand(text, source, trainers[-1])
            earlier.append(command)
            found.setdefault(text, command)
    return list(found.values())


COMMANDS = documented_commands()


def test_the_docs_show_the_zoo_commands_this_test_must_run() -> None:
    labels = {command.label for command in COMMANDS}
    assert {"train-ppo-ppo", "train-ppo-ppo_entities", "enjoy-ppo-BearingSLAM-Khepera-v1"} <= labels
    assert all("--eval-env-kwargs" not in c.argv for c in COMMANDS)
    text = (
        "Train:\n\n```bash\npython -m rl_zoo3.train --algo ppo \\\n    --env E  # why\n```\n"
        "or `python -m rl_zoo3.enjoy --algo ppo --env E`.\n"
    )
    assert zoo_commands(text) == [
        "python -m rl_zoo3.train --algo ppo --env E",
        "python -m rl_zoo3.enjoy --algo ppo --env E",
    ]
    yml = "#   python -m rl_zoo3.train --algo sac \\\n#       --env E\nkey: 1\n"
    assert zoo_commands(yml, ".yml") == ["python -m rl_zoo3.train --algo sac --env E"]
    docstring = '"""Run::\n\n    python -m rl_zoo3.train --algo sac \\\\\n        --env E\n"""'
    assert zoo_commands(docstring, ".py") == ["python -m rl_zoo3.train --algo sac --env E"]


@dataclass(frozen=True)
class ZooRun:
    """A finished command: its folder (rl-zoo3's default ``logs/`` is inside), output and
    the env settings the probe recorded, by role (``train``, ``eval``, ``enjoy``)."""

    folder: Path
    output: str
    envs: dict[str, list[str]]


def run_in(folder: Path, command: str, extra: list[str]) -> ZooRun:
    """Run ``command`` as written in bash, in ``folder``, ``extra`` arguments appended."""
    folder.mkdir(parents=True, exist_ok=True)
    probe = folder / "probe.jsonl"
    probe.unlink(missing_ok=True)
    environment = {
        **os.environ,
        "PATH": f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}",
        "PYTHONPATH": str(ROOT),
        PROBE_VARIABLE: str(probe),
        "SDL_VIDEODRIVER": "dummy",
    }
    result = subprocess.run(
        ["bash", "-c", f"{command} {shlex.join(extra)}"],
        cwd=folder,
        env=environment,
        capture_output=True,
        text=True,
        timeout=600,
    )
    output = result.stdout + result.stderr
    assert result.returncode == 0, f"{command}\n{output[-4000:]}"
    envs: dict[str, list[str]] = {}
    for line in probe.read_text(encoding="utf-8").splitlines():
        entry = json.loads(line)
        envs.setdefault(entry["role"], []).extend(entry["configs"])
    return ZooRun(folder, output, envs)


class ZooRuns:
    """The training runs of the module, each run once (``enjoy`` plays one of them)."""

    def __init__(self, root: Path) -> None:
        self.root = root
        self.runs: dict[str, ZooRun] = {}

    def train(self, command: DocumentedCommand) -> ZooRun:
        if command.command not in self.runs:
            extra = [
                "-n", str(TIMESTEPS), "--eval-freq", str(EVAL_FREQ), "--eval-episodes", "1",
                "--seed", "0", "--device", "cpu", *PROBED_PACKAGES,
                "--hyperparams", *TINY_HYPERPARAMS[command.algo],
            ]  # fmt: skip
            folder = self.root / f"run{len(self.runs)}"
            self.runs[command.command] = run_in(folder, command.command, extra)
        return self.runs[command.command]


@pytest.fixture(scope="module")
def zoo_runs(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ZooRuns]:
    yield ZooRuns(tmp_path_factory.mktemp("zoo"))


def yaml_env_kwargs(command: DocumentedCommand) -> dict[str, object]:
    """The settings of the env the command trains on: the registered id's kwargs, then
    the ``env_kwargs`` of the shipped YAML entry the command trains with."""
    import gymnasium as gym

    import bearing_env  # noqa: F401  (registers the ids)

    conf = re.fullmatch(r"\$\(bearing-env hyperparams (\w+)\)", command.option("--conf-file"))
    assert conf is not None, "the docs name a shipped file: $(bearing-env hyperparams NAME)"
    entries = yaml.safe_load(default_conf_file(conf.group(1)).read_text())
    key = hyperparams_key(command.option("--env"))
    return {**gym.spec(key).kwargs, **(entries[key].get("env_kwargs") or {})}


def _marks(command: DocumentedCommand) -> list[pytest.MarkDecorator]:
    return [] if command.algo in DEFAULT_RUN_ALGOS else [pytest.mark.slow]


@pytest.mark.parametrize(
    "command",
    [
        pytest.param(c, id=c.label, marks=_marks(c))
        for c in COMMANDS
        if c.verb == "train"
    ],
)
def test_a_documented_training_command_evaluates_on_its_training_task(
    command: DocumentedCommand, zoo_runs: ZooRuns
) -> None:
    run = zoo_runs.train(command)
    expected = repr(EnvConfig.create(**yaml_env_kwargs(command)))  # type: ignore[arg-type]
    assert run.envs["train"] and set(run.envs["train"]) == {expected}
    assert run.envs["eval"] and set(run.envs["eval"]) == {expected}
    env_id = command.option("--env")
    folder = run.folder / "logs" / command.algo / f"{env_id}_1"
    assert (folder / f"{env_id}.zip").is_file()
    assert (folder / "evaluations.npz").is_file()  # the evaluation env did run
    # rl-zoo3 saves the entry with Python tags (an OrderedDict of pairs).
    saved = yaml.load((folder / env_id / "config.yml").read_text(), Loader=yaml.UnsafeLoader)
    # An entry keyed by a task id has no env_kwargs: the id's own kwargs are the settings.
    import gymnasium as gym

    saved_kwargs = {**gym.spec(env_id).kwargs, **dict(dict(saved).get("env_kwargs") or {})}
    assert repr(EnvConfig.create(**saved_kwargs)) == expected


@pytest.mark.parametrize(
    "command",
    [
        pytest.param(c, id=c.label, marks=_marks(c))
        for c in COMMANDS
        if c.verb == "enjoy"
    ],
)
def test_a_documented_enjoy_command_plays_the_trained_model_on_its_task(
    command: DocumentedCommand, zoo_runs: ZooRuns
) -> None:
    assert command.trained_by is not None
    trained = zoo_runs.train(next(c for c in COMMANDS if c.command == command.trained_by))
    extra = ["-n", "25", "--no-render", "--device", "cpu", *PROBED_PACKAGES]
    run = run_in(trained.folder, command.command, extra)
    assert run.envs["enjoy"] == trained.envs["train"][:1]
    assert "Episode Reward" in run.output  # a whole episode was played


#: The shipped files whose entries are keyed by a task id (its kwargs carry the settings).
TASK_KEYED_FILES = ("ppo_entities", "ppo_attention", "ppo_shapes", "ppo_candidates")


def plain_command(name: str) -> DocumentedCommand:
    """rl-zoo3's plain command for a shipped file: its entry's id, no other flag."""
    entries = yaml.safe_load(default_conf_file(name).read_text())
    (env_id,) = entries
    return DocumentedCommand(
        f"python -m rl_zoo3.train --algo ppo --env {env_id} --gym-packages bearing_env "
        f'--conf-file "$(bearing-env hyperparams {name})"',
        f"train/sb3/hyperparams/{name}.yml",
    )


@pytest.mark.parametrize(
    "name",
    [pytest.param(n, marks=[] if n == "ppo_entities" else [pytest.mark.slow])
     for n in TASK_KEYED_FILES],
)
def test_the_plain_command_trains_and_evaluates_each_task_keyed_file(
    name: str, zoo_runs: ZooRuns
) -> None:
    """The entry has no ``env_kwargs`` of its own, so nothing differs between the training
    envs and the evaluation env rl-zoo3 makes from the id."""
    entries = yaml.safe_load(default_conf_file(name).read_text())
    (entry,) = entries.values()
    assert "env_kwargs" not in entry
    command = plain_command(name)
    test_a_documented_training_command_evaluates_on_its_training_task(command, zoo_runs)
    run = zoo_runs.train(command)
    assert "ValueError" not in run.output
