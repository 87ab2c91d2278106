"""Every table of measured figures in the README and the docs is what ``bearing-env
docs-tables`` writes from a results file kept in the repo, and a hand-edited number
fails the check. The reference pages state the current state (the history is in
``docs/notes.md``) and stay short."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

from bearing_env.tasks import TASKS
from bearing_env.train.common import doc_tables

ROOT = Path(__file__).resolve().parents[2]
#: Phrases of a lab notebook, which only the notes page may use.
NOTEBOOK_PHRASES = re.compile(
    r"under load|not kept|not shipped|not exported|the issue|target \(", re.IGNORECASE
)
#: The longest each reference page may be, in lines.
PAGE_LINES = {"performance.md": 150, "training.md": 200, "policies.md": 150}


def test_every_generated_table_matches_its_results_file() -> None:
    assert doc_tables.stale(ROOT) == []


def test_the_pages_hold_the_generated_blocks() -> None:
    found = {
        match["name"]
        for page in doc_tables.pages(ROOT)
        for match in doc_tables.BLOCK.finditer(page.read_text(encoding="utf-8"))
    }
    assert set(doc_tables._blocks()) <= found
    assert "bench-goals" in (ROOT / "docs" / "performance.md").read_text(encoding="utf-8")
    cards = doc_tables_cards()
    assert len(cards) >= 10  # every task card and the index


def doc_tables_cards() -> dict[Path, str]:
    from bearing_env.train.compare.task_cards import published_cards

    return published_cards(ROOT / "docs" / "tasks")


def copy_of_the_docs(folder: Path) -> Path:
    """The README, the pages, the cards and the results files (the bench's, the
    shipped models' records), under ``folder``."""
    shutil.copy(ROOT / "README.md", folder / "README.md")
    shutil.copytree(ROOT / "docs", folder / "docs", ignore=shutil.ignore_patterns("_build"))
    shutil.copytree(ROOT / "benchmarks" / "results", folder / "benchmarks" / "results")
    (folder / "agents" / "pretrained").mkdir(parents=True)
    for record in (ROOT / "agents" / "pretrained").glob("*.json"):
        shutil.copy(record, folder / "agents" / "pretrained" / record.name)
    return folder


def edit_a_number(path: Path, block: str | None = None) -> None:
    """Change one digit of the first number in a table row of ``block`` (of a card: of
    its baselines)."""
    text = path.read_text(encoding="utf-8")
    start = text.index("## Baselines" if block is None else f"<!-- docs-tables: {block} -->")
    match = re.compile(r"\| [^|\n]*?(\d)\.(\d)").search(text, start)
    assert match is not None
    digit = match.start(2)
    changed = "1" if text[digit] != "1" else "2"
    path.write_text(text[:digit] + changed + text[digit + 1 :], encoding="utf-8")


@pytest.mark.parametrize(
    ("page", "block"),
    [
        ("docs/performance.md", "bench-goals"),
        ("docs/performance.md", "bench-env"),
        ("README.md", "khepera-medians"),
        ("docs/results.md", "khepera-25cm"),
        ("docs/results.md", "fig11-fits"),
        ("docs/results.md", "robust-eval"),
        ("docs/environment.md", "observability"),
        ("docs/scaling.md", "compare-on-ray"),
        ("docs/tasks/BearingSLAM-Khepera-v1.md", None),
    ],
)
def test_a_hand_edited_number_fails_the_check_and_is_written_back(
    tmp_path: Path, page: str, block: str | None, capsys: pytest.CaptureFixture[str]
) -> None:
    root = copy_of_the_docs(tmp_path)
    original = (root / page).read_text(encoding="utf-8")
    edit_a_number(root / page, block)
    assert (root / page).read_text(encoding="utf-8") != original
    expected = f"{page}: {block or 'the card'}"
    assert doc_tables.stale(root) == [expected]
    with pytest.raises(SystemExit) as stopped:
        doc_tables.main(["--check", "--root", str(root)])
    assert stopped.value.code == 1
    assert f"stale: {expected}" in capsys.readouterr().out
    doc_tables.main(["--root", str(root)])
    assert (root / page).read_text(encoding="utf-8") == original
    assert doc_tables.stale(root) == []


def test_a_new_result_rewrites_the_page(tmp_path: Path) -> None:
    import json

    root = copy_of_the_docs(tmp_path)
    results = root / "benchmarks" / "results" / "bench_env.json"
    data = json.loads(results.read_text(encoding="utf-8"))
    data["planning"]["median_s"] = 0.000123
    results.write_text(json.dumps(data), encoding="utf-8")
    assert "docs/performance.md: bench-startup" in doc_tables.stale(root)
    doc_tables.write_all(root)
    assert "0.12 ms per move" in (root / "docs" / "performance.md").read_text(encoding="utf-8")


def test_writing_the_tables_twice_changes_nothing_the_second_time(tmp_path: Path) -> None:
    root = copy_of_the_docs(tmp_path)
    doc_tables.write_all(root)
    pages = {page: page.read_text(encoding="utf-8") for page in doc_tables.pages(root)}
    assert doc_tables.write_all(root) == []
    assert {page: page.read_text(encoding="utf-8") for page in pages} == pages
    assert doc_tables.stale(root) == []


@pytest.mark.parametrize(
    ("block", "source"),
    [
        ("observability", "docs/figures/observability_khepera.json"),
        ("robust-eval", "docs/figures/robust_eval.json"),
        ("compare-on-ray", "benchmarks/results/bench_compare.json"),
    ],
)
def test_each_measured_table_names_its_command_commit_machine_and_file(
    block: str, source: str
) -> None:
    import json

    measured = json.loads((ROOT / source).read_text(encoding="utf-8"))["measured"]
    assert {"command", "commit", "date", "machine"} <= measured.keys()
    text = doc_tables.render_block(block, ROOT)
    assert f"Measured by `{measured['command']}` on {measured['date']}, commit " in text
    assert measured["machine"] in text and f"file `{source}`" in text


def test_the_reference_pages_hold_no_lab_notebook_phrases() -> None:
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    pages += sorted((ROOT / "docs" / "tasks").glob("*.md"))
    found = [
        f"{page.relative_to(ROOT)}:{number}: {line.strip()}"
        for page in pages
        if page.name != "notes.md"
        for number, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1)
        if NOTEBOOK_PHRASES.search(line)
    ]
    assert found == []


@pytest.mark.parametrize(("page", "limit"), sorted(PAGE_LINES.items()))
def test_the_reference_pages_are_short(page: str, limit: int) -> None:
    lines = (ROOT / "docs" / page).read_text(encoding="utf-8").splitlines()
    assert len(lines) <= limit


def test_every_card_has_the_anchors_layout() -> None:
    cards = sorted((ROOT / "docs" / "tasks").glob("BearingSLAM*.md"))
    assert len(cards) == len(TASKS)  # one per task
    for card in cards:
        text = card.read_text(encoding="utf-8")
        assert "| Action space |" in text and "| Observation space |" in text, card.name
        for heading in ("## Starting state", "## Info", "## Version history"):
            assert heading in text, (card.name, heading)
        assert "../environment.md#observation" in text, card.name


#: Tables of numbers in the README and the docs that are not generated blocks, by page and
#: header: only the settings table (defaults, not measurements). A new hand-written table
#: of figures fails :func:`test_no_other_table_of_figures_is_hand_written`.
HAND_WRITTEN_TABLES: frozenset[tuple[str, str]] = frozenset(
    {("docs/environment.md", "| kwarg | default | meaning |")}
)


def tables_of_figures(text: str) -> list[str]:
    """The header lines of the Markdown tables outside generated blocks whose rows hold a
    decimal number, a percentage or a thousands comma."""
    text = doc_tables.BLOCK.sub("", text)
    headers: list[str] = []
    header: str | None = None
    figures = False
    for line in [*text.splitlines(), ""]:
        if line.startswith("|"):
            if header is None:
                header, figures = line, False
            elif not line.startswith("|---") and re.search(r"\d\.\d|\d%|\d,\d{3}", line):
                figures = True
        else:
            if header is not None and figures:
                headers.append(header)
            header = None
    return headers


def test_no_other_table_of_figures_is_hand_written() -> None:
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
    found = {
        (str(page.relative_to(ROOT)), header)
        for page in pages
        if page.name != "notes.md"
        for header in tables_of_figures(page.read_text(encoding="utf-8"))
    }
    unexpected = sorted(
        (page, header)
        for page, header in found
        if not any(page == p and header.startswith(h) for p, h in HAND_WRITTEN_TABLES)
    )
    assert unexpected == []
    assert len(found) <= len(HAND_WRITTEN_TABLES)


def test_the_cards_are_rendered_from_their_results_files_without_an_episode(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``bearing-env docs-tables`` is the cards' render-only path: after a change of the
    card writer (or of a task's text) it rewrites every card from its results file, and
    runs no episode."""
    from bearing_env.train.compare import runner

    def no_episode(*args: object, **kwargs: object) -> None:
        raise AssertionError("a card was rendered by running an episode")

    monkeypatch.setattr(runner, "run_episode", no_episode)
    monkeypatch.setattr(runner, "run_task", no_episode)
    root = copy_of_the_docs(tmp_path)
    cards = sorted((root / "docs" / "tasks").glob("BearingSLAM*.md"))
    published = {card: card.read_text(encoding="utf-8") for card in cards}
    for card in cards:
        card.write_text("# an old card\n", encoding="utf-8")
    doc_tables.main(["--root", str(root)])
    assert {card: card.read_text(encoding="utf-8") for card in cards} == published


def test_every_card_results_file_names_its_commit_date_and_machine() -> None:
    """The cards' results files carry a ``measured`` record, and the card quotes it."""
    import json

    from bearing_env.train.common.provenance import measured_sentence

    files = sorted((ROOT / "docs" / "tasks" / "results").glob("*.json"))
    assert len(files) == len(TASKS)  # one per card
    for path in files:
        measured = json.loads(path.read_text(encoding="utf-8"))["measured"]
        assert {"command", "commit", "date", "machine"} <= measured.keys(), path.name
        card = ROOT / "docs" / "tasks" / f"{path.stem}.md"
        sentence = measured_sentence(measured, f"docs/tasks/results/{path.name}")
        assert sentence in card.read_text(encoding="utf-8"), path.name


def test_no_results_file_or_page_names_a_dirty_tree() -> None:
    """A commit in a results file is a commit's hex name, never ``+changes``: a run on a
    dirty tree records the clean commit and its ``uncommitted`` files."""
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    pages = [page for page in pages if page.name != "notes.md"]  # history may tell of it
    results = [
        *sorted((ROOT / "benchmarks" / "results").glob("*.json")),
        *sorted((ROOT / "docs").rglob("*.json")),
        *sorted((ROOT / "agents" / "pretrained").glob("*.json")),
    ]
    dirty = [
        str(path.relative_to(ROOT))
        for path in [*pages, *results]
        if "+changes" in path.read_text(encoding="utf-8")
    ]
    assert dirty == []
