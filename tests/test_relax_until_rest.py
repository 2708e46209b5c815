"""The relax of RSF/THF held until the released system is at rest (``relax_max_s``,
docs/model.md, "Loading"): the final push starts from an equilibrium, and the summary says
whether the relax came to rest, which a relax cut short says it did not.

THF beta 45 with the 13.3 mm scope on a 6 mm wall mesh: released, the scope bent by the
straightened transverse colon springs out and carries the floppy colon with it, a motion that goes
on for most of a second. The final push after the relax is not what is checked, so 200 mm of the
scope stay in the sheath (the default keeps 20 mm) and it ends 18 cm sooner: about 30 s a run on
one core instead of 45. The push speed stays the default: at 0.6 m/s the straightening itself
tears this coarse wall (largest stretch past 1.6 before the relax).
"""

import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.case.outcomes import REST_TOLERANCE, rest_drift
from colonsim.insertion.case.scenario import InsertionCase, run_insertion

COARSE = dict(segment="thf", scope="sdc", angle_deg=45.0, element_size_mm=6.0, scope_spacing_mm=10.0,
              sheath_reserve_mm=200.0)


@pytest.fixture(scope="module")
def relaxed():
    return run_insertion(InsertionCase(**COARSE, relax_max_s=3.0))


def _relax(run):
    ts = run.timeseries
    return ts[ts["phase"] == "relax"]


def test_the_relax_ends_once_the_released_system_is_at_rest(relaxed):
    relax = _relax(relaxed)
    summary = relaxed.summary["relax"]
    assert summary["came_to_rest"]
    held = relax["time_s"].iloc[-1] - relax["time_s"].iloc[0]
    assert summary["held_s"] == pytest.approx(held, abs=2e-3)
    assert relaxed.model.case.relax_s < held < 3.0  # longer than the release, shorter than the bound
    assert max(rest_drift(relax["time_s"], relax["deformation_m"], relax["tip_displacement_m"])) < REST_TOLERANCE
    assert max(summary["deformation_drift_mm"], summary["tip_drift_mm"]) < REST_TOLERANCE * 1e3
    # ... and had not been at rest a window earlier: the relax did not wait for nothing
    early = relax[relax["time_s"] <= relax["time_s"].iloc[0] + relaxed.model.case.relax_s]
    assert max(rest_drift(early["time_s"], early["deformation_m"], early["tip_displacement_m"])) > REST_TOLERANCE
    # the push goes on from where the relax left it, to the same depth
    ts = relaxed.timeseries
    push = ts[ts["time_s"] > relax["time_s"].iloc[-1]]
    assert push["phase"].iloc[0] in ("push", "held push")
    assert push["depth_m"].iloc[0] == pytest.approx(relax["depth_m"].iloc[-1], abs=1e-6)


def test_a_relax_cut_short_says_it_did_not_come_to_rest(relaxed):
    short = run_insertion(InsertionCase(**COARSE, relax_max_s=0.15))
    assert short.summary["relax"]["came_to_rest"] is False
    assert short.summary["relax"]["held_s"] == pytest.approx(0.15, abs=0.011)
    # the push then starts from a state still moving, and the summary shows how much
    relax = short.summary["relax"]
    assert max(relax["deformation_drift_mm"], relax["tip_drift_mm"]) > REST_TOLERANCE * 1e3


def test_the_relax_bound_enters_the_key_only_where_there_is_a_relax():
    assert InsertionCase(relax_max_s=0.0).key() == InsertionCase().key()
    thf = InsertionCase(segment="thf", angle_deg=45.0)
    assert InsertionCase(segment="thf", angle_deg=45.0, relax_max_s=1.0).key() != thf.key()
    # a model without a relax (RSJ, fixed THF) keeps its key whatever the bound
    assert InsertionCase(relax_max_s=1.0).key() == InsertionCase().key()
    assert InsertionCase(segment="thf-fixed", relax_max_s=1.0).key() == InsertionCase(segment="thf-fixed").key()


@pytest.mark.parametrize("value", [0.05, -1.0, 11.0])
def test_a_relax_bound_shorter_than_the_relax_or_out_of_range_is_refused_in_one_line(value):
    with pytest.raises(ColonsimError, match=r"relax_max_s") as err:
        InsertionCase(relax_max_s=value).validate()
    assert "\n" not in str(err.value)


def test_the_command_line_says_whether_the_relax_came_to_rest():
    from colonsim.insertion.case.results import relax_words
    assert relax_words(None) == ""
    assert relax_words({"came_to_rest": True, "held_s": 2.158, "deformation_drift_mm": 0.01, "tip_drift_mm": 0.0}) \
        == "relaxed to rest 2.16 s after the release; "
    words = relax_words({"came_to_rest": False, "held_s": 0.15, "deformation_drift_mm": 1.234, "tip_drift_mm": 0.5})
    assert "did NOT come to rest in 0.15 s" in words and "1.234 mm" in words and "raise relax_max_s" in words
