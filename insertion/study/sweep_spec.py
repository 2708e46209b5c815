"""What a sweep runs: a TOML description (or a preset) expanded into validated insertion cases.

Format (every key of ``[fixed]``, ``[[grid]]`` and ``[lhs]`` is a field of
:class:`colonsim.insertion.case.scenario.InsertionCase`, in its user units, or ``scope_diameter_mm``)::

    [sweep]
    name = "rsj-scopes"          # names the default output folder
    seed = 1                     # seed of the Latin hypercube (default 0)
    description = "..."          # optional, free text
    animate = [{scope = "sdc", diameter_mm = 36}]   # optional: the runs whose movie is written (true: all)

    [fixed]                      # the same value in every case
    element_size_mm = 4.0

    [[grid]]                     # every combination of the lists (a scalar = a one-value list)
    segment = "rsj"
    scope = ["utc", "pdc", "sdc"]
    diameter_mm = [23, 36]
    friction = [0, 0.05, 0.1]

    [[grid]]                     # more blocks: the sweep is the union of the blocks
    segment = ["rsf", "thf"]
    scope = ["utc", "sdc"]
    angle_deg = [0, 30, 45]

or, for a space-filling design crossed with a grid (2 x 20 runs)::

    [[grid]]
    segment = "rsj"
    friction = [0, 0.1]

    [lhs]                        # Latin hypercube over continuous ranges [low, high]
    samples = 20
    diameter_mm = [20, 40]
    scope_diameter_mm = [9, 13]

- ``scope`` takes a named scope (:data:`colonsim.catalog.NAMED_SCOPES`) or a diameter in mm;
  ``scope_diameter_mm`` (numbers) is the same axis given as diameters. Give one of the two.
- ``material`` takes a material JSON path, ``centerline`` a patient's centerline CSV (relative
  paths are read from the TOML file's folder); ``""`` means the source's parameters (material)
  or none (centerline).
- With both ``[[grid]]`` and ``[lhs]``, every grid case is crossed with every hypercube sample.
  A key may appear in only one of ``[fixed]``, the grid blocks and ``[lhs]``.
- Hypercube values are rounded to 3 decimals (readable tables); the seed makes the sample, and so
  every key, reproducible. Identical cases (same :meth:`InsertionCase.key`) run once.
- ``[material]`` crosses every case with materials drawn from a calibration (:mod:`.material_samples`).

Every case is validated before anything runs (one-line errors naming the key and the fix): finite
numbers, something that varies (``[fixed]`` alone is ``colonsim insert``), at most :data:`MAX_RUNS`
runs, counted before any case is generated.
"""

from __future__ import annotations

import dataclasses
import difflib
import itertools
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType

import numpy as np

from colonsim.catalog import NAMED_SCOPES
from colonsim.errors import ColonsimError
from colonsim.inputs import check_input, read_input_text
from colonsim.limits import MAX_RUNS  # re-exported: the bound the sweep docs name
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.material_samples import MATERIAL_PARAMETERS, sample_materials
from colonsim.insertion.study.sweep_animation import animated_keys
from colonsim.insertion.study.sweep_presets import PRESETS  # re-exported: the presets load_sweep knows

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

SCOPE_DIAMETER = "scope_diameter_mm"
SECTIONS = ("sweep", "fixed", "grid", "lhs", "material")
SWEEP_KEYS = ("name", "seed", "description", "animate")
LHS_DECIMALS = 3
# Wall time of one run on one core: the thesis preset on the 2-core development machine (README):
# RSJ 5-17 s, RSF 45-120 s, THF 50-260 s at the default mesh.
RUN_SECONDS = (5.0, 260.0)


@dataclass
class SweepSpec:
    """A parsed sweep: its name, seed, source text and the cases it expands to."""

    name: str
    seed: int
    description: str
    cases: list = field(default_factory=list)
    source: str = ""
    lhs_ranges: list = field(default_factory=list)  # [(key, low, high)] of [lhs], in its order (adaptive sweeps)
    animated: frozenset = frozenset()  # keys of the cases whose movie is written ([sweep] animate)

    def document(self) -> dict:
        """A JSON-able description (written next to the results)."""
        return {"name": self.name, "seed": self.seed, "description": self.description, "runs": len(self.cases),
                "keys": [c.key() for c in self.cases], "toml": self.source}


def case_fields() -> MappingProxyType:
    """The fields of :class:`InsertionCase` by name (taken from the dataclass, never hard-coded)."""
    return _CASE_FIELDS


_CASE_FIELDS = MappingProxyType({f.name: f for f in dataclasses.fields(InsertionCase)})  # read-only: shared


def _unknown(key, where, known):
    close = difflib.get_close_matches(key, known, n=1)
    hint = f"did you mean {close[0]!r}? " if close else ""
    raise ColonsimError(f"unknown key {key!r} in [{where}]; {hint}use one of: {', '.join(known)}")


def _coerce(name, value, where, base: Path | None):
    """``value`` in the type of field ``name`` (floats as floats, so that keys do not depend on 23 vs 23.0)."""
    if name == SCOPE_DIAMETER:
        name, value = "scope", _number(SCOPE_DIAMETER, value, where)
    f = case_fields()[name]
    default = f.default
    if name == "scope":
        if isinstance(value, bool) or not isinstance(value, (str, int, float)):
            raise ColonsimError(f"{where}: scope = {value!r}; give {', '.join(NAMED_SCOPES)} or a diameter in mm")
        return "scope", (f"{_number(name, value, where):g}" if isinstance(value, (int, float)) else value.strip().lower())
    if name in ("material", "centerline"):  # paths relative to the TOML file's folder
        if not isinstance(value, str):
            what = "a material JSON or \"\" for the default" if name == "material" else "a centerline CSV"
            raise ColonsimError(f"{where}: {name} = {value!r}; give the path of {what}")
        if not value:
            return name, None
        try:
            path = Path(value).expanduser()
            if base is not None and not path.is_absolute():
                path = base / path
            return name, str(path.resolve())
        except (OSError, ValueError, RuntimeError) as exc:  # a NUL byte, an unknown ~user, a symlink loop
            raise ColonsimError(f"{where}: {name} = {value!r} is not a usable path ({exc})") from None
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise ColonsimError(f"{where}: {name} = {value!r}; give true or false")
        return name, value
    if isinstance(default, float):
        return name, _number(name, value, where)
    if isinstance(default, int):
        if isinstance(value, bool) or not isinstance(value, int):
            raise ColonsimError(f"{where}: {name} = {value!r}; give an integer")
        return name, value
    if isinstance(default, str):
        if not isinstance(value, str):
            raise ColonsimError(f"{where}: {name} = {value!r}; give a string")
        return name, value.strip().lower() if name == "segment" else value
    return name, value


def _number(name, value, where):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ColonsimError(f"{where}: {name} = {value!r}; give a number")
    try:
        number = float(value)
    except OverflowError:  # a TOML integer beyond any float
        number = math.inf
    if not math.isfinite(number):
        shown = repr(value) if len(repr(value)) <= 40 else f"{repr(value)[:12]}... ({len(repr(value))} digits)"
        raise ColonsimError(f"{where}: {name} = {shown}; give a finite number")
    return number


def _axis_keys(table, where):
    known = [k for k in (*case_fields(), SCOPE_DIAMETER) if k != MATERIAL_PARAMETERS]  # drawn by [material]
    for key in table:
        if key not in known:
            _unknown(key, where, known)
    if "scope" in table and SCOPE_DIAMETER in table:
        raise ColonsimError(f"[{where}] gives both scope and {SCOPE_DIAMETER}; they are the same axis, keep one")


def _grid_size(block, where) -> int:
    """Cases of a grid block (the product of its list lengths), counted without making them."""
    if not block:
        raise ColonsimError(f"[{where}] is empty; give at least one key = [values], or remove the block")
    return math.prod(len(v) if isinstance(v, list) else 1 for v in block.values())


def _grid_cases(block, where, base):
    _axis_keys(block, where)
    axes = []
    for key, values in block.items():
        values = values if isinstance(values, list) else [values]
        if not values:
            raise ColonsimError(f"[{where}] {key} is an empty list; give at least one value or remove the key")
        axes.append([_coerce(key, v, f"[{where}]", base) for v in values])
    return [dict(combo) for combo in itertools.product(*axes)]


def latin_hypercube(n: int, d: int, seed: int) -> np.ndarray:
    """``n`` points in [0, 1)^d, one per row and column stratum (scipy's LHS, seeded)."""
    from scipy.stats import qmc

    return qmc.LatinHypercube(d=d, seed=seed).random(n)


def _lhs_ranges(table):
    """``[lhs]`` as (samples, [(key, low, high)]), checked."""
    table = dict(table)
    samples = table.pop("samples", None)
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ColonsimError(f"[lhs] samples = {samples!r}; give the number of hypercube points, e.g. samples = 20")
    _axis_keys(table, "lhs")
    if not table:
        raise ColonsimError("[lhs] has no ranges; add e.g. diameter_mm = [20, 40]")
    ranges = []
    for key, bounds in table.items():
        if (not isinstance(bounds, list) or len(bounds) != 2
                or any(isinstance(b, bool) or not isinstance(b, (int, float)) for b in bounds)):
            raise ColonsimError(f"[lhs] {key} = {bounds!r}; give a range [low, high] of numbers with low < high")
        low, high = (_number(key, b, "[lhs]") for b in bounds)
        if not (low < high and math.isfinite(high - low)):
            raise ColonsimError(f"[lhs] {key} = {bounds!r}; give a range [low, high] of numbers with low < high")
        if key != SCOPE_DIAMETER and not isinstance(case_fields()[key].default, float):
            raise ColonsimError(f"[lhs] {key} is not a continuous input; put it in a [[grid]] block instead")
        ranges.append((key, low, high))
    return samples, ranges


def lhs_values(ranges, unit) -> list:
    """Case values (field -> value) of the points ``unit`` (n, d) in [0, 1)^d mapped onto ``ranges``
    (from :attr:`SweepSpec.lhs_ranges`), rounded to :data:`LHS_DECIMALS` as every hypercube is."""
    cases = []
    for row in np.atleast_2d(unit):
        values = (round(lo + u * (hi - lo), LHS_DECIMALS) for (_, lo, hi), u in zip(ranges, row))
        cases.append(dict(_coerce(key, v, "[lhs]", None) for (key, _, _), v in zip(ranges, values)))
    return cases


def parse_sweep(text: str, base: Path | None = None, origin: str = "sweep") -> SweepSpec:
    """Parse a sweep TOML document into a :class:`SweepSpec` with validated cases.

    Parameters
    ----------
    text : str
        The TOML document (format in the module docstring).
    base : Path or None
        Folder that relative material paths are read from.
    origin : str
        Where the text came from (file or preset), for messages.
    """
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ColonsimError(f"{origin} is not valid TOML: {exc}") from None
    for section in doc:
        if section not in SECTIONS:
            _unknown(section, "top level", list(SECTIONS))
    head = doc.get("sweep", {})
    if not isinstance(head, dict):
        raise ColonsimError(f"{origin}: [sweep] must be a table (name, seed, description)")
    for key in head:
        if key not in SWEEP_KEYS:
            _unknown(key, "sweep", list(SWEEP_KEYS))
    name = head.get("name", Path(origin).stem if origin.endswith(".toml") else "sweep")
    seed = head.get("seed", 0)
    if not isinstance(name, str) or not name.strip() or any(c in name for c in "/\\"):
        raise ColonsimError(f"[sweep] name = {name!r}; give a short name without slashes (it names the output folder)")
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ColonsimError(f"[sweep] seed = {seed!r}; give a non-negative integer")

    fixed = doc.get("fixed", {})
    if not isinstance(fixed, dict):
        raise ColonsimError(f"{origin}: [fixed] must be a table of key = value")
    _axis_keys(fixed, "fixed")
    for key, value in fixed.items():
        if isinstance(value, list):
            raise ColonsimError(f"[fixed] {key} = {value!r} is a list; put varying values in a [[grid]] block")
    fixed = dict(_coerce(k, v, "[fixed]", base) for k, v in fixed.items())

    grid = doc.get("grid", [])
    blocks = [grid] if isinstance(grid, dict) else grid
    if not isinstance(blocks, list) or not all(isinstance(b, dict) for b in blocks):
        raise ColonsimError(f"{origin}: [grid] / [[grid]] must be tables of key = [values]")
    wheres = ["grid" if len(blocks) == 1 else f"grid block {i}" for i in range(1, len(blocks) + 1)]
    lhs = doc.get("lhs")
    if lhs is not None and not isinstance(lhs, dict):
        raise ColonsimError(f"{origin}: [lhs] must be a table (samples = N and ranges key = [low, high])")
    if not blocks and lhs is None:
        what = "only [fixed] values: that is one run (use `colonsim insert` for it)" if fixed else "no runs"
        raise ColonsimError(f"{origin} describes {what}; add a [[grid]] block or an [lhs] table with the inputs to vary")
    _check_size(origin, [_grid_size(b, w) for b, w in zip(blocks, wheres)], lhs)
    grid_cases = []
    grid_keys = set()
    for block, where in zip(blocks, wheres):
        grid_cases += _grid_cases(block, where, base)
        grid_keys |= {("scope" if k == SCOPE_DIAMETER else k) for k in block}
    samples, lhs_ranges = _lhs_ranges(lhs) if lhs is not None else (0, [])
    lhs_cases = lhs_values(lhs_ranges, latin_hypercube(samples, len(lhs_ranges), seed)) if lhs is not None else []
    lhs_keys = {("scope" if k == SCOPE_DIAMETER else k) for k in (lhs or {}) if k != "samples"}
    fixed_keys = set(fixed)
    for a, b, ka, kb in (("fixed", "grid", fixed_keys, grid_keys), ("fixed", "lhs", fixed_keys, lhs_keys),
                         ("grid", "lhs", grid_keys, lhs_keys)):
        if ka & kb:
            raise ColonsimError(f"{', '.join(sorted(ka & kb))} appears in both [{a}] and [{b}]; give each input in one place")

    if lhs is None:
        combos = grid_cases or [{}]
    else:
        combos = [{**g, **s} for g in (grid_cases or [{}]) for s in lhs_cases]
    cases, seen = [], set()
    for values in combos:
        case = InsertionCase(**{**fixed, **values})
        try:
            case.validate()
        except ColonsimError as exc:
            shown = ", ".join(f"{k}={v}" for k, v in values.items())
            raise ColonsimError(f"case ({shown or 'defaults'}): {exc}") from None
        if case.key() not in seen:
            seen.add(case.key())
            cases.append(case)
    cases = sample_materials(doc, cases, base, seed, MAX_RUNS)
    _check_materials(cases)
    return SweepSpec(name=name.strip(), seed=seed, description=str(head.get("description", "")), cases=cases,
                     source=text, lhs_ranges=lhs_ranges,
                     animated=animated_keys(head.get("animate", False), cases, lambda k, v: _chosen(k, v, base)))


def _chosen(key, value, base):
    """One input of an ``animate`` table, checked and read as the grid reads it."""
    _axis_keys({key: value}, "sweep] animate = [{...}")
    return _coerce(key, value, "[sweep] animate", base)


def _check_size(origin, grid_sizes, lhs):
    """Refuse a sweep of more than :data:`MAX_RUNS` runs before making any case (a hypercube of
    1e8 samples would take minutes to draw and years to run)."""
    samples = lhs.get("samples") if isinstance(lhs, dict) else None
    samples = samples if isinstance(samples, int) and not isinstance(samples, bool) and samples > 0 else 1
    grid = sum(grid_sizes)
    runs = max(grid, 1) * samples
    if runs <= MAX_RUNS:
        return
    from colonsim.insertion.case.run_budget import human_duration

    parts = [f"{grid:,} grid cases"] if grid else []
    parts += [f"{samples:,} hypercube samples"] if lhs is not None else []
    low, high = (human_duration(runs * s if runs < 1e300 else math.inf) for s in RUN_SECONDS)
    raise ColonsimError(f"{origin} asks for {runs:,} runs ({' x '.join(parts)}), more than the {MAX_RUNS:,} a sweep may "
                        f"hold: at {RUN_SECONDS[0]:g}-{RUN_SECONDS[1]:g} s per run on one core that is {low} to {high} "
                        "of computing; lower the samples or the grid, or split it into sweeps with separate --out")


def _check_materials(cases):
    from colonsim.insertion.engine.material import load_material

    for path in sorted({c.material for c in cases if c.material}):
        load_material(check_input(path, "material file"))


def load_sweep(path=None, preset: str | None = None) -> SweepSpec:
    """A sweep from a TOML file or a preset name (exactly one of the two)."""
    if (path is None) == (preset is None):
        raise ColonsimError("give a sweep TOML file or --preset NAME (one of the two)")
    if preset is not None:
        if preset not in PRESETS:
            raise ColonsimError(f"unknown preset {preset!r}; use one of {', '.join(PRESETS)}")
        return parse_sweep(PRESETS[preset], origin=f"preset {preset}")
    path = Path(path)
    return parse_sweep(read_input_text(path, "sweep file"), base=path.parent, origin=str(path))
