"""CITATION.cff cites the software and the paper, in valid Citation File Format 1.2.0
(the keys it requires), and the package metadata names the project's URLs."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import bearing_env
from tests.extras import skip_module_without

skip_module_without("train", "yaml")
import yaml  # noqa: E402  (pyyaml is the train extra's)

tomllib = pytest.importorskip("tomllib")

ROOT = Path(__file__).resolve().parents[2]


def citation() -> dict[str, Any]:
    loaded = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert isinstance(loaded, dict)
    return loaded


def assert_persons_or_entities(people: Any) -> None:
    assert isinstance(people, list) and people
    for person in people:
        # CFF: a person has family-names (or name-particle/given-names); an entity a name.
        assert person.get("family-names") or person.get("name"), person


def test_the_citation_file_has_the_keys_cff_requires() -> None:
    cff = citation()
    assert cff["cff-version"] == "1.2.0"
    for key in ("message", "title", "authors"):
        assert isinstance(cff[key], (str, list)) and cff[key], key
    assert_persons_or_entities(cff["authors"])
    assert cff["type"] == "software"
    assert str(cff["version"]) == bearing_env.__version__
    assert cff["license"] == "MIT"


def test_the_preferred_citation_is_the_paper() -> None:
    paper = citation()["preferred-citation"]
    assert paper["type"] == "conference-paper"
    assert paper["title"] == (
        "Uncertainty Analysis of a Landmark Initialization Method for Simultaneous "
        "Localization and Mapping"
    )
    assert [a["family-names"] for a in paper["authors"]] == ["Huang", "Maire", "Keeratipranon"]
    assert_persons_or_entities(paper["authors"])
    assert paper["year"] == 2005
    assert "Australasian Conference on Robotics and Automation" in paper["collection-title"]


def test_the_citation_file_goes_into_the_sdist() -> None:
    lines = (ROOT / "MANIFEST.in").read_text(encoding="utf-8").splitlines()
    assert "include CITATION.cff" in lines


def test_the_metadata_has_classifiers_and_project_urls_under_one_base() -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert any(c.startswith("Programming Language :: Python :: 3") for c in project["classifiers"])
    assert "Intended Audience :: Science/Research" in project["classifiers"]
    urls = project["urls"]
    assert {"Homepage", "Documentation", "Source", "Issues"} <= set(urls)
    base = urls["Source"]
    assert all(url.startswith(base) for url in urls.values())
    assert citation()["repository-code"] == base
