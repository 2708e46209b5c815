"""A sweep's results table read back: what each column holds, and each row's key rebuilt from
its inputs, for the check of :func:`colonsim.schemas.check_results_table`.

Every table the sweep reads (to resume, to reuse another folder's runs, or for a report) passes
:func:`read_table`, before any run starts or anything is written.
"""

from __future__ import annotations

import dataclasses
import json
import math
from functools import lru_cache
from pathlib import Path

import pandas as pd

from colonsim import schemas
from colonsim.errors import ColonsimError
from colonsim.insertion.case.insertion_case import ABSENT_AT
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.sweep_rows import result_row

_FIELDS = dataclasses.fields(InsertionCase)


@lru_cache(maxsize=1)
def column_types() -> dict:
    """``{column: NUMBER | TEXT | FLAG}`` as the recorder writes them (a failed default run's row)."""
    row = result_row(InsertionCase(), {"status": "failed", "wall_time_s": 0.0, "finished_at": ""})
    kinds = {}
    for name, value in row.items():
        kinds[name] = (schemas.FLAG if isinstance(value, bool) else schemas.NUMBER if isinstance(value, (int, float))
                       else schemas.TEXT)
    return kinds


def _missing(value) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value)) or value is pd.NA or (
        isinstance(value, str) and value == "")


def case_from_row(row) -> InsertionCase:
    """The case a results row records: an input the row leaves empty at its default; an input the
    table lacks at the value that made the runs of before the input existed (``ABSENT_AT``: the
    time-step estimate of a table of before is "bounds", whatever today's default)."""
    defaults = InsertionCase()
    values = {}
    for f in _FIELDS:
        value = row.get(f.name)
        if f.name not in row and f.name in ABSENT_AT:  # a dict or a Series: "in" looks at its keys
            value = ABSENT_AT[f.name]
        elif _missing(value):
            value = getattr(defaults, f.name)
        elif f.name == "material_parameters" and isinstance(value, str):
            value = json.loads(value)
        elif hasattr(value, "item"):  # a numpy scalar
            value = value.item()
        values[f.name] = value
    return InsertionCase(**values)


def row_key(row) -> str:
    """The key of the inputs a results row records (:meth:`InsertionCase.key`)."""
    return case_from_row(row).key()


def read_table(path) -> pd.DataFrame:
    """The results table at ``path``, checked (:func:`colonsim.schemas.check_results_table`)."""
    path = Path(path)
    try:
        table = pd.read_parquet(path)
    except Exception as exc:  # pyarrow raises many types for a damaged file
        raise ColonsimError(f"cannot read {path} ({str(exc).splitlines()[0] if str(exc) else type(exc).__name__}); "
                            f"{schemas.RESULTS_RECOVERY}") from None
    return schemas.check_results_table(table, str(path), column_types(), row_key)
