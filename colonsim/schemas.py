"""What a file colonsim wrote must hold when colonsim reads it back, checked in one place per kind.

A file the program wrote can come back edited by hand: a column renamed, dropped or turned into
text, a key changed, a parameter set to NaN. Read as if it were right, it grows into tables with
both columns, a case run twice, a run lost after its work was done, or ``nan`` in a material card.
Each kind of file has one check here, called where the file is read, before anything runs or is
written; a file that fails is refused in one line naming the column or field and how to recover.

- **Results table** of a sweep (:func:`check_results_table`). Its columns are
  :data:`colonsim.catalog.COLUMNS`, read from the catalog, so a column added there is checked
  from then on. *Required* are ``key`` and ``status``, which identify a run and say whether it
  finished; without them no row can be matched to a case. Every other column is optional: a table
  written before a column existed lacks it, and the sweep reads it as the column's absent value.
  Whether a missing input column mattered is decided by the keys: every row's ``key`` must equal
  the hash of its inputs (the caller's ``key_of``, :meth:`InsertionCase.key`), so a dropped,
  emptied or edited input, or an edited key, leaves a row whose key no longer matches and the
  table is refused. A column that is present must hold what the sweep writes there (numbers,
  text or true/false flags, ``types``), numbers must not be infinite, ``status`` is ``ok`` or
  ``failed``, and no key appears twice.
- **Sweep document** ``sweep.json`` (:func:`check_sweep_document`): the keys of the sweep a
  folder holds, as text, as many as it says it runs.
- **Sweep folder** (:func:`check_run_folders`): every finished (``ok``) row has its run folder
  with its ``summary.json``.
- **Material document** ``material.json`` (:func:`check_material_document`): a law, and its
  parameters as finite numbers in Pa.
- **Mode manifest** of a calibration (:func:`check_manifest_columns`): its columns are the known
  ones (a misspelt ``weight`` is named, not ignored) and no file is listed twice.

A surrogate's files (``MODEL.json`` + ``MODEL.npz``) have their own check where they are loaded,
:mod:`colonsim.surrogate.store_checks`.

Ground floor: imports nothing of colonsim but the catalog and the errors; what a row's key is
comes from the caller.
"""

from __future__ import annotations

import difflib
import math
from pathlib import Path

from colonsim import catalog
from colonsim.errors import ColonsimError

NUMBER, TEXT, FLAG = "numbers", "text", "true/false flags"
REQUIRED_COLUMNS = ("key", "status")  # a run's identity: see the module
STATUSES = ("ok", "failed")
RESULTS_RECOVERY = ("restore the table as the sweep wrote it, or run the sweep into a new --out; nothing was run "
                    "or written")


def _rows(keys) -> str:
    keys = [str(k) for k in keys]
    return ", ".join(f"run {k}" for k in keys[:3]) + (f" and {len(keys) - 3} more" if len(keys) > 3 else "")


def _kind_of(series) -> str:
    """NUMBER, TEXT or FLAG: what a pandas column holds (an all-missing column holds anything)."""
    import pandas as pd

    if pd.api.types.is_bool_dtype(series):
        return FLAG
    if pd.api.types.is_numeric_dtype(series):
        return NUMBER
    values = series.dropna()
    if len(values) and all(isinstance(v, bool) for v in values):
        return FLAG
    if len(values) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
        return NUMBER
    return TEXT


def _holds(series, kind) -> bool:
    if series.isna().all():
        return True  # a column of a table written before the value existed: missing throughout
    found = _kind_of(series)
    return found == kind or (kind == FLAG and found == NUMBER and set(series.dropna().unique()) <= {0, 1})


def check_results_table(frame, name, types, key_of=None):
    """Refuse a sweep's results table that is not as the sweep wrote it (see the module).

    Parameters
    ----------
    frame : DataFrame
        The table as read.
    name : str
        How the user knows the file (its path).
    types : dict
        ``{column: NUMBER | TEXT | FLAG}``: what the sweep writes in each catalog column.
    key_of : callable(row dict) -> str, or None
        The key of a row's inputs; None: keys are not checked against inputs.

    Returns
    -------
    The table, unchanged.
    """
    missing = [c for c in REQUIRED_COLUMNS if c not in frame.columns]
    if missing:
        raise ColonsimError(f"{name} lacks the column(s) {', '.join(missing)}, which identify its runs; "
                            f"{RESULTS_RECOVERY}")
    unknown = [c for c in frame.columns if c not in catalog.COLUMNS and c not in types]
    for column in (c for c in {*catalog.COLUMNS, *types} if c not in frame.columns):
        renamed = difflib.get_close_matches(column, unknown, n=1, cutoff=0.8)
        if renamed:  # a column of a removed input stays readable; one that looks like a renamed one does not
            raise ColonsimError(f"{name}: column {renamed[0]!r} is not one the sweep writes and {column} is missing "
                                f"(renamed?); {RESULTS_RECOVERY}")
    for column in frame.columns:
        kind = types.get(column)
        if kind is None:
            continue
        series = frame[column]
        if not _holds(series, kind):
            bad = series[series.notna()].iloc[0]
            raise ColonsimError(f"{name}: column {column} holds {type(bad).__name__} values ({bad!r}) where the sweep "
                                f"writes {kind}; {RESULTS_RECOVERY}")
        if kind == NUMBER:
            values = series.astype(float)
            infinite = values.abs() == math.inf
            if infinite.any():
                raise ColonsimError(f"{name}: column {column} is infinite in {_rows(frame['key'][infinite])}; "
                                    f"{RESULTS_RECOVERY}")
    status = frame["status"].astype(str)
    odd = ~status.isin(STATUSES)
    if odd.any():
        raise ColonsimError(f"{name}: status {status[odd].iloc[0]!r} in {_rows(frame['key'][odd])} is neither ok nor "
                            f"failed; {RESULTS_RECOVERY}")
    keys = frame["key"]
    blank = keys.isna() | (keys.astype(str).str.strip() == "")
    if blank.any():
        raise ColonsimError(f"{name}: {int(blank.sum())} row(s) have no key; {RESULTS_RECOVERY}")
    twice = keys[keys.duplicated()]
    if len(twice):
        raise ColonsimError(f"{name}: key {twice.iloc[0]} is on {int((keys == twice.iloc[0]).sum())} rows (a run "
                            f"recorded twice); {RESULTS_RECOVERY}")
    if key_of is not None:
        for row in frame.to_dict("records"):
            _check_key(row, name, key_of, [c for c in types if c not in frame.columns])
    return frame


def _check_key(row, name, key_of, absent):
    try:
        key = key_of(row)
    except ColonsimError as exc:
        raise ColonsimError(f"{name}: the inputs of run {row['key']} cannot be read back ({exc}); "
                            f"{RESULTS_RECOVERY}") from None
    except (TypeError, ValueError) as exc:
        raise ColonsimError(f"{name}: the inputs of run {row['key']} cannot be read back ({type(exc).__name__}: "
                            f"{exc}); {RESULTS_RECOVERY}") from None
    if key == row["key"]:
        return
    empty = [c for c, v in row.items() if catalog.COLUMNS.get(c) is not None and catalog.COLUMNS[c].kind == catalog.INPUT
             and isinstance(v, float) and math.isnan(v)]
    hints = []
    if empty:
        hints.append(f"empty input(s) {', '.join(empty[:4])}")
    inputs_absent = [c for c in absent if catalog.COLUMNS.get(c) is not None
                     and catalog.COLUMNS[c].kind in (catalog.INPUT, catalog.SETTING)]
    if inputs_absent:
        hints.append(f"input column(s) {', '.join(inputs_absent[:4])} missing, read as their defaults")
    why = f" ({'; '.join(hints)})" if hints else " (an input or the key was edited)"
    raise ColonsimError(f"{name}: the key of run {row['key']} is not the hash of its inputs{why}; {RESULTS_RECOVERY}")


def check_run_folders(folder, frame, summary="summary.json"):
    """Refuse a sweep folder whose finished (``ok``) rows lack their run folder ``runs/<key>/``."""
    folder = Path(folder)
    lost = [k for k, s in zip(frame["key"], frame["status"]) if s == "ok" and not (folder / "runs" / str(k) / summary).is_file()]
    if lost:
        raise ColonsimError(f"{folder}: {_rows(lost)} recorded as finished but runs/<key>/{summary} is missing; "
                            f"{RESULTS_RECOVERY}")


def check_sweep_document(doc, path) -> dict:
    """The ``sweep.json`` of a sweep folder: an object whose ``keys`` are the text keys of its
    runs, as many as its ``runs`` says, and whose ``name`` and ``toml`` are text (or null)."""
    fix = "restore it as the sweep wrote it, or use another --out"
    if not isinstance(doc, dict):
        raise ColonsimError(f"{path} is not a JSON object; {fix}")
    keys = doc.get("keys")
    if not isinstance(keys, list) or not all(isinstance(k, str) and k for k in keys):
        raise ColonsimError(f"{path}: field keys is not a list of run keys; {fix}")
    if len(set(keys)) != len(keys):
        raise ColonsimError(f"{path}: field keys names a run twice; {fix}")
    runs = doc.get("runs", len(keys))
    if isinstance(runs, bool) or not isinstance(runs, int) or runs != len(keys):
        raise ColonsimError(f"{path}: field runs ({runs!r}) is not the number of keys ({len(keys)}); {fix}")
    for field in ("name", "toml"):
        if doc.get(field) is not None and not isinstance(doc[field], str):
            raise ColonsimError(f"{path}: field {field} is not text; {fix}")
    return doc


def check_material_document(doc, path, parameter_names) -> dict:
    """The parameters (``{name: Pa}``) of a ``material.json``: every one of ``parameter_names``
    (the law's) present, a finite number; the units Pa."""
    fix = "recalibrate, or restore the file colonsim calibrate wrote"
    params = doc.get("parameters") if isinstance(doc, dict) else None
    if not isinstance(params, dict) or doc.get("units", "Pa") != "Pa":
        raise ColonsimError(f"material file {path} has no parameters in Pa; {fix}")
    for name in parameter_names:
        value = params.get(name)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise ColonsimError(f"material file {path}: parameter {name} is {value!r}, not a finite number; {fix}")
    return {n: float(params[n]) for n in parameter_names}


def check_manifest_columns(columns, path, required, optional):
    """Refuse a manifest column that is neither ``required`` nor ``optional`` (naming the likely
    one meant), or a required one missing."""
    columns = [c.strip() for c in columns]
    missing = [c for c in required if c not in columns]
    if missing:
        raise ColonsimError(f"{path}: manifest lacks the column(s) {', '.join(missing)}; expected {','.join(required)}")
    known = (*required, *optional)
    for column in columns:
        if column not in known:
            close = difflib.get_close_matches(column.lower(), known, n=1)
            hint = f"did you mean {close[0]}?" if close else f"the known ones are {', '.join(known)}"
            raise ColonsimError(f"{path}: unknown column {column!r} ({hint}); rename or remove it")
    twice = [c for c in known if columns.count(c) > 1]
    if twice:
        raise ColonsimError(f"{path}: column {twice[0]} is given twice; keep one")


def check_listed_once(items, path, what="file"):
    """Refuse a manifest that lists one ``what`` twice: ``items`` are (name, resolved path) pairs."""
    seen = {}
    for name, item in items:
        if item in seen:
            raise ColonsimError(f"{path}: {seen[item]!r} and {name!r} are the same {what} ({item}); a curve counted "
                                "twice weighs double in the fit: list it once (give it weight 2 if that is meant)")
        seen[item] = name
