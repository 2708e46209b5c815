"""The usage example of the solver's module docstring runs and gives a sensible push."""

import numpy as np

import colonsim.insertion.engine.solver


def test_docstring_example_runs():
    # The scope starts 1 cm below the axis in a 36 mm lumen and is pushed at 60 cm/s for 5 ms
    # (3 mm of travel with a 2 ms ramp, 1 mm of it ramping): the tip does not reach the wall,
    # so the push force is the scope's inertia + damping (positive) and no contact is active.
    code = colonsim.insertion.engine.solver.__doc__.split("Example (run by the test suite)::")[1]
    scope = {}
    exec(compile("\n".join(line[4:] for line in code.splitlines()), "solver-example", "exec"), scope)
    history = scope["history"]
    assert len(history.time) == 6  # first step, then every millisecond up to 5 ms
    assert np.all(np.isfinite(scope["push_force"])) and scope["push_force"][-1] > 0.0
    assert np.all(scope["contact_force"] == 0.0)
    assert history.bodies["colon"]["positions"].shape == (6, len(scope["colon"].x0), 3)
    travelled = scope["sim"].state["scope"].x[0, 0] - scope["scope"].x0[0, 0]
    assert abs(travelled - 0.6 * (5e-3 - 1e-3)) < 1e-5
