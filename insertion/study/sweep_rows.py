"""One row of a sweep's results table per run (docs/sweeps.md, "Results"): its identity, every
input and every output, in the columns :data:`colonsim.catalog.COLUMNS` defines.
"""

from __future__ import annotations

import dataclasses
import math

from colonsim import catalog
from colonsim.insertion.anatomy.scopes import colonoscope
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.material_samples import material_columns
from colonsim.provenance import code_version

# the table's columns, units and meanings: colonsim.catalog.COLUMNS
IDENTITY = catalog.columns(catalog.PROVENANCE)
OUTPUTS = catalog.columns(catalog.OUTPUT)


def input_columns() -> list:
    """Every InsertionCase field (from the dataclass), the derived scope diameter, wall moduli and
    tissue stiffness."""
    return [f.name for f in dataclasses.fields(InsertionCase)] + ["scope_diameter_mm", catalog.WALL_MU0, catalog.WALL_C11,
                                                                  catalog.TISSUE_STIFFNESS]


# each field with what its column holds when the field is None: a column keeps one type, "" for
# absent strings, NaN for absent numbers
_ABSENT = tuple((f.name, "" if "str" in str(f.type) else math.nan) for f in dataclasses.fields(InsertionCase))


def input_row(case) -> dict:
    """The input columns of ``case``'s results row (:func:`input_columns`)."""
    row = {}
    for name, absent in _ABSENT:
        value = getattr(case, name)
        row[name] = absent if value is None else value
    row["scope_diameter_mm"] = round(colonoscope(case.scope).diameter * 1e3, 6)  # 11.3, not 11.299999999999999
    row.update(material_columns(case))  # drawn parameters as JSON text, mu0 and C11 in kPa, stiffness
    return row


def _outputs(summary) -> dict:
    """The scalar outputs of a summary (None for a failed run): NaN when undefined, cm and N."""
    def number(value):
        return float(value) if isinstance(value, (int, float)) else math.nan

    summary = summary or {}
    points = summary.get("points_cm") or {}
    out = {name: number(summary.get(name)) for name in OUTPUTS}
    for p in "ABC":
        out[f"point_{p}_cm"] = number((points.get(p) or {}).get("deformation_cm"))
    qs = summary.get("quasi_static") or {}
    # the ringing ratio of the push force and its verdict (colonsim.insertion.case.outcomes); the
    # energy check as information
    out["ringing_ratio"] = number(qs.get("ringing_ratio"))
    out["quasi_static"] = bool(qs.get("holds", False))
    snaps = qs.get("snap_throughs") or {}
    out["snap_throughs"] = number(snaps.get("count"))
    out["ringing_left_out_share"] = number(snaps.get("left_out_share"))
    out["kinetic_energy_check"] = bool((qs.get("energy") or {}).get("holds", False))
    out["came_to_rest"] = bool((summary.get("at_rest") or {}).get("came_to_rest", False))
    end = summary.get("end") or {}
    out["ended_by"] = str(summary.get("ended_by", ""))  # colonsim.insertion.case.run_summary.ENDINGS
    for name, key in (("end_depth_cm", "depth_cm"), ("end_push_force_N", "push_force_N"),
                      ("end_contact_force_N", "contact_force_N")):
        out[name] = number(end.get(key))
    return out


def result_row(case, outcome, timeseries_path="") -> dict:
    """The table row of one run (``outcome`` from :func:`colonsim.insertion.study.sweep_worker.execute`)."""
    ok = outcome["status"] == "ok"
    return {"key": case.key(), "status": outcome["status"], "error": outcome.get("error", ""),
            "wall_time_s": float(outcome["wall_time_s"]), "timeseries_path": timeseries_path if ok else "",
            "finished_at": outcome["finished_at"], "git_commit": code_version()["git_commit"] or "",
            **input_row(case), **_outputs(outcome.get("summary") if ok else None)}
