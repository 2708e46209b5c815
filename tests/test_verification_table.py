"""Every row of the verification table (colonsim.insertion.study.verification_table) against its
rule: at the CI size, or at full size with COLONSIM_FULL=1. Rows that only run at full size are
skipped in CI; rows run smaller in CI are marked slow."""

import math
import os

import pytest

from colonsim.insertion.study.verification import Comparison
from colonsim.insertion.study.verification_rules import GROUPS, SAME, Bound, Equal, Relative, Run
from colonsim.insertion.study.verification_table import CHECKS

FULL = os.environ.get("COLONSIM_FULL") == "1"


@pytest.mark.parametrize("check", [pytest.param(c, id=c.id, marks=[pytest.mark.slow] if c.slow else [])
                                   for c in CHECKS])
def test_row_meets_its_rule(check, serial_kernels):
    verdict = check.evaluate(FULL)
    if verdict is None:
        pytest.skip("full size only: set COLONSIM_FULL=1")
    assert verdict.passed, verdict.message()


def test_table_is_well_formed():
    ids = [c.id for c in CHECKS]
    assert len(set(ids)) == len(ids)
    for c in CHECKS:
        assert c.id.startswith(c.group + ".") and c.group in GROUPS, c.id
        assert c.rules and c.why and c.quantity, c.id
        assert isinstance(c.full, Run) and (c.reduced in (SAME, None) or isinstance(c.reduced, Run)), c.id


def test_rules_reject_what_they_should():
    c = Comparison("q", 2.0, 2.03, extra={"n": 3, "spread": 1e-3})
    assert Relative(0.02).passed(c) and not Relative(0.01).passed(c)
    assert math.isnan(Comparison("q", 0.0, 1.0).relative_error)
    assert not Relative(1.0).passed(Comparison("q", 0.0, 0.0))  # no relative error against zero: use a Bound
    assert Bound(2.0, 2.1).passed(c) and not Bound(upper=2.03).passed(c) and Bound(upper=2.03, inclusive=True).passed(c)
    assert not Bound(lower=2.03).passed(c) and Bound(lower=2.03, inclusive=True).passed(c)
    assert Bound(upper=2e-3, of="spread").passed(c) and not Bound(upper=1e-3, of="spread").passed(c)
    assert Equal("n", 3).passed(c) and not Equal("n", 2).passed(c)
    assert Bound(0.0, 0.03).text == "0 < measured < 0.03" and Bound(lower=0.15).text == "measured > 0.15"
    assert Relative(1e-3).text == "|rel. error| <= 0.001" and Equal("external work", 0.0).text == "external work = 0"
