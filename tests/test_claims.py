"""The claim evaluations of colonsim.insertion.study.claims on small hand-built results tables."""

import itertools
import math

import pandas as pd
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.study.claims import (NOT_EVALUATED, NOT_REPRODUCED, REPRODUCED, angle_dependence, evaluate_claims,
                              reduction_larger_at_small_diameter, rsj_ordering, sc_deform_less_rsj,
                              sc_less_friction_sensitive)
from colonsim.insertion.study.reference import source_rsj_table

# Hand-built RSJ deformations (cm): SDC 4.0, PDC 3.0, UTC 2.0 at D 36, friction adds 0.5 mu/0.1 to
# SDC and less to the small scopes; D 23 is 10 % deeper for SDC, less for the others.
BASE = {"sdc": 4.0, "pdc": 3.0, "utc": 2.0}
NARROW = {"sdc": 1.10, "pdc": 1.02, "utc": 1.01}  # factor at D = 23 mm
FRICTION_GAIN = {"sdc": 5.0, "pdc": 2.0, "utc": 1.0}  # cm per unit mu


def rsj_row(scope, d, mu, final=None, a=None, c=None, status="ok"):
    value = BASE[scope] * (NARROW[scope] if d == 23 else 1.0) + FRICTION_GAIN[scope] * mu
    final = value if final is None else final
    return {"segment": "rsj", "scope": scope, "diameter_mm": float(d), "friction": float(mu), "angle_deg": 0.0,
            "point_A_cm": 0.6 * final if a is None else a, "point_C_cm": final if c is None else c,
            "final_deformation_cm": final, "status": status}


def rsj_table():
    rows = [rsj_row(s, d, mu) for s, d, mu in itertools.product(BASE, (23, 36), (0.0, 0.05, 0.1))]
    return pd.DataFrame(rows)


def angle_rows(segment, values):
    """``values[scope]`` = deformations at angles 0, 30, 45."""
    return pd.DataFrame([{"segment": segment, "scope": s, "diameter_mm": 36.0, "friction": 0.0, "angle_deg": a,
                          "point_A_cm": math.nan, "point_C_cm": v, "final_deformation_cm": v, "status": "ok"}
                         for s, vs in values.items() for a, v in zip((0.0, 30.0, 45.0), vs)])


def replace(table, scope, d, mu, **values):
    t = table.copy()
    mask = (t["scope"] == scope) & (t["diameter_mm"] == d) & (t["friction"] == mu)
    assert mask.sum() == 1
    for k, v in values.items():
        t.loc[mask, k] = v
    return t


def test_consistent_table_reproduces_every_rsj_claim():
    t = rsj_table()
    for claim in (sc_deform_less_rsj, reduction_larger_at_small_diameter, sc_less_friction_sensitive, rsj_ordering):
        r = claim(t)
        assert r.verdict == REPRODUCED, (claim.__name__, r.reason)
        assert r.evidence and all(e["holds"] for e in r.evidence)
    assert len(sc_deform_less_rsj(t).evidence) == 12
    assert len(sc_less_friction_sensitive(t).evidence) == 4


def test_one_counterexample_is_not_reproduced_with_its_numbers():
    t = replace(rsj_table(), "pdc", 23, 0.1, final_deformation_cm=5.0)  # SDC there: 4.9
    r = sc_deform_less_rsj(t)
    assert r.verdict == NOT_REPRODUCED
    assert "PDC 5.00 cm >= SDC 4.90 cm at D 23 mm, mu 0.1" in r.reason
    assert sum(not e["holds"] for e in r.evidence) == 1


def test_missing_or_failed_runs_are_not_evaluated_never_guessed():
    t = rsj_table()
    # a counterexample among the runs present does not decide while a needed run is missing
    t = replace(t, "pdc", 23, 0.1, final_deformation_cm=5.0)
    t = t[~((t["scope"] == "sdc") & (t["diameter_mm"] == 36.0) & (t["friction"] == 0.05))]
    t = replace(t, "utc", 36, 0.0, status="failed", final_deformation_cm=math.nan)
    r = sc_deform_less_rsj(t)
    assert r.verdict == NOT_EVALUATED
    assert "RSJ SDC D 36 mm, mu 0.05 (not run)" in r.missing
    assert "RSJ UTC D 36 mm, mu 0 (failed)" in r.missing
    # an empty table: every claim not evaluated
    empty = t.iloc[:0]
    assert all(c.verdict == NOT_EVALUATED for c in evaluate_claims(empty))


def test_reduction_compares_relative_not_absolute_reductions():
    # SDC 4.4 -> PDC 3.0 at D 23 (32 %) and SDC 4.0 -> PDC 2.6 at D 36 (35 %): the absolute
    # reductions are equal (1.4 cm), the relative one is larger at D 36: not reproduced.
    t = rsj_table()
    for mu in (0.0, 0.05, 0.1):
        t = replace(t, "sdc", 23, mu, final_deformation_cm=4.4)
        t = replace(t, "sdc", 36, mu, final_deformation_cm=4.0)
        t = replace(t, "pdc", 23, mu, final_deformation_cm=3.0)
        t = replace(t, "pdc", 36, mu, final_deformation_cm=2.6)
    r = reduction_larger_at_small_diameter(t)
    assert r.verdict == NOT_REPRODUCED
    assert "PDC at mu 0: reduction 32% at D 23 mm <= 35% at D 36 mm" in r.reason
    assert all(e["holds"] for e in r.evidence if e["scope"] == "UTC")


def test_friction_sensitivity_uses_the_magnitude_of_the_change():
    # the UTC's deformation falls by 1 cm with friction while the SDC's rises by 0.5 cm
    t = rsj_table()
    t = replace(t, "sdc", 36, 0.1, final_deformation_cm=4.5)
    t = replace(t, "utc", 36, 0.1, final_deformation_cm=1.0)
    r = sc_less_friction_sensitive(t)
    assert r.verdict == NOT_REPRODUCED
    assert "D 36 mm: UTC changes by -1.00 cm, SDC by +0.50 cm" in r.reason


def test_rsj_ordering_needs_point_a_and_c_above_a():
    t = rsj_table()
    assert rsj_ordering(t).verdict == REPRODUCED
    no_a = replace(t, "utc", 23, 0.0, point_A_cm=math.nan)
    r = rsj_ordering(no_a)
    assert r.verdict == NOT_REPRODUCED and "UTC D 23 mm: no point A" in r.reason
    c_below = replace(t, "sdc", 36, 0.0, point_A_cm=4.5)
    r = rsj_ordering(c_below)
    assert r.verdict == NOT_REPRODUCED and "SDC D 36 mm: C 4.00 cm <= A 4.50 cm" in r.reason
    # A ordering broken (PDC above SDC at A) while C keeps the order
    r = rsj_ordering(replace(t, "pdc", 23, 0.0, point_A_cm=2.7))
    assert r.verdict == NOT_REPRODUCED and "D 23 mm, point A" in r.reason and "point C" not in r.reason


def test_the_source_numbers_reproduce_the_source_claims_at_mu_0():
    """docs/model.md's own table satisfies the claims it supports (mu = 0 only)."""
    src = source_rsj_table()
    assert sc_deform_less_rsj(src, frictions=(0.0,)).verdict == REPRODUCED
    assert reduction_larger_at_small_diameter(src, frictions=(0.0,)).verdict == REPRODUCED
    assert rsj_ordering(src).verdict == REPRODUCED
    # without friction runs the friction claim cannot be evaluated
    assert sc_less_friction_sensitive(src).verdict == NOT_EVALUATED


@pytest.mark.parametrize("values,verdict,reason", [
    # no advantage straight, large at 45 deg: the source's claim
    ({"sdc": (1.0, 2.0, 4.0), "pdc": (1.0, 1.8, 3.0), "utc": (0.98, 1.5, 2.0)}, REPRODUCED, ""),
    # straight sigmoid: nobody deforms it (advantage taken as 0), then a growing advantage
    ({"sdc": (1e-14, 2.0, 4.0), "pdc": (1e-14, 1.8, 3.0), "utc": (1e-14, 1.5, 2.0)}, REPRODUCED, ""),
    # sub-millimetre deformations at 0 deg: no measurable advantage, whatever their ratio
    ({"sdc": (0.06, 2.0, 4.0), "pdc": (0.01, 1.8, 3.0), "utc": (0.0, 1.5, 2.0)}, REPRODUCED, ""),
    # nothing measurable at any angle: no large advantage at 45 deg
    ({"sdc": (0.06, 5e-8, 5e-8), "pdc": (0.01, 5e-8, 5e-8), "utc": (0.0, 1e-3, 3e-4)}, NOT_REPRODUCED,
     "UTC: advantage 0% at beta = 45 is below 20%"),
    # the same advantage at every angle: a large one already at 0 deg
    ({"sdc": (2.0, 3.0, 4.0), "pdc": (1.4, 2.1, 2.8), "utc": (1.0, 1.5, 2.0)}, NOT_REPRODUCED,
     "PDC: advantage 30% at beta = 0 is not below 10%"),
    # advantage shrinks from 30 to 45 deg and stays small
    ({"sdc": (1.0, 2.0, 4.0), "pdc": (1.0, 1.5, 3.8), "utc": (1.0, 1.5, 3.5)}, NOT_REPRODUCED,
     "PDC: advantage over beta = {0, 30, 45} is 0%, 25%, 5%, not non-decreasing"),
])
def test_angle_dependence(values, verdict, reason):
    r = angle_dependence(angle_rows("thf", values), "thf")
    assert r.verdict == verdict, r.reason
    assert reason in r.reason
    assert angle_dependence(angle_rows("thf", values), "rsf").verdict == NOT_EVALUATED  # no RSF rows


def test_two_runs_of_one_case_are_an_error():
    t = rsj_table()
    with pytest.raises(ColonsimError, match="2 successful runs of RSJ SDC D 23 mm, mu 0"):
        sc_deform_less_rsj(pd.concat([t, t[(t["scope"] == "sdc") & (t["diameter_mm"] == 23) & (t["friction"] == 0)]]))


def test_advantage_floor():
    from colonsim.insertion.study.claims import NO_DEFORMATION_CM, advantage

    assert advantage(4.0, 3.0) == pytest.approx(0.25)
    assert advantage(0.5 * NO_DEFORMATION_CM, 0.0) == 0.0  # nothing measurable
    # only the small scope deforms the colon: negative, scaled by the floor
    assert advantage(0.0, 2.0 * NO_DEFORMATION_CM) == pytest.approx(-2.0)


def test_a_sweep_at_mu_0_only_is_judged_at_mu_0_when_told_so():
    """The resistance preset runs the RSJ at mu = 0 only: with ``frictions=(0.0,)`` the scope
    comparisons are judged there, while the friction claim still says what it lacks."""
    at_zero = rsj_table().query("friction == 0.0")
    default, told = evaluate_claims(at_zero), evaluate_claims(at_zero, frictions=(0.0,))
    assert [c.verdict for c in default[:3]] == [NOT_EVALUATED] * 3
    assert [c.verdict for c in told[:3]] == [REPRODUCED, REPRODUCED, NOT_EVALUATED]
    assert len(told[0].evidence) == 4  # 2 small-caliber scopes x 2 diameters
    worse = replace(at_zero, "utc", 36, 0.0, final_deformation_cm=5.0)
    assert evaluate_claims(worse, frictions=(0.0,))[0].verdict == NOT_REPRODUCED


def test_claims_compare_the_quantity_they_are_given():
    """The source's end values are also its largest: the claims can compare the largest
    deformation during the run instead of the end value, and then read that column only."""
    table = rsj_table().query("friction == 0.0").assign(max_deformation_cm=lambda t: t["final_deformation_cm"])
    worse_end = replace(table, "utc", 36, 0.0, final_deformation_cm=5.0)
    on_end = evaluate_claims(worse_end, frictions=(0.0,))
    on_largest = evaluate_claims(worse_end, frictions=(0.0,), quantity="max_deformation_cm")
    assert on_end[0].verdict == NOT_REPRODUCED and on_largest[0].verdict == REPRODUCED
    assert "max_deformation_cm" in on_largest[0].criterion
