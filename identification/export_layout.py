"""Finding the force-displacement table in a testing machine's export.

Machine software writes more than a table: a preamble of test parameters, a units row, results
after the data, a decimal comma, a Windows code page. The layouts read here follow public
descriptions of the common exports (and of open-source readers of them):

- Instron Bluehill 2/3: optional ``parameter, value, unit`` lines, a blank line, column names
  (``Time, Extension, Load``), units in a second row (``(s), (mm), (N)``); quoted numbers may
  carry thousands separators (``"1,234.5"``). Bluehill Universal puts results tables first.
- ZwickRoell testXpert: semicolon-separated with a decimal comma in German locales, names
  (``Standardkraft; Standardweg`` / ``Standard force; Standard travel``) then a units row.
- Shimadzu Trapezium: blank-line separated blocks: test header, test-piece table (names, units,
  values), then the data block with names (``Time, Force, Stroke``) and units rows.
- MTS TestSuite: ``Key: value`` lines, blank lines, names padded with spaces (``Axial Force``),
  a units row (``sec, mm, kN``); tab-separated when exported "for Excel".

The header is the first row naming a displacement and a force column that is followed (after an
optional units row) by a numeric row; everything above it is the preamble. The data end at the
first row that is not numeric; what follows is ignored as long as no further data rows come
(those mean a broken row inside the data, or a second curve in the same file: both errors).
"""

from __future__ import annotations

import codecs
import csv
import re
from dataclasses import dataclass, field

from colonsim.errors import ColonsimError
from colonsim.inputs import read_input
from colonsim.limits import TEXT_FILE_MAX_BYTES

DELIMITERS = ("\t", ";", ",")
_DISPLACEMENT_WORDS = ("disp", "extension", "elongation", "position", "crosshead", "stroke", "travel", "traverse",
                       "standardweg", "weg")
_FORCE_WORDS = ("force", "load", "kraft", "standardkraft", "prüfkraft", "pruefkraft")
# "Standard force", "Axial displacement", "Test force": the quantity is the word after these.
_QUALIFIERS = ("standard", "axial", "tensile", "test", "machine", "total", "measured")
# Columns that name a displacement or force word but hold something else.
_NOT_A_CURVE_COLUMN = ("rate", "speed", "velocity", "time", "strain", "stress", "energy", "work", "temperature", "cell")
_HEADER = re.compile(r"^\s*(?P<name>[^\W\d_][^\[\]()]*?)\s*(?:\[(?P<u1>[^\]]*)\]|\((?P<u2>[^)]*)\)|_(?P<u3>[A-Za-zµ]+)"
                     r"|\s/\s*(?P<u4>[A-Za-zµ]+))?\s*$")
_UNIT_TOKEN = re.compile(r"[^\W\d_%°][\w%°²³/.\-^ ]{0,11}|%")
# Numbers with a decimal point (thousands ",") or a decimal comma (thousands ".").
_POINT_NUMBER = re.compile(r"[+-]?(?:(?:[1-9]\d{0,2}(?:,\d{3})+|\d+)(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_COMMA_NUMBER = re.compile(r"[+-]?(?:(?:[1-9]\d{0,2}(?:\.\d{3})+|\d+)(?:,\d*)?|,\d+)(?:[eE][+-]?\d+)?")
_NON_FINITE = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)
_CONTROL = re.compile(r"[\x00-\x08\x0b\x0e-\x1f\x7f-\x9f]")
_LINE_BREAK = re.compile(r"\r\n|\r|\n")


@dataclass
class ExportTable:
    """The curve table of an export, as text cells, with where everything was found.

    Attributes
    ----------
    header : list of str
        Column names as written.
    units : list of str or None
        The units row under the header, when there is one.
    displacement_column, force_column : int
    rows : list of (line number, cells)
        The data rows, in file order (line numbers 1-based).
    preamble : list of (line number, cells)
        Rows above the header (comment lines included, without their ``#``).
    trailing : list of (line number, cells)
        Rows after the data, ignored (summary or results).
    encoding, delimiter, decimal : str
    """

    header: list
    units: list | None
    displacement_column: int
    force_column: int
    rows: list
    preamble: list
    trailing: list = field(default_factory=list)
    encoding: str = "utf-8"
    delimiter: str = ","
    decimal: str = "."
    header_line: int = 1

    def number(self, text):
        """A cell as a float (NaN/inf included), or None when it is not a number."""
        return parse_number(text, self.decimal)

    def describe(self) -> dict:
        """The layout as found, for provenance."""
        return {"encoding": self.encoding, "delimiter": {"\t": "tab", ";": "semicolon", ",": "comma"}[self.delimiter],
                "decimal_mark": self.decimal, "header_line": self.header_line,
                "units_row": self.units is not None, "data_lines": [self.rows[0][0], self.rows[-1][0]] if self.rows else None,
                "rows_after_data_ignored": len(self.trailing),
                "first_ignored_line": self.trailing[0][0] if self.trailing else None}


def parse_number(text, decimal="."):
    """``text`` as a float in the given decimal mark (thousands separators allowed), else None."""
    s = text.strip()
    if _NON_FINITE.fullmatch(s):
        return float(s)
    if decimal == "," and _COMMA_NUMBER.fullmatch(s):
        return float(s.replace(".", "").replace(",", "."))
    if decimal == "." and _POINT_NUMBER.fullmatch(s):
        return float(s.replace(",", ""))
    return None


def parse_column_name(text):
    """(lower-case name, unit or None) of a header cell like ``Load (N)``, ``force [N]``, ``force_N``."""
    m = _HEADER.match(text)
    if not m:
        return text.strip().lower(), None
    unit = m.group("u1") or m.group("u2") or m.group("u3") or m.group("u4")
    return m.group("name").strip().lower(), (unit.strip() if unit else None)


def _names(text, words):
    tokens = re.findall(r"[^\W\d_]+", parse_column_name(text)[0])
    if not tokens or any(t.startswith(_NOT_A_CURVE_COLUMN) for t in tokens):
        return False
    while len(tokens) > 1 and tokens[0] in _QUALIFIERS:
        tokens = tokens[1:]
    return tokens[0].startswith(words)


def curve_columns(header):
    """Indices (displacement, force) of the curve columns in ``header``; None where absent."""
    d = next((i for i, c in enumerate(header) if _names(c, _DISPLACEMENT_WORDS)), None)
    f = next((i for i, c in enumerate(header) if i != d and _names(c, _FORCE_WORDS)), None)
    return d, f


def unit_text(cell):
    """The unit in a units-row cell (``(mm)``, ``[N]``, ``sec``), '' if empty, None if not a unit."""
    s = cell.strip().strip("'\"").strip()
    if len(s) >= 2 and s[0] + s[-1] in ("()", "[]"):
        s = s[1:-1].strip()
    if not s:
        return ""
    return s if _UNIT_TOKEN.fullmatch(s) else None


def decode(raw: bytes, path) -> tuple[str, str]:
    """Text and encoding of an export: UTF-8 (with or without BOM), UTF-16 with BOM, else the
    Windows Western code page (Latin-1 for the bytes it leaves undefined)."""
    if raw.startswith((codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE)):
        candidates = ("utf-16",)
    else:
        candidates = ("utf-8-sig", "cp1252", "latin-1")
    for encoding in candidates:
        try:
            text = raw.decode(encoding)
            break
        except UnicodeDecodeError:
            continue
    else:
        raise ColonsimError(f"{path}: not a text CSV file (could not decode it); export the test as CSV")
    if _CONTROL.search(text):
        raise ColonsimError(f"{path}: not a text CSV file (it holds binary bytes); export the test as CSV or text")
    return text, {"utf-8-sig": "utf-8"}.get(encoding, encoding)


def split_row(line, delimiter):
    """Cells of one line (CSV quoting honoured, surrounding spaces dropped)."""
    try:
        cells = next(csv.reader([line], delimiter=delimiter, skipinitialspace=True), [])
    except csv.Error:  # e.g. a field beyond the csv module's size limit: not a table row
        cells = [line]
    return [c.strip() for c in cells]


def _numeric(cells, columns, decimal):
    return all(c < len(cells) and parse_number(cells[c], decimal) is not None for c in columns)


def _units_row(cells, d, f):
    return max(d, f) < len(cells) and all(unit_text(c) is not None for c in cells if c) and any(cells) \
        and all(parse_number(c) is None for c in cells if c)


def _decimal_mark(rows, columns):
    """',' when the cells read as decimal-comma numbers more often than as decimal-point ones."""
    point = comma = 0
    for cells in rows[:200]:
        for c in columns:
            s = cells[c].strip() if c < len(cells) else ""
            is_point, is_comma = bool(_POINT_NUMBER.fullmatch(s)), bool(_COMMA_NUMBER.fullmatch(s))
            point += is_point and not is_comma and "." in s
            comma += is_comma and not is_point and "," in s
    return "," if comma > point else "."


def read_text(path) -> tuple[str, str]:
    """Text and encoding of the file at ``path`` (see :func:`decode`)."""
    return decode(read_input(path, "test file", TEXT_FILE_MAX_BYTES), path)


def read_export(path) -> ExportTable:
    """Locate the curve table in the export at ``path`` (an existing file)."""
    text, encoding = read_text(path)
    content = [(n, ln) for n, ln in enumerate(_LINE_BREAK.split(text), start=1) if ln.strip()]
    if not [ln for _, ln in content if not ln.lstrip().startswith("#")]:
        raise ColonsimError(f"{path}: the file is empty; export the test curve with a header and data rows")
    found = _find_header(content)
    if found is None:
        raise _no_header_error(path, content)
    index, delimiter, header, d, f = found
    rows = [(n, split_row(ln, delimiter)) for n, ln in content[index + 1:] if not ln.lstrip().startswith("#")]
    units = None
    if rows and _units_row(rows[0][1], d, f):
        units, rows = rows[0][1], rows[1:]
    decimal = _decimal_mark([cells for _, cells in rows], range(len(header)))
    table = ExportTable(header, units, d, f, [], _preamble(content[:index], delimiter), encoding=encoding,
                        delimiter=delimiter, decimal=decimal, header_line=content[index][0])
    _collect_data(path, table, rows)
    return table


def _find_header(content):
    """(index in ``content``, delimiter, cells, displacement column, force column) of the data
    header: the first row naming both columns and followed by numbers, else the first naming both."""
    first = None
    for i, (_, line) in enumerate(content):
        if line.lstrip().startswith("#"):
            continue
        for delimiter in DELIMITERS:
            if delimiter not in line:
                continue
            cells = split_row(line, delimiter)
            d, f = curve_columns(cells)
            if d is None or f is None:
                continue
            candidate = (i, delimiter, cells, d, f)
            first = first or candidate
            following = [split_row(ln, delimiter) for _, ln in content[i + 1:i + 6] if not ln.lstrip().startswith("#")]
            if following and _units_row(following[0], d, f):
                following = following[1:]
            if following and (_numeric(following[0], (d, f), ".") or _numeric(following[0], (d, f), ",")):
                return candidate
    return first


def _no_header_error(path, content):
    """The error for a file without a recognisable header: name the row above the first numbers."""
    def cells_of(line):
        present = [dl for dl in DELIMITERS if dl in line]
        return max((split_row(line, dl) for dl in present), key=len) if present else [line.strip()]

    rows = [(n, cells_of(ln)) for n, ln in content if not ln.lstrip().startswith("#")]
    first_numbers = next((i for i, (_, cells) in enumerate(rows)
                          if sum(parse_number(c) is not None or parse_number(c, ",") is not None for c in cells) >= 2), None)
    above = [r for r in rows[:first_numbers] if r[1] and not all(unit_text(c) is not None for c in r[1] if c)] \
        if first_numbers else []
    (line, header), where = (above[-1], "the row above the first numbers") if above else (rows[0], "the first row")
    if len(header) < 2:
        return ColonsimError(
            f"{path}: not a CSV with displacement and force columns (found {len(header)} column at line {line}); "
            "expected a header like 'displacement [mm],force [N]'"
        )
    d, _ = curve_columns(header)
    missing = "displacement" if d is None else "force"
    return ColonsimError(
        f"{path}: no {missing} column among {header} (line {line}, {where}); "
        "name the columns e.g. 'displacement [mm]' and 'force [N]'"
    )


def _preamble(content, delimiter):
    """Rows above the header, split with the table's delimiter where they hold it."""
    rows = []
    for n, line in content:
        text = line.strip()
        if text.startswith("#"):
            rows.append((n, [text.lstrip("#").strip()]))
            continue
        present = [dl for dl in (delimiter, *DELIMITERS) if dl in text]
        rows.append((n, split_row(text, present[0]) if present else [text]))
    return rows


def _collect_data(path, table, rows):
    """Fill ``table.rows`` and ``table.trailing`` from the rows under the header."""
    d, f = table.displacement_column, table.force_column
    if not rows:
        raise ColonsimError(f"{path}: the file has a header but no data rows")
    first = rows[0][1]
    # Columns numeric in the first data row must stay numeric: a label there ("Mean", "Max")
    # marks a summary row, whatever numbers follow it.
    numeric = [c for c, cell in enumerate(first) if table.number(cell) is not None]

    def is_data(cells):
        return _numeric(cells, (d, f), table.decimal) and all(
            c >= len(cells) or not cells[c] or table.number(cells[c]) is not None for c in numeric)

    end = next((k for k, (_, cells) in enumerate(rows) if not is_data(cells)), len(rows))
    table.rows = rows[:end]
    if end == 0:
        line, cells = rows[0]
        raise ColonsimError(f"{path}: data row 1 is not numeric or is short (line {line}: {_shown(cells)}); "
                            "fix or remove it")
    second_header = None
    for line, cells in rows[end:]:
        if second_header is None and None not in curve_columns(cells):
            second_header = line
        elif is_data(cells):
            if second_header is not None:
                raise ColonsimError(f"{path}: holds a second curve (header at line {second_header}); "
                                    "export one specimen per file")
            bad_line, bad = rows[end]
            raise ColonsimError(f"{path}: data row {end + 1} is not numeric or is short (line {bad_line}: "
                                f"{_shown(bad)}); fix or remove it")
    table.trailing = rows[end:]


def _shown(cells, limit=60):
    text = repr(" | ".join(cells))
    return text if len(text) <= limit else text[:limit] + "...'"
