"""The project's documents refer only to files inside the project, and the design
document's measured facts are the ones the documentation pages report."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
DESIGN = DOCS / "design.md"
#: The pages that report measurements with their commands and seeds (the design
#: document quotes them).
MEASURED_PAGES = ("world_model.md", "results.md", "performance.md", "training.md",
                  "scaling.md")
#: Folders that are not the project's own text (tools, caches, build output).
SKIPPED_DIRS = {".git", ".venv", "build", "dist", "__pycache__", ".pytest_cache",
                ".hypothesis", ".ruff_cache", "runs", "outputs"}
#: The design document's old name, which never existed in the project (spelled so that
#: this file does not cite it either).
MISSING_NAME = "DESIGN" + ".md"
TEXT_SUFFIXES = {".py", ".md", ".toml", ".yml", ".yaml", ".txt", ".cfg", ".json"}


def project_text_files() -> list[Path]:
    files = []
    for path in ROOT.rglob("*"):
        parts = set(path.relative_to(ROOT).parts)
        if parts & SKIPPED_DIRS or any(p.endswith(".egg-info") for p in parts):
            continue
        if path.is_file() and (path.suffix in TEXT_SUFFIXES or path.name == "Makefile"):
            files.append(path)
    return files


def test_no_file_cites_the_missing_design_md() -> None:
    offenders = [
        f"{path.relative_to(ROOT)}:{number}"
        for path in project_text_files()
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if MISSING_NAME in line
    ]
    assert offenders == []


def _links(markdown: str) -> list[str]:
    return re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", markdown)


def test_relative_links_of_the_readme_and_the_documentation_pages_exist() -> None:
    pages = sorted(DOCS.rglob("*.md"))
    assert DESIGN in pages and len(pages) >= 10
    for document in (ROOT / "README.md", *pages):
        targets = [t for t in _links(document.read_text(encoding="utf-8"))
                   if "://" not in t]
        missing = [t for t in targets if not (document.parent / t).exists()]
        assert missing == [], (document.name, missing)


def test_the_design_document_names_only_existing_project_files() -> None:
    text = DESIGN.read_text(encoding="utf-8")
    paths = set(re.findall(r"`((?:bearing_env|agents|train|tests|benchmarks|docs)/[\w/.]*)`",
                           text))
    assert "bearing_env/slam/transfer.py" in paths
    missing = sorted(p for p in paths if not (ROOT / p).exists())
    assert missing == []


def test_the_design_document_covers_the_method_and_the_env_contract() -> None:
    text = DESIGN.read_text(encoding="utf-8")
    for needle in (
        "## 2. The method", "## 3. The environment contract", "## 4. Measured facts",
        "T(h1, h2)(z) = (z \u2212 h1) / (h2 \u2212 h1)", "FR", "FL", "centroid", "`\"paper\"`",
        "`\"conservative\"`", "on_inconsistency", "BearingSLAM-v1", "BearingSLAMDiscrete-v1",
        "Terminated", "Truncated", "landmark_contains_truth", "Determinism", "Rendering",
    ):
        assert needle in text, needle


def _section(text: str, heading: str) -> str:
    start = text.index(heading)
    end = text.find("\n## ", start + len(heading))
    return text[start:] if end < 0 else text[start:end]


def test_measured_facts_are_the_documentation_pages_numbers() -> None:
    """Every number of the design document's "Measured facts" and "Reference runs" with a
    decimal point or a thousands comma is one the measurement pages report: none is
    invented."""
    reported = "\n".join((DOCS / page).read_text(encoding="utf-8") for page in MEASURED_PAGES)
    design = DESIGN.read_text(encoding="utf-8")
    facts = _section(design, "## 4. Measured facts") + _section(design, "## 5. Reference runs")
    numbers = set(re.findall(r"(?<![\w.])\d[\d,]*\.\d+|(?<![\w.])\d{1,3}(?:,\d{3})+", facts))
    numbers -= {"1.05", "0.68", "0.05", "0.30", "0.25"}  # settings, not measurements
    # The design document links the pages for the figures that have a generated home
    # (the cards, the performance page, the figures' fits); it still quotes these.
    assert len(numbers) > 10
    missing = sorted(n for n in numbers if n not in reported)
    assert missing == []


# ----------------------------------------------------------------------------------------
# The registered ids and the info keys, against what the pages say
# ----------------------------------------------------------------------------------------

#: The pages that may state how many ids are registered (the notes are history).
REFERENCE_PAGES = (ROOT / "README.md", *sorted(DOCS.glob("*.md")), DOCS / "tasks" / "index.md")
NUMBER_WORDS = {
    "one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8,
    "nine": 9, "ten": 10, "eleven": 11, "twelve": 12, "fourteen": 14, "sixteen": 16,
    "twenty": 20, "twenty-eight": 28,
}  # fmt: skip
#: "<count> [qualifier] ids", "<count> named tasks", "<count> training tasks".
COUNT_PHRASE = re.compile(
    r"(?<![\w.])(?P<count>\d+|" + "|".join(sorted(NUMBER_WORDS, key=len, reverse=True)) + r")\s+"
    r"(?:(?P<qualifier>base|task|training|named|registered|versioned|Gymnasium)\s+)?"
    r"(?P<noun>ids|tasks)\b",
    re.IGNORECASE,
)


def bearing_env_ids() -> set[str]:
    """Every id Gymnasium holds whose env is one of bearing_env's."""
    import gymnasium as gym

    import bearing_env  # noqa: F401  (registers the ids)

    return {
        env_id
        for env_id, spec in gym.registry.items()
        if str(spec.entry_point).startswith("bearing_env.")
    }


def id_counts() -> dict[str | None, set[int]]:
    """What a count of ids may be, by the phrase's qualifier: the whole registry, the
    base ids (per version or all), the carded tasks, the training tasks."""
    from bearing_env.tasks import BASE_ID_KINDS, TASKS, TRAINING_TASKS, VERSIONS

    versions = len(VERSIONS)
    total = {len(bearing_env_ids())}
    return {
        None: total, "registered": total, "versioned": total, "gymnasium": total,
        "base": {len(BASE_ID_KINDS) // versions, len(BASE_ID_KINDS)},
        "task": {len(TASKS), len(TASKS) * versions},
        "named": {len(TASKS), len(TASKS) * versions},
        "training": {len(TRAINING_TASKS), len(TRAINING_TASKS) * versions},
    }  # fmt: skip


def stated_counts(text: str) -> list[tuple[str, str | None, int]]:
    """Each "N ids" / "N named tasks" / "N training tasks" of ``text``: the phrase, its
    qualifier (lower case) and N."""
    found = []
    for match in COUNT_PHRASE.finditer(text):
        qualifier = (match["qualifier"] or "").lower() or None
        if match["noun"].lower() == "tasks" and qualifier not in ("named", "training"):
            continue  # "the three sensor tasks" and the like: not a count of ids
        count = match["count"].lower()
        number = int(count) if count.isdigit() else NUMBER_WORDS[count]
        found.append((match[0], qualifier, number))
    return found


def test_the_registry_holds_every_id_of_the_task_table() -> None:
    from bearing_env.registration import ENV_IDS
    from bearing_env.tasks import REGISTERED_TASKS_BY_ID

    assert bearing_env_ids() == set(ENV_IDS) | set(REGISTERED_TASKS_BY_ID)


def test_the_ids_page_lists_every_registered_id() -> None:
    """The tasks page's "Every registered id" table is the registry, id for id."""
    from bearing_env.train.compare.task_cards import REGISTERED_IDS_HEADING

    text = (DOCS / "tasks" / "index.md").read_text(encoding="utf-8")
    section = _section(text, REGISTERED_IDS_HEADING)
    listed = re.findall(r"^\| `([\w-]+)` \|", section, re.MULTILINE)
    assert len(listed) == len(set(listed))
    assert set(listed) == bearing_env_ids()


def test_every_count_of_ids_the_pages_state_is_the_registry_s() -> None:
    """Each "N ids" (and "N base ids", "N named tasks", ...) of the README and the
    reference pages agrees with the registry; the README and the environment page state
    the total."""
    allowed = id_counts()
    wrong = [
        f"{page.relative_to(ROOT)}: {phrase!r}"
        for page in REFERENCE_PAGES
        for phrase, qualifier, number in stated_counts(page.read_text(encoding="utf-8"))
        if number not in allowed[qualifier]
    ]
    assert wrong == []
    for page in (ROOT / "README.md", DOCS / "environment.md", DOCS / "tasks" / "index.md"):
        totals = [
            number
            for _, qualifier, number in stated_counts(page.read_text(encoding="utf-8"))
            if qualifier in (None, "registered")
        ]
        assert totals and set(totals) <= allowed[None], page.name


def emitted_info_keys(env_id: str, **kwargs: object) -> set[str]:
    import gymnasium as gym

    env = gym.make(f"bearing_env:{env_id}", **kwargs)
    try:
        _, reset_info = env.reset(seed=0)
        env.action_space.seed(0)
        _, _, _, _, step_info = env.step(env.action_space.sample())
    finally:
        env.close()
    assert set(reset_info) == set(step_info)
    return set(reset_info)


def info_table_keys() -> set[str]:
    """The keys of the environment page's info table."""
    section = _section((DOCS / "environment.md").read_text(encoding="utf-8"), "## Info")
    return set(re.findall(r"^\| `(\w+)` \|", section, re.MULTILINE))


def card_info_keys(card: Path) -> set[str]:
    """The keys a card's Info section lists (before its first colon)."""
    section = _section(card.read_text(encoding="utf-8"), "## Info")
    listed = section.removeprefix("## Info").strip().partition(":")[0]
    return set(re.findall(r"`(\w+)`", listed))


def test_every_info_key_is_in_the_environment_page_s_info_table() -> None:
    """Every key an env's info holds (with the optional ones on) has a row in the info
    table, and every row is a key some env gives."""
    emitted = emitted_info_keys("BearingSLAM-v1", sensor_info=True) | emitted_info_keys(
        "BearingSLAMDiscrete-v1"
    )
    assert emitted == info_table_keys()


def test_every_card_lists_the_info_keys_its_id_gives() -> None:
    from bearing_env.tasks import TASKS

    cards = sorted((DOCS / "tasks").glob("BearingSLAM*.md"))
    assert len(cards) == len(TASKS)  # one per task
    for card in cards:
        assert card_info_keys(card) == emitted_info_keys(card.stem), card.name


def test_every_card_has_a_settings_row_for_each_setting_its_id_registers() -> None:
    """The field of view of the camera tasks, the obstacles' scenario, the noise of the
    sensor tasks, ...: each registered keyword has its row, in bold, marked registered."""
    from bearing_env.tasks import TASKS

    for task in TASKS:
        section = _section((DOCS / "tasks" / f"{task.id}.md").read_text(encoding="utf-8"),
                           "## Settings")  # fmt: skip
        rows = [line for line in section.splitlines() if line.startswith("| **")]
        for key in task.settings:
            assert any(re.search(f"`{key}[`.]", row) and "(registered)" in row for row in rows), (
                task.id,
                key,
            )
    camera = (DOCS / "tasks" / "BearingSLAM-Khepera-Camera90-v1.md").read_text(encoding="utf-8")
    assert "| **field of view (`field_of_view_deg`)** (registered) | 90°" in camera
    room = (DOCS / "tasks" / "BearingSLAM-FurnishedRoom-v1.md").read_text(encoding="utf-8")
    assert "| obstacles (`obstacles`) | 4 polygons" in room
