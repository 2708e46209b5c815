"""The constraints of the damped pushed rod, whose energy balance (like the conservation of free
vibration) is a row of the verification table (tests/test_verification_table.py)."""

import numpy as np
import pytest

from colonsim.insertion.study.verification_contact import damped_push_energy_balance


def test_push_then_hold_reactions_and_displacement():
    _, _, _, hist, sim = damped_push_energy_balance()
    # the push force is the reaction of the prescribed-velocity constraint; after the push the
    # fixed node takes over the reaction
    assert np.any(np.abs(hist.reactions[0][:, 0]) > 0.0)
    assert np.all(hist.reactions[0][hist.time > 8.5e-3] == 0.0)
    # the pushed node moved by the integral of the ramped velocity, 0.5 (8 ms - 1 ms), up to the
    # one step in which the window ends
    assert sim.state["scope"].x[0, 0] == pytest.approx(0.5 * (8e-3 - 1e-3), abs=0.5 * sim.dt)
