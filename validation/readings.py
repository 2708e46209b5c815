"""Physical readings of the claims that fail: sentences built from the sweep's numbers only.

A reading says what the runs behind a failed comparison did (their end and largest
deformation, where the RSJ curve peaks and falls, how the run ended) and whether the claim's
comparison holds on the largest deformation instead of the end value. It interprets nothing the
numbers do not show.
"""

from __future__ import annotations

import math

from colonsim.insertion.study.claims import NOT_REPRODUCED, advantage
from colonsim.insertion.study.reference import SOURCE_RSJ_CM

from .sections import rsj_facts
from .sweeps import find_case

ENDS = {"tip_past_end": "the tip 2 cm past the junction", "far_end": "the tip at the far end of the exit",
        "length_used": "the scope's available length pushed in", "jam": "a jam"}


def cm(v):
    return "-" if v is None or not math.isfinite(v) else f"{v:.2f} cm"


def _run(main, segment, scope, **inputs):
    case = find_case(main.cases, segment, scope, **inputs)
    row, _ = main.run(case) if case else (None, None)
    return row


def _value(row, column):
    return math.nan if row is None else float(row[column])


def _rsj(main, scope, d, mu, column):
    """``column`` of the RSJ run of ``scope`` at D = ``d`` mm and mu (NaN when it is missing)."""
    return _value(_run(main, "rsj", scope, diameter_mm=d, friction=mu), column)


def _failing(claim):
    """The comparisons of a claim that fail."""
    return [e for e in claim["evidence"] if not e["holds"]]


def _rsj_curve(facts, scope, d):
    """One RSJ run's curve in words: A, B, C with their depths, the tip's entry into the fixed exit, the end."""
    depth = facts["points_depth_cm"]
    parts = [f"{scope.upper()} D {d:g} mm: A = {cm(facts['A_cm'])} at {depth['A']:.1f} cm of push"
             if "A" in depth else f"{scope.upper()} D {d:g} mm: no point A (no first maximum followed by a minimum)"]
    if "B" in depth and "C" in depth:
        parts.append(f"B = {cm(facts['B_cm'])} at {depth['B']:.1f} cm, C = {cm(facts['C_cm'])} at {depth['C']:.1f} cm "
                     f"(a rise of {facts['C_cm'] - facts['B_cm']:.2f} cm from B)")
    if facts["junction_entry_depth_cm"] is not None:
        parts.append(f"the tip reaches the sigmoid's fixed end ({facts['junction_cm']:.1f} cm along the centerline) at "
                     f"{facts['junction_entry_depth_cm']:.1f} cm of push with {cm(facts['junction_entry_deformation_cm'])}")
    parts.append(f"the run ends with {ENDS.get(facts['ended_by'], facts['ended_by'])} at {facts['end_depth_cm']:.1f} cm "
                 f"with {cm(facts['final_cm'])}")
    text = "; ".join(parts)
    entry = facts["junction_entry_deformation_cm"]
    if entry is not None and math.isfinite(facts["final_cm"]) and facts["final_cm"] < entry:
        text += (f". Once the tip is in the fixed exit the sigmoid relaxes: {entry - facts['final_cm']:.2f} cm of "
                 "deformation is lost before the end of the run")
    return text + "."


def _rsj_ordering(claim, main):
    out, rises, source_rises, losses = [], [], [], []
    for e in _failing(claim):
        d = e["diameter_mm"]
        if e["check"] == "C > A":
            scope = e["scope"].lower()
            row = _run(main, "rsj", scope, diameter_mm=d, friction=0.0)
            facts, _, _ = rsj_facts(main, row)
            src = SOURCE_RSJ_CM[(scope, d)]
            rises.append(facts["C_cm"] - facts["B_cm"])
            source_rises.append(src["C"] - src["A"])
            if facts["junction_entry_deformation_cm"] is not None:
                losses.append(facts["junction_entry_deformation_cm"] - facts["final_cm"])
            out.append(_rsj_curve(facts, scope, d) + f" The source rises from A = {src['A']:.3f} to "
                       f"C = {src['C']:.3f} cm (+{src['C'] - src['A']:.2f} cm).")
        else:
            p = e["check"][-1]
            src = {s: SOURCE_RSJ_CM[(s, d)][p] for s in ("sdc", "pdc", "utc")}
            out.append(f"D {d:g} mm, point {p}: SDC {cm(e['SDC_cm'])}, PDC {cm(e['PDC_cm'])}, UTC {cm(e['UTC_cm'])} "
                       f"(source: SDC {src['sdc']:.3f}, PDC {src['pdc']:.3f}, UTC {src['utc']:.3f} cm).")
    if len(rises) > 1:
        summary = (f"C <= A in {len(rises)} runs: the rise from B to C is {_span(rises)} cm, the source's rise from A "
                   f"to C {_span(source_rises)} cm")
        if losses:
            summary += (f"; between the tip reaching the sigmoid's fixed end and the end of the run the deformation "
                        f"changes by {_span([-x for x in losses], signed=True)} cm")
        out.insert(0, summary + ".")
    return out


def _span(values, signed=False):
    values = [v for v in values if math.isfinite(v)]
    if not values:
        return "-"
    fmt = "{:+.2f}" if signed else "{:.2f}"
    lo, hi = fmt.format(min(values)), fmt.format(max(values))
    return lo if lo == hi else f"{lo} to {hi}"


def _rsj_scopes(claim, main):
    """sc_deform_less_rsj: the failing pairs, their largest values and how they ended."""
    out, on_max = [], []
    for e in _failing(claim):
        d, mu, sc = e["diameter_mm"], e["friction"], e["scope"].lower()
        small, sdc = _run(main, "rsj", sc, diameter_mm=d, friction=mu), _run(main, "rsj", "sdc", diameter_mm=d, friction=mu)
        m_sc, m_sdc = _value(small, "max_deformation_cm"), _value(sdc, "max_deformation_cm")
        on_max.append(m_sc < m_sdc)
        out.append(f"D {d:g} mm, mu {mu:g}: {sc.upper()} ends at {cm(e['scope_cm'])} ({small['ended_by']}), the SDC at "
                   f"{cm(e['sdc_cm'])} ({sdc['ended_by']}); largest during the run {sc.upper()} {cm(m_sc)}, SDC {cm(m_sdc)}.")
    if on_max:
        out.append(f"On the largest deformation during the run the comparison holds in {sum(on_max)} of these "
                   f"{len(on_max)} cases" + (": they fail on the value at the end of the run only." if all(on_max) else "."))
    return out


def _rsj_diameters(claim, main):
    out = []
    for e in _failing(claim):
        sc, mu = e["scope"].lower(), e["friction"]
        finals = {d: (_rsj(main, sc, d, mu, "final_deformation_cm"), _rsj(main, "sdc", d, mu, "final_deformation_cm"))
                  for d in (23.0, 36.0)}
        out.append(f"{sc.upper()}, mu {mu:g}: reduction {e['reduction_D23']:.0%} at D 23 mm "
                   f"({sc.upper()} {cm(finals[23.0][0])} vs SDC {cm(finals[23.0][1])}) against {e['reduction_D36']:.0%} "
                   f"at D 36 mm ({sc.upper()} {cm(finals[36.0][0])} vs SDC {cm(finals[36.0][1])}).")
    return out


def _rsj_friction(claim, main):
    out = []
    for e in _failing(claim):
        d, sc = e["diameter_mm"], e["scope"].lower()
        change = {s: _rsj(main, s, d, 0.1, "max_deformation_cm") - _rsj(main, s, d, 0.0, "max_deformation_cm")
                  for s in (sc, "sdc")}
        out.append(f"D {d:g} mm: from mu 0 to 0.1 the {sc.upper()}'s end value changes by {e['scope_change_cm']:+.2f} cm "
                   f"({e['scope_relative_change']:+.0%}), the SDC's by {e['sdc_change_cm']:+.2f} cm "
                   f"({e['sdc_relative_change']:+.0%}); the largest deformation during the run changes by "
                   f"{change[sc]:+.2f} cm ({sc.upper()}) and {change['sdc']:+.2f} cm (SDC), so on it the claim "
                   f"{'holds' if abs(change[sc]) < abs(change['sdc']) else 'fails too'}.")
    return out


def _angles(claim, main, segment, flexure_rows, flexure_source):
    symbol = "alpha" if segment == "rsf" else "beta"
    angles = sorted({float(k.rsplit("_", 1)[-1]) for e in claim["evidence"] for k in e if k.startswith("advantage_")})
    out = []
    for e in _failing(claim):
        sc = e["scope"].lower()
        parts, on_max = [], []
        for a in angles:
            small, sdc = _run(main, segment, sc, angle_deg=a, friction=0.0), _run(main, segment, "sdc", angle_deg=a, friction=0.0)
            m = (_value(small, "max_deformation_cm"), _value(sdc, "max_deformation_cm"))
            on_max.append(advantage(m[1], m[0]))
            parts.append(f"{symbol} {a:g}: {sc.upper()} {e[f'{symbol}_{a:g}_scope_cm']:.2f} (largest {m[0]:.2f}) vs SDC "
                         f"{e[f'{symbol}_{a:g}_sdc_cm']:.2f} (largest {m[1]:.2f}) cm at the end "
                         f"({small['ended_by']} / {sdc['ended_by']}), advantage {e[f'advantage_{symbol}_{a:g}']:.0%}")
        out.append(f"{sc.upper()}: " + "; ".join(parts) + ". On the largest deformation during the run the advantage is "
                   + ", ".join(f"{x:.0%}" for x in on_max) + f" at {symbol} = " + ", ".join(f"{a:g}" for a in angles) + ".")
    turns = [r for r in flexure_rows if r["segment"] == segment and r["advantage"] is not None]
    if turns:
        out.append(f"UTC advantage at other flexure turns ({flexure_source}): " + "; ".join(
            f"{symbol} {r['angle_deg']:g}, flexure {r['flexure_angle_deg']:g} deg: {r['advantage']:.0%}" for r in turns) + ".")
    return out


def add_readings(claims, main, flexure_rows, flexure_source="section 10"):
    """Give every NOT REPRODUCED claim a ``reading``: a list of sentences from the numbers (``flexure_source``:
    where the flexure turns' rows come from, as the reading cites them)."""
    for claim in claims:
        claim["reading"] = []
        if claim["verdict"] != NOT_REPRODUCED:
            continue
        name = claim["name"]
        if name == "rsj_ordering":
            claim["reading"] = _rsj_ordering(claim, main)
        elif name == "sc_deform_less_rsj":
            claim["reading"] = _rsj_scopes(claim, main)
        elif name == "reduction_larger_at_small_diameter":
            claim["reading"] = _rsj_diameters(claim, main)
        elif name == "sc_less_friction_sensitive":
            claim["reading"] = _rsj_friction(claim, main)
        elif name.startswith("angle_dependence_"):
            claim["reading"] = _angles(claim, main, name.rsplit("_", 1)[-1], flexure_rows, flexure_source)
    return claims
