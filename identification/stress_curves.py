"""Stress-stretch curves of the three test modes, and the manifest that lists them.

A curve file is a CSV table (``#`` comment lines allowed) with one deformation column and one
stress column, both named with what they are:

- deformation: ``stretch`` (l) or ``strain`` (engineering strain l - 1; ``strain [%]`` in per cent);
- stress: ``nominal_stress [unit]`` (force per undeformed area, first Piola) or
  ``cauchy_stress [unit]`` / ``true_stress [unit]`` (force per deformed area), unit one of
  :data:`STRESS_UNITS`, in brackets or after an underscore (``nominal_stress_MPa``). A column
  named only ``stress`` takes its measure from the option (``--stress-measure``); the measure is
  never guessed.

Cauchy stress becomes nominal stress by ``P = sigma / l`` in all three modes (the loaded
direction's cross-section shrinks by ``l`` in each: uniaxial, equibiaxial and planar alike, J = 1).

A mode manifest is a CSV ``specimen,file,mode`` with optional ``weight`` and the geometry columns
``length_mm,width_mm,thickness_mm``; any other column (a misspelt ``weight``) is refused naming the
one likely meant, and a file or specimen listed twice is refused (it would weigh double). A file holding a force-displacement curve of a strip (read by
:func:`colonsim.identification.testdata.read_curve`) needs its geometry and is a uniaxial test.
"""

from __future__ import annotations

import csv
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.schemas import check_listed_once, check_manifest_columns
from colonsim.identification.export_layout import read_text
from colonsim.identification.hyperelastic import MODES
from colonsim.identification.testdata import TensileCurve, check_input_file, read_curve

MODE_MANIFEST_REQUIRED = ("specimen", "file", "mode")
MODE_MANIFEST_OPTIONAL = ("weight", "length_mm", "width_mm", "thickness_mm")
STRESS_UNITS = {"pa": 1.0, "kpa": 1e3, "mpa": 1e6, "n/mm2": 1e6, "gpa": 1e9, "kgf/cm2": 9.80665e4, "psi": 6894.757293168}
STRESS_MEASURES = {"nominal": "nominal", "cauchy": "cauchy", "true": "cauchy"}
# "nominal_stress [MPa]", or the unit after an underscore ("nominal_stress_MPa") when it is a known one
_COLUMN = re.compile(r"^\s*(?P<name>[a-z_ ]+?)\s*(?:\[(?P<unit>[^\]]*)\]|_(?P<suffix>"
                     + "|".join(re.escape(u) for u in STRESS_UNITS) + r"))?\s*$", re.IGNORECASE)


@dataclass(frozen=True)
class ModeCurve:
    """One test curve as nominal stress against stretch, SI.

    Attributes
    ----------
    name : str
    mode : str
        One of :data:`colonsim.identification.hyperelastic.MODES`.
    stretch : ndarray
        Strictly increasing stretch of the loaded direction.
    stress : ndarray
        Nominal (first Piola) stress of the loaded direction, Pa.
    weight : float
        Weight of this curve's residuals in a joint fit (default 1).
    strip : TensileCurve or None
        The force-displacement curve it came from (a uniaxial strip), for the clamped FE model.
    """

    name: str
    mode: str
    stretch: np.ndarray
    stress: np.ndarray
    weight: float = 1.0
    strip: TensileCurve | None = field(default=None, repr=False, compare=False)
    meta: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        check_mode(self.name, self.mode)
        l = np.asarray(self.stretch, dtype=float)
        if l.size < 3:
            raise ColonsimError(f"{self.name}: only {l.size} points; a {self.mode} curve needs at least 3")
        steps = np.diff(l)
        if np.any(steps <= 0):
            i = int(np.flatnonzero(steps <= 0)[0])
            raise ColonsimError(f"{self.name}: the {self.mode} curve is not monotonic: stretch {l[i]:g} then {l[i + 1]:g} "
                                f"(points {i + 1}, {i + 2}); keep only the loading branch, in increasing stretch")
        if l[0] < 1.0 - 1e-9:
            raise ColonsimError(f"{self.name}: stretch {l[0]:g} < 1; the {self.mode} test is read as tension, drop the "
                                "compressive points")
        if not np.isfinite(self.weight) or self.weight <= 0:
            raise ColonsimError(f"{self.name}: weight {self.weight!r} must be a positive number")

    @property
    def max_stretch(self) -> float:
        return float(self.stretch[-1])


def check_mode(name, mode):
    if mode not in MODES:
        raise ColonsimError(f"{name}: test mode {mode!r} is unknown; use one of {', '.join(MODES)}")


def _stress_column(path, name, unit, measure_option):
    """(measure, factor to Pa, unit) of a stress column from its name, unit and the option."""
    words = name.lower().replace(" ", "_")
    stated = next((STRESS_MEASURES[w] for w in STRESS_MEASURES if words.startswith(w + "_")), None)
    option = None if measure_option is None else STRESS_MEASURES.get(measure_option.lower())
    if measure_option is not None and option is None:
        raise ColonsimError(f"--stress-measure {measure_option!r}: use nominal or cauchy")
    if stated and option and stated != option:
        raise ColonsimError(f"{path}: the column says {stated} stress but the option says {option}; drop one")
    measure = stated or option
    if measure is None:
        raise ColonsimError(f"{path}: the stress measure is not stated; name the column nominal_stress or cauchy_stress "
                            "(e.g. 'nominal_stress [MPa]') or pass --stress-measure nominal|cauchy")
    if unit is None:
        raise ColonsimError(f"{path}: the stress unit is not stated; write it in the header, e.g. '{name} [MPa]' "
                            f"({', '.join(STRESS_UNITS)})")
    try:
        return measure, STRESS_UNITS[unit.strip().lower().replace("²", "2").replace("^2", "2")], unit
    except KeyError:
        raise ColonsimError(f"{path}: unknown stress unit {unit!r}; use one of {', '.join(STRESS_UNITS)}") from None


def is_stress_curve(path) -> bool:
    """Whether ``path`` holds a stress-stretch table (its header names a stretch or strain column)."""
    header = _header(path)[0]
    return header is not None and any(_deformation_kind(c) for c in header)


def _deformation_kind(cell):
    m = _COLUMN.match(cell)
    return m.group("name").strip().lower() if m and m.group("name").strip().lower() in ("stretch", "strain") else None


def _header(path):
    text, _ = read_text(path)
    rows = [r for r in text.splitlines() if r.strip() and not r.lstrip().startswith("#")]
    if not rows:
        return None, []
    delimiter = next((d for d in ("\t", ";", ",") if d in rows[0]), None)
    split = (lambda r: [c.strip() for c in r.split(delimiter)]) if delimiter else (lambda r: r.split())
    return split(rows[0]), [split(r) for r in rows[1:]]


def read_stress_curve(path, mode, name=None, stress_measure=None, weight=1.0) -> ModeCurve:
    """Read a stress-stretch curve of ``mode`` and convert it to nominal stress in Pa (see the module)."""
    path = Path(path)
    name = name or path.stem
    check_input_file(path, "test data file")
    if mode is None:
        raise ColonsimError(f"{path}: the test mode is not given; pass --mode ({', '.join(MODES)}) or a manifest column mode")
    check_mode(name, mode)
    header, rows = _header(path)
    if header is None:
        raise ColonsimError(f"{path}: no table found; expected a header such as 'stretch,nominal_stress [MPa]'")
    kinds = [_deformation_kind(c) for c in header]
    if not any(kinds):
        raise ColonsimError(f"{path}: no stretch or strain column; name one 'stretch' or 'strain' in the header")
    d_col = next(i for i, k in enumerate(kinds) if k)
    s_cols = [i for i, c in enumerate(header) if i != d_col and _COLUMN.match(c) and "stress" in c.lower()]
    if len(s_cols) != 1:
        raise ColonsimError(f"{path}: expected one stress column beside '{header[d_col]}', found "
                            f"{len(s_cols) or 'none'}; name it e.g. 'nominal_stress [MPa]'")
    m = _COLUMN.match(header[s_cols[0]])
    measure, factor, unit = _stress_column(path, m.group("name").strip(), m.group("unit") or m.group("suffix"),
                                           stress_measure)
    d_unit = (_COLUMN.match(header[d_col]).group("unit") or "").strip()
    try:
        values = np.array([[float(r[d_col]), float(r[s_cols[0]])] for r in rows], dtype=float)
    except (ValueError, IndexError):
        bad = next(i for i, r in enumerate(rows) if not _numeric_row(r, d_col, s_cols[0]))
        raise ColonsimError(f"{path}: data row {bad + 1} is not two numbers ({','.join(rows[bad])}); remove it") from None
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise ColonsimError(f"{path}: no data rows, or a NaN/infinite value; remove the incomplete rows")
    deformation, stress = values[:, 0], values[:, 1] * factor
    if kinds[d_col] == "strain":
        if d_unit not in ("", "%", "-", "1"):
            raise ColonsimError(f"{path}: strain unit {d_unit!r}; give strain as a fraction ('strain') or in per cent ('strain [%]')")
        stretch = 1.0 + deformation * (0.01 if d_unit == "%" else 1.0)
    else:
        stretch = deformation
    if measure == "cauchy":
        stress = stress / stretch
    meta = {"path": str(path), "stress_measure": measure, "stress_unit": unit, "deformation": kinds[d_col],
            "converted": "cauchy stress / stretch" if measure == "cauchy" else None}
    return ModeCurve(name, mode, stretch, stress, float(weight), meta=meta)


def _numeric_row(row, *cols):
    try:
        return all(np.isfinite(float(row[c])) for c in cols)
    except (ValueError, IndexError):
        return False


def from_strip(curve: TensileCurve, weight=1.0) -> ModeCurve:
    """A strip's force-displacement curve as uniaxial nominal stress F / (w t) against 1 + d / L
    (the homogeneous reading; the clamped FE model reads the strip itself)."""
    keep = curve.displacement > 0
    return ModeCurve(curve.name, "uniaxial", 1.0 + curve.displacement[keep] / curve.length,
                     curve.force[keep] / (curve.width * curve.thickness), float(weight), strip=curve,
                     meta={"path": curve.meta.get("path"), "stress_measure": "nominal (force / undeformed section)",
                           "converted": "from force-displacement with the specimen's geometry",
                           "cleaning": curve.meta.get("cleaning")})


def read_mode_manifest(path, stress_measure=None, displacement_unit=None, force_unit=None) -> list[ModeCurve]:
    """Every curve a mode manifest lists (``specimen,file,mode`` [,weight] [,length_mm,width_mm,thickness_mm])."""
    path = Path(path)
    check_input_file(path, "manifest")
    text, _ = read_text(path)
    reader = csv.DictReader(r for r in text.splitlines() if r.strip() and not r.lstrip().startswith("#"))
    check_manifest_columns(reader.fieldnames or [], path, MODE_MANIFEST_REQUIRED, MODE_MANIFEST_OPTIONAL)
    rows = [{k.strip(): (v or "").strip() for k, v in row.items() if isinstance(k, str)} for row in reader]
    check_listed_once([(r["specimen"], r["specimen"]) for r in rows], path, "specimen name")
    check_listed_once([(r["specimen"], (path.parent / r["file"]).resolve()) for r in rows], path)
    curves = []
    for r in rows:
        name, mode = r["specimen"], r["mode"].lower()
        check_mode(f"{path}: specimen {name!r}", mode)
        try:
            weight = float(r.get("weight") or 1.0)
        except ValueError:
            raise ColonsimError(f"{path}: specimen {name!r} has a non-numeric weight {r.get('weight')!r}") from None
        file = path.parent / r["file"]
        check_input_file(file, "test data file")
        if is_stress_curve(file):
            curves.append(read_stress_curve(file, mode, name, stress_measure, weight))
            continue
        if mode != "uniaxial":
            raise ColonsimError(f"{file}: a force-displacement file is read as a uniaxial strip, but the manifest says "
                                f"{mode}; give {mode} tests as stress-stretch tables ('stretch,nominal_stress [MPa]')")
        geometry = {}
        for key in ("length", "width", "thickness"):
            cell = r.get(f"{key}_mm", "")
            try:
                geometry[key] = float(cell) * 1e-3 if cell else None
            except ValueError:
                raise ColonsimError(f"{path}: specimen {name!r} has a non-numeric {key}_mm {cell!r}") from None
        strip = read_curve(file, name=name, displacement_unit=displacement_unit, force_unit=force_unit,
                           given_as=f"{path.name} {{}}_mm", **geometry)
        curves.append(from_strip(strip, weight))
    if not curves:
        raise ColonsimError(f"{path}: the manifest lists no specimens")
    return curves
