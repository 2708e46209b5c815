"""The RSF manoeuvre run end to end on a coarse mesh: straighten (mobile part held to its axis),
relax (released, scope at rest), push on through the flexure into the fixed exit, where the
distal resistance holds the tip and the push goes on at half its speed.

A 6 mm wall mesh, scope nodes every 10 mm and the smoke push speed (0.6 m/s, colonsim.catalog) keep
the run to about 20 s on one core (110 s at the default speed): the phases, the constraint and the
held push's timing are the manoeuvre's, not the mechanics', and do not depend on the mesh or speed.
At 0.6 m/s the straightening push (23.9 cm) is shorter than the 24 cm its speed ramps take, so
this run also checks that such a push still stops at the sigmoid's end.
"""

import numpy as np
import pytest

from colonsim.catalog import SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
from colonsim.insertion.case.scenario import InsertionCase, run_insertion


@pytest.fixture(scope="module")
def rsf_run():
    return run_insertion(InsertionCase(segment="rsf", scope="utc", angle_deg=30.0, element_size_mm=6.0,
                                       push_speed=SMOKE_PUSH_SPEED, scope_spacing_mm=SMOKE_SCOPE_SPACING_MM),
                         snapshot_interval=0.01)


def test_phases_follow_the_mobile_part(rsf_run):
    ts, model = rsf_run.timeseries, rsf_run.model
    phases = list(dict.fromkeys(ts["phase"]))
    assert phases == ["straighten", "stop", "relax", "push", "held push", "settle"]
    held = ts[ts["phase"].isin(["straighten", "stop"])]
    relax = ts[ts["phase"] == "relax"]
    # straightening pushes to the end of the mobile part (the sigmoid and its half-fillet) ...
    assert held["depth_m"].max() == pytest.approx(model.geometry.mobile_end, abs=1e-3)
    # ... then the scope stands still for the relax: the constraint's release (relax_s), then until
    # the released system is at rest, as long as the summary says
    assert relax["depth_m"].max() - relax["depth_m"].min() < 1e-6
    outcome = rsf_run.summary["relax"]
    assert outcome["came_to_rest"] and model.case.relax_s - 1e-9 <= outcome["held_s"] <= model.case.relax_max_s
    assert relax["time_s"].max() - relax["time_s"].min() == pytest.approx(outcome["held_s"], abs=2e-3)
    # the final push goes on through the flexure: the run ends at the model's far end or when the
    # scope's available length is in, never on a jam
    assert rsf_run.summary["ended_by"] in ("far_end", "length_used")
    assert ts["tip_arc_m"].iloc[-1] > model.geometry.exit_start + 0.05  # 5 cm into the fixed exit


def test_mobile_part_moves_only_along_its_axis_while_straightened(rsf_run):
    model = rsf_run.model
    held_until = model.push.lateral_constraint_end
    x0 = model.shell.x0
    across_held, across_free = 0.0, 0.0
    for t, colon, _ in rsf_run.snapshots:
        for direction, nodes in model.geometry.mobile_axes:
            u = colon[nodes] - x0[nodes]
            across = np.linalg.norm(u - np.outer(u @ direction, direction), axis=1).max()
            if t < held_until - 1e-9:
                across_held = max(across_held, across)
            elif t > held_until + 0.01:
                across_free = max(across_free, across)
    # held: motion across the axis is removed at every step (round-off only); released: the wall
    # moves sideways as the scope bows into it
    assert across_held < 1e-9
    assert across_free > 1e-4


def test_the_push_slows_once_the_tip_is_held_and_ends_at_the_same_depth(rsf_run):
    ts, model = rsf_run.timeseries, rsf_run.model
    case, push = model.case, model.push
    held = ts[ts["phase"] == "held push"]
    first = held.iloc[0]
    # it starts at the first chunk (1 mm of push) after the tip came within the lead of the exit ...
    slow_from = model.geometry.exit_start - case.held_push_lead_mm * 1e-3
    assert first["tip_arc_m"] > slow_from
    before = ts[ts["time_s"] < push.slowed_at - 2e-3]
    assert before["tip_arc_m"].iloc[-1] < slow_from + 2e-3
    assert abs(before["distal_force_N"]).max() < case.distal_resistance_N
    # ... and, past its ramp, pushes at the share of the push speed
    steady = held[held["time_s"] > push.slowed_at + case.ramp_s + 0.01]
    speed = np.diff(steady["depth_m"]) / np.diff(steady["time_s"])
    assert len(speed) > 100 and np.allclose(speed, case.held_push_share * case.push_speed, rtol=1e-6)
    assert ts["depth_m"].iloc[-1] == pytest.approx(model.total_depth, abs=1e-9)  # to the depth of before
