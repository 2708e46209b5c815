"""The surrogate of a sweep table: domains, targets, files, presets and scope ranking.

Tables are SYNTHETIC (colonsim.surrogate.synthetic: a known smooth function plus noise): these tests
check the regression machinery, not physics.
"""

import json
import warnings
import zipfile

import numpy as np
import pandas as pd
import pytest

from colonsim.errors import ColonsimError
from colonsim.surrogate import OutOfDomainWarning, SweepSurrogate
from colonsim.surrogate.patients import PatientPresets, patient_inputs
from colonsim.surrogate.recommend import recommend
from colonsim.surrogate.store import load_surrogate, save_surrogate
from colonsim.surrogate.synthetic import synthetic_deformation, synthetic_sweep
from colonsim.surrogate.table import NAMED_SCOPES_MM

TARGETS = ("max_deformation_cm", "point_A_cm", "peak_contact_force_N")


@pytest.fixture(scope="module")
def grid_table():
    return synthetic_sweep(design="grid", noise_cm=0.02, seed=1, repeats=2)  # 10 runs per input and more


@pytest.fixture(scope="module")
def model(grid_table):
    return SweepSurrogate(targets=TARGETS, n_restarts=0).fit(grid_table)


def test_domain_records_varying_and_fixed_inputs(model, grid_table):
    rsj, rsf = model.domains_["rsj"], model.domains_["rsf"]
    assert rsj.inputs == ["scope_diameter_mm", "diameter_mm", "friction"]
    assert rsj.fixed == {"angle_deg": 0.0, "wall_thickness_mm": 2.0}
    assert rsf.inputs == ["scope_diameter_mm", "angle_deg", "friction"] and rsf.fixed["diameter_mm"] == 36.0
    np.testing.assert_allclose(rsf.low, [9.2, 0.0, 0.0])
    np.testing.assert_allclose(rsf.high, [12.8, 45.0, 0.1])
    assert rsj.scopes == {"utc": 9.2, "pdc": 11.3, "sdc": 12.8}
    assert rsj.n_runs == (grid_table.query("segment == 'rsj'")["status"] == "ok").sum()
    assert rsj.settings["element_size_mm"] == [3.0]


def test_undefined_targets_have_no_model_and_say_why(model):
    assert "point_A_cm" in model.models_["rsj"] and "point_A_cm" not in model.models_["rsf"]
    assert "0 runs" in model.skipped_["rsf"]["point_A_cm"]
    with pytest.raises(ColonsimError, match="no point_A_cm model for rsf"):
        model.predict({"scope": "sdc", "angle_deg": 30, "friction": 0}, "rsf", "point_A_cm")


def test_named_scopes_agree_with_the_solver():
    from colonsim.catalog import NAMED_SCOPES
    from colonsim.insertion.anatomy.scopes import colonoscope

    assert NAMED_SCOPES_MM == {k: round(colonoscope(k).diameter * 1e3, 6) for k in NAMED_SCOPES}


def test_predictions_recover_the_synthetic_function(model):
    rng = np.random.default_rng(5)
    q = {"scope_diameter_mm": rng.uniform(9.2, 12.8, 200), "angle_deg": rng.uniform(0, 45, 200),
         "friction": rng.uniform(0, 0.1, 200)}
    mean, std = model.predict(q, "rsf", return_std=True)
    truth = 1.05 * synthetic_deformation(q["scope_diameter_mm"], 36.0, q["angle_deg"], q["friction"])  # max = 1.05 final
    assert np.sqrt(np.mean((mean - truth) ** 2)) < 0.05  # deformations 2.4-5.3 cm, noise 0.02 cm
    assert np.mean(np.abs(mean - truth) <= 1.96 * std) > 0.85
    cv = model.cv_["rsf"]["max_deformation_cm"]
    assert cv["n"] == 53 and cv["rmse"] < 0.06 and 0.8 <= cv["coverage_95"] <= 1.0


def test_out_of_domain_warns_and_strict_raises(model):
    inside = {"scope": "pdc", "diameter_mm": 30.0, "friction": 0.05}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model.predict(inside, "rsj")
    with pytest.warns(OutOfDomainWarning, match="diameter_mm 40 outside 23-36"):
        model.predict({**inside, "diameter_mm": 40.0}, "rsj")
    with pytest.raises(ColonsimError, match="friction 0.2 outside 0-0.1.*--strict"):
        model.predict({**inside, "friction": 0.2}, "rsj", strict=True)
    # an input the sweep held fixed may not move
    with pytest.warns(OutOfDomainWarning, match="angle_deg 30 but every rsj run used 0"):
        model.predict({**inside, "angle_deg": 30.0}, "rsj")
    with pytest.raises(ColonsimError, match="give diameter_mm"):
        model.predict({"scope": "pdc", "friction": 0.05}, "rsj")
    with pytest.raises(ColonsimError, match="no model of segment 'thf'"):
        model.predict(inside, "thf")


def test_save_load_round_trip_without_pickle(model, tmp_path):
    json_path, npz_path = save_surrogate(model, tmp_path / "model", source="results.parquet")
    doc = json.loads(json_path.read_text())
    assert doc["format"] == "colonsim-surrogate" and doc["format_version"] == "1.5"
    assert doc["segments"]["rsj"]["domain"]["fixed"]["angle_deg"] == 0.0
    assert set(doc["segments"]["rsj"]["models"]["max_deformation_cm"]["cross_validation"]) >= {
        "rmse", "max_abs_error", "coverage_95"}
    with zipfile.ZipFile(npz_path) as z:
        assert all(name.endswith(".npy") for name in z.namelist())
    with np.load(npz_path, allow_pickle=False) as arrays:  # no object arrays inside: numbers, and the identity text
        assert all(arrays[k].dtype == float for k in arrays.files if not k.endswith("__belongs_to"))
        assert arrays["rsj__max_deformation_cm__belongs_to"].tolist() == ["rsj", "max_deformation_cm"]
        assert arrays["rsj__max_deformation_cm__draws"].shape == (16, 5)  # the hyperparameter draws, 3 inputs
    loaded = load_surrogate(json_path)
    rng = np.random.default_rng(2)
    q = {"scope_diameter_mm": rng.uniform(8, 14, 50), "diameter_mm": rng.uniform(20, 40, 50),
         "friction": rng.uniform(0, 0.12, 50)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", OutOfDomainWarning)
        for target in model.models_["rsj"]:
            a, b = model.predict(q, "rsj", target, return_std=True), loaded.predict(q, "rsj", target, return_std=True)
            np.testing.assert_array_equal(a[0], b[0])
            np.testing.assert_array_equal(a[1], b[1])
    assert loaded.report() == model.report()


def test_load_refuses_foreign_or_mismatched_files(model, tmp_path):
    save_surrogate(model, tmp_path / "a")
    save_surrogate(SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0)
                   .fit(synthetic_sweep(design="grid", segments=("rsj",))), tmp_path / "b")
    (tmp_path / "b.npz").replace(tmp_path / "a.npz")
    with pytest.raises(ColonsimError, match="does not belong"):
        load_surrogate(tmp_path / "a.json")
    (tmp_path / "c.json").write_text('{"format": "something else"}')
    with pytest.raises(ColonsimError, match="not a colonsim surrogate"):
        load_surrogate(tmp_path / "c.json")
    with pytest.raises(ColonsimError, match="not found"):
        load_surrogate(tmp_path / "missing.json")


def test_failed_runs_and_nan_targets_are_left_out():
    table = synthetic_sweep(n_runs=12, segments=("rsj",), n_failed=3, seed=4)
    table.loc[5, "final_deformation_cm"] = np.nan  # one ok run without this output
    m = SweepSurrogate(targets=("final_deformation_cm", "max_deformation_cm"), n_restarts=0).fit(table)
    assert m.training_ == {"runs": 12, "ok": 9, "failed": 3, "tip_folded": 0, "tip_folded_trained": False,
                           "git_commits": []}
    assert m.cv_["rsj"]["final_deformation_cm"]["n"] == 8 and m.cv_["rsj"]["max_deformation_cm"]["n"] == 9


def test_rows_left_out_are_counted_with_the_reason():
    table = synthetic_sweep(n_runs=12, segments=("rsj",), n_failed=0, seed=4)
    table.loc[2, "max_deformation_cm"] = np.inf
    table.loc[5, "max_deformation_cm"] = np.nan
    m = SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0).fit(table)
    assert m.cv_["rsj"]["max_deformation_cm"]["n"] == 10
    assert ("rsj max_deformation_cm: 2 of 12 successful runs left out (1 with an infinite value and 1 without "
            "a value (NaN)), 10 used") in m.notes_
    assert "note: rsj max_deformation_cm: 2 of 12" in m.report()


def test_an_input_missing_from_the_table_is_noted_and_a_query_setting_it_refused(grid_table):
    m = SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0).fit(grid_table.drop(columns=["diameter_mm"]))
    assert any("no column diameter_mm" in n for n in m.notes_)
    query = {"scope": "sdc", "friction": 0.0}
    m.predict(query, "rsj")  # without the input: answered
    with pytest.raises(ColonsimError, match="fitted on a table without diameter_mm"):
        m.predict({**query, "diameter_mm": 23.0}, "rsj")
    # a batch whose diameter column is empty sets nothing
    out = m.predict_frame(pd.DataFrame({"segment": ["rsj"], "scope": ["sdc"], "friction": [0.0], "diameter_mm": [np.nan]}))
    assert np.isfinite(out["max_deformation_cm"]).all()


def test_a_failed_save_leaves_the_earlier_model_untouched(model, tmp_path):
    """Both files are written and read back before either replaces the earlier pair."""
    json_path, npz_path = save_surrogate(model, tmp_path / "model")
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    broken = SweepSurrogate(targets=TARGETS, n_restarts=0).fit(synthetic_sweep(design="grid", noise_cm=0.05, seed=2))
    broken.cv_["rsj"]["max_deformation_cm"]["rmse"] = float("inf")  # a value JSON cannot hold
    for path in (tmp_path / "model", tmp_path / "fresh"):
        with pytest.raises(ColonsimError, match=r"cross_validation.rmse is inf, which JSON cannot hold"):
            save_surrogate(broken, path)
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before  # no stray .npz, nothing replaced
    load_surrogate(json_path)


def test_outputs_that_overflow_the_fit_are_refused():
    table = synthetic_sweep(n_runs=12, segments=("rsj",), n_failed=0, seed=4)
    table.loc[3, "max_deformation_cm"] = 1e300
    with pytest.raises(ColonsimError, match="rsj max_deformation_cm: the fit is not finite"):
        SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0).fit(table)


def test_varying_solver_setting_is_noted():
    table = synthetic_sweep(n_runs=10, segments=("rsj",), seed=2)
    table.loc[::2, "element_size_mm"] = 4.0
    m = SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0).fit(table)
    assert any("element_size_mm vary" in n for n in m.notes_)


def test_patient_presets_map_and_can_be_overridden(tmp_path):
    assert patient_inputs("rsf", sex="female", age="older") == {"angle_deg": 45.0, "friction": 0.1}
    assert patient_inputs("thf", sex="intermediate") == {"angle_deg": 30.0}
    assert patient_inputs("rsj", sex="female", region="European") == {"diameter_mm": 23.0}
    assert patient_inputs("rsf", region="african") == {}  # no regional diameter outside RSJ in the source
    with pytest.raises(ColonsimError, match="unknown region"):
        patient_inputs("rsf", region="asian")
    path = tmp_path / "presets.json"
    path.write_text(json.dumps({"sex_angle_deg": {"female": 40.0}}))
    presets = PatientPresets.from_json(path)
    assert patient_inputs("rsf", sex="female", presets=presets) == {"angle_deg": 40.0}
    assert presets.sex_angle_deg["male"] == 0.0


def test_recommend_ranks_by_diameter_with_confidence(model):
    rec = recommend(model, "rsj", patient_inputs("rsj", age="middle", region="european"))
    assert rec["ranking"] == ["utc", "pdc", "sdc"] and rec["reference"] == "sdc"
    by_scope = {s["scope"]: s for s in rec["scopes"]}
    assert by_scope["utc"]["p_less_than_reference"] > 0.99 and by_scope["sdc"]["p_less_than_reference"] is None
    assert rec["p_ranking"] > 0.99 and by_scope["utc"]["p_best"] > 0.99
    # adding the cross-validated error per scope can only make the order less sure
    assert rec["cv_rmse"] == pytest.approx(model.cv_["rsj"]["max_deformation_cm"]["rmse"])
    assert 0.0 < rec["p_ranking_with_cv_error"] <= rec["p_ranking"] + 0.01
    assert by_scope["utc"]["p_less_than_reference_with_cv_error"] <= by_scope["utc"]["p_less_than_reference"] + 0.01


def test_recommend_prints_the_interval_of_a_new_run_which_is_wider_than_the_trends(model):
    """The interval beside each scope is predict's (trend + scatter: what held-out runs score);
    on a noisy table it is wider than the trend's own, and where the scatter is nil they agree."""
    inputs = patient_inputs("rsj", age="middle", region="european")
    rec = recommend(model, "rsj", inputs)
    for s in rec["scopes"]:
        mean, sd = model.predict({**inputs, "scope": s["scope"]}, "rsj", return_std=True)
        assert s["mean"] == pytest.approx(mean[0], rel=1e-9) and s["std"] == pytest.approx(sd[0], rel=1e-9)
        assert s["high95"] == pytest.approx(mean[0] + 1.959964 * sd[0], rel=1e-6)
        assert s["std"] > 1.5 * s["std_trend"]  # the table scatters by 0.02 cm about a smooth trend

    domain, gp = model.model_for("rsj", "max_deformation_cm")

    class NoScatter:  # the same trend with no white noise: a new run is the trend
        def predict(self, X, return_std=False, return_cov=False):
            mean, cov = gp.predict(X, return_cov=True)
            if return_cov:
                return mean, cov
            return (mean, np.sqrt(np.diag(cov))) if return_std else mean

    class Quiet:
        cv_, tissue_ = model.cv_, None

        def model_for(self, segment, target):
            return domain, NoScatter()

        def error_unknown(self, segment, target):
            return None

    quiet = recommend(Quiet(), "rsj", inputs)
    assert all(s["std"] == pytest.approx(s["std_trend"], rel=1e-9) for s in quiet["scopes"])


def test_recommend_is_unsure_when_the_scope_does_not_matter():
    table = synthetic_sweep(design="grid", segments=("rsj",), noise_cm=0.05, seed=3, repeats=2)
    table["max_deformation_cm"] = 3.0 + 0.02 * table["diameter_mm"] + np.random.default_rng(0).normal(0, 0.05, len(table))
    m = SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0).fit(table)
    rec = recommend(m, "rsj", {"diameter_mm": 30.0, "friction": 0.05})
    p = {s["scope"]: s["p_less_than_reference"] for s in rec["scopes"]}
    assert 0.05 < p["utc"] < 0.95 and rec["p_ranking"] < 0.9


def test_predict_frame_batch(model):
    frame = pd.DataFrame({"segment": ["rsj", "RSF", "rsf"], "scope": ["utc", "sdc", "10.5"],
                          "diameter_mm": [23.0, np.nan, np.nan], "angle_deg": [np.nan, 30.0, 60.0],
                          "friction": [0.0, 0.05, 0.05]})
    with pytest.warns(OutOfDomainWarning):
        out = model.predict_frame(frame)
    assert list(out["in_domain"]) == [True, True, False] and "angle_deg 60" in out.loc[2, "domain_note"]
    assert out.loc[2, "scope_diameter_mm"] == 10.5
    assert np.isnan(out.loc[1, "point_A_cm"]) and np.isfinite(out.loc[0, "point_A_cm"])
    single = model.predict({"scope": "sdc", "angle_deg": 30.0, "friction": 0.05}, "rsf", return_std=True)
    assert out.loc[1, "max_deformation_cm"] == pytest.approx(single[0][0])
    assert out.loc[1, "max_deformation_cm_high95"] == pytest.approx(single[0][0] + 1.959964 * single[1][0])


def test_scope_names_fill_missing_diameters(model):
    values = model.query("rsj", {"scope": np.array(["utc", None, "sdc"], dtype=object),
                                 "scope_diameter_mm": np.array([np.nan, 10.0, np.nan])})
    np.testing.assert_array_equal(values["scope_diameter_mm"], [9.2, 10.0, 12.8])


def test_runs_whose_push_force_rang_are_counted_in_the_notes_and_trained_on():
    table = synthetic_sweep(design="grid", segments=("rsj",), seed=2)
    table["quasi_static"] = True
    quiet = SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0).fit(table)
    assert not any("quasi-static" in note for note in quiet.notes_)
    ok = table.index[table["status"] == "ok"]
    table.loc[ok[:3], "quasi_static"] = False
    rang = SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0).fit(table)
    assert f"rsj: 3 of {len(ok)} runs were not quasi-static (their push force rang" in " ".join(rang.notes_)
    assert rang.domains_["rsj"].n_runs == len(ok)  # they train like the others
