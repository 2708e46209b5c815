"""Specimen geometry stated in an export's preamble: width, thickness and free length.

Exports write test parameters as ``key, value[, unit]`` rows (``"Width (mm)","25.0"``,
``Width,25.00,mm``, Bluehill's ``Specimen : Width,25.00,mm``), as ``Key: value unit`` lines
(``Thickness: 1.8 mm``), or as a small table (names row, optional units row, one values row:
Trapezium's test-piece block). Every spelling below is matched on the words of the key,
case-insensitive; the unit comes from the key (``(mm)``, ``[mm]``), a unit cell or the value.

The free length between the grips is what the specimen model needs: a grip separation or
clamping length is preferred to a gauge length (which may be an extensometer's).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from colonsim.errors import ColonsimError
from colonsim.identification.export_layout import parse_column_name, parse_number, unit_text

QUANTITIES = ("length", "width", "thickness")
# Keys naming a value at some event of the test, or another instrument's length.
_NOT_SPECIMEN = ("break", "max", "maximum", "final", "end", "change", "rate", "speed", "extensometer", "area",
                 "strain", "force", "load")
_VALUE = re.compile(r"\s*(?P<number>[+-]?[\d.,]+(?:[eE][+-]?\d+)?)\s*(?P<unit>[^\W\d_][\w/%.²³]*)?\s*")
_KEY_VALUE = re.compile(r"\s*(?P<key>[^:=]*[^\W\d_][^:=]*?)\s*[:=]\s*(?P<value>.+)")


@dataclass(frozen=True)
class StatedValue:
    """One geometry value found in the preamble (in its stated unit)."""

    quantity: str
    value: float | None
    unit: str | None
    key: str
    line: int
    rank: int  # lower is preferred: grip separation (0) before gauge length (1)
    note: str = ""

    def shown(self) -> str:
        return f"{self.key!r} = {self.value:g}{' ' + self.unit if self.unit else ''} (line {self.line})"

    def metres(self, path, length_units) -> float:
        """The value in m; an error names the line when it cannot be used."""
        if self.value is None:
            raise ColonsimError(f"{path}: the preamble's {self.key!r} (line {self.line}) {self.note}; "
                                f"pass the {self.quantity} explicitly (--{self.quantity} in mm)")
        if not self.unit:
            raise ColonsimError(f"{path}: the preamble gives {self.key!r} = {self.value:g} (line {self.line}) without a "
                                f"unit; state it (e.g. '{self.key} (mm)') or pass --{self.quantity} in mm")
        try:
            return self.value * length_units[self.unit.lower()]
        except KeyError:
            raise ColonsimError(f"{path}: the preamble's {self.key!r} (line {self.line}) is in {self.unit!r}, not a "
                                f"length unit ({', '.join(length_units)}); fix it or pass --{self.quantity} in mm") from None


def quantity_of(key):
    """(quantity, rank) a preamble key names, or None."""
    name, _ = parse_column_name(key.split(" : ")[-1])
    words = re.findall(r"[^\W\d_]+", name)
    if not words or any(w in _NOT_SPECIMEN for w in words):
        return None
    if any(w in ("thickness", "dicke", "probendicke") for w in words):
        return "thickness", 0
    if any(w in ("width", "breite", "probenbreite") for w in words):
        return "width", 0
    lengthy = any(w in ("length", "distance", "separation") for w in words)
    if ("grip" in words or "clamping" in words or "clamp" in words or "free" in words) and lengthy \
            or "einspannlänge" in words:
        return "length", 0
    if ("gauge" in words or "gage" in words) and "length" in words or "messlänge" in words:
        return "length", 1
    return None


def _number(text, decimal):
    other = "," if decimal == "." else "."
    value = parse_number(text, decimal)
    return value if value is not None else parse_number(text, other)


def _value_and_unit(text, decimal):
    m = _VALUE.fullmatch(text)
    if not m:
        return None, None
    return _number(m.group("number"), decimal), m.group("unit")


def _key_value_rows(rows, decimal):
    for line, cells in rows:
        cells = [c for c in cells if c]
        if len(cells) == 1:
            m = _KEY_VALUE.fullmatch(cells[0])
            if not m:
                continue
            key, (value, unit) = m.group("key"), _value_and_unit(m.group("value"), decimal)
        elif len(cells) >= 2:
            key, (value, unit) = cells[0].rstrip(":").strip(), _value_and_unit(cells[1], decimal)
            if unit is None and len(cells) >= 3 and unit_text(cells[2]):
                unit = unit_text(cells[2])
        else:
            continue
        found = quantity_of(key)
        if found is None or value is None:
            continue
        unit = parse_column_name(key.split(" : ")[-1])[1] or unit
        yield StatedValue(found[0], value, unit, key, line, found[1])


def _table_rows(rows, decimal):
    """Values of a names row + optional units row + values rows (consecutive lines)."""
    for i, (line, cells) in enumerate(rows):
        columns = {c: quantity_of(cell) for c, cell in enumerate(cells) if cell and _number(cell, decimal) is None}
        columns = {c: q for c, q in columns.items() if q}
        if not columns:
            continue
        j, units, expected = i + 1, None, line + 1
        if j < len(rows) and rows[j][0] == expected and all(unit_text(c) is not None for c in rows[j][1] if c) \
                and all(_number(c, decimal) is None for c in rows[j][1] if c):
            units, j, expected = rows[j][1], j + 1, expected + 1
        values = []
        while j < len(rows) and rows[j][0] == expected and all(
                c < len(rows[j][1]) and _number(rows[j][1][c], decimal) is not None for c in columns):
            values.append(rows[j][1])
            j, expected = j + 1, expected + 1
        for c, (quantity, rank) in columns.items():
            if not values:
                continue
            unit = parse_column_name(cells[c])[1] or (unit_text(units[c]) if units and c < len(units) else None)
            if len(values) == 1:
                yield StatedValue(quantity, _number(values[0][c], decimal), unit or None, cells[c], line, rank)
            else:
                yield StatedValue(quantity, None, unit or None, cells[c], line, rank,
                                  note=f"lists {len(values)} test pieces")


def stated_geometry(preamble, decimal=".") -> dict:
    """Geometry values in the preamble rows ``[(line, cells), ...]``: quantity -> values, best first."""
    found = [*_key_value_rows(preamble, decimal), *_table_rows(preamble, decimal)]
    return {q: sorted((v for v in found if v.quantity == q), key=lambda v: (v.rank, v.line))
            for q in QUANTITIES if any(v.quantity == q for v in found)}
