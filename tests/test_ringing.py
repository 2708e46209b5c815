"""The ringing ratio (docs/model.md, "Time integration and damping") on forces with known answers."""

import numpy as np
import pytest

from colonsim.insertion.case.ringing import RINGING_LIMIT, RINGING_WINDOW, ringing_ratio


def pushed(z, force, contact_from=0.0):
    return ringing_ratio(z, force, z >= contact_from)


def test_a_force_oscillating_about_a_constant_mean():
    """F = 4 + 2 sin(2 pi z / 1 mm): the 1 cm mean is 4 N, the RMS about it 2 / sqrt(2) N."""
    z = np.linspace(0.0, 0.2, 40001)
    r = pushed(z, 4.0 + 2.0 * np.sin(2 * np.pi * z / 1e-3))
    assert r["mean_N"] == pytest.approx(4.0, rel=1e-3)
    assert r["rms_N"] == pytest.approx(2.0 / np.sqrt(2.0), rel=2e-3)
    assert r["ratio"] == pytest.approx(1.0 / (2.0 * np.sqrt(2.0)), rel=3e-3)
    assert r["push_cm"] == pytest.approx(20.0)


def test_a_smooth_trend_does_not_ring():
    """A force rising steadily, even steeply, is followed by its 1 cm mean (ratio near 0)."""
    z = np.linspace(0.0, 0.25, 2001)
    r = pushed(z, 1.0 + 40.0 * z + 100.0 * z**2)
    assert r["ratio"] < 0.01


@pytest.mark.parametrize("amplitude,holds", [(0.1, True), (0.4, False)])
def test_the_verdict_can_go_either_way(amplitude, holds):
    z = np.linspace(0.0, 0.2, 20001)
    r = pushed(z, 1.0 + amplitude * np.sin(2 * np.pi * z / 2e-3))
    assert (r["ratio"] < RINGING_LIMIT) is holds


def test_pauses_and_sampling_do_not_count():
    """Samples at a standing depth (the relax of RSF/THF) weigh nothing, and a run sampled twice
    as densely (half the push speed) measures the same thing."""
    z = np.linspace(0.0, 0.2, 4001)
    f = 3.0 + 0.5 * np.sin(2 * np.pi * z / 3e-3)
    base = pushed(z, f)
    paused = np.concatenate((z[:2000], np.full(500, z[2000]), z[2000:]))
    force = np.concatenate((f[:2000], 10.0 * np.random.default_rng(1).standard_normal(500), f[2000:]))
    assert pushed(paused, force)["ratio"] == pytest.approx(base["ratio"], rel=1e-3)
    z2 = np.linspace(0.0, 0.2, 8001)
    assert pushed(z2, 3.0 + 0.5 * np.sin(2 * np.pi * z2 / 3e-3))["ratio"] == pytest.approx(base["ratio"], rel=1e-2)


def test_it_starts_at_the_first_contact():
    z = np.linspace(0.0, 0.2, 4001)
    f = np.where(z < 0.05, 5.0 * np.sin(2 * np.pi * z / 2e-3), 2.0)  # the ramp's inertia before contact
    assert pushed(z, f, contact_from=0.05)["ratio"] == pytest.approx(0.0, abs=1e-9)
    assert pushed(z, f)["ratio"] > 0.5


def test_undefined_without_enough_push():
    z = np.linspace(0.0, 0.5 * RINGING_WINDOW, 50)
    assert np.isnan(pushed(z, np.ones_like(z))["ratio"])
    assert np.isnan(ringing_ratio(z, np.ones_like(z), np.zeros_like(z, dtype=bool))["ratio"])


def test_ringing_made_of_drops_is_told_from_an_oscillation():
    """A force rising with the push that drops by 3 N at three depths (a loop snapping through)
    rings about its 1 cm mean only around the drops; an oscillation of the same RMS rings
    everywhere and has no drop."""
    from colonsim.insertion.case.ringing import ringing_at_drops

    z = np.linspace(0.0, 0.3, 30001)
    steps = 2.0 + 30.0 * z - 3.0 * sum(z >= d for d in (0.08, 0.15, 0.22))
    r = ringing_ratio(z, steps, z >= 0.0, snaps=[])
    assert r["ratio"] > RINGING_LIMIT  # the steps, not left out, fail the ringing criterion ...
    at = ringing_at_drops(z, steps, z >= 0.0)
    assert at["drops"] == 3 and at["share"] > 0.95 and at["push_share"] < 0.15  # ... and are told apart
    wave = 2.0 + 30.0 * z + np.sqrt(2.0) * r["rms_N"] * np.sin(2 * np.pi * z / 3e-3)
    assert ringing_ratio(z, wave, z >= 0.0, snaps=[])["rms_N"] == pytest.approx(r["rms_N"], rel=0.1)
    at = ringing_at_drops(z, wave, z >= 0.0)
    assert at["drops"] == 0 and at["share"] == 0.0
