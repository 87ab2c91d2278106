"""The documentation site builds from ``docs/`` with warnings as errors, and every internal
link and image of the built HTML resolves; the README stays short, and the Python blocks
of the pages run as written.

The site is built once for the module (Sphinx, furo, MyST-Parser: the ``docs`` extra),
afresh into a temporary folder, as ``make docs`` builds it into ``docs/_build/html``.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest

from tests.extras import skip_module_without

skip_module_without("docs")

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
#: The README's hard limit; it aims at about 200 lines and sends the rest to the pages.
README_MAX_LINES = 220
#: Pages whose Python blocks are complete programs (the world model's block names
#: readings it does not define).
RUNNABLE_PAGES = ("quickstart.md", "policies.md", "environment.md", "index.md")


@pytest.fixture(scope="module")
def site(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("docs")
    html = out / "html"
    result = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-j", "auto",
         "-b", "html", "-d", str(out / "doctrees"), str(DOCS), str(html)],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "SDL_VIDEODRIVER": "dummy"},
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-5000:]
    assert result.stderr.strip() == "", result.stderr[-5000:]
    return html


class _Page(HTMLParser):
    """The link targets, image sources and element ids of one HTML page."""

    def __init__(self) -> None:
        super().__init__()
        self.links: list[str] = []
        self.images: list[str] = []
        self.ids: set[str] = set()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        values = dict(attrs)
        if values.get("id"):
            self.ids.add(str(values["id"]))
        if tag in ("a", "link") and values.get("href") is not None:
            self.links.append(str(values["href"]))
        if tag == "img" and values.get("src") is not None:
            self.images.append(str(values["src"]))


def _parse(path: Path) -> _Page:
    page = _Page()
    page.feed(path.read_text(encoding="utf-8"))
    return page


def test_the_site_has_a_page_for_every_document(site: Path) -> None:
    sources = {p.relative_to(DOCS).with_suffix(".html") for p in DOCS.rglob("*.md")
               if "_build" not in p.parts}  # fmt: skip
    built = {p.relative_to(site) for p in site.rglob("*.html")}
    assert sources <= built
    assert {Path("index.html"), Path("api.html"), Path("tasks/index.html")} <= built


def test_every_internal_link_and_image_resolves(site: Path) -> None:
    pages = {path: _parse(path) for path in site.rglob("*.html")}
    broken: list[str] = []
    checked = 0
    for path, page in pages.items():
        for kind, target in [("link", t) for t in page.links] + [("img", t) for t in page.images]:
            parts = urlsplit(target)
            if parts.scheme or target.startswith("//"):
                continue  # an external address
            file = (path.parent / unquote(parts.path)).resolve() if parts.path else path
            checked += 1
            if not file.exists():
                broken.append(f"{path.relative_to(site)}: {kind} {target}")
            elif kind == "link" and parts.fragment and file.suffix == ".html":
                ids = pages[file].ids if file in pages else _parse(file).ids
                if unquote(parts.fragment) not in ids:
                    broken.append(f"{path.relative_to(site)}: anchor {target}")
    assert checked > 500
    assert broken == []


def test_the_pages_show_their_figures(site: Path) -> None:
    images = {Path(src).name for src in _parse(site / "results.html").images}
    assert {"fig7_polygons.png", "fig10_khepera.png", "fig11_epsilon.png", "fig_robust.png",
            "khepera_area_vs_moves.png", "khepera_error_vs_moves.png"} <= images
    assert "fig7_polygons.png" in {Path(s).name for s in _parse(site / "index.html").images}


def test_the_api_reference_documents_the_public_names(site: Path) -> None:
    ids = _parse(site / "api.html").ids
    import bearing_env.agents
    import bearing_env.envs
    import bearing_env.slam

    for module in (bearing_env.envs, bearing_env.slam, bearing_env.agents):
        names = {f"{module.__name__}.{name}" for name in module.__all__}
        documented = {i for i in ids if i.startswith(module.__name__)}
        found = {n for n in names if any(i.endswith("." + n.rsplit(".", 1)[1]) for i in documented)}
        assert sorted(names - found) == [], module.__name__


def test_the_readme_is_short_and_has_the_first_hour() -> None:
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= README_MAX_LINES
    for needle in ("pip install", 'gym.make("BearingSLAM-v1"', "make demo", "make test",
                   "bearing-env compare", "bearing-env train", "## Citation",
                   "Uncertainty Analysis of a Landmark Initialization Method",
                   "docs/figures/"):
        assert needle in text, needle
    # The README links every page of the site but the API reference, generated there.
    linked = set(re.findall(r"\]\(docs/([\w/]+\.md)\)", text))
    # The task cards are linked from the task index, which the README links.
    pages = {
        p.relative_to(DOCS).as_posix()
        for p in DOCS.rglob("*.md")
        if "_build" not in p.parts and (p.parent.name != "tasks" or p.name == "index.md")
    }
    assert sorted(pages - linked - {"index.md", "api.md"}) == []


def test_the_docs_quick_start_is_the_readmes() -> None:
    readme = README.read_text(encoding="utf-8")
    section = readme.split("\n## Quick start\n", 1)[1].split("\n## ", 1)[0]
    (block,) = re.findall(r"```python\n(.*?)```", section, re.S)
    assert f"```python\n{block}```" in (DOCS / "quickstart.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("page", RUNNABLE_PAGES)
def test_the_python_blocks_of_a_page_run(page: str, tmp_path: Path) -> None:
    blocks = re.findall(r"```python\n(.*?)```", (DOCS / page).read_text(encoding="utf-8"), re.S)
    assert blocks
    for number, block in enumerate(blocks):
        result = subprocess.run(
            [sys.executable, "-c", block],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=300,
            env={**os.environ, "SDL_VIDEODRIVER": "dummy"},
        )
        assert result.returncode == 0, f"{page} block {number}:\n{result.stderr[-3000:]}"
