"""The commands' text tables: numbers to six significant digits, units as people write them, columns."""

from __future__ import annotations


def text_unit(name: str) -> str:
    """A unit name for text tables: N·m, kg·m², m/s²."""
    return name.replace("*", "·").replace("^2", "²")


def num(v) -> str:
    return f"{v:.6g}"


def clean(v, tiny):
    """Round-off below `tiny` printed as 0."""
    return 0.0 if abs(v) < tiny else v


def print_columns(head, rows):
    """A text table: the first column left-aligned, the others right-aligned, two spaces apart."""
    widths = [max(len(str(r[k])) for r in [head] + rows) for k in range(len(head))]
    for r in [head] + rows:
        print("  ".join(str(c).ljust(w) if k == 0 else str(c).rjust(w) for k, (c, w) in enumerate(zip(r, widths))))


def dumps(doc, **options) -> str:
    """json.dumps, with json imported by the commands that print JSON only."""
    import json
    return json.dumps(doc, **options)
