"""Colonoscope definitions (docs/model.md)."""

import math

import pytest

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.scopes import colonoscope


def test_named_scopes_and_material():
    assert [colonoscope(n).diameter for n in ("utc", "PDC", "Sdc")] == pytest.approx([9.2e-3, 11.3e-3, 12.8e-3])
    sdc = colonoscope("sdc")
    assert sdc.wave_speed == pytest.approx(74.0, abs=0.5)  # sqrt(16e6 / 2944) = 73.7 m/s
    assert sdc.flexural_rigidity == pytest.approx(16e6 * math.pi * 12.8e-3**4 / 64)
    assert colonoscope("utc").small_caliber and not sdc.small_caliber


def test_diameter_in_mm_and_rod():
    s = colonoscope("10.5")
    assert s.diameter == pytest.approx(10.5e-3) and s.name == "10.5 mm"
    rod = s.rod(start=(0, 0, 0), direction=(0, 0, 1), length=0.3, spacing=5e-3)
    assert rod.radius == pytest.approx(5.25e-3) and rod.x0[-1, 2] == pytest.approx(0.3)
    assert rod.flexural_rigidity == pytest.approx(s.flexural_rigidity)


@pytest.mark.parametrize("spec,message", [("gastroscope", "unknown scope"), ("0.0128", "outside 3-20 mm"),
                                          ("128", "outside 3-20 mm"), ("nan", "outside")])
def test_bad_scopes(spec, message):
    with pytest.raises(ColonsimError, match=message):
        colonoscope(spec)


def test_scope_must_fit_the_colon():
    colonoscope("sdc").check_fits(23e-3)
    with pytest.raises(ColonsimError, match="as wide as or wider than the colon"):
        colonoscope("15").check_fits(15e-3)
