"""Readings of the source's claims across the distal-resistance levels: sentences built from the
``resistance`` sweep's numbers only (the rows of :func:`validation.resistance.resistance_section`).

For every claim that is not reproduced at any level, a reading says what the runs did at each
level with the quantities that decide it: the scopes' lag (pushed depth minus the tip's advance,
the length of scope that has buckled behind the held tip), their final and largest deformation,
the peak contact force, and the RSJ's points. It interprets nothing the numbers do not show.
"""

from __future__ import annotations

import math

from colonsim.insertion.study.claims import NO_DEFORMATION_CM, NOT_REPRODUCED

SCOPES = ("utc", "pdc", "sdc")


def _cm(v):
    return "-" if v is None or not math.isfinite(v) else f"{v:.2f}"


def _at(rows, segment, level, **where):
    """Scope role -> row of ``segment`` at ``level`` whose columns match ``where``."""
    return {r["role"]: r for r in rows if r["segment"] == segment and r["level_N"] == level
            and all(r[k] == v for k, v in where.items())}


def _per_scope(runs, column):
    return " / ".join(_cm(runs[s][column]) if s in runs else "-" for s in SCOPES)


def _falls_with_diameter(runs, column):
    values = [runs[s][column] for s in SCOPES if s in runs and runs[s][column] is not None]
    return len(values) == len(SCOPES) and values[0] > values[1] > values[2]


def _levels(rows):
    return sorted({r["level_N"] for r in rows})


def angle_reading(rows, segment) -> list:
    """RSF / THF at the largest angle: per level the lag, final and largest deformation of the
    three scopes; whether the lag falls with the scope's diameter; where the thinner scopes deform
    the colon more than the SDC."""
    symbol = "alpha" if segment == "rsf" else "beta"
    angles = sorted({r["angle_deg"] for r in rows if r["segment"] == segment})
    if not angles:
        return []
    angle = angles[-1]
    out, reversed_at, ordered_lag, held = [], [], [], []
    for level in _levels(rows):
        runs = _at(rows, segment, level, angle_deg=angle)
        if not runs:
            continue
        out.append(f"{level:g} N, {symbol} {angle:g} deg (UTC / PDC / SDC): lag {_per_scope(runs, 'max_lag_cm')} cm, "
                   f"final {_per_scope(runs, 'final_deformation_cm')} cm, largest "
                   f"{_per_scope(runs, 'max_deformation_cm')} cm, peak contact {_per_scope(runs, 'peak_contact_force_N')} N.")
        if level > 0:
            held.append(level)
            ordered_lag.append(_falls_with_diameter(runs, "max_lag_cm"))
        sdc = runs.get("sdc")
        if sdc and any(s in runs and runs[s]["final_deformation_cm"] > sdc["final_deformation_cm"] + NO_DEFORMATION_CM
                       for s in ("utc", "pdc")):
            reversed_at.append(level)
    if held:
        lag_note = ("falls with the scope's diameter at every level that holds the tip"
                    if all(ordered_lag) else
                    f"falls with the scope's diameter at {sum(ordered_lag)} of the {len(held)} levels that hold the tip")
        out.append(f"The lag {lag_note} ({', '.join(f'{x:g}' for x in held)} N): the thinner the scope, the more of it "
                   "buckles behind the held tip.")
    if reversed_at:
        out.append(f"A small-caliber scope ends with more deformation than the SDC (by more than {NO_DEFORMATION_CM:g} cm) "
                   f"at {', '.join(f'{x:g}' for x in reversed_at)} N: there the advantage the claim needs is negative.")
    zero = _at(rows, segment, 0.0, angle_deg=angle)
    if zero:
        lag = max(r["max_lag_cm"] for r in zero.values())
        grows = _falls_with_diameter({s: {"v": -r["max_deformation_cm"]} for s, r in zero.items()}, "v")
        out.append(f"At 0 N nothing holds the tip (lag at most {_cm(lag)} cm): the largest deformation (UTC / PDC / SDC "
                   f"{_per_scope(zero, 'max_deformation_cm')} cm) "
                   + ("grows with the scope's diameter, the source's direction." if grows
                      else "does not grow with the scope's diameter."))
    return out


def reduction_reading(rows) -> list:
    """RSJ, D 23 against D 36 mm: per level the final deformation, lag and peak contact force of
    the three scopes in both colons."""
    out, spreads = [], []
    for level in _levels(rows):
        narrow, wide = _at(rows, "rsj", level, diameter_mm=23.0), _at(rows, "rsj", level, diameter_mm=36.0)
        if not (narrow and wide):
            continue
        if level > 0:
            spreads.append((level, *(max(r["final_deformation_cm"] for r in runs.values())
                                     - min(r["final_deformation_cm"] for r in runs.values()) for runs in (narrow, wide))))
        out.append(f"{level:g} N (UTC / PDC / SDC): final {_per_scope(narrow, 'final_deformation_cm')} cm at D 23 mm, "
                   f"{_per_scope(wide, 'final_deformation_cm')} cm at D 36 mm; lag {_per_scope(narrow, 'max_lag_cm')} "
                   f"against {_per_scope(wide, 'max_lag_cm')} cm; peak contact "
                   f"{_per_scope(narrow, 'peak_contact_force_N')} against {_per_scope(wide, 'peak_contact_force_N')} N.")
    if spreads:
        closer = sum(n < w for _, n, w in spreads)
        out.append(f"With the tip held ({' / '.join(f'{x[0]:g}' for x in spreads)} N) the three scopes end "
                   f"{' / '.join(_cm(x[1]) for x in spreads)} cm apart at D 23 mm and "
                   f"{' / '.join(_cm(x[2]) for x in spreads)} cm apart at D 36 mm: closer together in the narrow colon "
                   f"at {closer} of {len(spreads)} levels, so a scope's reduction there is "
                   + ("smaller, not larger." if closer == len(spreads) else "not larger at every level."))
    return out


def ordering_reading(rows) -> list:
    """RSJ points: A across the levels (reached before the tip enters the exit, where the
    resistance acts), C's growth with the level, where C overtakes A."""
    rsj = [r for r in rows if r["segment"] == "rsj" and r["point_A_cm"] is not None and r["point_C_cm"] is not None]
    if not rsj:
        return []
    spread, out, never = 0.0, [], []
    for scope in SCOPES:
        for d in sorted({r["diameter_mm"] for r in rsj}):
            runs = sorted((r for r in rsj if r["role"] == scope and r["diameter_mm"] == d), key=lambda r: r["level_N"])
            if not runs:
                continue
            spread = max(spread, max(r["point_A_cm"] for r in runs) - min(r["point_A_cm"] for r in runs))
            over = [r["level_N"] for r in runs if r["point_C_cm"] > r["point_A_cm"]]
            levels = " / ".join(f"{r['level_N']:g}" for r in runs)
            out.append(f"{scope.upper()} D {d:g} mm: A {_cm(runs[0]['point_A_cm'])} cm; C "
                       + " / ".join(_cm(r["point_C_cm"]) for r in runs) + f" cm at {levels} N; C > A "
                       + (f"from {over[0]:g} N" if over else "at no level") + ".")
            if not over:
                never.append(f"{scope.upper()} D {d:g} mm")
    same = "is identical at every level" if spread == 0 else f"changes by at most {spread:.3f} cm across the levels"
    out.insert(0, f"Point A {same}: the first maximum comes before the tip reaches the fixed exit, where the "
                  "resistance acts. C grows with the level; it stays below A at every level for "
                  + (", ".join(never) if never else "no run") + ".")
    return out


def claim_readings(claims, rows) -> dict:
    """Claim name -> reading, for the claims not reproduced at any level (the others need none)."""
    makers = {"angle_dependence_rsf": lambda: angle_reading(rows, "rsf"),
              "angle_dependence_thf": lambda: angle_reading(rows, "thf"),
              "reduction_larger_at_small_diameter": lambda: reduction_reading(rows),
              "rsj_ordering": lambda: ordering_reading(rows)}
    out = {}
    for claim in claims:
        verdicts = [v["verdict"] for v in claim["levels"].values()]
        if verdicts and all(v == NOT_REPRODUCED for v in verdicts) and claim["name"] in makers:
            out[claim["name"]] = makers[claim["name"]]()
    return out
