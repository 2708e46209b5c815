"""Scoring and matching that could fool the user: held-out runs that are training runs, a key
counted twice, a replicate table that matches nothing, a centerline saved with semicolons and
decimal commas, a query file with a header and no rows. Tables are SYNTHETIC
(colonsim.surrogate.synthetic)."""

import pytest

from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline_file import read_centerline_points
from colonsim.surrogate.holdout import score
from colonsim.surrogate.model import SweepSurrogate
from colonsim.surrogate.synthetic import synthetic_sweep
from colonsim.surrogate.table import read_query_file

from centerline_files import hairpin

TARGET = "max_deformation_cm"


def rsj(n, seed, segments=("rsj",)):
    return synthetic_sweep(n_runs=n, segments=segments, noise_cm=0.05, n_failed=0, seed=seed)


@pytest.fixture(scope="module")
def train():
    return rsj(24, seed=11)


@pytest.fixture(scope="module")
def model(train):
    return SweepSurrogate(targets=(TARGET,), n_restarts=0).fit(train)


def test_held_out_runs_are_scored_once_and_never_the_training_runs(model, train):
    held = rsj(20, seed=12)
    clean = score(model, held, TARGET)
    assert (clean["n"], clean["training_cases"], clean["duplicates"]) == (20, 0, 0)
    import pandas as pd

    trained = train.iloc[:5].assign(key="train-" + train["key"].iloc[:5])  # the synthetic keys repeat across tables
    mixed = pd.concat([held, held.iloc[:3], trained], ignore_index=True)  # 3 keys twice, 5 training runs
    s = score(model, mixed, TARGET)
    assert (s["n"], s["training_cases"], s["duplicates"]) == (20, 5, 3)
    assert s["rmse"] == pytest.approx(clean["rmse"])


def test_validating_on_the_training_table_is_refused(model, train, tmp_path, capsys):
    from colonsim.surrogate.store import save_surrogate

    save_surrogate(model, tmp_path / "model")
    train.to_parquet(tmp_path / "train.parquet")
    assert main(["surrogate", "validate", str(tmp_path / "model.json"), str(tmp_path / "train.parquet")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "every one of its 24 rsj runs is a case the model was fitted on" in err[0]


def test_a_replicate_table_that_matches_no_run_is_an_error(train):
    other = rsj(12, seed=13, segments=("rsf",))
    with pytest.raises(ColonsimError, match=r"the replicate table matches no run of the model: its successful runs "
                                            r"are of rsf, the model fits rsj"):
        SweepSurrogate(targets=(TARGET,), n_restarts=0, replicates=other).fit(train)


def test_a_semicolon_centerline_with_decimal_commas_reads_as_the_comma_one(tmp_path):
    plain = tmp_path / "plain.csv"
    plain.write_text(hairpin())
    semicolon = tmp_path / "semicolon.csv"
    semicolon.write_text(hairpin().replace(",", ";").replace(".", ","))
    a, b = read_centerline_points(plain), read_centerline_points(semicolon)
    assert a.digest() == b.digest() and len(b.points_mm) > 10
    bad = tmp_path / "bad.csv"
    bad.write_text(hairpin().replace(",", ";").replace(".", ",", 1).replace("0;0", "0;x", 1))
    with pytest.raises(ColonsimError, match=r"is not a number"):
        read_centerline_points(bad)


def test_a_query_file_with_a_header_and_no_rows_says_so(tmp_path):
    empty = tmp_path / "q.csv"
    empty.write_text("segment,scope,age,sex\n")
    with pytest.raises(ColonsimError, match=r"query file .*q.csv has a header \(segment, scope, age, sex\) but no rows"):
        read_query_file(empty)
    empty.write_text("segment,scope,age,sex\nrsj,utc,60,female\n")
    assert len(read_query_file(empty)) == 1
