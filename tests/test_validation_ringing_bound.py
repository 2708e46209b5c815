"""The proposed ringing bound of the validation report (validation/resistance.py): a run
above the ringing limit counts as quasi-static when half the push speed lowers its ratio by less
than 20 % and its rate pair passes. Each way it can come out, on made-up table rows."""

import dataclasses
import sys
from pathlib import Path

import pandas as pd
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the validation package

from validation import resistance  # noqa: E402
from colonsim.insertion.case.insertion_case import InsertionCase  # noqa: E402
from colonsim.insertion.study.sweep_presets import HALF_SPEED  # noqa: E402

CASE = InsertionCase(segment="thf", scope="9.2", angle_deg=30.0, distal_resistance_N=0.0)
BASE = {"ringing_ratio": 0.30, "final_deformation_cm": 1.10, "max_deformation_cm": 1.20,
        "peak_contact_force_N": 3.0, "peak_push_force_N": 1.1, "point_A_cm": None, "point_C_cm": None}


class HalfSweep:
    """The one run a half-speed sweep holds, under the key of ``CASE`` at half the push speed."""

    def __init__(self, **changed):
        self.row = pd.Series({**BASE, **changed})
        self.key = dataclasses.replace(CASE, push_speed=HALF_SPEED).key()

    def run(self, case):
        return (self.row, "ok") if case.key() == self.key else (None, "not run")


def bound(**changed):
    return resistance.ringing_bound(pd.Series(BASE), HalfSweep(**changed), CASE)


def test_a_ringing_half_the_speed_leaves_and_a_passing_rate_pair_hold_the_bound():
    found = bound(ringing_ratio=0.33, max_deformation_cm=1.22)
    assert found["bound"] is True
    assert found["half_ratio"] == pytest.approx(0.33)
    assert found["ratio_change"] == pytest.approx(0.10)
    assert resistance._rate_cell(found) == "passes"
    assert bound(ringing_ratio=0.45)["bound"] is True  # grows at half the speed: not inertia either
    assert bound(ringing_ratio=0.25)["bound"] is True  # -17 %


def test_a_ringing_that_falls_with_the_speed_is_inertia_and_fails_it():
    found = bound(ringing_ratio=0.23)  # -23 %
    assert found["rate"]["passed"] is True
    assert found["bound"] is False


def test_a_rate_pair_that_fails_fails_it_and_is_named():
    found = bound(ringing_ratio=0.30, max_deformation_cm=1.30)  # +8.3 % against the 5 % limit
    assert found["bound"] is False
    assert resistance._rate_cell(found) == "NO: max_deformation +8.3 %"


def test_without_the_half_speed_run_there_is_no_verdict():
    assert resistance.ringing_bound(pd.Series(BASE), None, CASE)["bound"] is None
    other = dataclasses.replace(CASE, angle_deg=45.0)
    assert resistance.ringing_bound(pd.Series(BASE), HalfSweep(), other)["bound"] is None


def test_runs_whose_tip_ended_turned_back_are_named():
    """The resistance section names the runs whose final values describe a fold (a tip turned
    back), and says nothing when there is none or when the sweep predates the column."""
    row = {"segment": "rsf", "scope": "UTC (9.2 mm)", "where": "alpha 30 deg", "level_N": 20.0,
           "final_deformation_cm": 0.0, "max_deformation_cm": 3.8, "tip_turned_back_cm": 59.4}
    lines = resistance._turned_back_lines([row, {**row, "level_N": 10.0, "tip_turned_back_cm": None}])
    assert len(lines) == 2 and "1 run(s)" in lines[0] and "RSF UTC (9.2 mm) alpha 30 deg 20 N from 59.4 cm" in lines[0]
    assert resistance._turned_back_lines([{**row, "tip_turned_back_cm": None}]) == []
    assert resistance._turned_back_lines([{k: v for k, v in row.items() if k != "tip_turned_back_cm"}]) == []


class TableSweep:
    """A resistance sweep's table as the generator reads it: (case, ringing ratio; None: failed) pairs."""

    def __init__(self, *runs):
        self.cases = [case for case, _ in runs]
        self._ratios = {case.key(): ratio for case, ratio in runs}

    def run(self, case):
        ratio = self._ratios.get(case.key())
        return (None, "failed") if ratio is None else (pd.Series({"ringing_ratio": ratio}), "ok")


def test_the_half_speed_sweep_holds_the_runs_above_the_limit_and_reads_back_as_their_twins():
    """validation/ringing_half_speed.py: a run at or above the limit is written, one below it, a
    failed one and one already at half the speed are not; the TOML parses to the keys the report
    looks up (every input that differs from the defaults, the resistance of 0 N included)."""
    from validation import ringing_half_speed as generator
    from colonsim.insertion.case.ringing import RINGING_LIMIT
    from colonsim.insertion.study.sweep_spec import parse_sweep

    quiet = dataclasses.replace(CASE, angle_deg=45.0)
    held = InsertionCase(segment="thf-fixed", scope="13.3", angle_deg=45.0, distal_resistance_N=20.0,
                         exit_length_mm=400.0)
    failed = dataclasses.replace(CASE, scope="11.1")
    slow = dataclasses.replace(CASE, push_speed=HALF_SPEED)
    sweep = TableSweep((CASE, 0.30), (quiet, 0.05), (held, RINGING_LIMIT), (failed, None), (slow, 0.5))
    cases = generator.ringing_cases(sweep)
    assert cases == [CASE, held]
    text = generator.half_speed_toml(cases, "abc1234")
    assert "distal_resistance_N = 0.0" in text and "exit_length_mm = 400.0" in text and "The 2 runs" in text
    keys = [c.key() for c in parse_sweep(text).cases]
    assert keys == [resistance.half_speed_twin(c).key() for c in cases]
    assert quiet.key() not in keys and CASE.key() not in keys
