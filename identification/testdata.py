"""Reading tensile test curves: CSV files and testing machines' exports, and a manifest of specimens.

A curve file holds one displacement column and one force column whose units are stated: in the
header (``displacement [mm],force [N]``, ``Extension (mm)``, ``force_N``), in a units row under
it, or given explicitly (``displacement_unit=``, ``force_unit=``). Exports with a preamble of
test parameters, a units row, a decimal comma, tabs or semicolons, a Windows code page and
summary rows after the data are read as written (:mod:`colonsim.identification.export_layout`).

Geometry is never guessed: free length, width and thickness come from the caller, a manifest CSV
(``specimen,file,length_mm,width_mm,thickness_mm``, paths relative to the manifest) or the
file's own preamble (:mod:`colonsim.identification.export_geometry`); a value given wins over the
preamble's, and a disagreement is reported.

Everything is converted to SI (m, N) on the way in.
"""

from __future__ import annotations

import csv
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.inputs import check_input
from colonsim.limits import TEXT_FILE_MAX_BYTES
from colonsim.schemas import check_listed_once, check_manifest_columns
from colonsim.identification.export_geometry import stated_geometry
from colonsim.identification.export_layout import parse_column_name, read_export, read_text, unit_text

LENGTH_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "in": 0.0254}
FORCE_UNITS = {"n": 1.0, "kn": 1e3, "mn": 1e-3, "gf": 9.80665e-3, "kgf": 9.80665, "lbf": 4.4482216152605}  # keys lower-case
_PREAMBLE_KEPT = 200  # preamble lines copied into provenance; beyond this a file is not a preamble


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
        check_tension(self.name, self.force)

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


class CurveWarning(UserWarning):
    """Something in a curve file the user should know about (the reading went on)."""


def check_geometry(name, length, width, thickness):
    for label, value in (("length", length), ("width", width), ("thickness", thickness)):
        if value is None:
            raise ColonsimError(f"{name}: specimen {label} is missing; give it explicitly (--{label} in mm, a manifest "
                                f"column {label}_mm, or a preamble line in the file such as '{label.capitalize()} (mm),2.0')")
        check_length(name, label, value)


def check_length(name, label, value):
    """A geometry value (m) must be finite and positive; the message quotes it in mm, as typed."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)) or not np.isfinite(value) or value <= 0:
        shown = f"{value * 1e3:g} mm" if isinstance(value, (int, float, np.floating)) else repr(value)
        raise ColonsimError(f"{name}: specimen {label} must be a positive number of mm, got {shown}")


def check_tension(name, force):
    """A tensile curve pulls: refuse forces that are zero throughout or mostly negative."""
    f = np.asarray(force, dtype=float)
    if f.size and not np.any(f):
        raise ColonsimError(f"{name}: the force is zero throughout; check that the force column holds the load "
                            "(and its unit)")
    if f.size and -f.min() > f.max():
        raise ColonsimError(
            f"{name}: the forces are compressive (down to {f.min():.4g} N, at most {f.max():.4g} N); a tensile test "
            "pulls the strip: if the machine records tension as negative, negate the force column")


def check_input_file(path, what):
    """``path`` must be an existing regular file: say which of missing/folder it is."""
    check_input(path, what, TEXT_FILE_MAX_BYTES)


def _unit_factor(unit, table, quantity, path):
    try:
        return table[unit.strip().lower()]
    except KeyError:
        raise ColonsimError(
            f"{path}: unknown {quantity} unit {unit!r}; use one of {', '.join(table)} "
            "(in the header, e.g. 'displacement [mm]', 'force [N]', or via the unit option)"
        ) from None


def _column_unit(path, table, col, option, quantity, units_table):
    """The factor to SI of a curve column, from its header, the units row or the option."""
    header_unit = parse_column_name(table.header[col])[1]
    row_unit = unit_text(table.units[col]) if table.units and col < len(table.units) else None
    stated = [u for u in (header_unit, row_unit) if u]
    if len({u.lower() for u in stated}) > 1:
        raise ColonsimError(f"{path}: the header says {quantity} in {header_unit!r} but the units row says {row_unit!r}; "
                            "fix one")
    file_unit = stated[0] if stated else None
    if file_unit and option and file_unit.lower() != option.lower():
        raise ColonsimError(f"{path}: the header says {quantity} in {file_unit!r} but the option says {option!r}; drop one")
    unit = file_unit or option
    if unit is None:
        raise ColonsimError(
            f"{path}: the {quantity} unit is not stated; put it in the header ('{table.header[col]} [mm]') "
            f"or pass it explicitly (--{quantity}-unit)"
        )
    return _unit_factor(unit, units_table, quantity, path), unit


def _resolve_geometry(path, given, stated, given_as):
    """Geometry (m) and where each value came from: the caller's value wins over the preamble's,
    and a disagreement between them is reported as a :class:`CurveWarning`."""
    geometry, sources = {}, {}
    for quantity in ("length", "width", "thickness"):
        values = stated.get(quantity, [])
        best = [v for v in values if v.rank == values[0].rank] if values else []
        value = given.get(quantity)
        if value is not None:
            geometry[quantity], sources[quantity] = value, given_as.format(quantity)
            try:
                in_file = best[0].metres(path, LENGTH_UNITS) if best else None
            except ColonsimError:
                in_file = None
            if in_file is not None and not np.isclose(in_file, value, rtol=1e-6, atol=0.0):
                warnings.warn(f"{path}: {given_as.format(quantity)} {value * 1e3:g} mm disagrees with the file's "
                              f"{best[0].shown()}; using {value * 1e3:g} mm", CurveWarning, stacklevel=3)
        elif best:
            metres = [v.metres(path, LENGTH_UNITS) for v in best]
            if not np.allclose(metres, metres[0], rtol=1e-6, atol=0.0):
                raise ColonsimError(f"{path}: the preamble gives the {quantity} differently: "
                                    f"{'; '.join(v.shown() for v in best)}; pass --{quantity} in mm")
            geometry[quantity], sources[quantity] = metres[0], f"preamble {best[0].shown()}"
    return geometry, sources


def read_curve(path, length=None, width=None, thickness=None, name=None, displacement_unit=None, force_unit=None,
               given_as="{} given"):
    """Read one tensile curve (a CSV or a testing machine's export) and convert it to SI.

    Parameters
    ----------
    path : str or Path
    length, width, thickness : float, optional
        Specimen geometry, m. A value not given is taken from the file's preamble when it states
        it (``Width (mm),25.0``, ``Grip separation: 100 mm``, ...); one given wins over the
        preamble, with a :class:`CurveWarning` when they disagree. Never defaulted.
    name : str, optional
        Specimen name, default the file stem.
    displacement_unit, force_unit : str, optional
        Units when the file does not state them (``mm``, ``m``, ``N``, ``kN`` ...); when
        both the file and the option give a unit they must agree.
    given_as : str
        How the given geometry is named in messages, ``{}`` standing for the quantity.
    """
    path = Path(path)
    name = name or path.stem
    given = {"length": length, "width": width, "thickness": thickness}
    for label, value in given.items():
        if value is not None:
            check_length(name, label, value)
    check_input_file(path, "test data file")
    table = read_export(path)
    d_col, f_col = table.displacement_column, table.force_column
    d_factor, d_unit = _column_unit(path, table, d_col, displacement_unit, "displacement", LENGTH_UNITS)
    f_factor, f_unit = _column_unit(path, table, f_col, force_unit, "force", FORCE_UNITS)
    lines = [line for line, _ in table.rows]
    d = np.array([table.number(cells[d_col]) for _, cells in table.rows])
    f = np.array([table.number(cells[f_col]) for _, cells in table.rows])
    with np.errstate(over="ignore"):  # a value beyond float range in SI is as unusable as NaN
        finite = np.isfinite(d * d_factor) & np.isfinite(f * f_factor)
    if not np.all(finite):
        bad = int(np.flatnonzero(~finite)[0])
        raise ColonsimError(f"{path}: NaN or infinite value at data row {bad + 1} (line {lines[bad]}); "
                            "remove the incomplete rows")
    if d.size < 3:
        raise ColonsimError(f"{path}: only {d.size} data rows; a tensile curve needs many points")
    steps = np.diff(d)
    if np.any(steps <= 0):
        bad = int(np.flatnonzero(steps <= 0)[0])
        raise ColonsimError(
            f"{path}: displacement is not strictly increasing at data row {bad + 2} (line {lines[bad + 1]}) "
            f"({d[bad]:g} then {d[bad + 1]:g}); keep only the loading branch and drop repeated samples"
        )
    geometry, sources = _resolve_geometry(path, given, stated_geometry(table.preamble, table.decimal), given_as)
    check_geometry(name, *(geometry.get(q) for q in ("length", "width", "thickness")))
    meta = {"path": str(path), "geometry_from": sources, "units": {"displacement": d_unit, "force": f_unit},
            "layout": table.describe()}
    if table.preamble:
        meta["preamble"] = [",".join(cells) for _, cells in table.preamble[:_PREAMBLE_KEPT]]
    return TensileCurve(name, d * d_factor, f * f_factor, geometry["length"], geometry["width"], geometry["thickness"],
                        meta=meta)


def read_manifest(path, displacement_unit=None, force_unit=None):
    """Read every curve listed in a manifest CSV (``specimen,file,length_mm,width_mm,thickness_mm``)."""
    path = Path(path)
    check_input_file(path, "manifest")
    text, _ = read_text(path)
    reader = csv.DictReader(row for row in text.splitlines() if not row.lstrip().startswith("#"))
    check_manifest_columns(reader.fieldnames or [], path, ("specimen", "file", "length_mm", "width_mm", "thickness_mm"), ())
    rows = [{k.strip(): (v or "").strip() for k, v in r.items() if isinstance(k, str)} for r in reader]
    if not rows:
        raise ColonsimError(f"{path}: manifest lists no specimens")
    seen = set()
    for r in rows:  # a specimen's name is its results folder (--per-specimen)
        name = r["specimen"]
        if not name or name in (".", "..") or any(c in name for c in "/\\"):
            raise ColonsimError(f"{path}: specimen name {name!r} cannot name a results folder; give a name without "
                                "slashes")
        if name in seen:
            raise ColonsimError(f"{path}: specimen {name!r} is listed twice (its results would overwrite each other); "
                                "give every row its own name")
        seen.add(name)
    check_listed_once([(r["specimen"], (path.parent / r["file"]).resolve()) for r in rows], path)
    curves = []
    for r in rows:
        geometry = {}
        for key in ("length", "width", "thickness"):
            text = r[f"{key}_mm"]
            try:  # an empty cell leaves the value to the curve file's preamble
                geometry[key] = float(text) * 1e-3 if text else None
            except ValueError:
                raise ColonsimError(f"{path}: specimen {r['specimen']!r} has a non-numeric {key}_mm {text!r}") from None
        curves.append(read_curve(path.parent / r["file"], name=r["specimen"], displacement_unit=displacement_unit,
                                 force_unit=force_unit, given_as=f"{path.name} {{}}_mm", **geometry))
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
                        meta={"averaged_specimens": [c.name for c in curves],
                              "sources": [r for c in curves for r in source_records(c)]})


def source_records(curve) -> list[dict]:
    """What the file(s) behind ``curve`` said beyond the table, for provenance: path, where the
    geometry came from, units, layout and preamble (one record per file of a mean curve)."""
    if "sources" in curve.meta:
        return list(curve.meta["sources"])
    keys = ("path", "geometry_from", "units", "layout", "preamble", "cleaning")
    return [{"specimen": curve.name, **{k: curve.meta[k] for k in keys if k in curve.meta}}] if "path" in curve.meta else []
