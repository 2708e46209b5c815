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

from colonsim import catalog
from colonsim.errors import ColonsimError
from colonsim.inputs import check_input, read_input_text
from colonsim.limits import QUERY_MAX_BYTES, TABLE_MAX_BYTES

# Derived from the catalog's columns (colonsim.catalog.COLUMNS), for the modules that import them.
SEGMENTS = catalog.segment_names()
# Continuous inputs a segment's model may depend on (those that vary in its runs).
INPUTS = catalog.columns(catalog.INPUT, surrogate=(catalog.SURROGATE_INPUT,))
INPUT_LABELS = {name: catalog.COLUMNS[name].label for name in INPUTS}
# How the command line spells each input (for messages).
INPUT_OPTIONS = {name: catalog.COLUMNS[name].option for name in INPUTS}
TARGETS = catalog.columns(catalog.OUTPUT, surrogate=(catalog.DEFAULT_TARGET,))
PAIN_PROXY = catalog.PAIN_PROXY  # the output scopes are ranked by (colonsim.catalog)
TARGET_LABELS = {name: catalog.COLUMNS[name].label
                 for name in catalog.columns(catalog.OUTPUT, surrogate=(catalog.DEFAULT_TARGET, catalog.TARGET))}
# Columns that are neither inputs nor solver settings: identity and outputs of a run, and the
# name older tables gave today's quasi_static.
NOT_SETTINGS = {name for name, column in catalog.COLUMNS.items() if column.kind != catalog.SETTING} | {
    "quasi_static_without_imposed_sliding"}
REQUIRED = ("status", "segment", "scope_diameter_mm")
CENTERLINE = "centerline"  # a patient model's centerline file (colonsim.catalog.COLUMNS)


def read_results(path) -> pd.DataFrame:
    """Read a sweep results table (Parquet or CSV) and check the columns the surrogate needs."""
    path = check_input(path, "results table", TABLE_MAX_BYTES)
    try:
        frame = pd.read_csv(path) if path.suffix.lower() == ".csv" else pd.read_parquet(path)
    except Exception as exc:  # pyarrow and pandas raise many types for a damaged file
        raise ColonsimError(f"cannot read results table {path}: {str(exc).splitlines()[0]}") from None
    return check_results(frame, str(path))


def read_query_file(path) -> pd.DataFrame:
    """The queries of a CSV file (``colonsim predict --csv``), one a row, read within
    :data:`colonsim.limits.QUERY_MAX_BYTES`; a file with a header and no rows is refused."""
    import io

    text = read_input_text(path, "query file", QUERY_MAX_BYTES)
    try:
        frame = pd.read_csv(io.StringIO(text))
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise ColonsimError(f"cannot read {path}: {str(exc).splitlines()[0]}") from None
    if frame.empty:
        raise ColonsimError(f"query file {path} has a header ({', '.join(map(str, frame.columns))}) but no rows; add "
                            "one query a row")
    return frame


def check_results(frame: pd.DataFrame, name="results table") -> pd.DataFrame:
    """The table with its required columns checked, the segment names normalized and the inputs
    and outputs the surrogate reads made numeric."""
    missing = [c for c in REQUIRED if c not in frame.columns]
    if missing:
        raise ColonsimError(f"{name} lacks the column(s) {', '.join(missing)}; is it a sweep's results table?")
    frame = frame.reset_index(drop=True)
    segments = catalog.segment_names()
    blank = frame["segment"].isna() | (frame["segment"].astype(str).str.strip() == "")
    if blank.any():
        raise ColonsimError(f"{name}: {int(blank.sum())} row(s) have no segment ({_rows(frame, blank)}); fill it in "
                            f"({', '.join(segments)}) or remove those rows")
    frame["segment"] = frame["segment"].astype(str).str.strip().str.lower()
    unknown = sorted(set(frame["segment"]) - set(segments))
    if unknown:
        raise ColonsimError(f"{name} has unknown segment(s) {', '.join(unknown)}; expected {', '.join(segments)}")
    frame["segment"] = anatomy_segments(frame, name)
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


def model_segment(segment, centerline=None) -> str:
    """The segment the surrogate models a run under: its colon model, or for a model that reads a
    patient's centerline file ``"<model>:<file stem>"``, one model per anatomy (runs on two
    patients' colons are not samples of one function)."""
    model = catalog.COLON_MODELS.get(segment)
    if model is None or not model.reads_centerline or not centerline:
        return segment
    return f"{segment}:{Path(str(centerline).replace(chr(92), '/')).stem.lower()}"


def anatomy_segments(frame: pd.DataFrame, name="results table") -> pd.Series:
    """:func:`model_segment` of every row; refuses a patient run without its file and two
    different files of one name."""
    segment = frame["segment"]
    if CENTERLINE not in frame.columns:
        return segment
    reads = segment.map(lambda s: catalog.COLON_MODELS[s].reads_centerline)
    files = frame[CENTERLINE].fillna("").astype(str).str.strip()
    if (reads & (files == "")).any():
        raise ColonsimError(f"{name}: {_rows(frame, reads & (files == ''))} run a patient model without a "
                            f"{CENTERLINE}; fill in the file or remove those rows")
    modelled = pd.Series([model_segment(s, f) for s, f in zip(segment, files)], index=frame.index)
    clash = {m for m in set(modelled[reads]) if files[reads & (modelled == m)].nunique() > 1}
    if clash:
        raise ColonsimError(f"{name}: runs on different centerline files named "
                            f"{', '.join(sorted(m.partition(':')[2] for m in clash))}; give each "
                            "patient's file its own name so the surrogate can tell the anatomies apart")
    return modelled


def _rows(frame: pd.DataFrame, mask) -> str:
    """The rows of ``mask`` as a user finds them: by run key if the table has one, else by data row."""
    mask = np.asarray(mask, dtype=bool)
    index = np.flatnonzero(mask)
    names = ([f"run {k}" for k in frame["key"].to_numpy()[index[:3]]] if "key" in frame.columns
             else [f"data row {i + 1}" for i in index[:3]])
    return ", ".join(names) + (f" and {len(index) - 3} more" if len(index) > 3 else "")


def numeric_column(frame: pd.DataFrame, column, name="results table") -> pd.Series:
    """``frame[column]`` as floats (blank = NaN); a text that is no number is an error naming the row."""
    if pd.api.types.is_numeric_dtype(frame[column]):  # numbers already (a sweep's Parquet): nothing to check
        return frame[column].astype(float)
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

    Inputs absent from the table, or undefined (NaN) in every run (C11 of a law without it), are
    neither: a query may not set them."""
    varying, fixed = [], {}
    for name in inputs:
        if name not in runs.columns or runs[name].isna().all():
            continue
        if runs[name].isna().any():
            raise ColonsimError(f"input column {name} has missing values in {int(runs[name].isna().sum())} of "
                                f"{len(runs)} successful runs (rows of an older colonsim, or wall laws with and without "
                                "that term); fit runs that all have it")
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


# The catalog's named scopes in mm (colonsim.catalog.NAMED_SCOPES); a sweep table's own scope
# column takes precedence.
NAMED_SCOPES_MM = {name: round(scope.diameter * 1e3, 6) for name, scope in catalog.NAMED_SCOPES.items()}
STANDARD_SCOPE = catalog.standard_scope().name


def scope_diameter_mm(spec, known=None) -> float:
    """Outer diameter (mm) of a scope given as :func:`colonsim.catalog.parse_scope` reads it, or by
    a name the sweep ran (``known``: name -> mm, as the table recorded it)."""
    key = str(spec).strip().lower()
    if known and key in known:
        return known[key]
    # back to mm; 9 decimals keep every typed value exact
    return round(catalog.parse_scope(spec)[1] * 1e3, 9)


def target_unit(target) -> str:
    """Unit of an output column (colonsim.catalog.COLUMNS; "" for none or an unknown column)."""
    return catalog.column_unit(target)
