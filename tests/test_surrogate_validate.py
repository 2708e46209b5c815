"""Scoring a surrogate on held-out runs, and the noise floor from replicate runs.

Tables are SYNTHETIC (colonsim.surrogate.synthetic: a known smooth function plus Gaussian noise of
a known sd): the tests check the machinery, not physics.
"""

import json

import numpy as np
import pytest

from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.surrogate.holdout import score
from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.replicates import replicate_scatter
from colonsim.surrogate.synthetic import synthetic_outputs, synthetic_sweep
from colonsim.surrogate.table import successful_runs

TARGET = "max_deformation_cm"
NOISE = 0.05  # cm, the synthetic scatter


def rsj(n_runs, seed, noise=NOISE):
    return synthetic_sweep(n_runs=n_runs, segments=("rsj",), noise_cm=noise, n_failed=0, seed=seed)


def replicates_of(table, n, seed, noise=NOISE, shared=False):
    """The first ``n`` cases of ``table`` run again (another mesh): the same inputs, new scatter of
    sd ``noise`` and an offset of 0.02 cm in every run. ``shared``: the new scatter adds to the
    originals' own (a mesh change that moves only part of the scatter), so the pairs see only it."""
    again = table.iloc[:n].copy()
    clean = synthetic_outputs("rsj", again["scope_diameter_mm"], again["diameter_mm"], again["angle_deg"],
                              again["friction"])[TARGET]
    again[TARGET] = (again[TARGET] if shared else clean) + 0.02 + np.random.default_rng(seed).normal(0.0, noise, n)
    again["element_size_mm"] = 2.8
    again["key"] = again["key"] + "-fine"  # another run: another key
    return again


@pytest.fixture(scope="module")
def train():
    return rsj(24, seed=11)


@pytest.fixture(scope="module")
def known():
    """Runs enough for a model without replicate runs to know its error: 10 per input (scope,
    colon diameter, friction; validation.MIN_RUNS_PER_INPUT)."""
    return rsj(30, seed=11)


@pytest.fixture(scope="module")
def test_table():
    return rsj(40, seed=12)


@pytest.fixture(scope="module")
def floored(train):
    return SweepSurrogate(targets=(TARGET,), n_restarts=1, replicates=replicates_of(train, 12, seed=13)).fit(train)


def test_replicate_pairs_measure_the_scatter(train, floored):
    s = floored.scatter_["rsj"][TARGET]
    assert s["pairs"] == 12 and s["unpaired"] == 0
    assert 0.6 * NOISE < s["sd"] < 1.5 * NOISE  # 11 degrees of freedom: +-30 % at 2 sd
    assert s["offset"] == pytest.approx(0.02, abs=0.05)
    assert floored.models_["rsj"][TARGET].noise_std >= s["sd"] * (1 - 1e-6)  # the floor holds


def test_too_few_replicate_pairs_is_an_error(train):
    reps = replicates_of(train, 2, seed=13)
    runs = successful_runs(train, "rsj")
    with pytest.raises(ColonsimError, match=r"2 pair\(s\) of runs of one case at two solver settings, at least 3"):
        replicate_scatter(runs, reps, "rsj", ["scope_diameter_mm", "diameter_mm", "friction"], TARGET)


def test_replicate_pairs_are_found_when_one_table_has_a_setting_the_other_lacks(train):
    """Runs scored against replicates written by another colonsim (a results column the runs lack,
    missing in their rows of the pool): the pairs are found, the missing setting read as a value."""
    reps = replicates_of(train, 12, seed=13).assign(held_push_pace=0.0)
    inputs = ["scope_diameter_mm", "diameter_mm", "friction"]
    found = replicate_scatter(successful_runs(train, "rsj"), reps, "rsj", inputs, TARGET)
    assert found["pairs"] == 12 and found["unpaired"] == 0


def test_heldout_score_is_calibrated_with_the_right_noise(floored, test_table):
    s = score(floored, test_table, TARGET)
    assert s["n"] == 40 and s["n_train"] == 24
    assert 0.85 <= s["coverage"]["95"] <= 1.0 and 0.3 <= s["coverage"]["50"] <= 0.7
    assert abs(s["z_mean"]) < 0.5 and 0.6 < s["z_sd"] < 1.5
    assert s["orders"]["held"] >= s["orders"]["mean_stated"] - 0.05


def test_heldout_score_exposes_an_overconfident_model(floored):
    """Held-out runs with ten times the scatter the model learned: the same score says so."""
    noisy = rsj(40, seed=12, noise=10 * NOISE)
    s = score(floored, noisy, TARGET)
    assert s["coverage"]["95"] < 0.7 and s["z_sd"] > 2.0
    assert s["orders"]["held"] < s["orders"]["mean_stated"] - 0.05


def test_validate_command(floored, test_table, tmp_path, capsys):
    from colonsim.surrogate.store import save_surrogate

    save_surrogate(floored, tmp_path / "model")
    test_table.to_parquet(tmp_path / "test.parquet")
    assert main(["surrogate", "validate", str(tmp_path / "model.json"), str(tmp_path / "test.parquet"),
                 "--plot", str(tmp_path / "reliability.png"), "-o", str(tmp_path / "scores.json")]) == 0
    text = capsys.readouterr().out
    assert "coverage of the 50 / 90 / 95 % intervals" in text and "standardized error: mean" in text
    assert (tmp_path / "reliability.png").stat().st_size > 10_000
    doc = json.loads((tmp_path / "scores.json").read_text())
    assert doc["scores"][0]["target"] == TARGET and len(doc["scores"][0]["reliability"]["observed"]) == 19
    # its noise sits at the replicate floor: the score says the model itself states no interval
    assert "at the floor the replicate runs measured" in doc["scores"][0]["error_unknown"]
    assert "the model itself prints no interval (too few runs" in text


def test_validate_command_of_a_model_that_knows_its_error(known, test_table, tmp_path, capsys):
    from colonsim.surrogate.store import save_surrogate

    save_surrogate(SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(known), tmp_path / "model")
    test_table.to_parquet(tmp_path / "test.parquet")
    assert main(["surrogate", "validate", str(tmp_path / "model.json"), str(tmp_path / "test.parquet")]) == 0
    text = capsys.readouterr().out
    assert "standardized error: mean" in text and "prints no interval" not in text


@pytest.mark.parametrize("drop,message", [("diameter_mm", "lacks the input column(s) diameter_mm"),
                                          (TARGET, "holds none of the outputs")])
def test_validate_refuses_a_table_without_the_model_inputs(floored, test_table, tmp_path, capsys, drop, message):
    from colonsim.surrogate.store import save_surrogate

    save_surrogate(floored, tmp_path / "model")
    test_table.drop(columns=[drop]).to_parquet(tmp_path / "test.parquet")
    assert main(["surrogate", "validate", str(tmp_path / "model.json"), str(tmp_path / "test.parquet")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("colonsim: error:") and message in err and len(err.splitlines()) == 1


# -- too few runs to know its error -----------------------------------------------------------------
def test_error_is_known_with_enough_runs_and_an_estimated_noise(known):
    from colonsim.surrogate.recommend import format_recommendation, recommend

    model = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(known)
    assert model.error_unknown("rsj", TARGET) is None
    rec = recommend(model, "rsj", {"diameter_mm": 30.0, "friction": 0.05})
    assert rec["p_ranking"] is not None and all(s["low95"] is not None for s in rec["scopes"])
    assert "probability this order holds" in format_recommendation(rec)


def test_too_few_runs_says_so_instead_of_a_number(train, tmp_path, capsys):
    from colonsim.surrogate.recommend import format_recommendation, recommend
    from colonsim.surrogate.store import save_surrogate

    model = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(train.iloc[:6])
    assert "too few runs to know its error (6 < 10)" == model.error_unknown("rsj", TARGET)
    rec = recommend(model, "rsj", {"diameter_mm": 30.0, "friction": 0.05})
    assert rec["p_ranking"] is None and all(s["std"] is None and s["p_best"] is None for s in rec["scopes"])
    text = format_recommendation(rec)
    assert "no probability or interval: the model rests on 6 runs" in text and "%" not in text
    save_surrogate(model, tmp_path / "model")
    assert main(["predict", str(tmp_path / "model.json"), "--diameter", "30", "--friction", "0.05", "--scope",
                 "pdc"]) == 0
    out = capsys.readouterr().out
    assert "(no interval: too few runs to know its error (6 < 10))" in out and "+-" not in out.split("\n")[1]


def test_noise_at_its_bound_is_not_an_estimate():
    """Runs without scatter: the fit puts the noise at the bottom of its range, which says nothing
    about a simulation's scatter; nor does a noise at the floor replicate runs measured (one source
    of the scatter only). A noise the fit estimated above that floor makes the error known (30 runs:
    10 per input, so that the runs-per-input rule does not speak first)."""
    clean = rsj(30, seed=11, noise=0.0)
    model = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(clean)
    assert model.error_unknown("rsj", TARGET).endswith("bottom of its range instead of estimating it; measure it "
                                                       "with replicate runs (fit --replicates)")
    few = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(clean.iloc[:24])  # replicates alone would not do
    assert few.error_unknown("rsj", TARGET).endswith("(fit --replicates) and fit at least 30 runs")
    at_floor = SweepSurrogate(targets=(TARGET,), n_restarts=1,
                              replicates=replicates_of(clean, 8, seed=3, noise=0.01)).fit(clean)
    assert "at the floor the replicate runs measured" in at_floor.error_unknown("rsj", TARGET)
    noisy = rsj(30, seed=11)  # scatter NOISE = 0.05 cm, of which the replicates see 0.01 cm
    measured = SweepSurrogate(targets=(TARGET,), n_restarts=1,
                              replicates=replicates_of(noisy, 8, seed=3, noise=0.01, shared=True)).fit(noisy)
    assert measured.models_["rsj"][TARGET].noise_std > 2 * measured.scatter_["rsj"][TARGET]["sd"]
    assert measured.error_unknown("rsj", TARGET) is None


def test_cross_validated_errors_larger_than_the_sd_make_the_error_unknown(known):
    from colonsim.surrogate.validation import error_unknown

    model = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(known)  # the noise estimated
    gp, cv = model.models_["rsj"][TARGET], dict(model.cv_["rsj"][TARGET])
    assert error_unknown(cv, gp) is None and cv["z_rms"] < 1.3
    assert "1.6 times the sd it states (at most 1.21 with 30 runs)" in error_unknown({**cv, "z_rms": 1.6}, gp)


def test_ten_runs_per_input_are_needed(known, train):
    """A model of fewer than 10 runs per input says its error is unknown, even where its noise was
    estimated and its cross-validated errors agree with its sd, with replicate runs or without (a
    noise above the replicates' floor is no sign that the fit separated scatter from trend); from 10
    per input that rule does not silence it."""
    from colonsim.surrogate.validation import MIN_RUNS_PER_INPUT, NOISE_AT_BOUND, error_unknown

    assert MIN_RUNS_PER_INPUT == 10
    small = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(known.iloc[:29])
    gp, cv = small.models_["rsj"][TARGET], small.cv_["rsj"][TARGET]
    assert gp.noise_level_ > NOISE_AT_BOUND * gp.noise_bottom() and cv["z_rms"] < 1.3  # no other check would catch it
    assert error_unknown(cv, gp) == "too few runs to know its error (29 < 10 per input, 30 for its 3); fit more runs"
    assert SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(known).error_unknown("rsj", TARGET) is None
    measured = SweepSurrogate(targets=(TARGET,), n_restarts=1,
                              replicates=replicates_of(train, 8, seed=3, noise=0.01, shared=True)).fit(train)
    gp, cv = measured.models_["rsj"][TARGET], measured.cv_["rsj"][TARGET]
    assert gp.noise_level_ > NOISE_AT_BOUND * gp.noise_bottom() and cv["z_rms"] < 1.2  # above the replicates'
    # floor and within the chi-square limit (1.23 for 24 runs): no other check would catch it
    assert measured.error_unknown("rsj", TARGET) == ("too few runs to know its error (24 < 10 per input, 30 for its "
                                                     "3); fit more runs")
    enough = SweepSurrogate(targets=(TARGET,), n_restarts=1,
                            replicates=replicates_of(known, 8, seed=3, noise=0.01, shared=True)).fit(known)
    assert enough.error_unknown("rsj", TARGET) is None


def test_fit_with_replicates_on_the_command_line(train, tmp_path, capsys):
    train.to_parquet(tmp_path / "train.parquet")
    replicates_of(train, 5, seed=13).to_parquet(tmp_path / "again.parquet")
    assert main(["surrogate", "fit", str(tmp_path / "train.parquet"), "-o", str(tmp_path / "model"), "--restarts", "0",
                 "--targets", TARGET, "--replicates", str(tmp_path / "again.parquet")]) == 0
    assert "noise floor" in capsys.readouterr().out and "(scatter of 5 replicate pairs" in (
        main(["surrogate", "info", str(tmp_path / "model.json")]) or capsys.readouterr().out)
    doc = json.loads((tmp_path / "model.json").read_text())
    assert doc["segments"]["rsj"]["models"][TARGET]["scatter"]["pairs"] == 5


# -- held-out runs vouch for the intervals (the shipped predictor) -----------------------------------
def held_out_rows(model, held):
    """The rows of a held-out table for ``model`` on the runs ``held`` (benchmarks/bench_predictor.py's fields)."""
    s = score(model, held, TARGET, "rsj")
    return [{"model": "rsj", "output": TARGET, "runs": s["n"], "coverage_95": s["coverage"]["95"],
             "coverage_50": s["coverage"]["50"]}]


def test_held_out_runs_decide_whether_intervals_are_printed(known, tmp_path):
    """Where a model carries the coverage of its intervals on at least 30 held-out runs, that
    coverage decides, both ways: a 29-run model that cross-validation cannot vouch for (fewer than
    10 runs per input) prints its intervals once 40 held-out runs bear them out; a model fitted on
    runs without scatter (its noise at the bottom of its range) does not, and the reason names the
    held-out coverage. Fewer than 30 held-out runs leave the cross-validation rule in charge. The
    record survives the files; an edited one is refused."""
    from colonsim.surrogate.predictor_fit import vouch
    from colonsim.surrogate.store import load_surrogate, save_surrogate

    held = rsj(40, seed=21)
    small = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(known.iloc[:29])
    assert small.error_unknown("rsj", TARGET).startswith("too few runs to know its error (29 < 10 per input")
    vouch(small, held_out_rows(small, held), {"synthetic_heldout": held})
    assert small.error_unknown("rsj", TARGET) is None
    assert "held out: 40 runs, 95 % intervals covered" in small.report()
    clean = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(rsj(30, seed=11, noise=0.0))
    vouch(clean, held_out_rows(clean, held), {"synthetic_heldout": held})
    why = clean.error_unknown("rsj", TARGET)
    assert why.startswith("its 95 % intervals covered ") and "of 40 held-out runs (synthetic_heldout)" in why
    # given the tables, a model's verdict names only the held-out sweeps of its own runs
    vouch(clean, held_out_rows(clean, held), {"synthetic_heldout": held, "rsf_heldout": held.assign(segment="rsf")})
    assert "of 40 held-out runs (synthetic_heldout)" in clean.error_unknown("rsj", TARGET)
    few = SweepSurrogate(targets=(TARGET,), n_restarts=1).fit(known.iloc[:29])
    vouch(few, held_out_rows(few, held.iloc[:25]), {"synthetic_heldout": held.iloc[:25]})
    assert few.error_unknown("rsj", TARGET).startswith("too few runs to know its error (29 < 10 per input")
    json_path, _ = save_surrogate(small, tmp_path / "model")
    assert load_surrogate(json_path).error_unknown("rsj", TARGET) is None
    doc = json.loads(json_path.read_text())
    doc["segments"]["rsj"]["models"][TARGET]["held_out"]["runs"] = 41  # 95 % coverage no longer a share of it
    json_path.write_text(json.dumps(doc))
    with pytest.raises(ColonsimError, match="held-out record .* is not a count of runs and shares of it"):
        load_surrogate(json_path)


def test_held_out_intervals_too_narrow_at_either_level_are_not_vouched_for():
    from colonsim.surrogate.validation import held_out_unknown

    record = {"runs": 30, "coverage_95": 29 / 30, "coverage_50": 15 / 30, "sweeps": ["s"]}
    assert held_out_unknown(record) is None
    assert held_out_unknown({**record, "coverage_95": 1.0, "coverage_50": 25 / 30}) is None  # too wide: stated
    assert "95 % intervals covered 25 of 30 held-out runs (s), too few" in held_out_unknown({**record, "coverage_95": 25 / 30})
    assert "50 % intervals covered 9 of 30" in held_out_unknown({**record, "coverage_50": 9 / 30})
