"""The length of the project's C++ functions, measured as code_shape measures Python's.

    python -m tests.tools.code_shape        # the counts, Python's and C++'s

There is no C++ parser here (no libclang), so this is a small scanner, and it measures
only what it documents:

1. Comments, string and character literals (raw strings too) and preprocessor lines (a
   ``#define``'s continuation lines with them) are blanked, keeping the line breaks; a
   ``'`` inside a number (``1'000``) is a digit separator, not a literal.
2. The rest is split into tokens and read scope by scope from the top: a namespace or an
   ``extern "C"`` block is read through, as is a class, struct or union body (its name
   joins the prefix); an enum body or a brace initialiser is skipped.
3. At namespace or class scope, a ``{`` opens a function body when the declaration before
   it has a parameter list: a ``(...)`` right after a name (``f``, ``Class::f``,
   ``~Class``, ``f<T>``, ``operator()``, ``operator==``, ``operator bool``), followed
   only by qualifiers (``const``, ``noexcept``, ``noexcept(...)``, ``override``,
   ``final``, ``&``, ``&&``, ``volatile``, ``[[...]]``), a trailing return type
   (``-> T``) or a constructor's member-initialiser list (``: a_(x), b_{y}``; its
   brace-initialisers are not the body). A control statement (``if``, ``for``,
   ``while``, ``switch``, ``catch``, ...) is never a function, and a lambda assigned to a
   variable at namespace scope is a variable, not a function.
4. Everything up to the body's matching ``}`` is the function's, lambdas and nested
   blocks included. Its length is the closing brace's line minus the name's line, plus one
   (the ``template <...>`` line and a return type on the line above are not counted).

A function's key is ``path:qualified::name`` (namespaces, classes, and the name as
written: ``csrc/slam/map_batch.cpp:bearing::slam::MapBatch::update``); an anonymous
namespace adds nothing to it, and overloads share their key (an allowance covers them all).
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from tests.tools.code_shape import MAX_FUNCTION_LINES, ROOT

#: The folders of C++ sources the limit holds in, and their file suffixes.
CPP_FOLDERS: tuple[str, ...] = ("csrc", "tests/cpp", "examples/cpp")
CPP_SUFFIXES = frozenset({".cpp", ".hpp"})

#: The C++ functions allowed over MAX_FUNCTION_LINES, each with its reason; the one list
#: (test_code_shape checks that each is still over the limit, so none outlives its need).
BINDINGS = "a module part's registration list: one m.def per kernel, in the order of its header"
ALLOWED_LONG: dict[str, str] = {
    "csrc/bindings/bind_env.cpp:bind_env": BINDINGS,
}

#: The bindings stay a thin layer over the library's checked entry points: at most this
#: many lines in the folder (comments included; a kernel's checks belong in the library).
BINDINGS_FOLDER = "csrc/bindings"
MAX_BINDINGS_LINES = 1200

#: Words that take parentheses but never name a function being defined.
NOT_NAMES = frozenset(
    {
        "if", "for", "while", "switch", "catch", "return", "sizeof", "alignof", "alignas",
        "decltype", "noexcept", "static_assert", "throw", "typeid", "new", "delete", "do",
        "else", "try", "case", "default", "requires", "co_await", "co_return", "co_yield",
        "__attribute__", "__declspec", "defined", "static_cast", "const_cast",
        "reinterpret_cast", "dynamic_cast",
    }
)  # fmt: skip
#: What may stand between a parameter list and its body (besides ``noexcept(...)``,
#: ``[[...]]``, ``-> T`` and ``: initialisers``).
QUALIFIERS = frozenset({"const", "volatile", "override", "final", "&", "try"})
CLASS_KEYS = frozenset({"class", "struct", "union"})
ACCESS = frozenset({"public", "private", "protected"})
OPENERS = {"(": ")", "[": "]", "{": "}"}


@dataclass(frozen=True)
class CppFunction:
    """One C++ function definition: where it is and how long."""

    path: str  # relative to the repository
    name: str  # qualified: namespace::Class::name
    lineno: int  # the line of its name
    lines: int

    @property
    def key(self) -> str:
        return f"{self.path}:{self.name}"


# ---------------------------------------------------------------------------------------
# 1. Blanking comments, literals and preprocessor lines
# ---------------------------------------------------------------------------------------

RAW_STRING = re.compile(r'(?:u8|[uUL])?R"([^ ()\\\t\n]{0,16})\(')


def _blank(text: str) -> str:
    """Spaces for every character of ``text`` but its line breaks."""
    return re.sub(r"[^\n]", " ", text)


def _literal_end(code: str, start: int, quote: str) -> int:
    """The index just past the literal opened by ``quote`` at ``start`` (escapes honoured)."""
    i = start + 1
    while i < len(code) and code[i] != quote and code[i] != "\n":
        i += 2 if code[i] == "\\" else 1
    return min(i + 1, len(code))


def _in_number(code: str, i: int) -> bool:
    """Whether the ``'`` at ``i`` is a digit separator: its token starts with a digit."""
    j = i
    while j > 0 and (code[j - 1].isalnum() or code[j - 1] in "_.'"):
        j -= 1
    return j < i and code[j].isdigit()


def _directive_end(code: str, start: int) -> int:
    """The end of the preprocessor line at ``start``: its last continuation line's break."""
    i = start
    while True:
        end = code.find("\n", i)
        if end < 0:
            return len(code)
        if code[start:end].rstrip().endswith("\\"):
            i = end + 1
            continue
        return end


def strip_cpp(code: str) -> str:
    """``code`` with comments, literals and preprocessor lines blanked (same line breaks)."""
    out: list[str] = []
    i, line_start = 0, True  # line_start: only blanks so far on this line
    while i < len(code):
        c, pair = code[i], code[i : i + 2]
        raw = RAW_STRING.match(code, i) if c in "uULR" else None
        if line_start and c == "#":
            end = _directive_end(code, i)
        elif pair == "//":
            end = code.find("\n", i)
            end = len(code) if end < 0 else end
        elif pair == "/*":
            end = code.find("*/", i + 2)
            end = len(code) if end < 0 else end + 2
        elif raw is not None and (i == 0 or not (code[i - 1].isalnum() or code[i - 1] == "_")):
            closing = f'){raw.group(1)}"'
            end = code.find(closing, raw.end())
            end = len(code) if end < 0 else end + len(closing)
        elif c == '"' or (c == "'" and not _in_number(code, i)):
            end = _literal_end(code, i, c)
        else:
            out.append(c)
            line_start = c == "\n" or (line_start and c.isspace())
            i += 1
            continue
        out.append(_blank(code[i:end]))
        line_start = line_start and pair == "/*"  # a comment before a # is a blank
        i = end
    return "".join(out)


# ---------------------------------------------------------------------------------------
# 2. Tokens and the scopes they open
# ---------------------------------------------------------------------------------------

TOKEN = re.compile(r"[A-Za-z_]\w*|\d[\w.']*|::|->|\.\.\.|\S")


@dataclass(frozen=True)
class Token:
    text: str
    line: int


def tokenize(stripped: str) -> list[Token]:
    """The tokens of blanked code, each with its line (1-based)."""
    tokens, line, last = [], 1, 0
    for match in TOKEN.finditer(stripped):
        line += stripped.count("\n", last, match.start())
        last = match.start()
        tokens.append(Token(match.group(), line))
    return tokens


def matching(tokens: list[Token], path: str) -> dict[int, int]:
    """Each opening bracket's index mapped to its closing one's; unbalanced code is an error
    (the scanner would mismeasure it, so it says so instead)."""
    pairs: dict[int, int] = {}
    stack: list[int] = []
    for i, token in enumerate(tokens):
        if token.text in OPENERS:
            stack.append(i)
        elif token.text in OPENERS.values():
            if not stack or OPENERS[tokens[stack[-1]].text] != token.text:
                raise ValueError(f"{path}:{token.line}: unbalanced {token.text!r}")
            pairs[stack.pop()] = i
    if stack:
        raise ValueError(f"{path}:{tokens[stack[-1]].line}: unclosed {tokens[stack[-1]].text!r}")
    return pairs


def _is_name(text: str) -> bool:
    return (text[0].isalpha() or text[0] == "_") and text not in NOT_NAMES


class _Scanner:
    """Reads one file's tokens scope by scope and collects its function definitions.

    A declaration's *head* is the list of its top-level token indices since the last
    ``;``, ``}`` or access specifier; a bracketed group stands in it as its opening index.
    """

    def __init__(self, tokens: list[Token], path: str) -> None:
        self.tokens, self.path = tokens, path
        self.pairs = matching(tokens, path)
        self.found: list[CppFunction] = []

    def text(self, index: int) -> str:
        return self.tokens[index].text

    def scope(self, i: int, prefix: str) -> int:
        """Read declarations from ``i`` to the scope's closing brace; the index past it."""
        head: list[int] = []
        while i < len(self.tokens):
            text = self.text(i)
            if text == "}":
                return i + 1
            if text == ";" or (text in ACCESS and not head and self._at(i + 1) == ":"):
                head, i = [], i + (1 if text == ";" else 2)
            elif text in ("(", "["):
                head.append(i)
                i = self.pairs[i] + 1
            elif text == "{":
                i, head = self.brace(i, head, prefix)
            else:
                head.append(i)
                i += 1
        return i

    def _at(self, i: int) -> str:
        return self.text(i) if i < len(self.tokens) else ""

    def brace(self, i: int, head: list[int], prefix: str) -> tuple[int, list[int]]:
        """Read the ``{`` at ``i`` after ``head``: the index past what it opens, the head after."""
        words = self._without_template(head)
        first = self.text(words[0]) if words else ""
        if "namespace" in [self.text(k) for k in words[:2]]:  # namespace a::b, inline namespace
            names = [self.text(k) for k in words if self.text(k) not in ("inline", "namespace")]
            return self.scope(i + 1, prefix + "".join(names) + ("::" if names else "")), []
        if first == "extern" and len(words) == 1:  # extern "C" { (the string is blanked)
            return self.scope(i + 1, prefix), []
        function = self.function_name(head)
        if function is not None:
            name_index, initialisers = function
            before = self.text(head[-1])
            if initialisers and (_is_name(before) or before == ">"):  # a member's b_{y}
                return self.pairs[i] + 1, [*head, i]
            close = self.pairs[i]
            line = self.tokens[name_index].line
            name = self.qualified_name(head, head.index(name_index))
            self.found.append(
                CppFunction(self.path, prefix + name, line, self.tokens[close].line - line + 1)
            )
            return close + 1, []
        if first in CLASS_KEYS:
            return self.scope(i + 1, prefix + self.class_name(words)), [*head, i]
        return self.pairs[i] + 1, [*head, i]  # an enum, a brace initialiser, a bare block

    def _without_template(self, head: list[int]) -> list[int]:
        """``head`` without a leading ``template <...>`` (its angle brackets balanced)."""
        k = 0
        while k < len(head) and self.text(head[k]) == "template":
            depth, k = 0, k + 1
            while k < len(head):
                depth += {"<": 1, ">": -1}.get(self.text(head[k]), 0)
                k += 1
                if depth == 0:
                    break
        return head[k:]

    def class_name(self, words: list[int]) -> str:
        """``Name::`` for ``struct alignas(8) Name final : Base``; nothing if anonymous."""
        names = []
        for k in words[1:]:
            text = self.text(k)
            if text == ":" or text == "final" or text == "<":
                break
            if _is_name(text) or text == "::":
                names.append(text)
        return "".join(names) + "::" if names else ""

    def function_name(self, head: list[int]) -> tuple[int, bool] | None:
        """The name token of the first parameter list in ``head`` that a body may follow,
        and whether a member-initialiser list follows it; None if there is none."""
        for k, index in enumerate(head):
            if self.text(index) != "(" or self._name_index(head, k) is None:
                continue
            tail = self._tail(head[k + 1 :])
            if tail is not None:
                name_index = self._name_index(head, k)
                assert name_index is not None
                return name_index, tail
        return None

    def _name_index(self, head: list[int], k: int) -> int | None:
        """The token naming the function whose parameter list is ``head[k]``: ``operator``
        in an operator's name, else the identifier before the list (past ``<...>``)."""
        for back in range(1, min(k, 4) + 1):
            if self.text(head[k - back]) == "operator":
                return head[k - back]
        if k == 0:
            return None
        before = self.text(head[k - 1])
        if before == ">":
            start = self._angle_start(head, k - 1)
            return head[start - 1] if start > 0 and _is_name(self.text(head[start - 1])) else None
        return head[k - 1] if _is_name(before) else None

    def _angle_start(self, head: list[int], k: int) -> int:
        """The position in ``head`` of the ``<`` that the ``>`` at ``k`` closes."""
        depth = 0
        for j in range(k, -1, -1):
            depth += {">": 1, "<": -1}.get(self.text(head[j]), 0)
            if depth == 0:
                return j
        return 0

    def _tail(self, rest: list[int]) -> bool | None:
        """Whether qualifiers and then a member-initialiser list follow a parameter list
        (False: qualifiers or a trailing return type only); None if ``rest`` is anything else."""
        j = 0
        while j < len(rest):
            text = self.text(rest[j])
            if text == ":":
                return True
            if text == "->":
                return False
            if text in ("noexcept", "throw") and j + 1 < len(rest) and self._at(rest[j + 1]) == "(":
                j += 2
            elif text in QUALIFIERS or text == "noexcept" or self._is_attribute(rest[j]):
                j += 1
            else:
                return None
        return False

    def _is_attribute(self, index: int) -> bool:
        return self.text(index) == "[" and self._at(index + 1) == "["

    def qualified_name(self, head: list[int], k: int) -> str:
        """The name as written at ``head[k]``: ``Class::~Class``, ``f``, ``operator()``."""
        if self.text(head[k]) == "operator":
            end = next(j for j in range(k + 1, len(head)) if self.text(head[j]) == "(")
            if self._at(head[end] + 1) == ")" and self._at(head[end] + 2) == "(":
                end += 1  # operator() itself: its () group, then the parameter list
            symbols = "".join(
                self.text(t) + (" " if _is_name(self.text(t)) else "")
                for t in range(head[k] + 1, head[end])
            )
            name = "operator" + (" " if symbols[:1].isalpha() else "") + symbols.strip()
        else:
            name = self.text(head[k])
        while k > 0 and self.text(head[k - 1]) == "~":
            name, k = "~" + name, k - 1
        while k > 1 and self.text(head[k - 1]) == "::":
            owner = k - 2
            if self.text(head[owner]) == ">":
                owner = self._angle_start(head, owner) - 1
            if owner < 0 or not _is_name(self.text(head[owner])):
                break
            name, k = f"{self.text(head[owner])}::{name}", owner
        return name


# ---------------------------------------------------------------------------------------
# 3. Files and the limit
# ---------------------------------------------------------------------------------------


def cpp_functions(path: Path, root: Path = ROOT) -> list[CppFunction]:
    """Every function defined in the C++ file ``path`` (at namespace or class scope)."""
    relative = path.relative_to(root).as_posix()
    tokens = tokenize(strip_cpp(path.read_text(encoding="utf-8")))
    scanner = _Scanner(tokens, relative)  # refuses unbalanced brackets
    scanner.scope(0, "")
    return scanner.found


def cpp_files(root: Path = ROOT) -> list[Path]:
    """The C++ sources and headers of the checked folders under ``root``."""
    folders = [root / folder for folder in CPP_FOLDERS]
    return sorted(p for folder in folders for p in folder.rglob("*") if p.suffix in CPP_SUFFIXES)


def project_cpp_functions(root: Path = ROOT) -> list[CppFunction]:
    """The functions of every C++ file in the checked folders under ``root``."""
    return [f for path in cpp_files(root) for f in cpp_functions(path, root)]


def too_long_cpp(functions: list[CppFunction]) -> list[CppFunction]:
    """The C++ functions longer than MAX_FUNCTION_LINES (the allowed ones included)."""
    return [f for f in functions if f.lines > MAX_FUNCTION_LINES]


def iter_report(functions: list[CppFunction]) -> Iterator[str]:
    """The summary lines for code_shape's main: the count, and each function over the limit."""
    long_ones = too_long_cpp(functions)
    yield f"{len(functions)} C++ functions in {', '.join(CPP_FOLDERS)}"
    yield f"C++ longer than {MAX_FUNCTION_LINES} lines: {len(long_ones)}"
    for f in long_ones:
        reason = ALLOWED_LONG.get(f.key)
        note = f"allowed: {reason}" if reason else "NOT ALLOWED"
        yield f"  {f.key} ({f.lines} lines, line {f.lineno}; {note})"
