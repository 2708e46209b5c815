"""Characteristic points, the quasi-static check and the jam detector on synthetic curves with known answers."""

import numpy as np
import pytest

from colonsim.insertion.case.outcomes import (JAM_FORCE, JAM_PROGRESS, JAM_PUSH, arc_along, characteristic_points, jammed,
                                              principal_stretches, quasi_static_fraction, sliding_kinetic_energy,
                                              tip_heading, turned_back)
from colonsim.insertion.case.ringing import ringing_wavelength
from colonsim.insertion.case.results import distal_words


def rsj_like(noise=0.0, seed=0):
    """A rise to A = 2 cm at t = 0.3, a dip to B = 1.2 cm at t = 0.5, a rise to C = 3.8 cm at 0.9."""
    t = np.linspace(0.0, 1.0, 501)
    u = np.interp(t, [0.0, 0.3, 0.5, 0.9, 1.0], [0.0, 0.02, 0.012, 0.038, 0.036])
    u = u + noise * np.random.default_rng(seed).standard_normal(t.size)
    return t, 0.6 * t, u


def test_points_a_b_c_found():
    t, z, u = rsj_like()
    p = characteristic_points(t, z, u)
    assert p["A"]["time_s"] == pytest.approx(0.3) and p["A"]["deformation_m"] == pytest.approx(0.02)
    assert p["B"]["time_s"] == pytest.approx(0.5) and p["B"]["deformation_m"] == pytest.approx(0.012)
    assert p["C"]["time_s"] == pytest.approx(0.9) and p["C"]["deformation_m"] == pytest.approx(0.038)
    assert p["C"]["depth_m"] == pytest.approx(0.54)


def test_recording_noise_is_not_taken_for_a():
    """Noise of 0.1 mm (0.3 % of the maximum) stays below the 5 % prominence threshold."""
    t, z, u = rsj_like(noise=1e-4)
    p = characteristic_points(t, z, u)
    assert p["A"]["time_s"] == pytest.approx(0.3, abs=0.02)
    assert p["C"]["time_s"] == pytest.approx(0.9, abs=0.02)


def test_monotone_curve_has_only_c():
    t = np.linspace(0, 1, 50)
    p = characteristic_points(t, t, t**2)
    assert p["A"] is None and p["B"] is None and p["C"]["time_s"] == pytest.approx(1.0)


def test_quasi_static_fraction():
    internal = np.r_[0.0, np.ones(9)]
    kinetic = np.r_[0.5, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.5, 0.5]
    # the first sample (no strain energy yet) is left out: 7 of the 9 others are below 10 %
    assert quasi_static_fraction(kinetic, internal) == pytest.approx(7 / 9)


def test_principal_stretch_of_a_stretched_and_rotated_triangle():
    from colonsim.insertion.engine.shell_membrane import reference_frames

    nodes = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    tri = np.array([[0, 1, 2]])
    dm_inv, _ = reference_frames(nodes, tri)
    stretch = np.diag([1.3, 0.9, 1.0])  # 1.3 along x, 0.9 along y
    c, s = np.cos(0.7), np.sin(0.7)
    rotation = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    x = nodes @ stretch.T @ rotation.T
    assert principal_stretches(x, tri, dm_inv)[0] == pytest.approx(1.3, rel=1e-12)


def test_sliding_kinetic_energy_removes_only_the_tank_tread_motion():
    # nodes on a quarter circle moving along the tangent at the push speed: nothing left
    phi = np.linspace(0.0, np.pi / 2, 40)
    x = np.column_stack([np.cos(phi), np.sin(phi), np.zeros_like(phi)])
    tangent = np.column_stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)])
    mass = np.full(40, 0.01)
    assert sliding_kinetic_energy(x, 0.6 * tangent, mass, 0.6) == pytest.approx(0.0, abs=1e-5)  # one-sided ends
    # a sideways velocity w on top of the sliding: 1/2 m w^2 exactly
    w = np.array([0.0, 0.0, 0.2])
    assert sliding_kinetic_energy(x, 0.6 * tangent + w, mass, 0.6) == pytest.approx(0.5 * 0.4 * 0.04, rel=1e-3)


# Jam detector: 4 cm of push sampled every 0.05 mm; the window is the last 1 cm of push, the force
# the mean over its last 5 mm.
PUSH = np.linspace(0.0, 0.04, 801)
STUCK = np.minimum(PUSH, 0.01)  # the tip stops 1 cm in and stays there


def test_jam_defaults():
    assert JAM_PUSH == 0.01 and JAM_PROGRESS == 1e-3 and JAM_FORCE == 43.0


def test_tip_held_under_the_largest_clinical_push_is_a_jam():
    force = 2.0 + 7000.0 * np.maximum(PUSH - 0.01, 0.0)  # a blocked tip: 70 N per cm of push once it stops
    assert jammed(PUSH, STUCK, force)
    # the same force with the tip following the push is no jam
    assert not jammed(PUSH, PUSH, force)


@pytest.mark.parametrize("level, jam", [(42.0, False), (44.0, True)])
def test_a_stalled_tip_jams_only_at_the_clinical_push(level, jam):
    # a tip stalled under a steady push: below 43 N the scope bows on until the tip passes
    assert jammed(PUSH, STUCK, np.full_like(PUSH, level)) is jam
    # a lower limit turns the 42 N stall into a jam too
    assert jammed(PUSH, STUCK, np.full_like(PUSH, level), force=40.0)


def test_a_stall_under_a_rising_moderate_force_is_no_jam():
    # measured: THF tips stalled at the hepatic flexure for 2.4-5.7 cm of push while the push rose
    # from 2 to 10 N, then passed
    force = 6.0 + 200.0 * np.maximum(PUSH - 0.01, 0.0)
    assert not jammed(PUSH, STUCK, force)


@pytest.mark.parametrize("advance, jam", [(2e-3, False), (0.5e-3, True)])
def test_tip_progress_over_the_window_against_the_threshold(advance, jam):
    # the tip creeps forward by `advance` over the last 1 cm of push (threshold: 1 mm) under 50 N
    arc = 0.01 + advance * np.clip((PUSH - 0.03) / 0.01, 0.0, 1.0)
    force = np.full_like(PUSH, 50.0)
    assert jammed(PUSH, arc, force) is jam
    # a looser threshold turns the 2 mm creep into a jam too
    assert jammed(PUSH, arc, force, progress=3e-3)


@pytest.mark.parametrize("pushed, jam", [(0.007, False), (0.0099, False), (0.012, True)])
def test_too_little_push_recorded_is_no_jam(pushed, jam):
    # stuck from the start under 50 N: a jam only once a whole window (1 cm) of push is on record
    z = np.linspace(0.0, pushed, 301)
    assert jammed(z, np.zeros_like(z), np.full_like(z, 50.0)) is jam


def test_constant_depth_is_no_jam():
    # the relax phase: no push, the tip at rest, the force high as the wall settles
    z = np.full(200, 0.03)
    assert not jammed(z, np.full(200, 0.01), np.linspace(50.0, 60.0, 200))
    # pushed 3 cm with the tip following, then held: the window (the last 1 cm of push) saw the tip advance
    z = np.r_[np.linspace(0.0, 0.03, 601), np.full(200, 0.03)]
    force = np.r_[np.full(601, 2.0), np.linspace(50.0, 60.0, 200)]
    assert not jammed(z, np.minimum(z, 0.03), force)


@pytest.mark.parametrize("mean, jam", [(45.0, True), (41.0, False)])
def test_ringing_force_is_judged_by_its_mean_over_5_mm(mean, jam):
    """The drive reaction rings: +-20 N at a period of 1/21 cm of push about a steady mean; the
    samples cross 43 N either way, the mean over the last 5 mm of push decides."""
    period = 0.01 / 21
    force = mean + 20.0 * np.cos(2 * np.pi * PUSH / period)
    assert np.any(force > 43.0) and np.any(force < 43.0)
    assert jammed(PUSH, STUCK, force) is jam


def _ringing_push(wavelength_m, amplitude_N=0.1, seed=0):
    """A push force along 30 cm of push: a slow rise, ringing with the given wavelength in push
    distance, recording noise, and a pause (many samples at one depth) halfway."""
    rng = np.random.default_rng(seed)
    z = np.linspace(0.0, 0.3, 6000)
    z = np.concatenate((z[:3000], np.full(500, z[3000]), z[3000:]))
    f = 1.0 + 5.0 * z + amplitude_N * np.sin(2.0 * np.pi * z / wavelength_m) + 0.01 * rng.standard_normal(z.size)
    return z, f, np.ones(z.size, dtype=bool)


@pytest.mark.parametrize("wavelength_mm", [2.5, 5.0, 8.0])
def test_ringing_wavelength_finds_the_period_in_push_distance(wavelength_mm):
    z, f, contact = _ringing_push(wavelength_mm * 1e-3)
    # periodogram bins over 30 cm of push are 1/0.3 per m apart: a 5 mm period is resolved to 1.5 %
    assert ringing_wavelength(z, f, contact) == pytest.approx(wavelength_mm * 1e-3, rel=0.04)


def test_ringing_wavelength_sees_through_a_swell_ten_times_larger():
    z, f, contact = _ringing_push(7e-3, amplitude_N=0.05)
    f = f + 0.5 * np.sin(2.0 * np.pi * z / 0.1)  # a 10 cm swell is trend, not ringing
    assert ringing_wavelength(z, f, contact) == pytest.approx(7e-3, rel=0.04)


def test_ringing_wavelength_needs_two_windows_of_push_after_contact():
    z, f, contact = _ringing_push(5e-3)
    short = z < 0.015
    assert np.isnan(ringing_wavelength(z[short], f[short], contact[short]))
    late = z > 0.285  # contact begins 1.5 cm before the end of the push
    assert np.isnan(ringing_wavelength(z, f, late))
    assert np.isnan(ringing_wavelength(z, f, np.zeros(z.size, dtype=bool)))


def test_the_tip_position_along_a_bend_is_its_arc_length_between_samples():
    """A 90 deg bend of radius 5 cm sampled every millimetre: a point at any angle, on the curve or
    1 cm inside it, reads R theta (within 1e-7 m: the interpolation errs by about h^3 / R^2, 0.4
    micrometres for h = 1 mm, and far less inside a segment), not the nearest sample's arc (up to
    0.5 mm away); a point before the start or past the end reads the end's arc."""
    radius = 0.05
    arc = np.linspace(0.0, 0.5 * np.pi * radius, int(0.5 * np.pi * radius / 1e-3) + 1)
    angle = arc / radius
    points = radius * np.column_stack([np.sin(angle), 1.0 - np.cos(angle), np.zeros_like(arc)])
    tangents = np.column_stack([np.cos(angle), np.sin(angle), np.zeros_like(arc)])
    for theta in np.linspace(0.01, 1.5, 37):
        for r in (radius, radius - 0.01):
            p = np.array([r * np.sin(theta), radius - r * np.cos(theta), 0.003])
            assert arc_along(points, arc, tangents, p) == pytest.approx(radius * theta, abs=1e-7)
    assert arc_along(points, arc, tangents, np.array([-0.01, 0.0, 0.0])) == 0.0
    assert arc_along(points, arc, tangents, np.array([0.06, 0.07, 0.0])) == pytest.approx(arc[-1])


def test_the_tip_position_moves_with_the_tip_not_in_steps_of_the_sampling():
    """Advanced 0.1 mm at a time along a straight centerline sampled every 1.003 mm, the position
    advances 0.1 mm each time (the nearest sample moved in steps of 1.003 mm)."""
    arc = np.linspace(0.0, 0.3, 300)
    points = np.column_stack([arc, np.zeros_like(arc), np.zeros_like(arc)])
    tangents = np.tile([1.0, 0.0, 0.0], (len(arc), 1))
    read = [arc_along(points, arc, tangents, np.array([x, 0.002, -0.001])) for x in np.arange(0.1, 0.11, 1e-4)]
    assert np.diff(read) == pytest.approx(np.full(len(read) - 1, 1e-4), abs=1e-12)


@pytest.mark.parametrize("turn_deg", [0.0, 30.0, 89.0, 91.0, 150.0, 180.0])
def test_the_tip_heading_is_the_angle_of_its_last_segment_to_the_lumen(turn_deg):
    """A quarter circle of radius 0.1 m as the centerline, the tip at its middle (45 deg round), its
    last segment turned by ``turn_deg`` from the tangent there, in the bend's plane: the heading
    is that angle whatever the scope's other nodes do."""
    arc = np.linspace(0.0, 0.05 * np.pi, 2001)
    phi = arc / 0.1
    tangents = np.stack([-np.sin(phi), np.cos(phi), np.zeros_like(phi)], axis=1)
    here = np.pi / 4
    t = np.array([-np.sin(here), np.cos(here), 0.0])
    n = np.array([np.cos(here), np.sin(here), 0.0])
    a = np.radians(turn_deg)
    tip = 0.1 * n
    scope = np.array([[5.0, 5.0, 5.0], tip - 0.005 * (np.cos(a) * t + np.sin(a) * n), tip])
    assert tip_heading(scope, 2, arc, tangents, 0.1 * here) == pytest.approx(turn_deg, abs=0.1)


def test_a_tip_turned_back_is_dated_from_the_push_it_stayed_so():
    depth = np.linspace(0.0, 0.6, 61)
    assert turned_back(depth, np.full(61, 30.0)) is None  # never
    heading = np.where(depth > 0.4, 170.0, 40.0)
    assert turned_back(depth, heading) == pytest.approx(0.41)
    heading[50] = 60.0  # back on course for one sample: dated from after it
    assert turned_back(depth, heading) == pytest.approx(0.51)
    heading[-1] = 80.0  # on course again at the end: not turned back
    assert turned_back(depth, heading) is None
    assert turned_back(depth, np.full(61, 120.0)) == 0.0 and turned_back([], []) is None


def test_the_command_line_says_when_the_tip_ended_turned_back():
    summary = {"max_lag_cm": 25.3, "final_lag_cm": 25.3, "tip_turned_back_cm": None,
               "distal_resistance": {"acting": True, "resistance_N": 20.0, "final_force_N": 0.0}}
    assert "TURNED BACK" not in distal_words(summary)
    assert "TURNED BACK at 59.4 cm" in distal_words({**summary, "tip_turned_back_cm": 59.4})
    assert "TURNED BACK" not in distal_words({k: v for k, v in summary.items() if k != "tip_turned_back_cm"})
