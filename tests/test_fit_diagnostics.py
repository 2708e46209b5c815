"""Fit diagnostics that tell the truth: the curve's own noise, a warning when the law cannot
follow the curve, identification words backed by numbers, the model-form share of mu0; and
`calibrate --compare-laws`: every law, fitted and ranked by BIC."""

import json

import numpy as np
import pandas as pd
import pytest

from colonsim.cli import main
from colonsim.identification.diagnostics import (identification_words, interpolation_variance, misfit_warning, noise_sd,
                                        shear_modulus)
from colonsim.identification.law_comparison import compare_laws, information_criteria
from colonsim.identification.objective import CurveObjective, make_model
from colonsim.identification.pipeline import Budget, calibrate
from colonsim.identification.report import material_document
from colonsim.identification.testdata import TensileCurve
from colonsim.identification.uniaxial import homogeneous_force
from colonsim.insertion.engine.material import load_material
from colonsim.laws import LAWS, get_law

BUDGET = Budget(designs=40, cma_popsize=10, cma_max_evaluations=200, nm_max_evaluations=400)
NOISE = 0.05  # N, the load-cell noise of the bundled synthetic data


def noisy_curve(law, params, seed=3, points=1200, noise=NOISE):
    d = np.linspace(0.05e-3, 60e-3, points)
    f = homogeneous_force(d, 0.1, 0.025, 0.002, get_law(law), params)
    f = f + noise * np.random.default_rng(seed).standard_normal(d.size)
    return TensileCurve(law, d, f, 0.1, 0.025, 0.002)


def fit(curve, law="mooney_rivlin_3"):
    return calibrate(CurveObjective(curve, make_model(curve, law, analytic=True)), budget=BUDGET)


def test_noise_estimate_from_the_curve_alone():
    c = noisy_curve("mooney_rivlin_3", [652.01, 42835.25, 219120.3])
    assert noise_sd(c.displacement, c.force) == pytest.approx(NOISE, rel=0.06)
    # interpolating halfway between two samples averages their noise: variance 1/2
    np.testing.assert_allclose(interpolation_variance([0.0, 1.0, 2.0], [0.0, 0.5, 2.0]), [1.0, 0.5, 1.0])


@pytest.fixture(scope="module")
def yeoh_fitted_with_mooney_rivlin():
    """The issue's case: a Yeoh tissue (mu0 = 90 kPa) fitted with the 3-parameter Mooney-Rivlin."""
    return fit(noisy_curve("yeoh", [45e3, 20e3, 40e3]))


def test_a_law_that_cannot_follow_the_curve_is_flagged(yeoh_fitted_with_mooney_rivlin):
    r = yeoh_fitted_with_mooney_rivlin
    assert r.fit["rms_over_noise"] > 5 and not r.fit["follows_curve"]
    warning = misfit_warning(r)
    assert "times what the curve's noise" in warning and "mooney_rivlin_3 does not follow" in warning
    doc = material_document(r)
    assert doc["warnings"] == [warning]
    assert "well identified" not in doc["small_strain"]["identification"]
    assert "understates the error" in doc["small_strain"]["identification"]


def test_a_law_that_follows_the_curve_is_not_flagged():
    r = fit(noisy_curve("mooney_rivlin_3", [652.01, 42835.25, 219120.3]))
    assert r.fit["follows_curve"] and 0.5 < r.fit["rms_over_noise"] < 1.5
    assert misfit_warning(r) is None
    mu0, sd = shear_modulus(r)
    assert mu0 == pytest.approx(2 * (652.01 + 42835.25), rel=0.05)
    assert material_document(r)["small_strain"]["identification"].startswith("well identified")
    # the clamp is stiffer than the closed form, so the clamped FE strip identifies a smaller mu0
    mc = r.model_comparison
    assert mc["mu0_closed_form_Pa"] == pytest.approx(mu0)
    assert 0.005 < 1 - mc["mu0_clamped_fe_Pa"] / mc["mu0_closed_form_Pa"] < 0.05
    assert material_document(r)["small_strain"]["model_form"]["difference_Pa"] == pytest.approx(
        mc["mu0_clamped_fe_Pa"] - mc["mu0_closed_form_Pa"])


@pytest.mark.parametrize("rel,words", [(0.01, "well identified"), (0.1, "moderately identified"),
                                       (0.6, "poorly identified")])
def test_identification_words_follow_the_numbers(rel, words):
    assert identification_words(1e5, rel * 1e5, True).startswith(words)
    assert "identified" not in identification_words(1e5, rel * 1e5, False)


# Generating parameters (Pa) inside every law's bounds; the C01 term of the two-parameter law is
# what the neo-Hookean cannot follow, the C11 term what the two-parameter law cannot.
GENERATING = {"neo_hookean": [40e3], "mooney_rivlin_2": [5e3, 40e3], "mooney_rivlin_3": [652.01, 42835.25, 219120.3]}
SIMPLER = {"mooney_rivlin_3": ("mooney_rivlin_2", "neo_hookean"), "mooney_rivlin_2": ("neo_hookean",), "neo_hookean": ()}


def test_simpler_laws_are_special_cases_of_mooney_rivlin_3():
    """What makes the family's comparison below fair: a simpler law is the larger one with zeros."""
    I1, I2 = np.array([3.2, 4.1, 5.0]), np.array([3.1, 3.9, 5.5])
    mr3 = get_law("mooney_rivlin_3")
    for name in SIMPLER:
        law = get_law(name)
        params = np.arange(1.0, 1 + len(law.parameter_names)) * 1e4
        full = [dict(zip(law.parameter_names, params)).get(p, 0.0) for p in mr3.parameter_names]
        for a, b in zip(law(I1, I2, params), mr3(I1, I2, full)):
            np.testing.assert_allclose(a, b, rtol=1e-14)


@pytest.mark.parametrize("law", SIMPLER)
def test_curves_from_each_law_pick_it(law):
    """Noisy curves from each Mooney-Rivlin law, compared within that family, pick that law or a
    simpler one that fits as well."""
    comparison = compare_laws(lambda name: fit(noisy_curve(law, GENERATING[law]), name), laws=tuple(SIMPLER))
    picked = comparison.chosen
    assert picked in (law, *SIMPLER[law])
    if picked != law:
        assert comparison.results[picked].fit["rms_over_noise"] < 1.2 * comparison.results[law].fit["rms_over_noise"]
    assert comparison.results[picked].fit["follows_curve"]
    table = comparison.table.set_index("law")
    assert table.loc[picked, "delta_bic"] == 0 and table.loc[picked, "chosen"]
    for simpler in SIMPLER[law]:  # a simpler law that cannot follow this curve is far behind
        assert table.loc[simpler, "delta_bic"] > 10 and not comparison.results[simpler].fit["follows_curve"]


def test_information_criteria():
    aic, bic = information_criteria(e1=2.0, n=20, k=3)
    assert aic == pytest.approx(20 * np.log(0.1) + 6) and bic == pytest.approx(20 * np.log(0.1) + 3 * np.log(20))


def test_cli_compare_laws_writes_table_figure_and_the_chosen_material(tmp_path, capsys):
    curve_file = tmp_path / "mr2.csv"
    c = noisy_curve("mooney_rivlin_2", GENERATING["mooney_rivlin_2"], points=400)
    curve_file.write_text("displacement [mm],force [N]\n" + "".join(f"{d * 1e3:.5f},{f:.5f}\n"
                                                                    for d, f in zip(c.displacement, c.force)))
    out = tmp_path / "laws"
    assert main(["calibrate", "--curve", str(curve_file), "--length", "100", "--width", "25", "--thickness", "2",
                 "--compare-laws", "--analytic", "--quick", "--no-progress", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "chosen: " in text
    table = pd.read_csv(out / "laws.csv")
    assert list(table["law"]) == list(LAWS)
    assert {"rms_N", "rms_over_noise", "aic", "bic", "delta_bic", "mu0_Pa", "mu0_sd_Pa", "C10_Pa", "C11_Pa"} <= set(table)
    doc = json.loads((out / "material.json").read_text())
    chosen = table.loc[table["chosen"], "law"].item()
    assert doc["law"] == chosen == doc["law_selection"]["chosen"]
    assert doc["law_selection"]["reason"].startswith("lowest BIC") and set(doc["law_selection"]["bic"]) == set(LAWS)
    assert (out / "laws.png").stat().st_size > 0
    for law in LAWS:  # every fitted law's material file loads for the insertion solver
        material = load_material(out / "laws" / law / "material.json")
        params = json.loads((out / "laws" / law / "material.json").read_text())["parameters"]
        assert material.law == law and material.named_parameters == params
