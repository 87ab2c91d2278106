"""``bearing-env suite``: compare once per task, the task cards and the index, and resuming
after an interruption."""

from __future__ import annotations

import json
import os
import re
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")

import pytest

from bearing_env.tasks import TASKS, TASKS_BY_ID
from bearing_env.train import cli
from bearing_env.train.compare.log import LOG_NAME, EpisodeLog
from bearing_env.train.compare.runner import EpisodeTask, run_locally
from bearing_env.train.compare.suite import (
    DEFAULT_POLICIES,
    build_parser,
    main,
    run_suite,
    suite_configs,
    task_models,
)
from tests.extras import needs

TWO_TASKS = ("BearingSLAM-Khepera-v1", "BearingSLAMDiscrete-Khepera-v1")


def quick_args(out: Path, docs: Path, *extra: str) -> list[str]:
    return [
        "--quick", "--tasks", *TWO_TASKS, "--episodes", "2", "--policies", "random", "greedy",
        "--bootstrap", "50", "--out", str(out), "--docs", str(docs), "--no-progress", *extra,
    ]  # fmt: skip


def links(markdown: str) -> list[str]:
    return re.findall(r"\]\(([^)#\s]+)\)", markdown)


def results(out: Path, task_id: str) -> list[dict[str, Any]]:
    """The logged episodes of a task without their timings, in a canonical order."""
    records = EpisodeLog(out / task_id / LOG_NAME).load()
    for record in records:
        record.pop("policy_seconds")
    return sorted(records, key=lambda r: (r["policy"], r["seed"]))


@needs("train", "matplotlib")  # the cards' area plots
@needs("render")  # the cards' frames
def test_quick_suite_on_two_tasks_writes_the_cards_and_the_index(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, docs = tmp_path / "out", tmp_path / "docs"
    main(quick_args(out, docs))
    printed = capsys.readouterr().out
    assert "complete: 2 tasks" in printed
    for task_id in TWO_TASKS:
        summary = json.loads((out / task_id / "summary.json").read_text())
        assert summary["config"]["env_id"] == f"bearing_env:{task_id}"
        assert {p: s["episodes"] for p, s in summary["policies"].items()} == {
            "random_polygonal": 2,
            "greedy_one_step": 2,
        }
        card = (docs / f"{task_id}.md").read_text()
        assert card.startswith(f"# {task_id}\n")
        for section in ("## Observation", "## Action", "## Reward", "## Episode end",
                        "## Settings", "## Baselines"):  # fmt: skip
            assert section in card
        assert "seeds 1000000..1000001" in card and "max_moves=10" in card
        # The mean-area table has a CI per policy and reported move count.
        mean_rows = [line for line in card.splitlines() if line.startswith("| random_polygonal")]
        assert re.search(r"\| [\d.e+-]+ \[[\d.e+-]+, [\d.e+-]+\] \|", mean_rows[0])
        assert "bearing-env suite --quick --tasks" in card and "--no-progress" not in card
        # The results file records the run: its command, commit, uncommitted files, date
        # and machine, and the card quotes them.
        measured = json.loads((docs / "results" / f"{task_id}.json").read_text())["measured"]
        assert {"command", "commit", "uncommitted", "date", "machine"} <= measured.keys()
        assert "+" not in (measured["commit"] or "")
        assert f"Measured by `{measured['command']}` on {measured['date']}" in card
        for target in links(card):
            assert (docs / target).stat().st_size > 0, target
        assert f"{task_id}_area.png" in links(card) and f"{task_id}_frame.png" in links(card)
    assert "Discrete(24)" in (docs / f"{TWO_TASKS[1]}.md").read_text()
    index = (docs / "index.md").read_text()
    for task in TASKS:
        assert f"`{task.id}`" in index
    assert sorted(links(index)) == sorted(f"{task_id}.md" for task_id in TWO_TASKS)
    glance = index.split("## Baselines at a glance", 1)[1]
    assert all(task_id in glance for task_id in TWO_TASKS)
    assert "BearingSLAM-Random8-v1" not in glance


def test_an_interrupted_suite_resumes_where_it_stopped(tmp_path: Path) -> None:
    whole, docs = tmp_path / "whole", tmp_path / "docs_whole"
    main(quick_args(whole, docs))

    class Interrupted(Exception):
        pass

    given: list[list[tuple[str, int]]] = []
    budget = [5]  # the first task has 4 episodes: the interrupt lands in the second

    def interrupted_executor(
        tasks: Sequence[EpisodeTask], workers: int
    ) -> Iterator[dict[str, Any]]:
        given.append([(task.label, task.seed) for task in tasks])
        for record in run_locally(tasks, workers):
            if budget[0] == 0:
                raise KeyboardInterrupt
            budget[0] -= 1
            yield record

    out, resumed_docs = tmp_path / "resumed", tmp_path / "docs_resumed"
    configs = suite_configs(build_parser().parse_args(quick_args(out, resumed_docs)))
    with pytest.raises(KeyboardInterrupt):
        run_suite(configs, out, resumed_docs, progress=False, executor=interrupted_executor)
    assert len(EpisodeLog(out / TWO_TASKS[0] / LOG_NAME).load()) == 4
    assert len(EpisodeLog(out / TWO_TASKS[1] / LOG_NAME).load()) == 1
    assert (resumed_docs / f"{TWO_TASKS[0]}.md").is_file()
    assert not (resumed_docs / f"{TWO_TASKS[1]}.md").exists()

    main(quick_args(out, resumed_docs))  # the same command again: it continues
    for task_id in TWO_TASKS:
        assert results(out, task_id) == results(whole, task_id)
        assert (out / task_id / "summary.json").read_text() == (
            whole / task_id / "summary.json"
        ).read_text()
    assert (resumed_docs / f"{TWO_TASKS[1]}.md").is_file()


def test_stop_after_leaves_the_rest_for_the_next_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out, docs = tmp_path / "out", tmp_path / "docs"
    main(quick_args(out, docs, "--stop-after", "3"))
    assert "INCOMPLETE" in capsys.readouterr().out
    assert len(EpisodeLog(out / TWO_TASKS[0] / LOG_NAME).load()) == 3
    assert not (out / TWO_TASKS[1]).exists() and not (docs / f"{TWO_TASKS[0]}.md").exists()
    assert "no card yet" in (docs / "index.md").read_text()
    main(quick_args(out, docs))
    assert "complete: 2 tasks" in capsys.readouterr().out
    for task_id in TWO_TASKS:
        assert len(EpisodeLog(out / task_id / LOG_NAME).load()) == 4
    card = (docs / f"{TWO_TASKS[0]}.md").read_text()
    assert "--stop-after" not in card  # the cards quote the command that reproduces them


@needs("train", "stable_baselines3", "torch")
def test_shipped_models_run_on_the_task_they_were_trained_on() -> None:
    # ppo_khepera's record names the base id and the scenario; ppo_furnished_room's names
    # the task's own id (its settings come from the task table).
    shipped = {
        "BearingSLAM-Khepera-v1": ["pretrained:ppo_khepera"],
        "BearingSLAM-FurnishedRoom-v1": ["pretrained:ppo_furnished_room"],
    }
    for task in TASKS:
        assert task_models(task) == shipped.get(task.id, []), task.id
    configs = dict(suite_configs(build_parser().parse_args([])))
    khepera = configs[TASKS_BY_ID["BearingSLAM-Khepera-v1"]]
    assert list(khepera.policies) == [
        "random_polygonal", "parallax", "greedy_one_step", "lookahead", "ppo_khepera",
    ]  # fmt: skip
    assert khepera.policies["ppo_khepera"] == "pretrained:name='ppo_khepera'"
    assert khepera.episodes == 50 and khepera.env_kwargs == {}
    random8 = configs[TASKS_BY_ID["BearingSLAM-Random8-v1"]]
    assert list(random8.policies.values()) == list(DEFAULT_POLICIES)  # no shipped model
    assert [task.id for task in configs] == [task.id for task in TASKS]


def test_bad_input_is_named(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exited:
        main(["--tasks", "BearingSLAM-Random9-v1", "--out", str(tmp_path)])
    assert exited.value.code == 2
    assert "'BearingSLAM-Random9-v1'" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(["--episodes", "0", "--out", str(tmp_path)])
    assert "--episodes" in capsys.readouterr().err


def test_bearing_env_dispatches_suite(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exited:
        cli.main(["suite", "--help"])
    assert exited.value.code == 0
    text = capsys.readouterr().out
    assert "bearing-env suite" in text and "--tasks" in text and "default 50" in text
    cli.main(["--help"])
    assert any(line.split()[:1] == ["suite"] for line in capsys.readouterr().out.splitlines())


def fake_summary(folder: Path, means: dict[str, float]) -> None:
    """A finished comparison's ``summary.json``: 4 episodes per policy, each with the
    given mean total area after 20 moves."""
    folder.mkdir(parents=True)
    policies = {
        label: {
            "episodes": 4,
            "area_after": {"20": {"mean": mean, "ci_low": mean / 2, "ci_high": mean * 2}},
        }
        for label, mean in means.items()
    }
    config = {"episodes": 4, "policies": list(means)}
    (folder / "summary.json").write_text(json.dumps({"config": config, "policies": policies}))


def test_the_index_keeps_the_rows_of_tasks_this_run_did_not_compare(tmp_path: Path) -> None:
    """The overview is read from the cards' results files (``docs/results/<id>.json``),
    which a later run on some of the tasks leaves in place for the others."""
    from bearing_env.train.compare.task_cards import INDEX_NAME, card_name, write_index

    first, second, uncarded = (TASKS_BY_ID[t] for t in (*TWO_TASKS, "BearingSLAM-Random8-v1"))
    docs, scratch = tmp_path / "docs", tmp_path / "scratch"
    docs.mkdir()
    scratch.mkdir()
    for task in (first, second):
        (docs / card_name(task)).write_text("# card\n")

    def results(task_id: str, means: dict[str, float]) -> None:
        folder = scratch / f"{task_id}-{len(list(scratch.glob('*')))}"
        fake_summary(folder, means)
        summary = json.loads((folder / "summary.json").read_text())
        (docs / "results").mkdir(exist_ok=True)
        data = {"task": task_id, "command": None, "summary": summary}
        (docs / "results" / f"{task_id}.json").write_text(json.dumps(data))

    results(first.id, {"random_polygonal": 2.0, "greedy_one_step": 0.5})
    results(second.id, {"random_polygonal": 3.0, "greedy_one_step": 0.25})
    results(uncarded.id, {"random_polygonal": 9.0})
    write_index(TASKS, docs)
    # A later run compares the first task only, with another policy set.
    results(first.id, {"random_polygonal": 1.5, "lookahead": 0.125})
    write_index(TASKS, docs)
    glance = (docs / INDEX_NAME).read_text().split("## Baselines at a glance", 1)[1]
    table = [line for line in glance.splitlines() if line.startswith("|")]
    rows = {line.split("|")[1].strip(): line for line in table if "-v1" in line}
    assert set(rows) == {first.id, second.id}  # no card, no row
    header = table[0]
    columns = [cell.strip() for cell in header.strip("|").split("|")]
    assert columns == [
        "task", "moves", "episodes", "random_polygonal", "lookahead", "greedy_one_step"
    ]  # fmt: skip
    assert "1.5 [0.75, 3]" in rows[first.id] and "0.5" not in rows[first.id]
    cells = [cell.strip() for cell in rows[second.id].strip("|").split("|")]
    assert cells == [second.id, "20", "4", "3 [1.5, 6]", "-", "0.25 [0.125, 0.5]"]
