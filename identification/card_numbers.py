"""Numbers in fixed-width card fields (LS-DYNA's keyword format: eight fields of 10 characters).

LS-DYNA reads a field of a fixed-format card from its 10 columns and ignores what lies past
column 80; a free-format value longer than the field is cut as well. A number written at full
precision (``4.14917562129292e-05``, 20 characters) therefore reads as ``4.149175621``: wrong by
orders of magnitude. :func:`fixed_field` writes the most precise text of a number that fits the
field: the shortest text that reads back to the same float when one fits, else the candidate
(positional ``0.00041492`` or exponent ``4.14918e-5``) closest to the number.
"""

from __future__ import annotations

import math

from colonsim.errors import ColonsimError

FIELD_WIDTH = 10
LINE_WIDTH = 80


def _exponent_text(value, digits):
    mantissa, exponent = f"{value:.{digits - 1}e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _candidates(value, width):
    for digits in range(1, 18):
        yield _exponent_text(value, digits)
    for decimals in range(0, width):
        yield f"{value:#.{decimals}f}"


def fixed_field(value, width=FIELD_WIDTH) -> str:
    """``value`` as the most precise text of at most ``width`` characters.

    Raises
    ------
    ColonsimError
        A NaN or infinite value, which no card field holds.
    """
    x = float(value)
    if not math.isfinite(x):
        raise ColonsimError(f"{value!r} is not a finite number; a card field cannot hold it")
    if x == 0.0:
        return "0.0"
    fitting = {t for t in _candidates(x, width) if len(t) <= width and float(t) != 0.0}
    # closest first, then shortest; "1.0" rather than "1." (same precision, easier to read)
    return min(fitting, key=lambda t: (abs(float(t) - x), len(t) + t.endswith("."), t.endswith("."), t))


def fixed_row(values, width=FIELD_WIDTH) -> str:
    """One card line: each value right-aligned in its field (integers as written, floats by
    :func:`fixed_field`)."""
    cells = [str(v) if isinstance(v, int) else fixed_field(v, width) for v in values]
    for cell in cells:
        if len(cell) > width:
            raise ColonsimError(f"{cell!r} is wider than a {width}-character field")
    return "".join(cell.rjust(width) for cell in cells)


def fixed_fields(line, width=FIELD_WIDTH) -> list[str]:
    """The fields of a fixed-format line (columns of ``width``, nothing past column 80)."""
    line = line[:LINE_WIDTH]
    return [line[i:i + width].strip() for i in range(0, len(line), width)]
