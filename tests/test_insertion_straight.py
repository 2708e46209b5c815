"""Insertion workflow end to end on the sanity case: a straight push through a straight tube."""

import json

import pytest

from colonsim.cli import main
from colonsim.insertion.case.scenario import InsertionCase, run_insertion


@pytest.fixture(scope="module")
def straight_run():
    return run_insertion(InsertionCase(segment="straight", scope="pdc", element_size_mm=4.0))


def test_straight_push_leaves_the_colon_undeformed(straight_run):
    """A centred scope pushed along the axis of a straight tube never touches the wall."""
    s = straight_run.summary
    assert s["max_deformation_cm"] < 0.01  # 0.1 mm
    assert s["peak_contact_force_N"] == 0.0
    assert s["max_wall_stretch"] == pytest.approx(1.0, abs=1e-6)


def test_the_push_reaches_the_far_end(straight_run):
    ts = straight_run.timeseries
    # the run ends once the tip crosses the far end ring's plane (x = 20 cm), checked every 10 ms
    # of simulated time (6 mm of push at 0.6 m/s)
    assert straight_run.summary["ended_by"] == "far_end"
    assert 0.0 <= ts["tip_past_end_m"].iloc[-1] <= 0.0062
    # the tip follows the pushed end: a stiff rod in a sheath, no axial buckling
    assert 0.20 + ts["tip_past_end_m"].iloc[-1] == pytest.approx(ts["depth_m"].iloc[-1], abs=0.002)
    # the drive only overcomes the scope's mass-proportional drag (alpha m v = 5 * m * 0.6)
    m = straight_run.model.rod.mass.sum()
    assert ts["push_force_N"].iloc[-50:].mean() == pytest.approx(5.0 * m * 0.6, rel=0.1)


def test_cli_insert_writes_results_and_rejects_bad_input(tmp_path, capsys):
    out = tmp_path / "ins"
    assert main(["insert", "--segment", "straight", "--scope", "utc", "--element-size", "4", "--no-progress",
                 "--out", str(out)]) == 0
    summary = json.loads((out / "straight_UTC" / "summary.json").read_text())
    assert summary["mesh"]["wall_triangles"] > 0 and summary["inputs"]["scope"] == "utc"
    assert (out / "comparison.csv").is_file() and (out / "straight_UTC" / "timeseries.csv").is_file()
    for args, message in ((["--scope", "36", "--diameter", "23"], "outside 3-20 mm"),
                          (["--scope", "15", "--diameter", "15"], "as wide as or wider than the colon"),
                          (["--friction", "-0.1"], "friction"),
                          (["--diameter", "-5"], "diameter_mm"),
                          (["--material", str(tmp_path / "none.json")], "not found")):
        capsys.readouterr()
        assert main(["insert", *args, "--no-progress", "--out", str(tmp_path / "bad")]) == 2
        err = capsys.readouterr().err.strip()
        assert message in err and len(err.splitlines()) == 1, err
