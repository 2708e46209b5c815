"""Reader of a patient's centerline CSV (docs/model.md, "A patient's centerline").

Format: a comma-separated text file (or semicolon- or tab-separated, whose numbers may then have
a decimal comma, as spreadsheets in German or French locales save them); lines starting with
``#`` are comments (say where the points come from), blank lines are skipped. The first other line is the header; the units are
part of the column names:

========================  =========================================================================
column                    content
========================  =========================================================================
``x_mm, y_mm, z_mm``      required: the centerline points in mm, in the order the scope meets them
                          (the first point is the anus end: the scope's sheath sits there)
``label``                 required: ``fixed`` (held: retroperitoneal) or ``mobile`` (free:
                          intraperitoneal). A blank cell continues the label above, so a label at
                          the first point of each range is enough; the first row must have one
``diameter_mm``           optional: lumen (inner) diameter at the point, mm; blank cells are
                          interpolated linearly along the points (constant beyond the first and
                          last given value)
``name``                  optional: name of the range (``sigmoid``), continued from above like
                          ``label``; default ``"<label> <k>"`` for the k-th range (``fixed 1``)
========================  =========================================================================

A range is a run of consecutive points with the same label and name; it starts at its first
point. Other columns are refused (a misspelt ``diamter_mm`` would otherwise be ignored). Every
error is one line naming the file line, the problem and the fix.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import re
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.inputs import check_input, read_input_text
from colonsim.limits import TEXT_FILE_MAX_BYTES

MIN_POINTS = 5  # scipy's cubic smoothing spline needs 5 points
DUPLICATE_MM = 1e-3  # consecutive points closer than 1 um repeat a point (chord-length parameter 0)
DIAMETER_RANGE_MM = (5.0, 120.0)  # a lumen narrower than 5 mm holds no scope; 120 mm is beyond any colon
COORDINATE_LIMIT_MM = 1e4  # 10 m: a larger coordinate is a unit slip (um or nm written as mm)
MIN_EXTENT_MM = 20.0  # points spanning less are no colon: a centerline in metres (0.2 for 20 cm) written as mm
COORDINATES = ("x_mm", "y_mm", "z_mm")
OPTIONAL = ("diameter_mm", "name")
LABELS = ("fixed", "mobile")
_UNIT_SUFFIX = re.compile(r"^([xyz])\s*(?:[_ ]\s*|\[|\()\s*([a-zµ]+)\s*[\])]?$")


@dataclass(frozen=True)
class CenterlinePoints:
    """The points of a centerline file as read (mm, per point; ``lines`` = file line numbers)."""

    path: str
    points_mm: np.ndarray  # (n, 3)
    labels: tuple  # per point, "fixed" or "mobile"
    names: tuple  # per point, the range name
    diameters_mm: np.ndarray | None  # (n,) with blanks interpolated, or None without the column
    lines: tuple  # file line of each point

    def digest(self) -> str:
        """SHA-256 of what was read (points, labels, names, diameters): the same for the same
        content whatever the comments, line endings or number formatting."""
        doc = {"points_mm": self.points_mm.tolist(), "labels": list(self.labels), "names": list(self.names),
               "diameters_mm": None if self.diameters_mm is None else self.diameters_mm.tolist()}
        return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()

    def where(self, i) -> str:
        return f"{self.path} line {self.lines[i]}"


def _header(cells, path, line):
    names = [c.strip().lower() for c in cells]
    for c in names:
        m = _UNIT_SUFFIX.match(c)
        if c in ("x", "y", "z") or (m and c not in COORDINATES):
            unit = f" in {m.group(2)}" if m else " without a unit"
            raise ColonsimError(f"{path} line {line}: column {c!r} gives a coordinate{unit}; colonsim reads "
                                "millimetres: name the columns x_mm, y_mm, z_mm (convert the values to mm if needed)")
    missing = [c for c in (*COORDINATES, "label") if c not in names]
    if missing:
        raise ColonsimError(f"{path} line {line}: no column {', '.join(missing)}; the header needs x_mm, y_mm, z_mm "
                            "and label (optional: diameter_mm, name)")
    unknown = [c for c in names if c not in (*COORDINATES, "label", *OPTIONAL)]
    if unknown or len(set(names)) != len(names):
        what = f"unknown column {unknown[0]!r}" if unknown else "a column appears twice"
        raise ColonsimError(f"{path} line {line}: {what}; use x_mm, y_mm, z_mm, label, diameter_mm, name")
    return names


def _number(text, column, path, line, decimal="."):
    if decimal == "," and "," in text and "." not in text:
        text = text.replace(",", ".")
    try:
        value = float(text)
    except ValueError:
        raise ColonsimError(f"{path} line {line}: {column} = {text!r} is not a number; give a number in mm") from None
    if not math.isfinite(value):
        raise ColonsimError(f"{path} line {line}: {column} = {text!r} is not a finite number; give a number in mm")
    return value


def _rows(path: Path):
    """(line number, cells) of the header and each data row, and the decimal mark: a header
    split by semicolons (or tabs) rather than commas leaves the comma to decimals, as a spreadsheet
    in a German or French locale saves it."""
    text = read_input_text(path, "centerline file", TEXT_FILE_MAX_BYTES, fallbacks=("cp1252",))
    lines = text.splitlines()
    header = next((ln for ln in lines if ln.strip() and not ln.lstrip().startswith("#")), "")
    delimiter = max((",", ";", "\t"), key=header.count)
    rows = []
    for number, cells in zip(range(1, len(lines) + 1), csv.reader(lines, delimiter=delimiter)):
        if not cells or all(not c.strip() for c in cells) or cells[0].lstrip().startswith("#"):
            continue
        rows.append((number, cells))
    if not rows:
        raise ColonsimError(f"centerline file {path} holds no header; the first line must name the columns "
                            "x_mm, y_mm, z_mm, label")
    return rows, "." if delimiter == "," else ","


def read_centerline_points(path) -> CenterlinePoints:
    """Read and check a centerline CSV (module docstring); raise :class:`ColonsimError` on bad input."""
    path = Path(path)
    ((header_line, header), *data), decimal = _rows(path)
    columns = _header(header, path, header_line)
    points, labels, names, diameters, lines = [], [], [], [], []
    label = name = None
    for line, cells in data:
        if len(cells) > len(columns) and any(c.strip() for c in cells[len(columns):]):
            raise ColonsimError(f"{path} line {line}: {len(cells)} cells for {len(columns)} columns; "
                                "remove the extra cells or name their column")
        row = dict(zip(columns, (c.strip() for c in cells)))
        row.update({c: "" for c in columns if c not in row})
        points.append([_number(row[c], c, path, line, decimal) for c in COORDINATES])
        if any(abs(v) > COORDINATE_LIMIT_MM for v in points[-1]):
            raise ColonsimError(f"{path} line {line}: a coordinate beyond {COORDINATE_LIMIT_MM:g} mm; give the "
                                "coordinates in mm")
        given = row["label"].lower()
        if given:
            if given not in LABELS:
                raise ColonsimError(f"{path} line {line}: label {row['label']!r} is not fixed or mobile; write fixed "
                                    "(retroperitoneal, held) or mobile (free), or leave it blank to continue the "
                                    "label above")
            label = given
        elif label is None:
            raise ColonsimError(f"{path} line {line}: the first point has no label; write fixed or mobile")
        labels.append(label)
        if row.get("name"):
            name = row["name"]
        names.append(name)
        if "diameter_mm" in columns:
            diameters.append(math.nan if not row["diameter_mm"]
                             else _number(row["diameter_mm"], "diameter_mm", path, line, decimal))
            low, high = DIAMETER_RANGE_MM
            if not (math.isnan(diameters[-1]) or low <= diameters[-1] <= high):
                raise ColonsimError(f"{path} line {line}: diameter_mm = {diameters[-1]:g} is outside "
                                    f"{low:g}-{high:g} mm; give the lumen diameter in mm")
        lines.append(line)
    if len(points) < MIN_POINTS:
        raise ColonsimError(f"{path}: {len(points)} point(s); a centerline needs at least {MIN_POINTS} "
                            "(a cubic smoothing spline), give more points")
    p = np.array(points)
    extent = float(np.ptp(p, axis=0).max())
    if extent < MIN_EXTENT_MM:
        raise ColonsimError(f"{path}: the points span {extent:.3g} mm, no colon is that small; the _mm columns take "
                            f"millimetres (coordinates in metres? multiply them by 1000)")
    gaps = np.linalg.norm(np.diff(p, axis=0), axis=1)
    if np.any(gaps < DUPLICATE_MM):
        i = int(np.argmax(gaps < DUPLICATE_MM))
        raise ColonsimError(f"{path} lines {lines[i]} and {lines[i + 1]} repeat the same point; delete one of them")
    if "mobile" not in labels:
        raise ColonsimError(f"{path}: no point is labelled mobile, so nothing can deform; label the free "
                            "(intraperitoneal) range, e.g. the sigmoid, mobile")
    return CenterlinePoints(str(path), p, tuple(labels), _range_names(labels, names),
                            _fill_diameters(diameters, p, path) if "diameter_mm" in columns else None, tuple(lines))


def _range_names(labels, names):
    """Each point's range name: the given one, or ``"<label> <k>"`` for the k-th range without one."""
    out, k, previous = [], 0, None
    for label, name in zip(labels, names):
        if (label, name) != previous:
            k += 1
            previous = (label, name)
            default = f"{label} {k}"
        out.append(name if name is not None else default)
    return tuple(out)


def _fill_diameters(diameters, points, path):
    d = np.array(diameters, dtype=float)
    given = ~np.isnan(d)
    if not given.any():
        raise ColonsimError(f"{path}: the diameter_mm column is empty; give at least one diameter or drop the column")
    chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    return np.interp(chord, chord[given], d[given])


@lru_cache(maxsize=64)
def _cached(resolved: str, mtime_ns: int, size: int) -> CenterlinePoints:
    return read_centerline_points(resolved)


def load_centerline_points(path) -> CenterlinePoints:
    """:func:`read_centerline_points`, cached per file state (path, modification time, size)."""
    path = check_input(Path(path).expanduser(), "centerline file", TEXT_FILE_MAX_BYTES)
    stat = path.stat()
    return _cached(str(path), stat.st_mtime_ns, stat.st_size)
