"""Reading tensile test curves: CSV files with stated units, and a manifest of specimens.

A curve file is a CSV with one displacement column and one force column whose units are in the
header, e.g. ``displacement [mm],force [N]`` or ``displacement_mm,force_N``; or the units are
given explicitly (``displacement_unit=``, ``force_unit=``). Geometry is never guessed: free
length, width and thickness come from the caller or a manifest CSV with the columns
``specimen,file,length_mm,width_mm,thickness_mm`` (paths relative to the manifest).

Everything is converted to SI (m, N) on the way in.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError

LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "in": 0.0254}
FORCE_UNITS = {"n": 1.0, "kn": 1e3, "mn": 1e-3, "gf": 9.80665e-3, "kgf": 9.80665, "lbf": 4.4482216152605}  # keys lower-case
_DISPLACEMENT_NAMES = ("displacement", "extension", "elongation", "disp", "position", "crosshead")
_FORCE_NAMES = ("force", "load")
_HEADER = re.compile(r"^\s*(?P<name>[A-Za-z][A-Za-z ]*?)\s*(?:\[(?P<u1>[^\]]*)\]|\((?P<u2>[^)]*)\)|_(?P<u3>[A-Za-zµ]+))?\s*$")


@dataclass(frozen=True)
class TensileCurve:
    """One force-displacement curve of a strip specimen, in SI units.

    Attributes
    ----------
    name : str
    displacement : ndarray
        Grip displacement, m, strictly increasing.
    force : ndarray
        Axial force, N.
    length, width, thickness : float
        Free length between the grips, width and wall thickness, m.
    """

    name: str
    displacement: np.ndarray
    force: np.ndarray
    length: float
    width: float
    thickness: float
    meta: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        check_geometry(self.name, self.length, self.width, self.thickness)

    @property
    def max_displacement(self) -> float:
        return float(self.displacement[-1])

    def force_at(self, displacement):
        """Experimental force linearly interpolated at ``displacement`` (m)."""
        d = np.asarray(displacement, dtype=float)
        if np.any(d > self.displacement[-1] * (1 + 1e-9)) or np.any(d < self.displacement[0] * (1 - 1e-9) - 1e-12):
            raise ColonsimError(
                f"{self.name}: asked for the force outside the measured displacement range "
                f"{self.displacement[0] * 1e3:.3g}-{self.displacement[-1] * 1e3:.3g} mm; "
                "choose simulation displacements inside it"
            )
        return np.interp(d, self.displacement, self.force)


def check_geometry(name, length, width, thickness):
    for label, value in (("length", length), ("width", width), ("thickness", thickness)):
        if value is None:
            raise ColonsimError(f"{name}: specimen {label} is missing; give it explicitly (e.g. --{label} in mm or a manifest column {label}_mm)")
        if not np.isfinite(value) or value <= 0:
            raise ColonsimError(f"{name}: specimen {label} must be a positive number, got {value!r}")


def _parse_header(col):
    m = _HEADER.match(col)
    if not m:
        return col.strip().lower(), None
    unit = m.group("u1") or m.group("u2") or m.group("u3")
    return m.group("name").strip().lower(), (unit.strip() if unit else None)


def _unit_factor(unit, table, quantity, path):
    try:
        return table[unit.strip().lower()]
    except KeyError:
        raise ColonsimError(
            f"{path}: unknown {quantity} unit {unit!r}; use one of {', '.join(table)} "
            "(in the header, e.g. 'displacement [mm]', 'force [N]', or via the unit option)"
        ) from None


def read_curve(path, length, width, thickness, name=None, displacement_unit=None, force_unit=None):
    """Read one tensile curve CSV and convert it to SI.

    Parameters
    ----------
    path : str or Path
    length, width, thickness : float
        Specimen geometry, m (required, never defaulted).
    name : str, optional
        Specimen name, default the file stem.
    displacement_unit, force_unit : str, optional
        Units when the header does not state them (``mm``, ``m``, ``N``, ``kN`` ...); when
        both the header and the option give a unit they must agree.
    """
    path = Path(path)
    name = name or path.stem
    check_geometry(name, length, width, thickness)
    if not path.is_file():
        raise ColonsimError(f"{path}: test data file not found; check the path")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise ColonsimError(f"{path}: not a text CSV file (could not decode as UTF-8); export the test as CSV") from None
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise ColonsimError(f"{path}: the file is empty; export the test curve with a header and data rows")
    try:
        dialect = csv.Sniffer().sniff(lines[0], delimiters=",;\t")
        delimiter = dialect.delimiter
    except csv.Error:
        delimiter = ","
    rows = list(csv.reader(lines, delimiter=delimiter))
    header = [c.strip() for c in rows[0]]
    if len(header) < 2:
        raise ColonsimError(
            f"{path}: not a CSV with displacement and force columns (found {len(header)} column); "
            "expected a header like 'displacement [mm],force [N]'"
        )
    parsed = [_parse_header(c) for c in header]
    d_col = next((i for i, (n, _) in enumerate(parsed) if n.startswith(_DISPLACEMENT_NAMES)), None)
    f_col = next((i for i, (n, _) in enumerate(parsed) if n.startswith(_FORCE_NAMES)), None)
    if d_col is None or f_col is None:
        missing = "displacement" if d_col is None else "force"
        raise ColonsimError(
            f"{path}: no {missing} column among {header}; name the columns e.g. 'displacement [mm]' and 'force [N]'"
        )
    units = {}
    for quantity, col, option, table in (("displacement", d_col, displacement_unit, LENGTH_UNITS),
                                         ("force", f_col, force_unit, FORCE_UNITS)):
        header_unit = parsed[col][1]
        if header_unit and option and header_unit.lower() != option.lower():
            raise ColonsimError(f"{path}: the header says {quantity} in {header_unit!r} but the option says {option!r}; drop one")
        unit = header_unit or option
        if unit is None:
            raise ColonsimError(
                f"{path}: the {quantity} unit is not stated; put it in the header ('{header[col]} [mm]') "
                f"or pass it explicitly (--{quantity}-unit)"
            )
        units[quantity] = _unit_factor(unit, table, quantity, path)
    data = rows[1:]
    if not data:
        raise ColonsimError(f"{path}: the file has a header but no data rows")
    try:
        d = np.array([float(r[d_col]) for r in data])
        f = np.array([float(r[f_col]) for r in data])
    except (ValueError, IndexError) as exc:
        bad = next(i for i, r in enumerate(data) if not _row_ok(r, d_col, f_col))
        raise ColonsimError(
            f"{path}: data row {bad + 1} is not numeric or is short ({exc}); fix or remove it"
        ) from None
    if not (np.all(np.isfinite(d)) and np.all(np.isfinite(f))):
        bad = int(np.flatnonzero(~(np.isfinite(d) & np.isfinite(f)))[0])
        raise ColonsimError(f"{path}: NaN or infinite value at data row {bad + 1}; remove the incomplete rows")
    if d.size < 3:
        raise ColonsimError(f"{path}: only {d.size} data rows; a tensile curve needs many points")
    steps = np.diff(d)
    if np.any(steps <= 0):
        bad = int(np.flatnonzero(steps <= 0)[0])
        raise ColonsimError(
            f"{path}: displacement is not strictly increasing at data row {bad + 2} "
            f"({d[bad]:g} then {d[bad + 1]:g}); keep only the loading branch and drop repeated samples"
        )
    return TensileCurve(name, d * units["displacement"], f * units["force"], float(length), float(width),
                        float(thickness), meta={"path": str(path)})


def _row_ok(row, d_col, f_col):
    try:
        float(row[d_col]), float(row[f_col])
        return True
    except (ValueError, IndexError):
        return False


def read_manifest(path, displacement_unit=None, force_unit=None):
    """Read every curve listed in a manifest CSV (``specimen,file,length_mm,width_mm,thickness_mm``)."""
    path = Path(path)
    if not path.is_file():
        raise ColonsimError(f"{path}: manifest not found; check the path")
    with path.open(newline="", encoding="utf-8-sig") as fh:
        reader = csv.DictReader(row for row in fh if not row.lstrip().startswith("#"))
        fields = [c.strip() for c in (reader.fieldnames or [])]
        required = ["specimen", "file", "length_mm", "width_mm", "thickness_mm"]
        missing = [c for c in required if c not in fields]
        if missing:
            raise ColonsimError(f"{path}: manifest lacks the column(s) {', '.join(missing)}; expected {','.join(required)}")
        rows = [{k.strip(): (v or "").strip() for k, v in r.items() if k} for r in reader]
    if not rows:
        raise ColonsimError(f"{path}: manifest lists no specimens")
    curves = []
    for r in rows:
        geometry = {}
        for key in ("length", "width", "thickness"):
            try:
                geometry[key] = float(r[f"{key}_mm"]) * 1e-3
            except ValueError:
                raise ColonsimError(f"{path}: specimen {r['specimen']!r} has a non-numeric {key}_mm {r[f'{key}_mm']!r}") from None
        curves.append(read_curve(path.parent / r["file"], name=r["specimen"], displacement_unit=displacement_unit,
                                 force_unit=force_unit, **geometry))
    return curves


def write_curve(path, curve: TensileCurve, comment=None):
    """Write a curve as CSV in mm and N (the units test machines export)."""
    path = Path(path)
    with path.open("w", newline="") as fh:
        if comment:
            for line in comment.splitlines():
                fh.write(f"# {line}\n")
        fh.write("displacement [mm],force [N]\n")
        for d, f in zip(curve.displacement, curve.force):
            fh.write(f"{d * 1e3:.4f},{f:.4f}\n")


def mean_curve(curves, step=0.25e-3, name="mean_curve") -> TensileCurve:
    """The mean force curve of several specimens (the source's way of fitting one parameter set).

    Every curve is linearly interpolated onto a common grid of ``step`` (m) up to the shortest
    curve's last displacement (no extrapolation) and averaged; the thickness is the mean
    thickness. All specimens must share length and width.
    """
    curves = list(curves)
    if not curves:
        raise ColonsimError("no curves to average")
    for c in curves[1:]:
        if not (np.isclose(c.length, curves[0].length) and np.isclose(c.width, curves[0].width)):
            raise ColonsimError(
                f"{c.name}: a mean curve needs specimens of equal length and width "
                f"({c.length * 1e3:g} x {c.width * 1e3:g} mm vs {curves[0].length * 1e3:g} x {curves[0].width * 1e3:g} mm); "
                "fit them separately with --per-specimen"
            )
    end = min(c.max_displacement for c in curves)
    grid = np.arange(step, end + 1e-12, step)
    if grid.size < 3:
        raise ColonsimError(f"the shortest curve ends at {end * 1e3:.3g} mm: too short to average on a {step * 1e3:g} mm grid")
    force = np.mean([np.interp(grid, c.displacement, c.force) for c in curves], axis=0)
    thickness = float(np.mean([c.thickness for c in curves]))
    return TensileCurve(name, grid, force, curves[0].length, curves[0].width, thickness,
                        meta={"averaged_specimens": [c.name for c in curves]})
