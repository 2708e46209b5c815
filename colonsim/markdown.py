"""Markdown tables for the generated reports (``colonsim demo``, ``validation/report.py``)."""

from __future__ import annotations

import math

import numpy as np

NOT_RUN = "**NOT RUN**"  # a report section whose sweep or input was not given


def percent(v, spec="+.2g"):
    """A signed share as a percentage, '-' for None/NaN: ``percent(0.052)`` is '+5.2 %'."""
    if v is None or not math.isfinite(v):
        return "-"
    return f"{100 * v:{spec}} %"


def num(v, digits=4):
    """A number for a table: 4 significant digits, '-' for None/NaN."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e5):
        return f"{v:.{digits - 1}e}"
    return f"{v:.{digits}g}"


def md_table(rows, columns, fmt=num):
    """Markdown table of ``rows`` (dicts); ``columns`` = [(header, key or callable(row))]; cells
    that are not strings are written by ``fmt``."""
    lines = ["| " + " | ".join(h for h, _ in columns) + " |", "|" + "---|" * len(columns)]
    for r in rows:
        cells = []
        for _, key in columns:
            v = key(r) if callable(key) else r.get(key)
            cells.append(v if isinstance(v, str) else fmt(v))
        lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(lines)


def frame_table(frame, fmt=num):
    """Markdown table of every column of a pandas DataFrame."""
    return md_table(frame.to_dict("records"), [(c, c) for c in frame.columns], fmt)
