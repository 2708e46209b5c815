"""Joint (multi-mode) fits on curves that cannot be what their headers say, or that the law does
not follow (colonsim.identification.curve_checks): refused before the fit, or warned about by
name with the likely cause, the warning recorded in material.json; and the good curves pass."""

import json

import numpy as np
import pytest

from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.identification.curve_checks import misfit_warnings
from colonsim.identification.hyperelastic import calibration_law
from colonsim.identification.joint import calibrate_joint
from colonsim.identification.stress_curves import read_mode_manifest, read_stress_curve

LAW, TRUE = "mooney_rivlin_2", [20e3, 5e3]  # Pa
REACH = {"uniaxial": 2.0, "equibiaxial": 1.6, "planar": 1.8}


def write_modes(folder, scale=None, header="stretch,nominal_stress [kPa]", rows=None):
    """SYNTHETIC curves of LAW in the three modes, 0.5 % noise, one CSV each, and their manifest.
    ``scale``: {mode: factor} applied to the written stress (a wrong unit)."""
    rng = np.random.default_rng(3)
    law = calibration_law(LAW)
    lines = ["specimen,file,mode"]
    for mode, top in REACH.items():
        l = np.linspace(1.0, top, 30)
        p = law.nominal_stress(mode, l, TRUE)
        p = p + rng.normal(0.0, 0.005 * p.max(), l.size)
        p *= (scale or {}).get(mode, 1.0)
        body = rows(l, p) if rows else [f"{a:.6f},{b / 1e3:.6f}" for a, b in zip(l, p)]
        (folder / f"{mode}.csv").write_text("\n".join([header, *body]) + "\n")
        lines.append(f"{mode},{mode}.csv,{mode}")
    (folder / "manifest.csv").write_text("\n".join(lines) + "\n")
    return folder / "manifest.csv"


def calibrate(manifest, out, capsys):
    code = main(["calibrate", "--manifest", str(manifest), "--law", LAW, "--no-progress", "--out", str(out)])
    captured = capsys.readouterr()
    return code, captured.err.strip().splitlines()


def test_curves_the_law_follows_give_no_warning(tmp_path, capsys):
    code, err = calibrate(write_modes(tmp_path), tmp_path / "out", capsys)
    assert code == 0 and err == []
    doc = json.loads((tmp_path / "out" / "material.json").read_text())
    assert doc["warnings"] == []
    for curve in doc["fit"]["curves"]:
        assert curve["follows_curve"] and curve["rms_over_noise"] < 2.0 and curve["r2"] > 0.99
    assert doc["parameters"]["C10"] == pytest.approx(TRUE[0], rel=0.05)


def test_a_curve_in_the_wrong_unit_is_named_with_the_cause(tmp_path, capsys):
    code, err = calibrate(write_modes(tmp_path, scale={"equibiaxial": 10.0}), tmp_path / "out", capsys)
    assert code == 0
    named = [line for line in err if line.startswith("colonsim: warning: equibiaxial (equibiaxial)")]
    assert len(named) == 1 and "a unit off by 10?" in named[0] and "does not follow this curve" in named[0]
    doc = json.loads((tmp_path / "out" / "material.json").read_text())
    assert any(w.startswith("equibiaxial (equibiaxial)") and "unit off by 10" in w for w in doc["warnings"])
    assert not next(c for c in doc["fit"]["curves"] if c["curve"] == "equibiaxial")["follows_curve"]


@pytest.mark.parametrize("header, rows, match", [
    ("strain,nominal_stress [kPa]", lambda l, p: [f"{100 * (a - 1):.4f},{b / 1e3:.6f}" for a, b in zip(l, p)],
     r"stretch reaches 101, beyond any tissue or rubber test \(at most 10\) \(per-cent strain under a plain 'strain' "
     r"header\? name the column 'strain \[%\]'\)"),
    ("stretch,nominal_stress [kPa]", lambda l, p: [f"{a:.6f},{-b / 1e3:.6f}" for a, b in zip(l, p)],
     r"the stress is negative in tension .*give tension as positive stress"),
    ("stretch,nominal_stress [kPa]",  # a load cell's noise (1 Pa) and nothing else
     lambda l, p: [f"{a:.6f},{b:.6f}" for a, b in zip(l, 1e-3 * np.random.default_rng(5).normal(size=l.size))],
     r"the stress does not rise above its noise .*no load was recorded"),
])
def test_a_curve_that_cannot_be_what_its_header_says_is_refused_before_the_fit(tmp_path, capsys, header, rows, match):
    manifest = write_modes(tmp_path, header=header, rows=rows)
    code, err = calibrate(manifest, tmp_path / "out", capsys)
    assert code == 2 and len(err) == 1 and re_search(match, err[0]), err
    assert not (tmp_path / "out" / "material.json").exists()


def re_search(pattern, text):
    import re

    return re.search(pattern, text) is not None


def test_a_manifest_with_a_file_twice_or_a_misspelt_column_is_refused(tmp_path):
    manifest = write_modes(tmp_path)
    good = read_mode_manifest(manifest)
    assert [c.mode for c in good] == list(REACH)
    (tmp_path / "twice.csv").write_text("specimen,file,mode\na,uniaxial.csv,uniaxial\nb,./uniaxial.csv,uniaxial\n")
    with pytest.raises(ColonsimError, match=r"'a' and 'b' are the same file .*list it once"):
        read_mode_manifest(tmp_path / "twice.csv")
    (tmp_path / "typo.csv").write_text("specimen,file,mode,wieght\na,uniaxial.csv,uniaxial,2\n")
    with pytest.raises(ColonsimError, match=r"unknown column 'wieght' \(did you mean weight\?\)"):
        read_mode_manifest(tmp_path / "typo.csv")


def test_a_negative_small_strain_modulus_is_a_warning(tmp_path):
    curve = read_stress_curve(write_modes(tmp_path).parent / "uniaxial.csv", "uniaxial")
    rows = [{"curve": curve.name, "mode": "uniaxial", "follows_curve": True}]
    assert misfit_warnings(LAW, rows, [curve], mu0=1e3) == []
    assert "small-strain shear modulus is -1000 Pa, not positive" in misfit_warnings(LAW, rows, [curve], mu0=-1e3)[0]


def test_a_single_curve_joint_fit_reports_its_noise_ratio_both_ways(tmp_path):
    curve = read_stress_curve(write_modes(tmp_path).parent / "uniaxial.csv", "uniaxial")
    fits = calibrate_joint([curve], LAW).per_curve.iloc[0]
    assert fits["follows_curve"] and fits["rms_over_noise"] < 2.0
    fails = calibrate_joint([curve], "neo_hookean").per_curve.iloc[0]  # one term cannot bend with the data
    assert not fails["follows_curve"] and fails["rms_over_noise"] > 2.0
