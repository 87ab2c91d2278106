"""Optional extras fail politely: after a plain install (no extras) every command or call
that needs the ``render`` or ``train`` extra says which one to install, without a
traceback, and ``compare`` runs the heuristics without stable-baselines3.

A plain install is simulated by making the extras' modules unimportable
(``sys.modules[name] = None``) in a fresh interpreter before ``bearing_env.train.cli.main`` runs.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import gymnasium as gym
import pytest

import bearing_env  # noqa: F401  (registers the ids)
from bearing_env.extras import (
    MODULE_EXTRAS,
    MissingExtraError,
    available,
    install_command,
    missing_extra,
    require,
)
from bearing_env.train.common.errors import EXIT_ERROR, exit_on_missing_extra
from tests.extras import import_or_skip, needs

ROOT = Path(__file__).resolve().parents[2]
RENDER = 'pip install "bearing_env[render]"'
TRAIN = 'pip install "bearing_env[train]"'
#: What a plain ``pip install bearing_env`` lacks: every extra's modules.
PLAIN_INSTALL_LACKS = tuple(MODULE_EXTRAS)

_PLAIN_CLI = """
import sys
for name in {blocked!r}:
    sys.modules[name] = None
from bearing_env.train.cli import main
main({argv!r})
"""


def plain_cli(
    argv: list[str], cwd: Path, blocked: tuple[str, ...] = PLAIN_INSTALL_LACKS
) -> subprocess.CompletedProcess[str]:
    """``bearing-env ARGV`` in a fresh interpreter where ``blocked`` cannot be imported."""
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "PYTHONPATH": str(ROOT)}
    code = _PLAIN_CLI.format(blocked=list(blocked), argv=argv)
    return subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
        cwd=cwd, env=env,
    )


def error_line(result: subprocess.CompletedProcess[str], prog: str) -> str:
    assert result.returncode == EXIT_ERROR, result.stderr
    assert "Traceback" not in result.stderr, result.stderr
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith(f"{prog}: error: "), lines
    return lines[0]


def test_the_blocking_shim_does_make_the_modules_unimportable(tmp_path: Path) -> None:
    code = "import sys; sys.modules['pygame'] = None\nimport pygame"
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60
    )
    assert result.returncode != 0 and "ModuleNotFoundError" in result.stderr


# --------------------------------------------------------------------------------------
# Commands
# --------------------------------------------------------------------------------------


def test_demo_without_pygame_runs_and_says_to_install_the_render_extra(tmp_path: Path) -> None:
    out = tmp_path / "out"
    result = plain_cli(["demo", "--episodes", "1", "--moves", "2", "--out", str(out)], tmp_path)
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr
    assert "median total area" in result.stdout  # the demo itself ran
    assert "no animation" in result.stderr and RENDER in result.stderr
    assert not (out / "demo_khepera.gif").exists()


def test_train_without_the_train_extra_says_to_install_it(tmp_path: Path) -> None:
    result = plain_cli(["train", "--algo", "ppo", "--timesteps", "64"], tmp_path)
    line = error_line(result, "bearing-env train")
    assert TRAIN in line
    assert not (tmp_path / "runs").exists()


@pytest.mark.parametrize(
    "missing",
    ["stable_baselines3", pytest.param("yaml", marks=needs("train", "stable_baselines3"))],
)
def test_train_names_the_one_missing_package(tmp_path: Path, missing: str) -> None:
    result = plain_cli(["train", "--algo", "ppo"], tmp_path, blocked=(missing,))
    line = error_line(result, "bearing-env train")
    assert {"stable_baselines3": "'stable-baselines3'", "yaml": "'pyyaml'"}[missing] in line
    assert TRAIN in line


@pytest.mark.parametrize("blocked", [PLAIN_INSTALL_LACKS, ("rliable",)])
def test_evaluate_without_the_train_extra_says_to_install_it(
    tmp_path: Path, blocked: tuple[str, ...]
) -> None:
    result = plain_cli(["evaluate", "model.zip", "--out", "out"], tmp_path, blocked=blocked)
    line = error_line(result, "bearing-env evaluate")
    assert TRAIN in line and ("'rliable'" in line or blocked != ("rliable",))
    assert not (tmp_path / "out").exists()


def test_figures_without_matplotlib_says_to_install_the_train_extra(tmp_path: Path) -> None:
    result = plain_cli(["figures", "--out", str(tmp_path / "figs")], tmp_path)
    line = error_line(result, "bearing-env figures")
    assert "'matplotlib'" in line and TRAIN in line


def test_compare_quick_without_sb3_runs_the_heuristics_and_skips_the_shipped_models(
    tmp_path: Path,
) -> None:
    out = tmp_path / "quick"
    result = plain_cli(["compare", "--quick", "--episodes", "2", "--out", str(out)], tmp_path)
    assert result.returncode == 0, result.stderr
    assert "Traceback" not in result.stderr
    assert "skipped the shipped models (ppo_khepera)" in result.stderr
    assert "'stable-baselines3'" in result.stderr and TRAIN in result.stderr
    assert "no plots" in result.stderr  # matplotlib is missing too
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert list(summary["policies"]) == ["random_polygonal", "parallax", "greedy_one_step"]
    assert "greedy_one_step" in result.stdout  # the tables, printed without rich
    assert not list(out.glob("*.png"))
    assert ".png" not in (out / "report.md").read_text(encoding="utf-8")


def test_compare_quick_with_every_extra_includes_the_shipped_model(tmp_path: Path) -> None:
    """The counterpart of the test above: the skip happens only without SB3."""
    import_or_skip("stable_baselines3")
    from bearing_env.train.compare.cli import shipped_policies

    assert shipped_policies("bearing_env:BearingSLAM-v1", {"scenario": "khepera"}) == [
        "pretrained:ppo_khepera"
    ]


def test_compare_with_an_sb3_policy_without_sb3_says_to_install_the_train_extra(
    tmp_path: Path,
) -> None:
    argv = ["compare", "--policies", "random", "pretrained:ppo_khepera", "--episodes", "1",
            "--out", str(tmp_path / "out")]
    line = error_line(plain_cli(argv, tmp_path), "bearing-env compare")
    assert "'stable-baselines3'" in line and TRAIN in line


def test_the_generalisation_script_without_the_train_extra_says_to_install_it(
    tmp_path: Path,
) -> None:
    code = (
        "import runpy, sys\n"
        f"for name in {list(PLAIN_INSTALL_LACKS)!r}:\n    sys.modules[name] = None\n"
        "sys.argv = ['generalisation.py', '--out', 'g']\n"
        "runpy.run_module('bearing_env.train.studies.generalisation', run_name='__main__')\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
        cwd=tmp_path, env=env,
    )
    line = error_line(result, "bearing-env generalisation")
    assert "'stable-baselines3'" in line and TRAIN in line
    assert not (tmp_path / "g").exists()


# --------------------------------------------------------------------------------------
# Library calls
# --------------------------------------------------------------------------------------


def test_rendering_without_pygame_names_the_render_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "pygame", None)
    env = gym.make("BearingSLAM-v1", scenario="khepera", render_mode="rgb_array")
    try:
        env.reset(seed=0)
        with pytest.raises(MissingExtraError) as error:
            env.render()
    finally:
        env.close()
    assert error.value.extra == "render" and error.value.name == "pygame"
    assert RENDER in str(error.value)


def test_a_shipped_model_without_sb3_names_the_train_extra(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from bearing_env.agents import SB3Policy

    monkeypatch.setitem(sys.modules, "stable_baselines3", None)
    with gym.make("BearingSLAM-v1", scenario="khepera") as env:
        with pytest.raises(MissingExtraError) as error:
            SB3Policy.pretrained("ppo_khepera", env)
    assert error.value.extra == "train"
    assert TRAIN in str(error.value)


def test_require_and_available(monkeypatch: pytest.MonkeyPatch) -> None:
    assert available("numpy") and require("numpy", "x").__name__ == "numpy"
    monkeypatch.setitem(sys.modules, "tqdm", None)
    assert not available("tqdm") and not available("numpy", "tqdm")
    assert not available("no_such_module_anywhere")
    with pytest.raises(MissingExtraError, match=r"progress bars needs the package 'tqdm'"):
        require("tqdm", "progress bars")
    # A package of no extra is named with its own pip line, not an extra's.
    with pytest.raises(ImportError, match=r"pip install no_such_module_anywhere$") as error:
        require("no_such_module_anywhere", "a test")
    assert not isinstance(error.value, MissingExtraError)
    assert install_command("render") == RENDER


def test_only_the_extras_modules_become_clean_failures() -> None:
    assert missing_extra(ModuleNotFoundError("x", name="torch"), "it") is not None
    assert missing_extra(ModuleNotFoundError("x", name="numpy"), "it") is None
    assert missing_extra(ImportError("cannot import name 'x'", name="torch"), "it") is None
    # A broken core dependency still shows its traceback: it is a bug, not a missing extra.
    with pytest.raises(ModuleNotFoundError), exit_on_missing_extra("bearing-env x"):
        raise ModuleNotFoundError("No module named 'numpy'", name="numpy")
    with pytest.raises(SystemExit) as exit_info, exit_on_missing_extra("bearing-env x"):
        raise ModuleNotFoundError("No module named 'torch'", name="torch")
    assert exit_info.value.code == EXIT_ERROR
