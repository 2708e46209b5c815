"""A jam is an outcome: a run whose tip cannot go on ends there and says where and why."""

import numpy as np
import pytest

import colonsim.insertion.case.scenario as scenario
from colonsim.catalog import SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
from colonsim.insertion.anatomy.colon_segments import straight_colon
from colonsim.insertion.case.outcomes import JAM_FORCE, JAM_PUSH, PEAK_WINDOW
from colonsim.insertion.case.scenario import InsertionCase, run_insertion
from colonsim.insertion.engine.constraints import PrescribedVelocity

STENOSIS_X = 0.10  # m along the straight tube
STENOSIS_RADIUS = 2e-3  # m: a held iris far narrower than any scope


def _iris(geometry, element_size):
    """Nodes of the rings within 0.6 element sizes of the stenosis."""
    return np.flatnonzero(np.abs(geometry.nodes[:, 0] - STENOSIS_X) < 0.6 * element_size)


def _stenosed_tube(segment, diameter, angle_deg, element_size, wall_thickness, *args, **kwargs):
    """The straight sanity tube with its wall drawn in to a 2 mm iris at x = 10 cm."""
    g = straight_colon(0.20, diameter, element_size, wall_thickness)
    ring = _iris(g, element_size)
    radial = g.nodes[ring, 1:]
    g.nodes[ring, 1:] = radial * (STENOSIS_RADIUS / np.linalg.norm(radial, axis=1))[:, None]
    return g


def _with_rigid_iris(build):
    """The iris held still by a zero prescribed velocity: a rigid obstacle, not fixed colon wall
    (held colon wall is a smooth tube the scope slides along), so the scope is stopped by it."""
    def wrapped(case):
        model = build(case)
        iris = _iris(model.geometry, case.element_size_mm * 1e-3)
        model.solver.constraints.append(PrescribedVelocity(model.shell, iris, (0.0, 0.0, 0.0)))
        return model
    return wrapped


@pytest.fixture(scope="module")
def jammed_run():
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(scenario, "colon_geometry", _stenosed_tube)
        mp.setattr(scenario, "build_insertion", _with_rigid_iris(scenario.build_insertion))
        # the smoke push speed and scope spacing (colonsim.catalog): the jam rule is checked, not the
        # mechanics of the approach; about 25 s on one core (55 s at the default)
        return run_insertion(InsertionCase(segment="straight", scope="sdc", element_size_mm=4.0,
                                           push_speed=SMOKE_PUSH_SPEED, scope_spacing_mm=SMOKE_SCOPE_SPACING_MM))


def test_a_scope_against_a_closed_lumen_ends_in_a_jam(jammed_run):
    s = jammed_run.summary
    assert s["ended_by"] == "jam"
    assert "jammed" in s["end"]["reason"]
    # the tip stopped at the iris (its hemispherical end a radius and half a wall before it) ...
    tip_stop = STENOSIS_X - jammed_run.model.scope.diameter / 2
    assert s["end"]["tip_arc_cm"] == pytest.approx(tip_stop * 100, abs=0.6)
    # ... long before the scope's available length was pushed in, and with the push force loaded
    assert s["end"]["depth_cm"] < 0.9 * jammed_run.model.total_depth * 100
    last = ts_last_push(jammed_run.timeseries, PEAK_WINDOW)
    assert last["push_force_N"].mean() >= JAM_FORCE


def ts_last_push(ts, push):
    """The samples of the last ``push`` metres of push."""
    return ts[ts["depth_m"] >= ts["depth_m"].iloc[-1] - push]


def test_the_jam_is_detected_within_the_window(jammed_run):
    """The run ends within about 1 cm of push (the window) plus a 6 mm check interval after the
    tip stops, plus the push it takes the blocked scope to pass 43 N (measured: under 1 cm)."""
    ts = jammed_run.timeseries
    stopped = ts["tip_arc_m"] >= ts["tip_arc_m"].iloc[-1] - 1e-3
    first = ts["depth_m"][stopped].iloc[0]
    assert ts["depth_m"].iloc[-1] - first < JAM_PUSH + 0.006 + 0.01
