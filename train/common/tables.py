"""Tables of numbers on a terminal (rich), laid out so that no number is split.

Rich fits a table that is too wide by narrowing its widest columns, whatever they hold,
so on an 80-column terminal "0.192" became "0.19" over "2". :func:`fit_widths` plans the
column widths instead: every column keeps at least the width of its longest word (a
number, or a bound of a confidence interval), so cells wrap only at spaces; the room left
goes first to whole header words, then to whole cells. A table whose header words do not
fit between box lines is drawn without them (two spaces between columns); when even the
longest cell words do not fit, the last columns are left out and the caption says which
(:func:`print_table`).
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from typing import Any

#: Rich's default box: a border left of each column and one at the end, one space of
#: padding either side of each cell.
BORDERS_PER_COLUMN = 3


def boxed_chrome(columns: int) -> int:
    """The characters a boxed table's borders and padding take on each line."""
    return BORDERS_PER_COLUMN * columns + 1


def compact_chrome(columns: int) -> int:
    """Without a box: two spaces between columns (rich's collapsed padding around a blank
    divider), none at the edges."""
    return 2 * (columns - 1)


def _longest_word(texts: Sequence[str]) -> int:
    return max((len(word) for text in texts for word in text.split()), default=1)


def _grow(widths: list[int], targets: Sequence[int], room: int) -> list[int]:
    """``widths`` raised toward ``targets`` within ``room`` more characters in all, in
    proportion to what each column lacks."""
    lacking = [max(0, target - width) for width, target in zip(widths, targets, strict=True)]
    total = sum(lacking)
    if total <= room:
        return [width + extra for width, extra in zip(widths, lacking, strict=True)]
    shares = [room * need // total for need in lacking]
    leftover = room - sum(shares)
    for index in sorted(range(len(widths)), key=lambda i: lacking[i] - shares[i], reverse=True):
        if leftover == 0:
            break
        if shares[index] < lacking[index]:
            shares[index] += 1
            leftover -= 1
    return [width + share for width, share in zip(widths, shares, strict=True)]


def fit_widths(
    header: Sequence[str], rows: Sequence[Sequence[str]], room: int
) -> list[int] | None:
    """The content width of each column, ``room`` characters in all (the line's width less
    its borders and padding), or None when the columns' longest cell words alone do not
    fit."""
    columns = [[name, *(row[index] for row in rows)] for index, name in enumerate(header)]
    natural = [max(len(text) for text in column) for column in columns]
    if sum(natural) <= room:
        return natural
    widths = [_longest_word(column[1:]) for column in columns]
    if sum(widths) > room:
        return None
    with_header_words = [
        max(width, _longest_word(column[:1])) for width, column in zip(widths, columns, strict=True)
    ]
    for targets in (with_header_words, natural):
        widths = _grow(widths, targets, room - sum(widths))
    return widths


def header_words_fit(header: Sequence[str], widths: Sequence[int]) -> bool:
    return all(_longest_word([name]) <= width for name, width in zip(header, widths, strict=True))


def plan_layout(
    header: Sequence[str], rows: Sequence[Sequence[str]], total_width: int
) -> tuple[int, bool, list[int] | None]:
    """How to draw the table in ``total_width`` characters: how many columns (from the
    left) are shown, whether in a box, and their widths (None: the first column alone,
    folded)."""
    shown = len(header)
    while shown > 0:
        names, cells = header[:shown], [row[:shown] for row in rows]
        boxed = fit_widths(names, cells, total_width - boxed_chrome(shown))
        if boxed is not None and header_words_fit(names, boxed):
            return shown, True, boxed
        compact = fit_widths(names, cells, total_width - compact_chrome(shown))
        if compact is not None:
            return shown, False, compact
        if shown == 1:
            break
        shown -= 1
    return 1, True, None


def print_table(
    title: str,
    header: Sequence[str],
    rows: Sequence[Sequence[str]],
    console: Any = None,
    numeric: Collection[int] | None = None,
) -> None:
    """``rows`` under ``header`` as a rich table on ``console`` (default: a new one, the
    terminal's width), the ``numeric`` columns (default: all but the first) right-justified.
    Columns that do not fit are left out from the right (the first always stays), named in
    the caption."""
    from rich import box
    from rich.console import Console
    from rich.table import Table

    console = console or Console()
    right_justified = range(1, len(header)) if numeric is None else numeric
    shown, boxed, widths = plan_layout(header, rows, console.width)
    left_out = header[shown:]
    caption = f"left out at {console.width} columns: {', '.join(left_out)}" if left_out else None
    table = (
        Table(title=title, caption=caption)
        if boxed
        else Table(
            title=title,
            caption=caption,
            box=box.SIMPLE_HEAD,
            show_edge=False,
            pad_edge=False,
            collapse_padding=True,
        )
    )
    for index, name in enumerate(header[:shown]):
        table.add_column(
            name,
            justify="right" if index in right_justified else "left",
            width=None if widths is None else widths[index],
            overflow="fold",
        )
    for row in rows:
        table.add_row(*row[:shown])
    console.print(table)
