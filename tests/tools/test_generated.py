"""The structs the C++ library declares once: their Python files are generated from the
build and current, and no source lists a struct's fields a second time."""

from __future__ import annotations

import math
import re
from pathlib import Path

from bearing_env import _core
from tests.tools import generate_stubs

ROOT = generate_stubs.ROOT
#: Where each struct's fields are declared: the library header of its X-macro.
HOMES = {
    "State": "csrc/include/bearing_core/slam/state.hpp",
    "Outputs": "csrc/include/bearing_core/slam/state.hpp",
    "Params": "csrc/include/bearing_core/slam/state.hpp",
    "Encoded": "csrc/include/bearing_core/slam/state.hpp",
    "Window": "csrc/include/bearing_core/slam/state.hpp",
    "Levels": "csrc/include/bearing_core/slam/state.hpp",
    "Report": "csrc/include/bearing_core/env/types.hpp",
    "BatchState": "csrc/include/bearing_core/env/types.hpp",
    "Settings": "csrc/include/bearing_core/env/types.hpp",
}
#: Listings kept on purpose, with why: (struct, file) -> reason.
ALLOWED = {
    ("Params", "tests/golden_replay.py"): "the golden corpus's file format: its settings line",
}
SOURCE_FOLDERS = ("csrc", "examples", "bearing_env", "agents", "train", "benchmarks", "tests")
SUFFIXES = {".py", ".pyi", ".cpp", ".hpp"}
#: A listing: this share of a struct's fields named in its order, each within MAX_GAP lines
#: of the one before.
SHARE = 0.75
MAX_GAP = 3
#: The structs checked: those of at least this many fields (a use of a smaller one, its
#: three arrays passed in order, reads like a listing of it).
MIN_FIELDS = 6


#: What declares a name (group 1), not a use of it: a Python field (``name:`` at a line's
#: start), a string literal, a C++ member (``Type name;`` or ``Type name = value;``) or an
#: X-macro row (``X(type, 3, name, ...)``).
DECLARATIONS = tuple(
    re.compile(pattern)
    for pattern in (
        r"(?m)^[ \t]*([A-Za-z_]\w*)[ \t]*:(?!:)",
        r"[\"']([A-Za-z_]\w*)[\"']",
        r"\b[A-Za-z_][\w:<>,]*[ \t]+([A-Za-z_]\w*)[ \t]*(?:;|=(?!=))",
        r"\b[A-Z_]+\(\s*[\w:<>]+\s*,\s*(?:\d+\s*,\s*)?([A-Za-z_]\w*)\s*,",
    )
)


def declarations(text: str) -> list[tuple[int, str]]:
    """Every declared name of ``text`` and its offset, in the text's order."""
    return sorted(
        {(m.start(1), m.group(1)) for pattern in DECLARATIONS for m in pattern.finditer(text)}
    )


def listings(
    text: str, fields: list[str], declared: list[tuple[int, str]] | None = None
) -> list[int]:
    """The lines where a listing of ``fields`` starts: their declarations in their order,
    naming at least SHARE of them (at least 3), each within MAX_GAP lines of the one before
    (``declared``: the text's :func:`declarations`, when the caller has them)."""
    needed = max(3, math.ceil(SHARE * len(fields)))
    index_of = {name: k for k, name in enumerate(fields)}
    # (line, k) of every declaration of field k, in the text's order.
    named = [
        (text.count("\n", 0, at), index_of[name])
        for at, name in (declarations(text) if declared is None else declared)
        if name in index_of
    ]
    found: list[int] = []
    start = 0
    while start < len(named):
        (first, index), line, matched = named[start], named[start][0], 1
        for at, k in named[start + 1 :]:
            if at - line > MAX_GAP:
                break
            if k > index:
                index, line, matched = k, at, matched + 1
        if matched >= needed:
            found.append(first + 1)
            while start < len(named) and named[start][0] <= line:
                start += 1
        else:
            start += 1
    return found


def source_files() -> list[Path]:
    generated = {generate_stubs.STUB, generate_stubs.SCHEMA}
    return [
        path
        for folder in SOURCE_FOLDERS
        for path in sorted((ROOT / folder).rglob("*"))
        if path.suffix in SUFFIXES and path not in generated and "_build" not in path.parts
    ]


def test_the_generated_stub_and_structs_match_the_build() -> None:
    stale = [
        str(path.relative_to(ROOT))
        for path, text in generate_stubs.generated().items()
        if path.read_text(encoding="utf-8") != text
    ]
    assert stale == [], "run `make stubs`"


def test_every_struct_has_a_home() -> None:
    assert set(HOMES) == set(_core.SCHEMAS)


def test_no_struct_field_list_is_written_twice() -> None:
    where: dict[str, list[str]] = {}
    texts = {path: path.read_text(encoding="utf-8") for path in source_files()}
    declared = {path: declarations(text) for path, text in texts.items()}
    for name, schema in _core.SCHEMAS.items():
        fields = [field[0] for field in schema]
        if len(fields) < MIN_FIELDS:
            continue
        for path, text in texts.items():
            relative = str(path.relative_to(ROOT))
            if (name, relative) in ALLOWED:
                continue
            for line in listings(text, fields, declared[path]):
                where.setdefault(name, []).append(f"{relative}:{line}")
    homes = {name: [at.split(":")[0] for at in found] for name, found in where.items()}
    assert {name: sorted(set(files)) for name, files in homes.items()} == {
        name: [home] for name, home in HOMES.items() if len(_core.SCHEMAS[name]) >= MIN_FIELDS
    }, where


def test_the_check_finds_a_field_list_written_again() -> None:
    fields = [field[0] for field in _core.SCHEMAS["Report"]]
    # One per line, as a namedtuple or a struct would list them, with types between.
    declared = "\n".join(f"    {name}: NDArray[np.float64]  # ({name})" for name in fields)
    assert listings(f"class Copy(NamedTuple):\n{declared}\n", fields) == [2]
    # Several per line, as a tuple of names would.
    assert listings(", ".join(f'"{name}"' for name in fields), fields) == [1]
    # As C++ members.
    assert listings("\n".join(f"View1<double> {name};" for name in fields), fields) == [1]
    # Three quarters of them still count; fewer, or out of order, or far apart, do not.
    keep = math.ceil(SHARE * len(fields))
    quoted = [f"'{name}'" for name in fields]
    assert listings(" ".join(quoted[:keep]), fields) == [1]
    assert listings(" ".join(quoted[: keep - 1]), fields) == []
    assert listings(" ".join(reversed(quoted)), fields) == []
    assert listings("\n\n\n\n".join(quoted), fields) == []
    # Uses are not declarations: every field assigned or passed by keyword.
    assert listings("\n".join(f"    self.{name}[rows] = 0" for name in fields), fields) == []
    assert listings("\n".join(f"    {name}=value," for name in fields), fields) == []
