"""Today's run rules applied to a results table written under earlier ones (docs/quasi_static.md).

The ringing ratio's force floor and the snap-throughs it leaves out (2026-12-07) are functions of
a run's recorded push force, and a folded tip's end a function of its recorded heading: a table
written before them is read with them applied wherever its runs' time series allow, and says so,
row by row, in the column :data:`RULES`:

- ``current``: the row was written under today's rules (it records its snap-throughs);
- ``from series``: its quasi-static verdict (and, for a folded tip, its end and its deformation
  outputs up to the fold) recomputed here from its time series;
- ``as recorded (...)``: no time series to recompute from; the row's values are those of the rules
  it was written under.

A run of before whose tip ended turned back (``tip_turned_back_cm``) would have ended at the fold:
its ``ended_by`` becomes ``tip_folded``, its end depth the fold's, and its final, largest and A/B/C
deformations and peak push force those of its series up to the fold. Its lag and contact force
are not in every series (a sweep record keeps six columns): they stay as recorded, and the row
says so. A fold that came and went before the end is not seen in a table of before.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from colonsim.catalog import TIP_FOLDED
from colonsim.insertion.anatomy.manoeuvre import SETTLE
from colonsim.insertion.case.outcomes import characteristic_points, peak_trend
from colonsim.insertion.case.ringing import push_ringing, ringing_cause, ringing_holds

RULES = "rules"
CURRENT = "current"
FROM_SERIES = "from series"
SERIES_COLUMNS = ["phase", "depth_cm", "deformation_cm", "push_force_N", "contact_nodes"]


def _series(folder, row):
    path = Path(folder) / str(row.get("timeseries_path") or "")
    if not str(row.get("timeseries_path") or "") or not path.is_file():
        return None
    try:
        return pd.read_csv(path, usecols=SERIES_COLUMNS)
    except (ValueError, OSError):  # a series without those columns (older or foreign): not recomputed
        return None


def requalified_ringing(ts) -> dict:
    """The ringing verdict of a run's time series (cm and N columns, as a run folder holds them)."""
    ring = push_ringing(ts["phase"], ts["depth_cm"] / 100, ts["push_force_N"], ts["contact_nodes"])
    return {"ringing_ratio": ring["ratio"], "quasi_static": ringing_holds(ring),
            "snap_throughs": float(len(ring["snap_throughs"])), "ringing_left_out_share": ring["left_out_share"],
            "ringing_cause": ringing_cause(ring)}


def _up_to_fold(ts, fold_cm) -> dict:
    """The deformation outputs of a series cut at the push depth ``fold_cm`` where its tip folded."""
    push = ts[ts["phase"] != SETTLE]
    cut = push[push["depth_cm"] <= fold_cm + 1e-9]
    if len(cut) < 3:
        return {}
    z, u = cut["depth_cm"].to_numpy() / 100, cut["deformation_cm"].to_numpy() / 100
    points = characteristic_points(z, z, u)
    out = {"ended_by": TIP_FOLDED, "end_depth_cm": fold_cm, "final_deformation_cm": u[-1] * 100,
           "max_deformation_cm": u.max() * 100, "peak_push_force_N": peak_trend(z, cut["push_force_N"].to_numpy())}
    for p in "ABC":
        out[f"point_{p}_cm"] = math.nan if points[p] is None else points[p]["deformation_m"] * 100
    return out


def apply_current_rules(table: pd.DataFrame, folder) -> pd.DataFrame:
    """A copy of ``table`` (a sweep's results, its run folders under ``folder``) with today's rules
    applied where its rows were written under earlier ones, and the :data:`RULES` column."""
    out = table.copy()
    for name in ("snap_throughs", "ringing_left_out_share"):
        if name not in out:
            out[name] = math.nan
    out["ringing_cause"] = ""
    out[RULES] = ""
    for i, row in out.iterrows():
        if row.get("status") != "ok":
            continue
        if np.isfinite(row.get("snap_throughs", math.nan)):
            out.at[i, RULES] = CURRENT
            continue
        ts = _series(folder, row)
        if ts is None:
            out.at[i, RULES] = "as recorded (no time series: the rules it was written under)"
            continue
        values, note = {}, FROM_SERIES
        fold = row.get("tip_turned_back_cm")
        if fold is not None and np.isfinite(fold) and row.get("ended_by") != TIP_FOLDED:
            values = _up_to_fold(ts, float(fold))
            ts = ts[ts["depth_cm"] <= float(fold) + 1e-9]  # the run ends at the fold
            note += "; tip folded: lag and contact force as recorded to the end of the run"
        values.update(requalified_ringing(ts))
        for name, value in values.items():
            out.at[i, name] = value
        out.at[i, RULES] = note
    return out
