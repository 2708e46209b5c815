"""The closing hold of every insertion: held until the run has come to rest, and a summary that
says whether it did (docs/model.md, "Loading")."""

import numpy as np
import pandas as pd
import pytest

from colonsim.insertion.case.outcomes import REST_TOLERANCE, REST_WINDOW, rest_drift
from colonsim.insertion.case.results import rest_words
from colonsim.insertion.case.run_summary import rest_summary


def hold(deformation, tip, duration=0.2, dt=1e-3, start=1.0):
    """A recorded hold from ``start``: deformation(t) and tip(t) (m) sampled every ``dt``."""
    t = start + np.arange(0.0, duration + 0.5 * dt, dt)
    return pd.DataFrame({"time_s": t, "deformation_m": deformation(t - start), "tip_displacement_m": tip(t - start)})


def test_the_drift_is_what_moved_over_the_last_window():
    ts = hold(lambda t: 0.01 + 1e-3 * t, lambda t: 0.0 * t)  # 1 mm/s: 0.05 mm over 0.05 s
    u, w = rest_drift(ts["time_s"], ts["deformation_m"], ts["tip_displacement_m"])
    assert u == pytest.approx(1e-3 * REST_WINDOW, rel=1e-6) and w == 0.0
    assert rest_drift([0.0, 0.01], [0.0, 0.0], [0.0, 0.0]) is None  # too short to tell


@pytest.mark.parametrize("speed,came", [(0.1 * REST_TOLERANCE / REST_WINDOW, True),
                                        (3.0 * REST_TOLERANCE / REST_WINDOW, False)])
def test_the_verdict_can_go_either_way(speed, came):
    """A tip still creeping at 3 tolerances per window has not come to rest; at a tenth, it has."""
    ts = hold(lambda t: 0.012 + 0.0 * t, lambda t: speed * t)
    rest = rest_summary(ts, hold_start=1.0)
    assert rest["came_to_rest"] is came
    assert rest["held_s"] == pytest.approx(0.2)
    assert ("did NOT come to rest" in rest_words(rest)) is (not came)


def test_a_run_that_ended_under_load_never_came_to_rest():
    ts = hold(lambda t: 0.0 * t, lambda t: 0.0 * t)
    rest = rest_summary(ts, hold_start=5.0)  # the hold was still to come when the run ended (a jam, a tear)
    assert rest["came_to_rest"] is False and rest["deformation_drift_mm"] is None
    assert "without coming to rest" in rest_words(rest)
