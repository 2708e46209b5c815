"""The run-time estimate of an insertion, made before it starts: close to the steps a run takes,
and a refusal naming the likely cause when a run would take far too long."""

import json
import re

import pytest

from colonsim.cli import main
from colonsim.catalog import SMOKE_PUSH_SPEED
from colonsim.errors import ColonsimError
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH
from colonsim.insertion.case.run_budget import check_run_budget, check_sweep_budget, estimate_run
from colonsim.insertion.case.scenario import InsertionCase

COARSE = dict(segment="straight", scope="pdc", element_size_mm=7.5)


def stiffer(tmp_path, factor):
    doc = json.loads(REFERENCE_MATERIAL_PATH.read_text())
    doc["parameters"] = {k: v * factor for k, v in doc["parameters"].items()}
    path = tmp_path / f"x{factor:g}.json"
    path.write_text(json.dumps(doc))
    return str(path)


def test_the_estimate_is_printed_and_close_to_the_steps_taken(tmp_path, capsys):
    assert main(["insert", "--segment", "straight", "--scope", "pdc", "--element-size", "7.5", "--no-progress",
                 "--push-speed", str(SMOKE_PUSH_SPEED), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    estimated = int(re.search(r"about ([\d,]+) time steps", out).group(1).replace(",", ""))
    taken = int(re.search(r"(\d+) steps in", out).group(1))
    # contact shortens the step a little; the run may end before the push does
    assert 0.5 * estimated < taken < 1.5 * estimated


def test_a_wall_in_the_wrong_unit_is_refused_with_the_cause_and_the_limit_can_be_raised(tmp_path):
    case = InsertionCase(**COARSE, material=stiffer(tmp_path, 1e6))  # MPa written as Pa
    budget = estimate_run(case)
    assert budget.limited_by == "colon" and budget.steps > 1e6
    with pytest.raises(ColonsimError, match=r"1e\+06 times stiffer than the reference tissue.*raise --max-steps"):
        check_run_budget(case, max_steps=1_000_000)
    assert check_run_budget(case, max_steps=int(2 * budget.steps)).steps == budget.steps


def test_other_causes_are_named():
    with pytest.raises(ColonsimError, match=rf"the slow push \(0.005 m/s, default {InsertionCase().push_speed:g}\)"):
        check_run_budget(InsertionCase(**COARSE, push_speed=0.005), max_steps=100_000)


def test_a_sweep_is_checked_on_its_longest_run_per_material(tmp_path):
    quick, slow = InsertionCase(**COARSE), InsertionCase(**COARSE, push_speed=0.005)
    check_sweep_budget([quick], max_steps=100_000)
    with pytest.raises(ColonsimError, match="the slow push"):
        check_sweep_budget([quick, slow], max_steps=100_000)
