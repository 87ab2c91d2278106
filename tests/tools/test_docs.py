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
