"""Insertion workflow end to end on the sanity case: a straight push through a straight tube."""

import json

import pytest

from colonsim.catalog import SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
from colonsim.cli import main
from colonsim.insertion.case.scenario import InsertionCase, chunk_seconds, run_insertion


@pytest.fixture(scope="module")
def straight_run():
    # at the smoke push speed and scope spacing (colonsim.catalog): a centred scope sliding through
    # a straight tube has no mechanics that a faster push would change; about 8 s on one core (30 s)
    return run_insertion(InsertionCase(segment="straight", scope="pdc", element_size_mm=4.0,
                                       push_speed=SMOKE_PUSH_SPEED, scope_spacing_mm=SMOKE_SCOPE_SPACING_MM))


def test_straight_push_leaves_the_colon_undeformed(straight_run):
    """A centred scope pushed along the axis of a straight tube never touches the wall."""
    s = straight_run.summary
    assert s["max_deformation_cm"] < 0.01  # 0.1 mm
    assert s["peak_contact_force_N"] == 0.0
    assert s["max_wall_stretch"] == pytest.approx(1.0, abs=1e-6)


def test_the_push_reaches_the_far_end_and_rests(straight_run):
    ts = straight_run.timeseries
    case = straight_run.case
    # the run ends once the tip crosses the far end ring's plane (x = 20 cm), checked every mm of
    # push; the scope then slows to rest over the stop distance and settles: held at least
    # settle_s, ended at the first check of the end rules (a chunk's end) once at rest
    assert straight_run.summary["ended_by"] == "far_end"
    settle = ts[ts["phase"] == "settle"]
    held = settle["time_s"].iloc[-1] - settle["time_s"].iloc[0]
    shortest = 2 * case.stop_distance_mm * 1e-3 / case.push_speed + case.settle_s
    assert shortest - 2e-3 <= held <= shortest + chunk_seconds(case) + 2e-3
    crossing = ts["depth_m"][ts["tip_past_end_m"] >= 0.0].iloc[0]
    assert ts["depth_m"].iloc[-1] - crossing == pytest.approx(case.stop_distance_mm * 1e-3, abs=1.1e-3)
    # brought to rest where the push stopped and held: nothing moves at the end
    assert ts["kinetic_scope_J"].iloc[-1] < 1e-9 and ts["kinetic_colon_J"].iloc[-1] < 1e-9
    # the tip follows the pushed end: a stiff rod in a sheath, no axial buckling
    assert 0.20 + ts["tip_past_end_m"].iloc[-1] == pytest.approx(ts["depth_m"].iloc[-1], abs=0.002)
    # and points on along the tube (a straight scope in a straight tube: heading 0 deg)
    assert ts["tip_heading_deg"].max() < 1.0 and straight_run.summary["tip_turned_back_cm"] is None


def test_a_sliding_scope_is_not_dragged(straight_run):
    """Beyond its ramp-up the drive pushes a scope through a straight frictionless tube with no
    force (within 0.05 N): the scope's damping acts across its axis and on its strain rate only,
    neither of which a sliding scope has (docs/model.md, "Time integration and damping")."""
    ts = straight_run.timeseries
    case = straight_run.case
    plateau = ts[(ts["phase"] == "push") & (ts["time_s"] > case.ramp_s)]
    assert len(plateau) > 100
    assert plateau["push_force_N"].abs().max() < 0.05


def test_cli_insert_writes_results_and_rejects_bad_input(tmp_path, capsys):
    out = tmp_path / "ins"
    assert main(["insert", "--segment", "straight", "--scope", "utc", "--element-size", "4", "--no-progress",
                 "--push-speed", str(SMOKE_PUSH_SPEED), "--scope-spacing", str(SMOKE_SCOPE_SPACING_MM),
                 "--out", str(out)]) == 0
    summary = json.loads((out / "straight_UTC" / "summary.json").read_text())
    assert summary["mesh"]["wall_triangles"] > 0 and summary["inputs"]["scope"] == "utc"
    assert summary["inputs"]["push_speed"] == SMOKE_PUSH_SPEED
    assert (out / "comparison.csv").is_file() and (out / "straight_UTC" / "timeseries.csv").is_file()
    for args, message in ((["--scope", "36", "--diameter", "23"], "outside 3-20 mm"),
                          (["--scope", "15", "--diameter", "15"], "as wide as or wider than the colon"),
                          (["--friction", "-0.1"], "friction"),
                          (["--push-speed", "0"], "push_speed = 0.0 is outside [0.001, 5]"),
                          (["--diameter", "-5"], "diameter_mm"),
                          (["--material", str(tmp_path / "none.json")], "not found")):
        capsys.readouterr()
        assert main(["insert", *args, "--no-progress", "--out", str(tmp_path / "bad")]) == 2
        err = capsys.readouterr().err.strip()
        assert message in err and len(err.splitlines()) == 1, err
