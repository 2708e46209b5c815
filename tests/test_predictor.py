"""The shipped predictor's machinery: the tissue stiffness factor, the patient-space presets, the
model as package data, its queries (domain refusals, --extrapolate, --material) and the held-out
table. The models here are tiny fixtures fitted in the test on a SYNTHETIC table
(tests/predictor_fixture.py), not physics; no predictor is shipped by these tests."""

import json
import math
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from colonsim.catalog import TISSUE_STIFFNESS, WALL_C11, WALL_MU0
from colonsim.cli import main
from colonsim.data import REFERENCE_MATERIAL_PATH, TENSILE_DIR
from colonsim.errors import ColonsimError
from colonsim.insertion.case.case_material import case_material
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.material_samples import material_columns
from colonsim.insertion.study.sweep_presets import PATIENT_MODELS, PATIENT_PARTS, PATIENT_RANGES, PRESETS, patient_space
from colonsim.insertion.study.sweep_spec import case_fields, parse_sweep
from colonsim.insertion.study.tissue_stiffness import STRETCHES, shape_mismatch, stiffness_factor, uniaxial_stress
from colonsim.laws import get_wall_law
from colonsim.surrogate import predictor
from colonsim.surrogate.domain import OutOfDomainWarning
from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.predictor import NO_SHIPPED, load_shipped, predict_deformation
from colonsim.surrogate.predictor_fit import fit_predictor, save_predictor
from colonsim.surrogate.tissue import tissue_representation

from predictor_fixture import REFERENCE_C11_KPA, REFERENCE_MU0_KPA, synthetic_patient_table

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import bench_predictor  # noqa: E402

REFERENCE = (652.01, 42835.25, 219120.3)
FAST = {"n_restarts": 0, "hyperparameter_draws": 0}
DEFORMATIONS = ("max_deformation_cm", "final_deformation_cm")


@pytest.fixture(scope="module")
def shipped(tmp_path_factory):
    """A tiny predictor fitted on a SYNTHETIC patient table (3 tip-folded runs), saved as the package does."""
    folder = tmp_path_factory.mktemp("predictor")
    model = fit_predictor({"patient_space_rsf": synthetic_patient_table(n=72, folded=3)},
                          held_out=["patient_space_rsf_heldout"], targets=DEFORMATIONS, **FAST)
    save_predictor(model, folder / "patient_space")
    return folder / "patient_space"


def material_file(path, factor, covariance=True, law="mooney_rivlin_3", parameters=None):
    params = dict(zip(("C10", "C01", "C11"), (factor * v for v in REFERENCE))) if parameters is None else parameters
    doc = {"format": "colonsim-material/1", "law": law, "units": "Pa", "parameters": params}
    if covariance:
        doc["covariance_Pa2"] = np.diag([(0.05 * v) ** 2 for v in params.values()]).tolist()
        doc["correlation"] = {"names": list(params)}
    path.write_text(json.dumps(doc))
    return path


# -- the stiffness factor ------------------------------------------------------------------------------

def test_the_reference_scaled_maps_back_to_its_factor_and_the_specimens_span_0_76_to_1_27():
    assert stiffness_factor("mooney_rivlin_3", [REFERENCE, [1.3 * v for v in REFERENCE]]) == pytest.approx([1.0, 1.3])
    assert shape_mismatch("mooney_rivlin_3", [[1.3 * v for v in REFERENCE]])[0] == pytest.approx(0.0, abs=1e-12)
    truth = json.loads((TENSILE_DIR / "ground_truth.json").read_text())["specimens"]
    rows = [[s["parameters_Pa"][n] for n in ("C10", "C01", "C11")] for s in truth.values()]
    factors = stiffness_factor("mooney_rivlin_3", rows)
    assert factors.min() == pytest.approx(0.756, abs=1e-3) and factors.max() == pytest.approx(1.272, abs=1e-3)
    low, high = PATIENT_RANGES["stiffness_factor"]
    assert low < factors.min() and factors.max() < high
    # another law with another curve shape: its level maps, its shape is said to differ
    assert shape_mismatch("neo_hookean", [[20_000.0]])[0] > 0.1


@pytest.mark.parametrize("law,rows", [("yeoh", [[20e3, 5e3, 1e3], [30e3, 1e3, 4e3], [1e3, 1e3, 1e3]]),
                                      ("ogden_1", [[30e3, 8.0], [20e3, 4.0], [40e3, 12.0]])])
def test_many_materials_map_as_each_alone(law, rows):
    """A batch of draws (combined per parameter for a law linear in them) maps as each row alone."""
    model = get_wall_law(law)
    alone = [model.uniaxial_nominal_stress(STRETCHES, tuple(row)) for row in rows]
    assert uniaxial_stress(law, rows) == pytest.approx(np.array(alone), rel=1e-10)


def test_a_stiffness_factor_scales_every_parameter_of_the_reference():
    assert case_material(None, None, 1.5).parameters == pytest.approx([1.5 * v for v in REFERENCE])
    with pytest.raises(ColonsimError, match="stiffness_factor = -1"):
        case_material(None, None, -1.0)


def test_an_ogden_wall_keeps_its_exponents_when_scaled(tmp_path):
    path = tmp_path / "ogden.json"
    path.write_text(json.dumps({"format": "colonsim-material/1", "law": "ogden_1", "units": "Pa",
                                "parameters": {"mu1": 30_000.0, "alpha1": 8.0}}))
    assert case_material(str(path), None, 2.0).parameters == pytest.approx((60_000.0, 8.0))


def test_every_results_row_carries_its_wall_as_a_stiffness_factor():
    case = InsertionCase(material=str(REFERENCE_MATERIAL_PATH),
                         material_parameters=dict(zip(("C10", "C01", "C11"), (1.25 * v for v in REFERENCE))))
    assert material_columns(case)[TISSUE_STIFFNESS] == pytest.approx(1.25)
    assert material_columns(InsertionCase())[TISSUE_STIFFNESS] == pytest.approx(1.0)


def test_the_tissue_enters_as_the_stiffness_only_when_the_walls_are_one_law_scaled():
    scaled = synthetic_patient_table(n=10)
    inputs = ["friction", WALL_MU0, WALL_C11, TISSUE_STIFFNESS]
    kept, note = tissue_representation(scaled, inputs)
    assert kept == ["friction", TISSUE_STIFFNESS] and "stands for them" in note
    drawn = scaled.assign(**{WALL_C11: np.linspace(150.0, 300.0, len(scaled))})  # C11 drawn apart from mu0
    kept, note = tissue_representation(drawn, inputs)
    assert kept == ["friction", WALL_MU0, WALL_C11] and note is None


# -- the presets -------------------------------------------------------------------------------------------

def test_each_patient_model_has_a_hypercube_and_independent_held_out_and_replicate_ones_inside_it():
    for model, (inputs, own, runs, seed) in PATIENT_MODELS.items():
        train = tomllib.loads(patient_space(model))
        assert train["grid"][0]["segment"] == model and train["lhs"]["samples"] >= 12 * len(inputs)
        assert ("angle_deg" in train["lhs"]) == (model != "rsj")
        for part in PATIENT_PARTS:
            other = tomllib.loads(patient_space(model, part))
            assert other["grid"][0]["segment"] == model and other["sweep"]["seed"] != train["sweep"]["seed"]
            for name in inputs:
                lo, hi = train["lhs"][name]
                assert lo + (hi - lo) / runs <= other["lhs"][name][0] < other["lhs"][name][1] <= hi - (hi - lo) / runs
        held = [tomllib.loads(patient_space(model, part)) for part in PATIENT_PARTS if part.startswith("heldout")]
        assert held[0]["lhs"]["samples"] >= 30 and sum(h["lhs"]["samples"] for h in held) == 100
        seeds = {tomllib.loads(patient_space(model, part))["sweep"]["seed"] for part in ("", *PATIENT_PARTS)}
        assert len(seeds) == 1 + len(PATIENT_PARTS)  # every part its own hypercube
        assert tomllib.loads(patient_space(model, "replicates"))["grid"][0]["element_size_mm"] == [3, 2.8]
    assert tomllib.loads(patient_space("rsj"))["lhs"]["diameter_mm"] == [20, 40]


@pytest.mark.skipif("stiffness_factor" not in case_fields(),
                    reason="the case input stiffness_factor lands with InsertionCase (the lead's change of 2026-12-07)")
def test_the_patient_space_presets_parse_into_cases():
    spec = parse_sweep(PRESETS["patient_space_rsf"], origin="preset")
    assert len(spec.cases) == PATIENT_MODELS["rsf"][2]
    assert {round(c.stiffness_factor, 3) for c in spec.cases} <= {round(v, 3) for v in np.arange(0.6, 1.6005, 0.001)}


def test_one_preset_runs_the_predictors_fourteen_sweeps_each_into_its_folder(tmp_path, capsys):
    assert main(["sweep", "--preset", "patient_space", "--dry-run", "--out", str(tmp_path / "ps")]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("sweep patient_space")]
    assert len(lines) == 14 and sum(int(line.split(": ")[1].split()[0]) for line in lines) == 708
    assert f"0 already in {tmp_path / 'ps' / 'patient_space_thf_replicates'}/" in lines[-1]
    assert main(["sweep", "--preset", "patient_space", "--adaptive", "--budget", "5"]) == 2
    assert "--adaptive takes one sweep" in capsys.readouterr().err


# -- the shipped model -------------------------------------------------------------------------------------

def test_without_a_shipped_model_the_call_says_so_and_how_to_fit_one(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(predictor, "SHIPPED", tmp_path / "patient_space")
    monkeypatch.delenv(predictor.OVERRIDE, raising=False)
    with pytest.raises(ColonsimError, match="ships no fitted predictor.*colonsim surrogate fit"):
        load_shipped()
    assert main(["predict", "--segment", "rsf", "--angle", "45", "--scope", "9.2", "--diameter", "36"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"colonsim: error: {NO_SHIPPED}"
    assert main(["recommend", "--segment", "rsf", "--angle", "45"]) == 2
    assert main(["surrogate", "info"]) == 2
    assert capsys.readouterr().err.count("ships no fitted predictor") == 2


def test_the_shipped_model_names_its_sweeps_engine_and_domain_and_left_out_folded_tips(shipped):
    model = load_shipped(shipped)
    about = model.about_
    assert about["sweeps"] == ["patient_space_rsf"] and about["held_out_sweeps"] == ["patient_space_rsf_heldout"]
    assert about["engine_commits"] == ["0123abc"] and about["tip_folded_left_out"] == 3
    assert "tissue_stiffness 0.6" in about["domain"]["rsf"]
    assert model.domains_["rsf"].n_runs == 69 and "3 tip-folded runs left out" in model.report()
    assert TISSUE_STIFFNESS in model.domains_["rsf"].inputs and WALL_MU0 not in model.domains_["rsf"].inputs


def test_tip_folded_runs_train_only_when_asked():
    table = synthetic_patient_table(n=30, folded=2)
    model = SweepSurrogate(targets=("max_deformation_cm",), tip_folded=True, **FAST).fit(table)
    assert model.domains_["rsf"].n_runs == 30 and model.training_["tip_folded_trained"]


def test_predict_inside_answers_outside_refuses_by_how_much_unless_extrapolating(shipped):
    model = load_shipped(shipped)
    inside = predict_deformation("rsf", "utc", angle_deg=30, diameter_mm=36, friction=0.05, distal_resistance_N=5,
                                 tissue_stiffness=1.0, model=model)
    row = inside.iloc[0]
    assert row["in_domain"] and row["max_deformation_cm_low95"] < row["max_deformation_cm"] < row["max_deformation_cm_high95"]
    with pytest.raises(ColonsimError, match=r"angle_deg 75 outside 0\.\d+-60 \(15 deg above\).*--extrapolate"):
        predict_deformation("rsf", "utc", angle_deg=75, diameter_mm=36, friction=0.05, distal_resistance_N=5,
                            model=model)
    with pytest.warns(OutOfDomainWarning, match="angle_deg 75"):
        out = predict_deformation("rsf", "utc", angle_deg=75, diameter_mm=36, friction=0.05, distal_resistance_N=5,
                                  extrapolate=True, model=model)
    assert not out.iloc[0]["in_domain"] and "angle_deg 75" in out.iloc[0]["domain_note"]


def test_a_patient_model_the_predictor_was_not_fitted_on_is_refused_naming_what_it_covers(shipped, capsys, monkeypatch):
    monkeypatch.setenv(predictor.OVERRIDE, str(shipped))
    assert main(["predict", "--segment", "thf", "--angle", "30", "--scope", "9.2", "--diameter", "36"]) == 2
    err = capsys.readouterr().err.strip()
    assert err == ("colonsim: error: the predictor has no model of segment 'thf': it covers rsf, fitted on the sweeps "
                   "patient_space_rsf; ask one of those, or fit a surrogate on a sweep of your own "
                   "('colonsim surrogate fit RESULTS -o MODEL')")


def test_a_material_maps_to_its_stiffness_with_its_uncertainty_in_the_interval(shipped, tmp_path):
    model = load_shipped(shipped)
    query = dict(angle_deg=30, diameter_mm=36, friction=0.05, distal_resistance_N=5, model=model)
    given = predict_deformation("rsf", "pdc", tissue_stiffness=1.2, **query).iloc[0]
    mapped = predict_deformation("rsf", "pdc", material=material_file(tmp_path / "m.json", 1.2), **query).iloc[0]
    assert mapped["max_deformation_cm"] == pytest.approx(given["max_deformation_cm"], abs=0.02)
    assert mapped["max_deformation_cm_std_tissue"] > 0 == given["max_deformation_cm_std_tissue"]
    assert "m.json maps to tissue stiffness 1.2 (sd 0.0" in mapped["tissue_note"]
    assert "departs from the reference" not in mapped["tissue_note"]
    other = tmp_path / "nh.json"  # a neo-Hookean wall: another shape than the reference's, said so
    other.write_text(json.dumps({"format": "colonsim-material/1", "law": "neo_hookean", "units": "Pa",
                                 "parameters": {"C10": 40_000.0}}))
    with pytest.warns(OutOfDomainWarning):
        note = predict_deformation("rsf", "pdc", material=other, extrapolate=True, **query).iloc[0]["tissue_note"]
    assert "departs from the reference wall's shape by" in note
    point = predict_deformation("rsf", "pdc", material=material_file(tmp_path / "p.json", 1.2, covariance=False),
                                **query).iloc[0]
    assert point["max_deformation_cm_std_tissue"] == 0 and "no parameter uncertainty" in point["tissue_note"]
    with pytest.raises(ColonsimError, match=r"tissue stiffness 3 outside 0\.6\d*-1\.\d+ of the rsf runs \(1\.\d+ above\)"):
        predict_deformation("rsf", "pdc", material=material_file(tmp_path / "s.json", 3.0), **query)
    with pytest.raises(ColonsimError, match="takes the tissue as its stiffness factor"):
        model.predict_frame(__import__("pandas").DataFrame([{"segment": "rsf", "scope": "pdc", WALL_MU0: 90.0,
                                                               "angle_deg": 30, "diameter_mm": 36, "friction": 0.05,
                                                               "distal_resistance_N": 5}]))


def test_a_tampered_shipped_model_is_refused(shipped, tmp_path):
    for suffix in (".json", ".npz"):
        (tmp_path / f"patient_space{suffix}").write_bytes(shipped.with_suffix(suffix).read_bytes())
    doc = json.loads((tmp_path / "patient_space.json").read_text())
    doc["segments"]["rsf"]["models"]["max_deformation_cm"]["y_scale"] = -1.0
    (tmp_path / "patient_space.json").write_text(json.dumps(doc))
    with pytest.raises(ColonsimError, match="y_scale.*must be positive"):
        load_shipped(tmp_path / "patient_space")


def test_the_cli_uses_the_shipped_model_and_marks_every_extrapolated_number(shipped, monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(predictor, "SHIPPED", shipped)
    patient = ["--segment", "rsf", "--angle", "30", "--diameter", "36", "--friction", "0.05", "--distal-resistance", "5"]
    assert main(["predict", *patient, "--scope", "9.2"]) == 0
    out = capsys.readouterr().out
    assert "max_deformation_cm" in out and "95 %" in out and "[EXTRAPOLATED]" not in out
    assert "the reference wall (tissue stiffness 1" in out
    far = ["--segment", "rsf", "--angle", "75", "--diameter", "36", "--friction", "0.05", "--distal-resistance", "5"]
    assert main(["predict", *far, "--scope", "9.2"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "angle_deg 75 outside" in err and "above" in err
    assert main(["predict", *far, "--scope", "9.2", "--extrapolate"]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if "(95 %:" in line]
    assert lines and all("[EXTRAPOLATED]" in line for line in lines)
    assert main(["recommend", *far, "--extrapolate"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("[EXTRAPOLATED] RSF") and all("[EXTRAPOLATED]" in line for line in text.splitlines()
                                                        if " mm): " in line or "sd, cm" in line)
    assert main(["surrogate", "info"]) == 0
    assert "; fitted on patient_space_rsf (held out: patient_space_rsf_heldout) by the engine of 0123abc" in \
        capsys.readouterr().out.splitlines()[0]
    assert main(["predict", *patient, "--scope", "9.2", "--material",
                 str(material_file(tmp_path / "m.json", 3.0))]) == 2
    assert "tissue stiffness 3 outside" in capsys.readouterr().err
    # a material inside: its stiffness and spread, nothing marked; outside with --extrapolate: every number marked
    assert main(["predict", *patient, "--scope", "9.2", "--material", str(material_file(tmp_path / "i.json", 1.2))]) == 0
    out = capsys.readouterr().out
    assert "i.json maps to tissue stiffness 1.2 (sd 0.0" in out and "[EXTRAPOLATED]" not in out
    stiff = str(material_file(tmp_path / "m.json", 3.0))
    assert main(["predict", *patient, "--scope", "9.2", "--material", stiff, "--extrapolate"]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if "(95 %:" in line]
    assert len(lines) == 2 and all("[EXTRAPOLATED]" in line for line in lines)
    assert main(["recommend", *patient, "--material", stiff, "--extrapolate"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("[EXTRAPOLATED] RSF") and all("[EXTRAPOLATED]" in line for line in text.splitlines()
                                                        if " mm): " in line or "sd, cm" in line)
    assert "tissue stiffness 3 outside" in text


# -- the held-out table ----------------------------------------------------------------------------------

def test_the_held_out_table_passes_honest_runs_and_fails_biased_ones(shipped):
    model = load_shipped(shipped)
    honest = synthetic_patient_table(n=40, seed=7, shrink=0.05, folded=2)
    rows = bench_predictor.predictor_table(model, honest)
    largest = next(r for r in rows if r["output"] == "max_deformation_cm")
    assert largest["runs"] == 38 and largest["tip_folded_left_out"] == 2
    assert largest["coverage_95_ok"] and largest["rmse"] < 0.1 * largest["spread_sd"]
    assert math.isnan(largest["scatter_sd"]) and largest["scatter_from"] == "not measured"
    biased = bench_predictor.predictor_table(model, synthetic_patient_table(n=40, seed=7, shrink=0.05, bias_cm=0.3))
    assert not any(r["coverage_95_ok"] or r["coverage_50_ok"] for r in biased)
    table = bench_predictor.format_table(rows + biased)
    assert "| RSF | max_deformation_cm | 38 (2 tip-folded left out) |" in table and "FAILS" in table



def test_the_fit_stores_its_held_out_coverage_which_then_decides_the_intervals(tmp_path, capsys, monkeypatch):
    """benchmarks/fit_predictor.py scores the held-out sweeps and stores their coverage per output:
    honest held-out runs let the predictor print intervals; held-out runs 0.3 cm above every
    prediction (what a biased model meets) make it print the means with the reason instead."""
    import fit_predictor

    sweeps = {"patient_space_rsf": synthetic_patient_table(n=72, folded=3),
              "honest/patient_space_rsf_heldout": synthetic_patient_table(n=32, seed=8, shrink=0.05),
              "biased/patient_space_rsf_heldout": synthetic_patient_table(n=32, seed=8, shrink=0.05, bias_cm=0.3)}
    for name, table in sweeps.items():
        (tmp_path / name).mkdir(parents=True)
        table.to_parquet(tmp_path / name / "results.parquet")
    monkeypatch.setattr(fit_predictor, "fit_predictor", lambda *a, **k: fit_predictor_fast(*a, **k))
    for kind in ("honest", "biased"):
        out = tmp_path / kind / "model" / "patient_space"
        assert fit_predictor.main(["--train", str(tmp_path / "patient_space_rsf"), "--replicates", "--heldout",
                                   str(tmp_path / kind / "patient_space_rsf_heldout"), "--out", str(out)]) == 0
        model = load_shipped(out)
        held = model.held_out_["rsf"]["max_deformation_cm"]
        assert held["runs"] == 32 and held["sweeps"] == ["patient_space_rsf_heldout"]
        why = model.error_unknown("rsf", "max_deformation_cm")
        assert (why is None) == (kind == "honest"), why
    assert capsys.readouterr().out.count("held out: 32 runs, 95 % intervals covered") == 4  # two outputs, two fits


def fit_predictor_fast(tables, **options):
    return fit_predictor(tables, **{**options, "targets": DEFORMATIONS, **FAST})


def test_the_bench_prints_the_table_and_says_in_one_line_when_there_is_nothing_to_score(shipped, tmp_path, capsys,
                                                                                          monkeypatch):
    synthetic_patient_table(n=40, seed=3, shrink=0.05).to_parquet(tmp_path / "heldout.parquet")
    args = ["--model", str(shipped.with_suffix(".json")), "--heldout", str(tmp_path / "heldout.parquet")]
    assert bench_predictor.main([*args, "--json", str(tmp_path / "table.json")]) == 0
    assert "| RSF | final_deformation_cm | 40 |" in capsys.readouterr().out
    assert len(json.loads((tmp_path / "table.json").read_text())["rows"]) == 2
    monkeypatch.setattr(predictor, "SHIPPED", tmp_path / "none")
    assert bench_predictor.main(["--heldout", str(tmp_path / "heldout.parquet")]) == 2
    assert capsys.readouterr().err.strip() == f"bench_predictor: {NO_SHIPPED}"

@pytest.mark.skipif(not predictor.shipped_exists() or not bench_predictor.RECORD.exists(),
                    reason="no predictor is shipped yet (the patient-space sweeps have not been run)")
def test_the_shipped_predictor_reproduces_its_committed_held_out_table():
    committed = json.loads(bench_predictor.RECORD.read_text())["rows"]
    table = bench_predictor.table_of(bench_predictor.records_of("heldout"), "heldout")
    replicates = bench_predictor.records_of("replicates")
    rows = bench_predictor.predictor_table(load_shipped(), table, bench_predictor.table_of(replicates, "replicates")
                                           if replicates else None)
    assert [(r["model"], r["output"], r["runs"], r["coverage_95_ok"], r["coverage_50_ok"]) for r in rows] == \
        [(r["model"], r["output"], r["runs"], r["coverage_95_ok"], r["coverage_50_ok"]) for r in committed]
    assert [r["rmse"] for r in rows] == pytest.approx([r["rmse"] for r in committed], rel=1e-6)
    stored = load_shipped().held_out_  # the coverage that decides which outputs print intervals
    assert [(stored[r["model"]][r["output"]]["runs"], stored[r["model"]][r["output"]]["coverage_95"],
             stored[r["model"]][r["output"]]["coverage_50"]) for r in rows] == \
        [(r["runs"], r["coverage_95"], r["coverage_50"]) for r in committed]


@pytest.mark.skipif(not predictor.shipped_exists(), reason="no predictor is shipped yet (the patient-space sweeps "
                    "have not been run)")
def test_the_shipped_predictor_refuses_a_point_outside_its_domain_and_a_tampered_file(tmp_path, monkeypatch):
    monkeypatch.delenv(predictor.OVERRIDE, raising=False)
    model = load_shipped()
    for segment in model.domains_:
        with pytest.raises(ColonsimError, match=r"scope_diameter_mm 20 outside 9-13\.5 \(6\.5 mm above\)"):
            predict_deformation(segment, scope_diameter_mm=20, diameter_mm=30, angle_deg=30, model=model)
    for suffix in (".json", ".npz"):
        (tmp_path / f"patient_space{suffix}").write_bytes(predictor.SHIPPED.with_name(f"patient_space{suffix}").read_bytes())
    doc = json.loads((tmp_path / "patient_space.json").read_text())
    segment = next(iter(doc["segments"]))
    doc["segments"][segment]["models"]["final_deformation_cm"]["noise_level"] = float("nan")
    (tmp_path / "patient_space.json").write_text(json.dumps(doc))
    with pytest.raises(ColonsimError, match="noise_level.*not finite"):
        load_shipped(tmp_path / "patient_space")
    arrays = bytearray((tmp_path / "patient_space.npz").read_bytes())
    arrays[len(arrays) // 2] ^= 0xFF
    (tmp_path / "patient_space.npz").write_bytes(bytes(arrays))
    with pytest.raises(ColonsimError, match="does not belong to .* \\(checksum differs\\)"):
        load_shipped(tmp_path / "patient_space")


# -- the query's defaults, the domain of the design, the override, the light import ---------------------------

def test_the_domain_widens_to_the_design_range_only_within_one_stratum_of_the_runs(shipped):
    """The synthetic runs are uniform, not a hypercube: an end the runs reach within one stratum
    (range / 72 runs) becomes the design's edge, an end they miss by more keeps the runs' bound."""
    domain = load_shipped(shipped).domains_["rsf"]
    table = synthetic_patient_table(n=72, folded=3).iloc[3:]
    j = domain.inputs.index("angle_deg")
    stratum = 60.0 / 72
    assert table["angle_deg"].max() > 60.0 - stratum and domain.high[j] == 60.0
    assert table["angle_deg"].min() > stratum and domain.low[j] == table["angle_deg"].min()


def test_a_predictor_query_takes_the_insertions_defaults_and_says_so_a_users_model_does_not(shipped):
    assert predictor.QUERY_DEFAULTS == {k: getattr(InsertionCase(), k) for k in predictor.QUERY_DEFAULTS}
    model = load_shipped(shipped)
    row = predict_deformation("rsf", "pdc", angle_deg=30, diameter_mm=36, model=model).iloc[0]
    assert row["friction"] == 0.0 and row["distal_resistance_N"] == 5.0
    assert "friction 0, distal_resistance_N 5 (colonsim insert's defaults" in row["tissue_note"]
    given = predict_deformation("rsf", "pdc", angle_deg=30, diameter_mm=36, friction=0.05, model=model).iloc[0]
    assert given["friction"] == 0.05 and "friction 0," not in given["tissue_note"]
    model.about_ = None  # a model of the user's: every input named
    with pytest.raises(ColonsimError, match="give friction"):
        predict_deformation("rsf", "pdc", angle_deg=30, diameter_mm=36, model=model)


def test_the_environment_variable_puts_another_model_in_the_shipped_ones_place(shipped, tmp_path, monkeypatch,
                                                                                capsys):
    monkeypatch.setattr(predictor, "SHIPPED", tmp_path / "none")
    monkeypatch.setenv(predictor.OVERRIDE, str(shipped.with_suffix(".json")))
    assert load_shipped().about_["sweeps"] == ["patient_space_rsf"]
    assert main(["predict", "--segment", "rsf", "--angle", "45", "--scope", "9.2", "--diameter", "36"]) == 0
    assert "(colonsim insert's defaults" in capsys.readouterr().out
    monkeypatch.setenv(predictor.OVERRIDE, str(tmp_path / "missing"))
    with pytest.raises(ColonsimError, match=f"{predictor.OVERRIDE}=.*missing: no model there.*unset it"):
        load_shipped()


def test_the_predict_command_imports_neither_numba_nor_the_insertion_engine(shipped):
    """`colonsim predict` answers in about a second: it loads no solver module and no Numba (a
    subprocess, so that nothing this test session imported counts)."""
    import os
    import subprocess

    code = ("import sys\nfrom colonsim.cli import main\n"
            "assert main(['predict', '--segment', 'rsf', '--angle', '45', '--scope', '9.2', '--diameter', '36']) == 0\n"
            "print(sorted(m for m in sys.modules if m == 'numba' or m.startswith(('colonsim.insertion.engine.',"
            " 'colonsim.insertion.case.', 'colonsim.insertion.anatomy.'))))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          env={**os.environ, predictor.OVERRIDE: str(shipped)})
    assert done.returncode == 0, done.stderr
    loaded = eval(done.stdout.strip().splitlines()[-1])
    # the material file reader and the tissue mapping it serves are plain Python over numpy
    assert set(loaded) <= {"colonsim.insertion.engine.material", "colonsim.insertion.case.case_material"}, loaded


def test_the_chance_of_a_coverage_tells_a_verdict_of_thirty_runs_from_luck():
    # all 30 inside a calibrated 95 % interval happens one time in five: a FAILS that may be chance
    assert bench_predictor.chance(1.0, 30, 0.95) == pytest.approx(0.40, abs=0.01)
    assert bench_predictor.chance(21 / 30, 30, 0.5) == pytest.approx(0.043, abs=0.001)  # too wide: unlikely by chance
    assert bench_predictor.chance(0.5, 30, 0.5) == pytest.approx(1.0)
    assert bench_predictor.chance(5 / 30, 30, 0.5) < 1e-3



def test_what_the_bands_ask_of_a_perfect_predictor_grows_with_the_held_out_runs():
    both = [bench_predictor.pass_chance(n, 0.95, (0.88, 0.99)) * bench_predictor.pass_chance(n, 0.5, (0.38, 0.62))
            for n in (30, 100)]
    assert both[0] == pytest.approx(0.58, abs=0.01) and both[1] == pytest.approx(0.98, abs=0.01)
