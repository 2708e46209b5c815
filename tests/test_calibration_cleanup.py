"""Clean-up of test curves (colonsim.identification.cleanup): slack and preload found where they
are and only there, the re-referenced curve, decimation, and the record in material.json."""

import json

import numpy as np
import pytest

from colonsim.data import BUNDLED_MANIFEST
from colonsim.errors import ColonsimError
from colonsim.identification.cleanup import clean, decimate, find_preload, find_slack
from colonsim.identification.testdata import TensileCurve, read_manifest, write_curve
from colonsim.identification.uniaxial import homogeneous_force
from colonsim.laws import get_law
from colonsim.workflows import CalibrationRequest, calibrate

LAW, PARAMS = get_law("mooney_rivlin_3"), (652.01, 42835.25, 219120.3)
L, W, T = 0.1, 0.025, 0.002


def strip(d0, noise=0.05, seed=0):
    """A strip mounted with slack d0 > 0 (flat start) or preload d0 < 0 (starts under load)."""
    rng = np.random.default_rng(seed)
    d = np.arange(max(0.0, 0.0), 0.06, 2e-5)
    taut = np.clip(d - d0, 0.0, None)
    f = homogeneous_force(taut, L + d0, W, T, LAW, PARAMS) + rng.normal(0.0, noise, d.size)
    return TensileCurve("synthetic", d, f, L, W, T)


def test_slack_is_found_where_it_is():
    assert find_slack(strip(3e-3).displacement, strip(3e-3).force) == pytest.approx(3e-3, abs=0.3e-3)
    assert find_slack(strip(0.0).displacement, strip(0.0).force) is None
    assert find_preload(strip(0.0).displacement, strip(0.0).force) is None
    for c in read_manifest(BUNDLED_MANIFEST):  # the bundled curves have a rising toe, no slack
        assert find_slack(c.displacement, c.force) is None and find_preload(c.displacement, c.force) is None


def test_preload_is_found_and_corrected_only_when_asked():
    c = strip(-4e-3)
    assert find_preload(c.displacement, c.force) == pytest.approx(-4e-3, abs=0.4e-3)  # 0.3 mm short: a line misses the toe
    same, notes = clean(c)
    assert same is c and "starts under load" in notes[0]
    fixed, _ = clean(c, "detect")
    assert fixed.length == pytest.approx(L - 4e-3, abs=0.4e-3) and fixed.displacement[0] == 0.0 == fixed.force[0]


def test_given_load_start_and_decimation():
    c, _ = clean(strip(2e-3), 2e-3, 50)
    assert c.length == pytest.approx(L + 2e-3) and c.displacement.size == 50
    assert [s["step"] for s in c.meta["cleaning"]] == ["load start", "decimation"]
    with pytest.raises(ColonsimError, match="outside the curve"):
        clean(strip(0.0), 0.07)
    with pytest.raises(ColonsimError, match="at least 5 points"):
        decimate(strip(0.0), 3)


def test_slack_correction_is_said_and_recorded(tmp_path, capsys):
    path = tmp_path / "slack.csv"
    write_curve(path, strip(3e-3))
    calibrate(CalibrationRequest(curve=path, length_mm=100, width_mm=25, thickness_mm=2, analytic=True, quick=True,
                                 show_progress=False), tmp_path / "out")
    assert "slack region found: the load starts at" in capsys.readouterr().out
    doc = json.loads((tmp_path / "out" / "material.json").read_text())
    step = doc["specimen"]["cleaning"][0]
    assert step["how"] == "slack region found in the data" and step["length_mm_after"] == pytest.approx(103, abs=0.3)
    assert (tmp_path / "out" / "cleaning.png").is_file()
    mu0 = doc["small_strain"]["mu0_Pa"]
    assert mu0 == pytest.approx(2 * (PARAMS[0] + PARAMS[1]), rel=0.1)
