"""The tissue's share of a prediction's spread (colonsim.surrogate.tissue): the law of total variance
against cases with a known answer, the surrogate with and without tissue inputs, its files, the
command line, and one real sweep end to end.

Tables other than the end-to-end sweep's are SYNTHETIC (colonsim.surrogate.synthetic plus a known
linear effect of mu0): they check the machinery, not physics."""

import json
import warnings

import numpy as np
import pandas as pd
import pytest

from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM, WALL_C11, WALL_MU0
from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.surrogate import OutOfDomainWarning, SegmentDomain, SweepSurrogate
from colonsim.surrogate.recommend import recommend
from colonsim.surrogate.store import load_surrogate, save_surrogate
from colonsim.surrogate.synthetic import synthetic_sweep
from colonsim.surrogate.tissue import TissueDistribution, plan, split_predict
from test_material_samples import COV, material_file, population_file

TARGET = "max_deformation_cm"  # the pain proxy, what recommend ranks by
SLOPE = -0.02  # cm per kPa of mu0 in the synthetic tables
MU0S, C11S = [80.0, 85.0, 90.0, 95.0, 100.0], [140.0, 160.0, 150.0, 145.0, 155.0]


def tissue_table(mu0s=MU0S, c11s=C11S, noise=0.003, seed=0):
    """The synthetic RSJ grid (18 runs) crossed with wall materials; deformation + SLOPE (mu0 - 90)."""
    rng = np.random.default_rng(seed)
    base = synthetic_sweep(design="grid", segments=("rsj",), noise_cm=0.0, n_failed=0, seed=1)
    parts = []
    for mu0, c11 in zip(mu0s, c11s):
        t = base.assign(**{WALL_MU0: mu0, WALL_C11: c11}, key=base["key"] + f"-{mu0:g}")
        t[TARGET] = t[TARGET] + SLOPE * (mu0 - 90.0) + rng.normal(0.0, noise, len(t))
        parts.append(t)
    return pd.concat(parts, ignore_index=True)


class LinearTrend:
    """A stand-in GP: mean A + 0.1 scope + B mu0, a constant sd S (trend covariance S^2 I)."""

    A, B, S = 1.0, 0.03, 0.02

    def predict(self, X, return_std=False, return_cov=False):
        mean = self.A + 0.1 * X[:, 0] + self.B * X[:, 1]
        if return_cov:
            return mean, self.S**2 * np.eye(len(X))
        return (mean, np.full(len(X), self.S)) if return_std else mean


DOMAIN = SegmentDomain("rsj", ["scope_diameter_mm", WALL_MU0, WALL_C11], np.array([9.0, 0.0, 0.0]),
                       np.array([13.0, 300.0, 400.0]), {}, 20, {"utc": 9.2, "sdc": 12.8})


def test_the_split_is_the_law_of_total_variance_for_a_mean_linear_in_mu0(tmp_path):
    dist = TissueDistribution.from_file(material_file(tmp_path))
    query, p = plan(DOMAIN, {"scope_diameter_mm": np.array([9.2, 12.8])}, 2, dist)
    X, _, _ = DOMAIN.check(query, n=2)
    mean, total, tissue, surrogate = split_predict(LinearTrend(), DOMAIN, X, p)
    mu0 = dist.draws()[WALL_MU0]
    # exact over the draws: Var_t[A + B mu0] = B^2 var(mu0), E_t[S^2] = S^2
    assert tissue == pytest.approx(LinearTrend.B * mu0.std(), rel=1e-9)
    assert surrogate == pytest.approx(LinearTrend.S, rel=1e-12)
    assert total == pytest.approx(np.hypot(tissue, surrogate)) and mean == pytest.approx(1.0 + 0.1 * X[:, 0] + 0.03 * mu0.mean())
    # and the analytic value: mu0 = 2 (C10 + C01), var(mu0) = 4 (S00 + S11 + 2 S01) (truncation is negligible
    # here); the sd of an sd estimated from K draws is about sd / sqrt(2K): 5 of them is 11 % at K = 1000
    sd_mu0 = 2.0 * np.sqrt(COV[0, 0] + COV[1, 1] + 2 * COV[0, 1]) / 1e3
    assert tissue == pytest.approx(LinearTrend.B * sd_mu0, rel=0.11)
    # the same seed, the same answer
    again = split_predict(LinearTrend(), DOMAIN, X[:1], plan(DOMAIN, {"scope_diameter_mm": 9.2}, 1, dist)[1])
    assert again[2] == pytest.approx(tissue[:1], rel=1e-12)


def test_a_given_tissue_has_no_tissue_part_and_a_partial_one_is_refused(tmp_path):
    dist = TissueDistribution.from_file(material_file(tmp_path))
    query, p = plan(DOMAIN, {"scope_diameter_mm": 9.2, WALL_MU0: 90.0, WALL_C11: 150.0}, 1, dist)
    X, _, _ = DOMAIN.check(query)
    mean, total, tissue, surrogate = split_predict(LinearTrend(), DOMAIN, X, p)
    assert tissue[0] == 0.0 and total[0] == surrogate[0] == LinearTrend.S and mean[0] == pytest.approx(1.0 + 0.92 + 2.7)
    with pytest.raises(ColonsimError, match="give all of wall_mu0_kPa, wall_C11_kPa"):
        plan(DOMAIN, {"scope_diameter_mm": 9.2, WALL_MU0: 90.0}, 1, dist)


def test_recommend_splits_each_scope_and_ranks_over_the_mixture(tmp_path):
    values = np.array([[10_000.0, 35_000.0, 140_000.0], [15_000.0, 30_000.0, 160_000.0],
                       [30_000.0, 35_000.0, 200_000.0]])
    dist = TissueDistribution.from_file(population_file(tmp_path, values))

    class Model:
        tissue_, cv_ = dist, {"rsj": {TARGET: {"rmse": 0.01, "n": 12}}}

        def model_for(self, segment, target):
            return DOMAIN, LinearTrend()

        def error_unknown(self, segment, target):
            return None

    rec = recommend(Model(), "rsj", {})
    mu0 = 2 * (values[:, 0] + values[:, 1]) / 1e3  # the three specimens, equally weighted
    for s in rec["scopes"]:
        assert s["std_tissue"] == pytest.approx(LinearTrend.B * mu0.std(), rel=1e-9)
        assert s["std_surrogate"] == pytest.approx(LinearTrend.S, rel=1e-9)
    assert rec["ranking"] == ["utc", "sdc"] and rec["tissue"]["modelled"] and rec["tissue"]["draws"] == 3
    # the tissue moves both scopes together: the difference (0.36 cm, sd 0.028) is as sure as without it
    assert rec["scopes"][0]["p_less_than_reference"] == pytest.approx(1.0)


@pytest.fixture(scope="module")
def tissue_model():
    return SweepSurrogate(targets=(TARGET,), n_restarts=0).fit(tissue_table())


def test_a_gp_on_runs_linear_in_mu0_recovers_the_tissue_part(tissue_model):
    dist = tissue_model.tissue_
    assert dist.kind == "empirical" and len(dist.points[WALL_MU0]) == 5  # the runs' five materials
    assert WALL_MU0 in tissue_model.domains_["rsj"].inputs
    mean, total, tissue, surrogate = tissue_model.predict({"scope": "pdc", "diameter_mm": 30.0, "friction": 0.05}, "rsj",
                                                          return_split=True)
    assert tissue[0] == pytest.approx(abs(SLOPE) * np.std(MU0S), rel=0.1)
    assert surrogate[0] < tissue[0] and total[0] == pytest.approx(np.hypot(tissue[0], surrogate[0]))


def test_one_material_fits_exactly_as_before_and_old_tables_still_fit():
    old = synthetic_sweep(design="grid", noise_cm=0.02, seed=1, repeats=2)
    one = old.assign(**{WALL_MU0: 86.97452, WALL_C11: 219.1203, "material_parameters": ""})
    a, b = (SweepSurrogate(targets=(TARGET,), n_restarts=0).fit(t) for t in (old, one))
    assert a.domains_["rsj"].inputs == b.domains_["rsj"].inputs and b.domains_["rsj"].fixed[WALL_MU0] == 86.97452
    query = {"scope": "pdc", "diameter_mm": 30.0, "friction": 0.05}
    assert np.array_equal(a.predict(query, "rsj", return_std=True), b.predict(query, "rsj", return_std=True))
    assert any("no column wall_mu0_kPa, wall_C11_kPa" in n for n in a.notes_) and a.tissue_ is None
    for model, why in ((a, "no wall material columns"), (b, "one wall material (mu0 86.97 kPa)")):
        out = model.predict_frame(pd.DataFrame([{**query, "segment": "rsj"}]), targets=[TARGET])
        assert np.isnan(out.loc[0, TARGET + "_std_tissue"]) and why in out.loc[0, "tissue_note"]
        assert "not modelled" in out.loc[0, "tissue_note"]
        assert out.loc[0, TARGET + "_std_surrogate"] == out.loc[0, TARGET + "_std"]


def test_a_term_the_law_lacks_is_no_input_and_mixed_laws_are_refused():
    table = tissue_table().assign(**{WALL_C11: np.nan})
    model = SweepSurrogate(targets=(TARGET,), n_restarts=0).fit(table)
    assert WALL_C11 not in model.domains_["rsj"].inputs and WALL_MU0 in model.domains_["rsj"].inputs
    assert any("wall_C11_kPa undefined (NaN) in every run" in n for n in model.notes_)
    mixed = tissue_table()
    mixed.loc[:10, WALL_C11] = np.nan
    with pytest.raises(ColonsimError, match="wall_C11_kPa has missing values in 11 of 90"):
        SweepSurrogate(targets=(TARGET,), n_restarts=0).fit(mixed)


def test_draws_outside_the_runs_tissue_range_warn_or_fail_strict(tissue_model, tmp_path):
    model = load_surrogate(save_surrogate(tissue_model, tmp_path / "m")[0])
    # mu0 ~ 104 +- 1.8 kPa against 80-100 in the runs: nearly every draw outside
    model.tissue_ = TissueDistribution.from_file(material_file(tmp_path, mean=[22_000.0, 30_000.0, 150_000.0]))
    query = {"scope": "pdc", "diameter_mm": 30.0, "friction": 0.05}
    with pytest.warns(OutOfDomainWarning, match="outside the runs' tissue range"):
        model.predict(query, "rsj", return_std=True)
    with pytest.raises(ColonsimError, match="drop --strict"):
        model.predict(query, "rsj", strict=True)


def test_the_tissue_distribution_is_saved_without_pickle(tissue_model, tmp_path):
    json_path, _ = save_surrogate(tissue_model, tmp_path / "m")
    doc = json.loads(json_path.read_text())
    assert doc["tissue"]["kind"] == "empirical" and doc["tissue"]["points_kPa"][WALL_MU0] == MU0S
    loaded = load_surrogate(json_path)
    query = {"scope": "utc", "diameter_mm": 25.0, "friction": 0.0}
    assert np.allclose(loaded.predict(query, "rsj", return_split=True), tissue_model.predict(query, "rsj", return_split=True))
    posterior = TissueDistribution.from_file(material_file(tmp_path))
    again = TissueDistribution.from_dict(json.loads(json.dumps(posterior.to_dict())))
    assert np.array_equal(again.draws()[WALL_MU0], posterior.draws()[WALL_MU0])


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tissue")
    tissue_table().to_parquet(folder / "results.parquet")
    synthetic_sweep(design="grid", noise_cm=0.02, seed=1, repeats=2).to_parquet(folder / "old.parquet")
    for table, name in (("results", "model"), ("old", "old")):
        assert main(["surrogate", "fit", str(folder / f"{table}.parquet"), "-o", str(folder / name), "--restarts", "0",
                     "--targets", TARGET]) == 0
    return folder


def test_cli_predict_and_recommend_state_both_parts(fitted, capsys):
    capsys.readouterr()
    assert main(["predict", str(fitted / "model.json"), "--segment", "rsj", "--diameter", "30", "--friction", "0.05"]) == 0
    out = capsys.readouterr().out
    assert out.count("sd: tissue") == 3 and "surrogate" in out and "averaged over 5 materials" in out
    assert main(["recommend", str(fitted / "model.json"), "--segment", "rsj", "--region", "european", "--age", "young",
                 "--json"]) == 0
    rec = json.loads(capsys.readouterr().out)
    assert all(s["std_tissue"] > 0 and s["std_surrogate"] > 0 for s in rec["scopes"]) and rec["tissue"]["modelled"]
    assert main(["recommend", str(fitted / "model.json"), "--segment", "rsj", "--region", "european", "--age", "young"]) == 0
    assert "uncertainty split (sd, cm): UTC tissue" in capsys.readouterr().out


def test_cli_says_plainly_when_the_tissue_is_not_modelled(fitted, capsys):
    capsys.readouterr()
    assert main(["predict", str(fitted / "old.json"), "--segment", "rsj", "--diameter", "30", "--friction", "0.05",
                 "--scope", "pdc", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["predictions"][0]
    assert row[TARGET + "_std_tissue"] is None and "tissue part not modelled" in row["tissue_note"]
    assert main(["recommend", str(fitted / "old.json"), "--segment", "rsj", "--region", "european", "--age", "young"]) == 0
    out = capsys.readouterr().out
    assert "uncertainty: surrogate only; tissue part not modelled" in out and "tissue 0" not in out


def test_cli_material_option_and_one_line_errors(fitted, tmp_path, capsys):
    values = np.array([[12_000.0, 31_000.0, 150_000.0], [10_000.0, 36_000.0, 145_000.0]])  # mu0 86 and 92 kPa
    args = ["predict", str(fitted / "model.json"), "--segment", "rsj", "--diameter", "30", "--friction", "0.05",
            "--scope", "pdc", "--json"]
    capsys.readouterr()
    assert main(args + ["--material", str(population_file(tmp_path, values))]) == 0
    assert "the 2 specimens of population.json" in json.loads(capsys.readouterr().out)["predictions"][0]["tissue_note"]
    for extra, message in ((["--wall-mu0", "90"], "give all of wall_mu0_kPa, wall_C11_kPa"),
                           (["--material", str(tmp_path / "none.json")], "not found")):
        assert main(args + extra) == 2
        err = capsys.readouterr().err.strip()
        assert message in err and len(err.splitlines()) == 1


@pytest.mark.slow
def test_a_real_sweep_over_drawn_materials_end_to_end(tmp_path, capsys):
    """RSJ at the smoke size (colonsim.catalog), 2 scopes x 2 posterior draws (66 s under the README's
    test command; the straight tube is not used: its scope never touches the wall, so every output is 0
    whatever the tissue)."""
    from colonsim.insertion.study.sweep import run_sweep
    from colonsim.insertion.study.sweep_spec import parse_sweep

    material_file(tmp_path, mean=[14_400.0, 33_000.0, 153_000.0], cov=np.diag([4e6, 4e6, 9e6]))
    spec = parse_sweep(f'[fixed]\nelement_size_mm = {SMOKE_ELEMENT_MM}\nscope_spacing_mm = {SMOKE_SCOPE_SPACING_MM}\n'
                       f'push_speed = {SMOKE_PUSH_SPEED}\n'
                       '[[grid]]\nsegment = "rsj"\nscope = ["utc", "sdc"]\n'
                       '[material]\nfile = "material.json"\nsamples = 2\nseed = 2\n', base=tmp_path)
    report = run_sweep(spec.cases, tmp_path / "sweep", workers=2, spec=spec, progress=False, log=lambda *a: None)
    table = report.table
    assert report.ok == 4 and table[WALL_MU0].nunique() == 2
    summary = json.loads((tmp_path / "sweep" / "runs" / table["key"][0] / "summary.json").read_text())
    assert summary["material"]["C10"] == json.loads(table["material_parameters"][0])["C10"]
    assert main(["surrogate", "fit", str(tmp_path / "sweep" / "results.parquet"), "-o", str(tmp_path / "m"),
                 "--restarts", "0", "--targets", TARGET, "peak_push_force_N"]) == 0
    assert json.loads((tmp_path / "m.json").read_text())["tissue"]["kind"] == "posterior"  # the file the sweep drew from
    capsys.readouterr()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", OutOfDomainWarning)  # 2 draws span little of the posterior
        assert main(["predict", str(tmp_path / "m.json"), "--scope", "utc", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)["predictions"][0]
    # four runs are too few for the model to know its error: the mean over the tissue, no sd to split
    assert row[TARGET] == row[TARGET] and f"{TARGET}: too few runs to know its error (4 < 10)" in row["error_note"]
    assert row[TARGET + "_std_tissue"] is None and row[TARGET + "_std_surrogate"] is None
    assert "averaged over 1000 draws of the posterior of material.json" in row["tissue_note"]
