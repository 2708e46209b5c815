"""The source's claims (docs/model.md, "Reference results") evaluated on a sweep results table.

Each function takes the table of :mod:`colonsim.insertion.study.sweep` (one row per run: ``segment``, ``scope``,
``diameter_mm``, ``friction``, ``angle_deg``, ``point_A_cm``, ``point_C_cm``,
``final_deformation_cm``, ``status``) and returns a :class:`ClaimResult` whose verdict is

- ``REPRODUCED``: every comparison the criterion names holds;
- ``NOT REPRODUCED``: every run is there and at least one comparison fails (``reason`` says which);
- ``NOT EVALUATED``: a run the criterion needs is missing or failed (``missing`` lists them);
  nothing is guessed from the runs that are there.

A run's scope is UTC, PDC or SDC by name, or by its ``scope_diameter_mm`` when that is a
catalogue or a source-mesh diameter (:func:`colonsim.catalog.scope_role`), so the source's
meshed scopes (9.2 / 11.1 / 13.3 mm) count as its UTC / PDC / SDC.

The criterion of each claim is stated in ``ClaimResult.criterion``; the thresholds that make a
vague claim testable ("little", "large") are keyword arguments with their defaults documented.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from colonsim.catalog import NAMED_SCOPES, TIP_FOLDED, scope_role
from colonsim.errors import ColonsimError

REPRODUCED = "REPRODUCED"
NOT_REPRODUCED = "NOT REPRODUCED"
NOT_EVALUATED = "NOT EVALUATED"
# The scopes the source's claims are about (not every scope the catalog may hold).
SMALL_CALIBER = ("utc", "pdc")
STANDARD = "sdc"
FRICTIONS = (0.0, 0.05, 0.1)
RSJ_DIAMETERS = (23.0, 36.0)
ANGLES = (0.0, 30.0, 45.0)
# Below this the standard scope barely deforms the colon: no relative advantage can be read from
# it. 1 mm is a third of the 3 mm wall mesh; the source's deformations are 1.3 cm and up.
NO_DEFORMATION_CM = 0.1


@dataclass
class ClaimResult:
    """Verdict on one claim with the numbers behind it."""

    name: str
    statement: str
    criterion: str
    verdict: str
    evidence: list = field(default_factory=list)
    reason: str = ""
    missing: list = field(default_factory=list)

    def to_dict(self) -> dict:
        return {"name": self.name, "statement": self.statement, "criterion": self.criterion, "verdict": self.verdict,
                "reason": self.reason, "missing": list(self.missing), "evidence": list(self.evidence)}


class _Runs:
    """Looks runs up in a results table by their inputs; remembers what it could not find."""

    def __init__(self, table: pd.DataFrame):
        self.table = table
        self.missing = []
        names = table["scope"].astype(str).str.lower()
        if "scope_diameter_mm" in table:
            by_size = table["scope_diameter_mm"].astype(float).map(scope_role)
            names = names.where(names.isin(tuple(NAMED_SCOPES)), by_size)
        self._roles = names

    def value(self, column, segment, scope, **inputs):
        """``column`` of the one ok run matching the inputs (floats compared with a tolerance);
        None (recorded as missing) when there is no such run or it failed."""
        t = self.table
        mask = (t["segment"].astype(str).str.lower() == segment) & (self._roles == scope)
        for name, value in inputs.items():
            mask &= np.isclose(t[name].astype(float), float(value), rtol=0.0, atol=1e-9)
        rows = t[mask]
        label = _label(segment, scope, **inputs)
        ok = rows[rows["status"] == "ok"]
        folded = ok[ok["ended_by"].astype(str) == TIP_FOLDED] if "ended_by" in ok else ok.iloc[:0]
        ok = ok.drop(folded.index)
        if len(ok) > 1:
            raise ColonsimError(f"the results table holds {len(ok)} successful runs of {label}; "
                                "evaluate the claims on a table with one run per case")
        if len(ok) == 0:
            why = "its tip folded: outside the model" if len(folded) else "failed" if len(rows) else "not run"
            self.missing.append(f"{label} ({why})")
            return None
        return float(ok[column].iloc[0])


def _label(segment, scope, **inputs):
    names = {"diameter_mm": ("D", " mm"), "friction": ("mu", ""), "angle_deg": ("angle", " deg")}
    parts = [f"{names[k][0]} {v:g}{names[k][1]}" for k, v in inputs.items()]
    return f"{segment.upper()} {scope.upper()} " + ", ".join(parts)


def _verdict(result: ClaimResult, runs: _Runs, failures: list) -> ClaimResult:
    if runs.missing:
        result.verdict = NOT_EVALUATED
        result.missing = runs.missing
        result.reason = f"{len(runs.missing)} run(s) missing: " + "; ".join(runs.missing)
    elif failures:
        result.verdict = NOT_REPRODUCED
        result.reason = "; ".join(failures)
    else:
        result.verdict = REPRODUCED
    return result


def relative_reduction(standard, small):
    """(SDC - SC) / SDC: the fraction of the standard scope's deformation a small scope saves."""
    return (standard - small) / standard


def sc_deform_less_rsj(table, diameters=RSJ_DIAMETERS, frictions=FRICTIONS,
                       quantity="final_deformation_cm") -> ClaimResult:
    """Small-caliber scopes deform the RSJ less than the standard one, at every D and mu."""
    runs = _Runs(table)
    result = ClaimResult(
        "sc_deform_less_rsj",
        "Small-caliber scopes (UTC, PDC) deform the RSJ less than the standard scope (SDC).",
        f"For every colon diameter D in {_list(diameters, ' mm')} and friction mu in {_list(frictions)}: "
        f"{quantity} of UTC < that of SDC and {quantity} of PDC < that of SDC (strict; "
        f"{len(diameters) * len(frictions) * 2} comparisons).", NOT_EVALUATED)
    failures = []
    for d in diameters:
        for mu in frictions:
            sdc = runs.value(quantity, "rsj", STANDARD, diameter_mm=d, friction=mu)
            for sc in SMALL_CALIBER:
                v = runs.value(quantity, "rsj", sc, diameter_mm=d, friction=mu)
                if v is None or sdc is None:
                    continue
                holds = v < sdc
                result.evidence.append({"diameter_mm": d, "friction": mu, "scope": sc.upper(), "scope_cm": v,
                                        "sdc_cm": sdc, "reduction": relative_reduction(sdc, v), "holds": bool(holds)})
                if not holds:
                    failures.append(f"{sc.upper()} {v:.2f} cm >= SDC {sdc:.2f} cm at D {d:g} mm, mu {mu:g}")
    return _verdict(result, runs, failures)


def reduction_larger_at_small_diameter(table, small=23.0, large=36.0, frictions=FRICTIONS,
                                       quantity="final_deformation_cm") -> ClaimResult:
    """The small-caliber scopes' reduction is larger in the narrow (23 mm) than in the wide colon."""
    runs = _Runs(table)
    result = ClaimResult(
        "reduction_larger_at_small_diameter",
        f"The reduction of RSJ deformation by small-caliber scopes is larger for D = {small:g} mm than for D = {large:g} mm.",
        f"Relative reduction r = (SDC - SC) / SDC of {quantity}. For each SC scope (UTC, PDC) and each mu in "
        f"{_list(frictions)}: r(D = {small:g} mm) > r(D = {large:g} mm) ({2 * len(frictions)} comparisons).",
        NOT_EVALUATED)
    failures = []
    for mu in frictions:
        sdc = {d: runs.value(quantity, "rsj", STANDARD, diameter_mm=d, friction=mu) for d in (small, large)}
        for sc in SMALL_CALIBER:
            v = {d: runs.value(quantity, "rsj", sc, diameter_mm=d, friction=mu) for d in (small, large)}
            if None in v.values() or None in sdc.values():
                continue
            r = {d: relative_reduction(sdc[d], v[d]) for d in (small, large)}
            holds = r[small] > r[large]
            result.evidence.append({"scope": sc.upper(), "friction": mu, f"reduction_D{small:g}": r[small],
                                    f"reduction_D{large:g}": r[large], "holds": bool(holds)})
            if not holds:
                failures.append(f"{sc.upper()} at mu {mu:g}: reduction {r[small]:.0%} at D {small:g} mm "
                                f"<= {r[large]:.0%} at D {large:g} mm")
    return _verdict(result, runs, failures)


def sc_less_friction_sensitive(table, diameters=RSJ_DIAMETERS, low=0.0, high=0.1,
                               quantity="final_deformation_cm") -> ClaimResult:
    """Small-caliber scopes are less sensitive to friction than the standard scope."""
    runs = _Runs(table)
    result = ClaimResult(
        "sc_less_friction_sensitive",
        "Small-caliber scopes are less sensitive to friction.",
        f"Sensitivity = |{quantity}(mu = {high:g}) - {quantity}(mu = {low:g})| in cm, per scope, in the RSJ. "
        f"For each D in {_list(diameters, ' mm')} and each SC scope (UTC, PDC): sensitivity of SC < sensitivity "
        f"of SDC ({2 * len(diameters)} comparisons).", NOT_EVALUATED)
    failures = []
    for d in diameters:
        def change(scope):
            a = runs.value(quantity, "rsj", scope, diameter_mm=d, friction=low)
            b = runs.value(quantity, "rsj", scope, diameter_mm=d, friction=high)
            return None if a is None or b is None else (b - a, a)

        sdc = change(STANDARD)
        for sc in SMALL_CALIBER:
            c = change(sc)
            if c is None or sdc is None:
                continue
            holds = abs(c[0]) < abs(sdc[0])
            result.evidence.append({"diameter_mm": d, "scope": sc.upper(), "scope_change_cm": c[0],
                                    "scope_relative_change": c[0] / c[1], "sdc_change_cm": sdc[0],
                                    "sdc_relative_change": sdc[0] / sdc[1], "holds": bool(holds)})
            if not holds:
                failures.append(f"D {d:g} mm: {sc.upper()} changes by {c[0]:+.2f} cm, SDC by {sdc[0]:+.2f} cm")
    return _verdict(result, runs, failures)


def advantage(standard, small, floor=NO_DEFORMATION_CM):
    """Relative reduction (SDC - SC) / SDC of the small scope; 0 where neither scope deforms the
    colon by ``floor`` cm (nothing measurable to reduce), and (SDC - SC) / ``floor`` where only the
    small scope does (a negative advantage not blown up by a near-zero SDC)."""
    if max(standard, small) < floor:
        return 0.0
    return (standard - small) / max(standard, floor)


def angle_dependence(table, segment, angles=ANGLES, friction=0.0, little=0.10, large=0.20,
                     quantity="final_deformation_cm") -> ClaimResult:
    """RSF (alpha) or THF (beta): the small-caliber advantage grows with the angle, from little or
    none at the smallest angle to a large one at the largest.

    ``little`` and ``large`` turn the source's words into numbers: "little or no advantage" is a
    relative reduction below ``little`` (10 %), "a large one" at least ``large`` (20 %, the order of
    the source's own RSJ reductions at D = 36 mm: PDC 20 %, UTC 38 %).
    """
    runs = _Runs(table)
    symbol = {"rsf": "alpha", "thf": "beta"}.get(segment, "angle")
    lo, hi = angles[0], angles[-1]
    result = ClaimResult(
        f"angle_dependence_{segment}",
        f"{segment.upper()}: the advantage of small-caliber scopes depends on {symbol}: small angles (male-like) "
        "show little or no advantage, large angles (female-like) a large one.",
        f"Advantage a = (SDC - SC) / SDC of {quantity} at mu = {friction:g} (a = 0 where both scopes deform the colon by "
        f"less than {NO_DEFORMATION_CM:g} cm: nothing measurable to reduce). For each SC scope (UTC, PDC): (i) a does not decrease with {symbol} over "
        f"{_list(angles, ' deg')}; (ii) a({symbol} = {lo:g}) < {little:.0%} (little or none); "
        f"(iii) a({symbol} = {hi:g}) >= {large:.0%} (large).", NOT_EVALUATED)
    failures = []
    sdc = {a: runs.value(quantity, segment, STANDARD, angle_deg=a, friction=friction) for a in angles}
    for sc in SMALL_CALIBER:
        v = {a: runs.value(quantity, segment, sc, angle_deg=a, friction=friction) for a in angles}
        if None in v.values() or None in sdc.values():
            continue
        adv = [advantage(sdc[a], v[a]) for a in angles]
        monotone = all(x <= y for x, y in zip(adv, adv[1:]))
        small_ok, large_ok = adv[0] < little, adv[-1] >= large
        result.evidence.append({"scope": sc.upper(), **{f"{symbol}_{a:g}_scope_cm": v[a] for a in angles},
                                **{f"{symbol}_{a:g}_sdc_cm": sdc[a] for a in angles},
                                **{f"advantage_{symbol}_{a:g}": x for a, x in zip(angles, adv)},
                                "non_decreasing": monotone, "little_at_smallest": small_ok, "large_at_largest": large_ok,
                                "holds": bool(monotone and small_ok and large_ok)})
        shown = ", ".join(f"{x:.0%}" for x in adv)
        if not monotone:
            failures.append(f"{sc.upper()}: advantage over {symbol} = {_list(angles)} is {shown}, not non-decreasing")
        if not small_ok:
            failures.append(f"{sc.upper()}: advantage {adv[0]:.0%} at {symbol} = {lo:g} is not below {little:.0%}")
        if not large_ok:
            failures.append(f"{sc.upper()}: advantage {adv[-1]:.0%} at {symbol} = {hi:g} is below {large:.0%}")
    return _verdict(result, runs, failures)


def rsj_ordering(table, diameters=RSJ_DIAMETERS, friction=0.0) -> ClaimResult:
    """The orderings of the source's RSJ table: SDC > PDC > UTC at A and at C, and C > A."""
    runs = _Runs(table)
    result = ClaimResult(
        "rsj_ordering",
        "RSJ (the source's table, mu = 0): SDC > PDC > UTC at point A and at point C, and C > A in every case.",
        f"At mu = {friction:g}, for each D in {_list(diameters, ' mm')}: deformation at A of SDC > PDC > UTC, the same "
        "at C, and for each of the six runs C > A. A run without a point A (a deformation curve with no first "
        "maximum followed by a minimum) fails the comparisons that need A.", NOT_EVALUATED)
    failures = []
    scopes = ("sdc", "pdc", "utc")
    for d in diameters:
        values = {s: {p: runs.value(f"point_{p}_cm", "rsj", s, diameter_mm=d, friction=friction) for p in "AC"}
                  for s in scopes}
        if any(v is None for s in scopes for v in values[s].values()):
            continue
        for p in "AC":
            seq = [values[s][p] for s in scopes]
            holds = all(np.isfinite(seq)) and seq[0] > seq[1] > seq[2]
            result.evidence.append({"check": f"SDC > PDC > UTC at {p}", "diameter_mm": d,
                                    **{f"{s.upper()}_cm": values[s][p] for s in scopes}, "holds": bool(holds)})
            if not holds:
                failures.append(f"D {d:g} mm, point {p}: SDC {seq[0]:.2f}, PDC {seq[1]:.2f}, UTC {seq[2]:.2f} cm")
        for s in scopes:
            a, c = values[s]["A"], values[s]["C"]
            holds = bool(np.isfinite(a) and np.isfinite(c) and c > a)
            result.evidence.append({"check": "C > A", "diameter_mm": d, "scope": s.upper(), "A_cm": a, "C_cm": c,
                                    "holds": holds})
            if not holds:
                failures.append(f"{s.upper()} D {d:g} mm: C {c:.2f} cm <= A {a:.2f} cm" if np.isfinite(a)
                                else f"{s.upper()} D {d:g} mm: no point A")
    return _verdict(result, runs, failures)


def evaluate_claims(table, frictions=FRICTIONS, quantity="final_deformation_cm") -> list[ClaimResult]:
    """Every claim of the source, in the order it states them; ``frictions``: the RSJ frictions
    the first two claims compare the scopes at (a sweep at mu = 0 only: ``(0.0,)``); ``quantity``:
    the deformation the claims about deformation compare (the source's end values, which in its
    runs are also the largest; ``max_deformation_cm`` compares the largest during the run). The
    RSJ ordering compares points A and C whatever ``quantity`` is."""
    return [sc_deform_less_rsj(table, frictions=frictions, quantity=quantity),
            reduction_larger_at_small_diameter(table, frictions=frictions, quantity=quantity),
            sc_less_friction_sensitive(table, quantity=quantity), angle_dependence(table, "rsf", quantity=quantity),
            angle_dependence(table, "thf", quantity=quantity), rsj_ordering(table)]


def _list(values, unit=""):
    return "{" + ", ".join(f"{v:g}" for v in values) + "}" + unit
