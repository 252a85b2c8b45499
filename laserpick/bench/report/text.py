"""How the report writes numbers and tables: percentages, k of n, times (s) and Markdown
tables that line up as plain text too."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

DASH = "–"


def percent(rate: float | None) -> str:
    """A fraction (0..1) as a percentage with one decimal, or a dash."""
    if rate is None or not math.isfinite(rate):
        return DASH
    return f"{100 * rate:.1f} %"


def fraction(k: int | None, n: int | None) -> str:
    """k of n as "p % (k/n)", or a dash when n is 0 or unknown."""
    if k is None or not n:
        return DASH
    return f"{percent(k / n)} ({k}/{n})"


def _num(x: float) -> str:
    """A time (s) to about three significant digits (0.004, 0.52, 3.84, 51.7)."""
    return f"{x:.1f}" if abs(x) >= 10 else f"{x:.2f}" if abs(x) >= 1 else f"{x:.3f}"


def seconds(mean: float | None, std: float | None = None) -> str:
    """A time (s) with its standard deviation when known, or a dash."""
    if mean is None:
        return DASH if std is None else f"? ± {_num(std)} s"
    return f"{_num(mean)} s" if std is None else f"{_num(mean)} ± {_num(std)} s"


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[object]]) -> list[str]:
    """A Markdown table whose columns are padded to line up as plain text too."""
    cells = [[str(c) for c in header]] + [[str(c) for c in row] for row in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]

    def line(row: list[str]) -> str:
        return "| " + " | ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)) + " |"

    return [line(cells[0]), "|" + "|".join("-" * (w + 2) for w in widths) + "|"] + [
        line(r) for r in cells[1:]
    ]
