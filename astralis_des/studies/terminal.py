"""A report's tables drawn to fit the terminal: every value whole, never cut to "...".

Tried in turn until the table fits: as it is; a row's name wrapped at its words; each value's
interval under it; the columns that do not fit moved to a table below (and below that), each
repeating the columns that name a row. Headers wrap at their words.
"""

from __future__ import annotations

from dataclasses import replace

from rich.cells import cell_len
from rich.table import Table

from astralis_des.studies.reports import TextTable

KEY_WIDTH = 24  # columns a row's name keeps before it wraps at its words


def fitted(table: TextTable, width: int) -> list[Table]:
    """``table`` as rich tables, one under another, none wider than ``width`` columns (unless
    a row's name and one value alone are wider)."""
    widths = column_widths(table)
    if drawn_width(widths) > width:
        widths = column_widths(table, key_width=KEY_WIDTH)
    if drawn_width(widths) > width:
        table = replace(table, rows=[row[:table.keys] + [v.replace(" [", "\n[")
                                                         for v in row[table.keys:]]
                                     for row in table.rows])
        widths = column_widths(table, key_width=KEY_WIDTH)
    keys = list(range(min(table.keys, len(widths))))
    groups, group = [], list(keys)
    for i in range(len(keys), len(widths)):
        if len(group) > len(keys) and drawn_width([widths[j] for j in [*group, i]]) > width:
            groups.append(group)
            group = list(keys)
        group.append(i)
    groups.append(group)
    return [_drawn(table, columns, widths, first=n == 0, last=n == len(groups) - 1)
            for n, columns in enumerate(groups)]


def _drawn(table: TextTable, columns: list[int], widths: list[int], *, first: bool,
           last: bool) -> Table:
    title = table.title if first else "(continued)" if table.title else ""
    out = Table(title=title or None,
                caption=" ".join(table.notes) if last and table.notes else None)
    for j in columns:
        out.add_column(table.headers[j], justify="left" if j < table.keys else "right",
                       width=widths[j], overflow="fold")
    for row in table.rows:
        out.add_row(*(row[j] for j in columns))
    return out


def column_widths(table: TextTable, key_width: int | None = None) -> list[int]:
    """Each column's width: its widest value, or its longest word if wider (a header wraps);
    a column naming rows at most ``key_width`` (then its names wrap at their words)."""
    widths = []
    for i, header in enumerate(table.headers):
        cells = [row[i] for row in table.rows]
        widest = max((cell_len(line) for cell in cells for line in cell.splitlines()),
                     default=0)
        longest_word = max((cell_len(word) for text in (header, *cells)
                            for word in text.split()), default=1)
        if i < table.keys and key_width is not None:
            widest = min(widest, key_width)
        widths.append(max(widest, longest_word))
    return widths


def drawn_width(widths: list[int]) -> int:
    """A rich table's width: a space either side of each column, a rule between and round
    them."""
    return sum(w + 2 for w in widths) + len(widths) + 1
