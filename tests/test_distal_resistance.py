"""The distal resistance (docs/model.md, "Loading"): its regularised law in closed form, nothing
changed at 0 N, where it acts in each colon model, and its place in keys, tables and queries."""

import hashlib
import json
import math

import numpy as np
import pytest

from colonsim import catalog
from colonsim.errors import ColonsimError
from colonsim.insertion.case.scenario import (EXIT_MARGIN, InsertionCase, begin_settling, build_insertion,
                                              resistance_share, run_insertion)
from colonsim.insertion.engine.constraints import LineConstraint, PrescribedVelocity
from colonsim.insertion.engine.rod import Rod
from colonsim.insertion.engine.solver import ExplicitSolver
from colonsim.insertion.engine.tip_resistance import TipResistance, regularised_force

COARSE_MM = 7.5


@pytest.mark.parametrize("u0", [1e-3, -1e-3, 0.0, 0.2, 1.0, -1.0])
def test_regularised_law_is_solved_at_the_new_velocity(u0):
    R, vc, b = 5.0, 0.003, 0.01  # b: the tip's velocity change per newton over the step
    F = regularised_force(u0, b, R, vc)
    u = u0 + b * F
    assert F == pytest.approx(-R * max(-1.0, min(1.0, u / vc)), abs=1e-12)  # the law holds at the new velocity
    if abs(u0) <= vc + b * R:  # creeping: u = u0 / (1 + b R / v_c)
        assert u == pytest.approx(u0 / (1.0 + b * R / vc), abs=1e-15)
    else:  # sliding either way: the full resistance against the motion
        assert F == -math.copysign(R, u0)


def test_plain_coulomb_sticks_then_slips():
    assert regularised_force(0.02, 0.01, 5.0, 0.0) == pytest.approx(-2.0)  # stuck: the velocity is cancelled
    assert regularised_force(0.2, 0.01, 5.0, 0.0) == -5.0  # slipping: the full resistance


def _pushed_rod(resistances=(), velocity=(0.3, 0.0, 0.0)):
    """A rod pushed out of its sheath for 0.05 s against tip resistances of the given forces (N,
    creep speed 3 mm/s): the solver, the drive and the resistances."""
    rod = Rod.straight(0.3, 12.8e-3, 16e6, 2944.0, spacing=5e-3, damping_time=3e-3, lateral_damping=200.0)
    drive = PrescribedVelocity(rod, [0], velocity, ramp=0.02)
    sheath = LineConstraint(rod, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), extent=(-math.inf, 0.1))
    resisted = [TipResistance(rod, rod.tip_node, (1.0, 0.0, 0.0), force, creep_speed=3e-3)
                for force in resistances]
    sim = ExplicitSolver([rod], constraints=[drive, sheath], resistances=resisted)
    sim.run(0.05, record_interval=1e-3)
    return sim, drive, resisted


def test_zero_resistance_changes_nothing_bit_for_bit():
    free, _, _ = _pushed_rod()
    zero, _, _ = _pushed_rod([0.0])
    assert np.array_equal(free.state["scope"].x, zero.state["scope"].x)
    assert np.array_equal(free.state["scope"].v, zero.state["scope"].v)
    held, drive, _ = _pushed_rod([2.0])
    assert not np.array_equal(free.state["scope"].x, held.state["scope"].x)
    assert drive.reaction[0] == pytest.approx(2.0, rel=0.05)  # the push now carries the resistance


def _held_after_push(creep_speed_at_rest, waits=6):
    """A rod pushed against a 2 N tip resistance, its drive then stopped: the resisted force after
    each 0.05 s of waiting at rest, with the resistance's creep speed at rest as given."""
    sim, _, (tip,) = _pushed_rod([2.0], velocity=lambda t: np.array([0.3 if t < 0.05 else 0.0, 0.0, 0.0]))
    tip.creep_speed = creep_speed_at_rest
    forces = []
    for _ in range(waits):
        sim.run(0.05, record_interval=1e-3)
        forces.append(tip.force)
    return np.array(forces)


def test_at_rest_a_creeping_tip_relaxes_its_load_and_a_sticking_one_holds_it():
    creeping = _held_after_push(3e-3)
    assert abs(creeping[-1]) < 0.15 * abs(creeping[0])  # the load leaks away for as long as one waits
    held = _held_after_push(0.0)
    assert abs(held[0]) > 0.5 and np.allclose(held, held[0], rtol=1e-6)  # static friction: the state of the stop, kept


def test_the_settling_run_holds_the_tip_without_creep():
    model = build_insertion(InsertionCase(segment="rsf", angle_deg=45.0, element_size_mm=COARSE_MM,
                                          settle_lateral_damping=150.0))
    assert model.resistance.creep_speed > 0.0
    begin_settling(model)
    assert model.resistance.creep_speed == 0.0 and model.rod.lateral_damping == 150.0


def key_without(case, *names):
    """The key of ``case`` computed by hand with ``names`` left out of its inputs."""
    inputs = case.to_dict()
    for name in names:
        del inputs[name]
    return hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()[:12]


def test_zero_resistance_builds_no_resistance_and_keeps_the_key_of_before():
    case = InsertionCase(segment="rsf", angle_deg=45.0, element_size_mm=COARSE_MM, distal_resistance_N=0.0,
                         relax_max_s=0.0, time_step_estimate="bounds")  # the relax and the time step of before
    assert build_insertion(case).resistance is None
    # the runs of before lacked the first five and the last; the three between stay out at their defaults
    assert case.key() == key_without(case, "distal_resistance_N", "failure_stretch", "held_push_share",
                                     "held_push_lead_mm", "relax_max_s",
                                     "centerline", "centerline_smoothing_mm", "material_parameters",
                                     "time_step_estimate", "contact_surface", "contact_face_subdivision",
                                     "stiffness_factor", "held_push_pace", "straighten_speed_factor")
    assert InsertionCase(distal_resistance_N=5.0).key() != InsertionCase(distal_resistance_N=0.0).key()


@pytest.mark.parametrize("segment, angle", [("rsj", 0.0), ("rsf", 45.0), ("thf", 45.0), ("thf-fixed", 0.0)])
def test_the_resistance_waits_at_the_exit_and_the_exit_takes_the_length(segment, angle):
    model = build_insertion(InsertionCase(segment=segment, angle_deg=angle, element_size_mm=COARSE_MM))
    g, r = model.geometry, model.resistance
    assert r is not None and r.resistance == 5.0
    assert r.creep_speed == pytest.approx(0.01 * model.case.held_push_share * model.case.push_speed)  # the held push's
    assert r.engagement == 0.0  # the tip starts at the entry, far before the exit
    assert resistance_share(g, g.exit_start - 1e-3) == 0.0 and resistance_share(g, g.exit_start + 1e-2) == 1.0
    assert resistance_share(g, g.exit_start + 5e-3) == pytest.approx(0.5)
    if catalog.colon_model(segment).exit_takes_length:
        assert g.centerline_length >= model.total_depth + EXIT_MARGIN - 1e-9  # the far end is out of reach
    else:
        assert g.centerline_length == pytest.approx(g.exit_start + 0.1)  # RSJ keeps its 10 cm exit


def test_the_straight_tube_has_no_exit_to_resist_in():
    assert build_insertion(InsertionCase(segment="straight", element_size_mm=COARSE_MM)).resistance is None


@pytest.mark.parametrize("value", [-1.0, 101.0, math.nan])
def test_a_resistance_outside_its_range_is_refused_in_one_line(value):
    with pytest.raises(ColonsimError, match="distal_resistance_N .* outside"):
        InsertionCase(distal_resistance_N=value).validate()


@pytest.mark.parametrize("value", [-1.0, 501.0, math.nan])
def test_a_held_push_lead_outside_its_range_is_refused_in_one_line(value):
    with pytest.raises(ColonsimError, match=r"held_push_lead_mm .* outside \[0, 500\]; give the distance before"):
        InsertionCase(held_push_lead_mm=value).validate()


def test_a_held_push_lead_enters_the_key_only_where_a_resistance_holds_the_tip():
    # 50 mm by default (2026-11-28); at 0, the runs of before, it stays out of the key
    assert InsertionCase(held_push_lead_mm=50.0).key() == InsertionCase().key()
    before = InsertionCase(held_push_lead_mm=0.0, time_step_estimate="bounds")
    assert before.key() != InsertionCase().key()
    assert before.key() == key_without(before, "held_push_lead_mm", "relax_max_s",  # no relax in the RSJ
                                       "centerline", "centerline_smoothing_mm", "material_parameters",
                                       "failure_stretch", "time_step_estimate", "contact_surface",
                                       "contact_face_subdivision", "stiffness_factor", "held_push_pace",
                                       "straighten_speed_factor")
    # nothing holds the tip: the lead does nothing and stays out
    free = InsertionCase(distal_resistance_N=0.0)
    assert InsertionCase(distal_resistance_N=0.0, held_push_lead_mm=0.0).key() == free.key()
    assert InsertionCase(distal_resistance_N=0.0, held_push_lead_mm=120.0).key() == free.key()


def test_with_a_lead_the_push_slows_before_the_exit_and_the_tip_meets_it_at_the_held_speed():
    # RSJ on a 6 mm mesh with the 13.3 mm scope, its nodes every 10 mm (the smoke spacing): about
    # 20 s; 60 mm is more than the ramp's 4.5 cm of push, so the held push's speed is reached
    # before the tip enters the exit
    lead_mm = 60.0
    run = run_insertion(InsertionCase(segment="rsj", scope="sdc", element_size_mm=6.0, held_push_lead_mm=lead_mm,
                                      scope_spacing_mm=catalog.SMOKE_SCOPE_SPACING_MM))
    ts, model = run.timeseries, run.model
    case, push, exit_start = model.case, model.push, model.geometry.exit_start
    # the held push starts at the first chunk (1 mm of push) after the tip came within the lead ...
    first = ts[ts["phase"] == "held push"].iloc[0]
    assert exit_start - lead_mm * 1e-3 <= first["tip_arc_m"] < exit_start - lead_mm * 1e-3 + 2e-3
    # ... the resistance still waits for the exit ...
    entered = ts.loc[ts["tip_arc_m"] > exit_start, "time_s"].iloc[0]
    assert abs(ts.loc[ts["time_s"] < entered, "distal_force_N"]).max() == 0.0
    assert abs(ts["distal_force_N"]).max() > 0.5 * case.distal_resistance_N
    # ... and the tip enters it at the held push's speed
    assert push.speed(entered) == pytest.approx(case.held_push_share * case.push_speed, rel=1e-9)


def test_the_results_table_and_the_surrogate_know_the_resistance():
    assert catalog.COLUMNS["distal_resistance_N"].surrogate == catalog.SURROGATE_INPUT
    assert catalog.COLUMNS["distal_resistance_N"].option == "--distal-resistance"
    for name in ("max_lag_cm", "final_lag_cm"):
        assert catalog.COLUMNS[name].kind == catalog.OUTPUT


def test_a_surrogate_fitted_over_the_resistance_needs_it_in_every_query():
    from colonsim.surrogate import SweepSurrogate
    from colonsim.surrogate.synthetic import synthetic_sweep

    table = synthetic_sweep(n_runs=24, segments=("rsf",), noise_cm=0.01, n_failed=0, seed=3)
    level = np.resize([0.0, 5.0, 10.0, 20.0], len(table))
    table = table.assign(distal_resistance_N=level,
                         final_deformation_cm=table["final_deformation_cm"] + 0.05 * level)  # SYNTHETIC
    model = SweepSurrogate(targets=("final_deformation_cm",), n_restarts=0).fit(table)
    assert "distal_resistance_N" in model.domains_["rsf"].inputs
    query = {"scope": "pdc", "angle_deg": 30.0, "friction": 0.05}
    with pytest.raises(ColonsimError, match="give distal_resistance_N .*--distal-resistance on the command line"):
        model.predict(query, "rsf", "final_deformation_cm")
    low, high = (model.predict({**query, "distal_resistance_N": r}, "rsf", "final_deformation_cm")[0]
                 for r in (0.0, 20.0))
    assert high > low + 0.5  # it learned the resistance's effect
