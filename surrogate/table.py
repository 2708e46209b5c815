"""The sweep results table (one row per insertion run) as the surrogate reads it.

Contract with the sweep: ``results.parquet`` or ``.csv`` with identity columns (``key``,
``status``, ...), inputs (``segment``, ``scope``, ``scope_diameter_mm``, ``diameter_mm``,
``angle_deg``, ``friction``, ``wall_thickness_mm``, ``material``), other solver settings and the
scalar outputs below (NaN when undefined or failed). Only runs with status "ok" train.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from colonsim.errors import ColonsimError

SEGMENTS = ("rsj", "rsf", "thf", "thf-fixed", "straight")
# Continuous inputs a segment's model may depend on (those that vary in its runs).
INPUTS = ("scope_diameter_mm", "diameter_mm", "angle_deg", "friction", "wall_thickness_mm")
INPUT_LABELS = {"scope_diameter_mm": "scope diameter [mm]", "diameter_mm": "colon diameter [mm]",
                "angle_deg": "angle alpha/beta [deg]", "friction": "friction coefficient",
                "wall_thickness_mm": "wall thickness [mm]"}
# How the command line spells each input (for messages).
INPUT_OPTIONS = {"scope_diameter_mm": "--scope", "diameter_mm": "--diameter", "angle_deg": "--angle",
                 "friction": "--friction", "wall_thickness_mm": "--wall-thickness"}
TARGETS = ("final_deformation_cm", "max_deformation_cm", "point_A_cm", "point_C_cm", "peak_contact_force_N",
           "peak_push_force_N", "max_wall_stretch")
TARGET_LABELS = {"final_deformation_cm": "final colon deformation [cm]", "max_deformation_cm": "maximum colon deformation [cm]",
                 "point_A_cm": "deformation at point A [cm]", "point_B_cm": "deformation at point B [cm]",
                 "point_C_cm": "deformation at point C [cm]", "peak_contact_force_N": "peak contact force [N]",
                 "peak_push_force_N": "peak push force [N]", "max_wall_stretch": "maximum wall stretch"}
# Columns that are neither inputs nor solver settings: identity and outputs of a run.
NOT_SETTINGS = {"key", "status", "error", "wall_time_s", "timeseries_path", "finished_at", "git_commit", "segment", "scope",
                "quasi_static", "quasi_static_literal", "quasi_static_without_imposed_sliding", "ended_by", "end_depth_cm",
                "end_push_force_N", "end_contact_force_N", "simulated_time_s", "point_B_cm", *INPUTS, *TARGET_LABELS}
REQUIRED = ("status", "segment", "scope_diameter_mm")


def read_results(path) -> pd.DataFrame:
    """Read a sweep results table (Parquet or CSV) and check the columns the surrogate needs."""
    path = Path(path)
    if not path.is_file():
        raise ColonsimError(f"results table {path} not found; give the results.parquet (or .csv) a sweep wrote")
    try:
        frame = pd.read_csv(path) if path.suffix.lower() == ".csv" else pd.read_parquet(path)
    except Exception as exc:  # pyarrow and pandas raise many types for a damaged file
        raise ColonsimError(f"cannot read results table {path}: {str(exc).splitlines()[0]}") from None
    return check_results(frame, str(path))


def check_results(frame: pd.DataFrame, name="results table") -> pd.DataFrame:
    """The table with its required columns checked, the segment names normalized and the inputs
    and outputs the surrogate reads made numeric."""
    missing = [c for c in REQUIRED if c not in frame.columns]
    if missing:
        raise ColonsimError(f"{name} lacks the column(s) {', '.join(missing)}; is it a sweep's results table?")
    frame = frame.reset_index(drop=True)
    blank = frame["segment"].isna() | (frame["segment"].astype(str).str.strip() == "")
    if blank.any():
        raise ColonsimError(f"{name}: {int(blank.sum())} row(s) have no segment ({_rows(frame, blank)}); fill it in "
                            f"({', '.join(SEGMENTS)}) or remove those rows")
    frame["segment"] = frame["segment"].astype(str).str.strip().str.lower()
    unknown = sorted(set(frame["segment"]) - set(SEGMENTS))
    if unknown:
        raise ColonsimError(f"{name} has unknown segment(s) {', '.join(unknown)}; expected {', '.join(SEGMENTS)}")
    for column in (*INPUTS, *TARGET_LABELS):
        if column in frame.columns:
            frame[column] = numeric_column(frame, column, name)
    for column in INPUTS:
        if column in frame.columns and np.isinf(frame[column]).any():
            raise ColonsimError(f"{name}: input {column} is infinite in {_rows(frame, np.isinf(frame[column]))}; "
                                "fix or remove those rows")
    if not (frame["status"] == "ok").any():
        raise ColonsimError(f"{name} has no run with status 'ok'; nothing to fit")
    return frame


def _rows(frame: pd.DataFrame, mask) -> str:
    """The rows of ``mask`` as a user finds them: by run key if the table has one, else by data row."""
    mask = np.asarray(mask, dtype=bool)
    index = np.flatnonzero(mask)
    names = ([f"run {k}" for k in frame["key"].to_numpy()[index[:3]]] if "key" in frame.columns
             else [f"data row {i + 1}" for i in index[:3]])
    return ", ".join(names) + (f" and {len(index) - 3} more" if len(index) > 3 else "")


def numeric_column(frame: pd.DataFrame, column, name="results table") -> pd.Series:
    """``frame[column]`` as floats (blank = NaN); a text that is no number is an error naming the row."""
    values = pd.to_numeric(frame[column], errors="coerce")
    bad = values.isna() & frame[column].notna() & (frame[column].astype(str).str.strip() != "")
    if bad.any():
        first = frame[column][bad].iloc[0]
        raise ColonsimError(f"{name}: column {column} holds {first!r}, not a number, in {_rows(frame, bad)}; "
                            "fix or remove those rows")
    return values.astype(float)


def successful_runs(frame: pd.DataFrame, segment: str) -> pd.DataFrame:
    """The runs of one segment with status 'ok'."""
    return frame[(frame["segment"] == segment) & (frame["status"] == "ok")].reset_index(drop=True)


def _constant(values: pd.Series) -> bool:
    v = values.dropna()
    if v.empty:
        return True
    if pd.api.types.is_numeric_dtype(v):
        return bool(np.ptp(v.to_numpy(dtype=float)) <= 1e-9 * max(1.0, float(np.abs(v).max())))
    return v.astype(str).nunique() == 1


def split_inputs(runs: pd.DataFrame, inputs=INPUTS):
    """Which candidate inputs vary over ``runs`` (the model's inputs) and which are fixed (value).

    Inputs absent from the table are neither: a query may not set them."""
    varying, fixed = [], {}
    for name in inputs:
        if name not in runs.columns:
            continue
        if runs[name].isna().any():
            raise ColonsimError(f"input column {name} has missing values in successful runs; fix the sweep table")
        if _constant(runs[name]):
            fixed[name] = float(runs[name].iloc[0])
        else:
            varying.append(name)
    return varying, fixed


def solver_settings(runs: pd.DataFrame):
    """The other columns (solver settings such as element_size_mm, material): their values, and
    the names of those that vary between runs (mixing e.g. two mesh sizes adds scatter)."""
    settings, varying = {}, []
    for name in runs.columns:
        if name in NOT_SETTINGS:
            continue
        values = runs[name].dropna()
        if values.empty:
            continue
        if pd.api.types.is_numeric_dtype(values) and not pd.api.types.is_bool_dtype(values):
            uniq = sorted({float(v) for v in values})
        else:
            uniq = sorted({str(v) for v in values})
        settings[name] = uniq if len(uniq) <= 10 else uniq[:10] + ["..."]
        if not _constant(values):
            varying.append(name)
    return settings, varying


def scope_diameters(runs: pd.DataFrame) -> dict:
    """Scope name (lower case) -> outer diameter in mm, as the runs used them."""
    if "scope" not in runs.columns:
        return {}
    pairs = runs[["scope", "scope_diameter_mm"]].dropna().drop_duplicates()
    return {str(s).strip().lower(): float(d) for s, d in zip(pairs["scope"], pairs["scope_diameter_mm"])}


# docs/model.md (the same numbers as colonsim.insertion.anatomy.scopes.NAMED_SCOPES, kept here so that reading a
# surrogate does not import the solver); a sweep table's own scope column takes precedence.
NAMED_SCOPES_MM = {"utc": 9.2, "pdc": 11.3, "sdc": 12.8}
SMALL_CALIBER = ("utc", "pdc")
STANDARD_SCOPE = "sdc"


def scope_diameter_mm(spec, known=None) -> float:
    """Outer diameter (mm) of a scope given by name (utc, pdc, sdc or one the sweep ran) or in mm."""
    key = str(spec).strip().lower()
    table = {**NAMED_SCOPES_MM, **(known or {})}
    if key in table:
        return table[key]
    try:
        value = float(key.removesuffix("mm"))
    except ValueError:
        raise ColonsimError(f"unknown scope {spec!r}; give {', '.join(sorted(table))} or an outer diameter in mm") from None
    if not 3.0 <= value <= 20.0:
        raise ColonsimError(f"scope diameter {value:g} mm is implausible (3-20 mm); give it in millimetres")
    return value


def target_unit(target) -> str:
    """Unit of an output column, read from its name (``_cm`` -> cm, ``_N`` -> N, else none)."""
    return {"cm": "cm", "N": "N"}.get(str(target).rsplit("_", 1)[-1], "")
