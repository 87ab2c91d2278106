"""Sphinx configuration of the bearing_env documentation (``make docs``).

Sphinx with the furo theme and MyST-Parser, as Farama's Gymnasium and Minigrid sites do:
the pages stay Markdown that reads on a repository host as well as in the built site,
and autodoc reads the package's docstrings, which are written in reStructuredText
(double backticks, ``:class:`` roles), as they are.
"""

from __future__ import annotations

import os
import re
from typing import Any

from docutils import nodes
from docutils.utils import new_document
from myst_parser.parsers.sphinx_ import MystParser
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

import bearing_env

project = "bearing_env"
author = "bearing_env authors"
copyright = "the bearing_env authors, MIT licence"
release = bearing_env.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build"]

# Markdown headings get anchors, so pages link to each other's sections as a repository
# host's renderer does ([text](page.md#a-heading)).
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

# The docstrings' own conventions: reStructuredText with Google-style sections (Args:,
# Returns:, Raises:), members in source order, type hints in the signature.
autodoc_member_order = "bysource"
autodoc_typehints = "signature"
autodoc_default_options = {"show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = False
# The attributes' types stay in the signatures (numpy's ``str_`` reads as a link in rST).
napoleon_attr_annotations = False
# Attributes as fields of their class, so a dataclass field is not described twice.
napoleon_use_ivar = True
# A method without its own docstring shows none, not Gymnasium's generic text.
autodoc_inherit_docstrings = False

html_theme = "furo"
html_title = f"bearing_env {release}"
html_static_path: list[str] = []
# No build date in the pages: the same sources build the same site.
html_last_updated_fmt = None
# Rendering in a headless build must not open a window.
os.environ.setdefault("SDL_VIDEODRIVER", "dummy")


class MarkdownDirective(SphinxDirective):
    """Parses its content as MyST Markdown: the env classes' docstrings follow
    Gymnasium's convention (Markdown with ``##`` headings and pipe tables)."""

    has_content = True

    def run(self) -> list[nodes.Node]:
        document = new_document(self.env.docname, self.state.document.settings)
        MystParser().parse("\n".join(self.content), document)
        return list(document.children)


def markdown_docstrings(
    app: Sphinx, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    """Wraps a Gymnasium-style Markdown docstring (one that opens with a ``## `` heading)
    in the ``markdown`` directive; its headings become bold lines, since a section cannot
    open inside an object's description."""
    if not lines or not lines[0].startswith("## "):
        return
    body = [re.sub(r"^#{2,} (.*)$", r"**\1**", line) for line in lines]
    lines[:] = [".. markdown::", ""] + [f"   {line}" if line else "" for line in body]


def setup(app: Sphinx) -> None:
    app.add_directive("markdown", MarkdownDirective)
    app.connect("autodoc-process-docstring", markdown_docstrings)
