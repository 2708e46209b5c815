"""Push profiles: speeds, depths and phase timing against closed-form kinematics."""

import numpy as np
import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.manoeuvre import continuous_push, straighten_relax_push


def test_continuous_push_reaches_the_depth_smoothly():
    p = continuous_push(0.20, speed=0.6, ramp=0.05)
    assert p.duration == pytest.approx(0.025 + 0.20 / 0.6)
    assert p.depth(p.duration) == pytest.approx(0.20, rel=1e-12)
    assert p.speed(0.0) == 0.0 and p.speed(0.025) == pytest.approx(0.3) and p.speed(0.1) == pytest.approx(0.6)
    # depth is the integral of speed (trapezoid on a fine grid)
    t = np.linspace(0, p.duration, 20001)
    v = np.array([p.speed(x) for x in t])
    assert np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(t)) == pytest.approx(p.depth(p.duration), rel=1e-6)


def test_straighten_relax_push_phases():
    p = straighten_relax_push(0.15, 0.40, speed=0.6, ramp=0.05, relax=0.1)
    names = [ph.name for ph in p.phases]
    assert names == ["straighten", "stop", "relax", "push"]
    straighten, stop, relax, push = p.phases
    # the mobile part is held until the scope has come to rest at the straightening depth
    assert straighten.lateral_constraint and stop.lateral_constraint
    assert not relax.lateral_constraint and not push.lateral_constraint
    assert p.lateral_constraint_end == stop.end == relax.start
    assert p.speed(stop.end) == pytest.approx(0.0, abs=1e-12)
    assert p.depth(stop.end) == pytest.approx(0.15, rel=1e-12)
    # it rests there for the relax time, released, then the push goes on to the total depth
    assert relax.end - relax.start == pytest.approx(0.1)
    assert p.depth(relax.end) == pytest.approx(0.15, rel=1e-12)
    assert p.depth(p.duration) == pytest.approx(0.40, rel=1e-12)
    assert p.phase_at(relax.start + 0.01).name == "relax"
    assert continuous_push(0.2).lateral_constraint_end is None


@pytest.mark.parametrize("args,message", [((-0.1,), "must be positive"), ((0.2, 0.0), "push speed"),
                                          ((0.2, 0.6, -1.0), "ramp")])
def test_bad_profiles(args, message):
    with pytest.raises(ColonsimError, match=message):
        continuous_push(*args)
    with pytest.raises(ColonsimError, match="must lie between 0 and the total depth"):
        straighten_relax_push(0.5, 0.4)
