"""Formatting of the tables: numbers, prose paragraphs, Markdown tables, and
the order scenes and models are listed in."""

from __future__ import annotations

import textwrap

KNOWN_SCENES = ["pairs", "debris", "pile", "pile+shuffle", "chain"]
MODELS = ["rigid", "sphere", "particle"]
ISAS = ["sse2", "avx2", "avx512", "auto"]
LAYOUTS = ["soa", "packed", "records"]
ORDERS = ["input", "colour"]


def fmt_rate(value: float | None) -> str:
    """Millions per second, three significant figures or so."""
    if value is None:
        return ""
    if value >= 100:
        return f"{value:.0f}"
    if value >= 10:
        return f"{value:.1f}"
    return f"{value:.2f}"


def fmt_ratio(value: float | None, digits: int = 2) -> str:
    return "" if value is None else f"{value:.{digits}f}"


def fmt_err(value) -> str:
    if value is None:
        return "n/a"
    if value == 0:
        return "0"
    if value >= 1e4:
        return f"{value:.1e}"
    if value >= 100:
        return f"{value:.0f}"
    return f"{value:.2f}"


def fmt_n(n: int | None) -> str:
    if n is None:
        return ""
    if n >= 1 << 20 and n % (1 << 20) == 0:
        return f"{n >> 20}Mi"
    if n >= 1 << 10 and n % (1 << 10) == 0:
        return f"{n >> 10}Ki"
    return f"{n:,}"


def para(*text: str) -> list[str]:
    """One paragraph of prose, wrapped at 100 columns, then a blank line."""
    return textwrap.wrap(" ".join(text), width=100, break_on_hyphens=False, break_long_words=False) + [""]


def table(header: list[str], rows: list[list[str]], align: list[str] | None = None) -> list[str]:
    """A Markdown table; align is 'l' or 'r' per column (numbers right)."""
    if align is None:
        align = ["l"] * len(header)
    sep = ["---:" if a == "r" else "---" for a in align]
    out = ["| " + " | ".join(header) + " |", "| " + " | ".join(sep) + " |"]
    out += ["| " + " | ".join(r) + " |" for r in rows]
    return out


def drop_empty_columns(header, rows, align, keep=0):
    """Remove columns (after the first `keep`) that are empty in every row."""
    cols = [i for i in range(len(header)) if i < keep or any(r[i] not in ("", None) for r in rows)]
    return [header[i] for i in cols], [[r[i] for i in cols] for r in rows], [align[i] for i in cols]


def scene_order(scene: str) -> tuple:
    if scene in KNOWN_SCENES:
        return (0, KNOWN_SCENES.index(scene), scene)
    if scene == "file":
        return (2, 0, scene)
    return (1, 0, scene)


def model_order(model: str) -> int:
    return MODELS.index(model) if model in MODELS else len(MODELS)
