"""The sweeps the validation report reads: their tables, the cases they define, and runs found by
their inputs or paired with the run of the other sweep that differs in one input.

Two sweeps: the main one (the ``thesis`` preset: the source's insertions) and the validation one
(the ``validation`` preset: the same cases on a finer mesh, at half the push speed, and at other
flexure turns). A validation run is paired with the main run whose inputs differ from its own in
exactly one of :data:`PAIRED_INPUTS`; the input that differs names the check.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from colonsim.catalog import scope_role
from colonsim.errors import ColonsimError
from colonsim.insertion.case.results import RUN_SUMMARY
from colonsim.insertion.case.insertion_case import ABSENT_AT
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.run_rules import RULES, apply_current_rules
from colonsim.insertion.study.sweep_table import case_from_row
from colonsim.insertion.study.sweep import TABLE, read_results
from colonsim.insertion.study.sweep_spec import load_sweep, parse_sweep

SCOPES = ("utc", "pdc", "sdc")
# the input a validation run changes -> the check it belongs to
PAIRED_INPUTS = {"element_size_mm": "mesh", "push_speed": "rate", "flexure_angle_deg": "flexure"}


@dataclass
class Sweep:
    """A sweep folder as the report sees it.

    ``cases`` are the runs the sweep defines (its ``sweep.json``, or the preset when the folder
    holds no sweep yet), ``table`` the rows finished so far (only those of ``cases``), ``ran``
    whether a results table exists at all.
    """

    label: str
    folder: Path | None
    cases: list
    table: pd.DataFrame
    ran: bool

    def __post_init__(self):
        self._rows = {row["key"]: row for _, row in self.table.iterrows()}

    def run(self, case):
        """(row, status) of ``case``: the table row and "ok", or None and "failed: ..." / "not run"."""
        row = self._rows.get(case.key())
        if row is None:
            return None, "not run"
        if row["status"] != "ok":
            return None, "failed: " + " ".join(str(row.get("error", "")).split())
        return row, "ok"

    def run_folder(self, row) -> Path:
        return self.folder / Path(str(row["timeseries_path"])).parent

    def summary(self, row) -> dict:
        path = self.run_folder(row) / RUN_SUMMARY
        return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}

    def timeseries(self, row, columns=None):
        path = self.folder / str(row["timeseries_path"])
        return pd.read_csv(path, usecols=columns) if path.is_file() else None

    def commits(self) -> dict:
        """Commit that produced the rows -> number of rows."""
        counts = {}
        for c in self.table.get("git_commit", pd.Series([], dtype=str)):
            c = c if isinstance(c, str) and c else "not recorded"
            counts[c] = counts.get(c, 0) + 1
        return counts

    def describe(self) -> dict:
        ok = int((self.table["status"] == "ok").sum()) if len(self.table) else 0
        estimates = {}
        for case in self.cases:
            if case.key() in self._rows:
                estimates[case.time_step_estimate] = estimates.get(case.time_step_estimate, 0) + 1
        rules = self.table[RULES].value_counts().to_dict() if RULES in self.table else {}
        return {"label": self.label, "folder": None if self.folder is None else str(self.folder), "ran": self.ran,
                "defined": len(self.cases), "in_table": int(len(self.table)), "ok": ok,
                "failed": int(len(self.table) - ok), "code": self.commits(), "time_step_estimate": estimates,
                "rules": {str(k): int(v) for k, v in rules.items() if k}}


def read_sweep(label, folder, preset=None, optional=False) -> Sweep:
    """The sweep in ``folder``. Without a results table there, the report's optional sweeps
    (``preset`` given: defined by the preset; ``optional``: with no runs) come back empty; the
    main sweep is an error."""
    folder = None if folder is None else Path(folder)
    has_table = folder is not None and (folder / TABLE).is_file()
    if not has_table and optional:
        return Sweep(label, folder, [], pd.DataFrame(columns=["key", "status"]), False)
    if not has_table:
        if preset is None:
            raise ColonsimError(f"no {TABLE} in {folder}; run `colonsim sweep --preset thesis --out {folder}` first "
                                "or give the folder of a finished sweep with --sweep")
        return Sweep(label, folder, load_sweep(preset=preset).cases, pd.DataFrame(columns=["key", "status"]), False)
    try:
        table = read_results(folder)
    except Exception as exc:  # a truncated or foreign file: pyarrow raises its own types
        raise ColonsimError(f"cannot read {folder / TABLE} ({' '.join(str(exc).split())}); give the folder of a "
                            "sweep written by `colonsim sweep`") from None
    spec = folder / "sweep.json"
    if spec.is_file():
        try:
            cases = parse_sweep(json.loads(spec.read_text(encoding="utf-8"))["toml"], base=folder,
                                origin=str(spec)).cases
        except (KeyError, ValueError) as exc:
            raise ColonsimError(f"{spec} is not a sweep record ({exc}); move it away to read the table alone") from None
        cases = [recorded_case(c, set(table["key"])) for c in cases]
        table = table[table["key"].isin({c.key() for c in cases})].reset_index(drop=True)
    else:  # a table without its record: the runs in it are the sweep
        cases = [case_from_row(row) for _, row in table.iterrows()]
    return Sweep(label, folder, cases, apply_current_rules(table, folder), True)


def recorded_case(case, keys):
    """``case``, or the same case at the time-step estimate of before 2026-12-07 ("bounds") where
    only that one is in the table: a record of before is read at the engine that made it (the
    report names it per sweep), not taken for missing."""
    if case.key() in keys or case.time_step_estimate == ABSENT_AT["time_step_estimate"]:
        return case
    before = dataclasses.replace(case, time_step_estimate=ABSENT_AT["time_step_estimate"])
    return before if before.key() in keys else case


def role(case) -> str | None:
    """utc / pdc / sdc of a case's scope (named, or by a catalogue or meshed diameter)."""
    name = str(case.scope).lower()
    if name in SCOPES:
        return name
    try:
        return scope_role(float(name.removesuffix("mm")))
    except ValueError:
        return None


def scope_label(case) -> str:
    r = role(case)
    name = str(case.scope)
    shown = name.upper() if name.lower() in SCOPES else f"{name} mm"
    return f"{r.upper()} ({shown})" if r and name.lower() not in SCOPES else shown


def find_case(cases, segment, scope, **inputs):
    """The one case of ``segment`` whose scope plays ``scope`` (utc / pdc / sdc) with these inputs."""
    found = [c for c in cases if c.segment == segment and role(c) == scope
             and all(math.isclose(float(getattr(c, k)), float(v), abs_tol=1e-9) for k, v in inputs.items())]
    if len(found) > 1:
        raise ColonsimError(f"the sweep defines {len(found)} {segment.upper()} {scope.upper()} runs with {inputs}; "
                            "give a sweep with one run per case")
    return found[0] if found else None


def paired(validation: Sweep, main: Sweep) -> list:
    """(check, input, validation case, main case or None) for every validation case: the main
    case whose inputs differ from it in one of :data:`PAIRED_INPUTS` only."""
    out = []
    main_inputs = [(m, m.to_dict()) for m in main.cases]
    for v in validation.cases:
        mine = v.to_dict()
        base, changed = None, None
        for m, theirs in main_inputs:
            diff = [k for k in mine if mine[k] != theirs[k]]
            if len(diff) == 1 and diff[0] in PAIRED_INPUTS:
                base, changed = m, diff[0]
                break
        if base is None:  # the variant's base run is not defined by the main sweep: name the input from the defaults
            default = InsertionCase().to_dict()
            changed = next((k for k in PAIRED_INPUTS if mine[k] != default[k]), None)
        if changed is not None:
            out.append((PAIRED_INPUTS[changed], changed, v, base))
    return out


def relative_change(base, variant, floor):
    """(variant - base) / base; NaN where either is undefined or both lie below ``floor`` (nothing
    measurable to change)."""
    if base is None or variant is None or not (np.isfinite(base) and np.isfinite(variant)):
        return math.nan
    if max(abs(base), abs(variant)) < floor:
        return math.nan
    return (variant - base) / max(abs(base), floor)
