"""The surrogate on the command line, end to end on a SYNTHETIC sweep table (regression machinery,
not physics): fit -> predict (text, JSON, batch CSV) -> recommend -> plot; one-line errors, exit 2."""

import json

import pandas as pd
import pytest

from colonsim.cli import main
from colonsim.surrogate.synthetic import synthetic_sweep


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("surrogate")
    synthetic_sweep(design="grid", noise_cm=0.02, seed=1, repeats=2).to_parquet(folder / "results.parquet")
    code = main(["surrogate", "fit", str(folder / "results.parquet"), "-o", str(folder / "model"), "--restarts", "0",
                 "--targets", "max_deformation_cm", "point_C_cm", "peak_contact_force_N"])
    assert code == 0
    return folder


def test_fit_writes_model_and_reports_cv(fitted, capsys):
    assert (fitted / "model.json").is_file() and (fitted / "model.npz").is_file()
    assert main(["surrogate", "info", str(fitted / "model.json")]) == 0
    text = capsys.readouterr().out
    assert "CV RMSE" in text and "95% coverage" in text and "rsf: 53 runs" in text
    assert "averaged over 16 hyperparameter draws" in text  # the default up to 100 runs


def test_fit_can_predict_with_the_likelihood_maximum_alone(fitted, capsys):
    assert main(["surrogate", "fit", str(fitted / "results.parquet"), "-o", str(fitted / "plug"), "--restarts", "0",
                 "--targets", "max_deformation_cm", "--hyperparameter-draws", "0"]) == 0
    assert "hyperparameter draws" not in capsys.readouterr().out
    doc = json.loads((fitted / "plug.json").read_text())
    assert doc["estimator"]["hyperparameter_draws"] == 0


def test_predict_json(fitted, capsys):
    assert main(["predict", str(fitted / "model.json"), "--segment", "rsf", "--angle", "40", "--age", "middle",
                 "--scope", "utc", "sdc", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)["predictions"]
    assert [r["scope"] for r in rows] == ["utc", "sdc"] and all(r["in_domain"] for r in rows)
    assert rows[0]["friction"] == 0.05 and rows[0]["angle_deg"] == 40.0
    assert rows[0]["max_deformation_cm"] < rows[1]["max_deformation_cm"]
    assert rows[0]["max_deformation_cm_low95"] < rows[0]["max_deformation_cm"] < rows[0]["max_deformation_cm_high95"]
    assert "point_C_cm" not in rows[0]  # undefined for RSF


def test_predict_batch_csv(fitted, tmp_path, capsys):
    queries = tmp_path / "queries.csv"
    queries.write_text("segment,scope,diameter_mm,angle_deg,friction,sex,region\n"
                       "rsj,utc,23,,0,,\nrsj,sdc,,,0.1,,african\nrsf,pdc,,,0.05,female,\n")
    out = tmp_path / "predictions.csv"
    assert main(["predict", str(fitted / "model.json"), "--csv", str(queries), "-o", str(out)]) == 0
    table = pd.read_csv(out)
    assert len(table) == 3 and table["in_domain"].all()
    assert list(table["diameter_mm"][:2]) == [23.0, 36.0] and table.loc[2, "angle_deg"] == 45.0
    assert table.loc[:1, "point_C_cm"].notna().all() and pd.isna(table.loc[2, "point_C_cm"])
    assert "max_deformation_cm" in capsys.readouterr().out


def test_recommend_and_plot(fitted, tmp_path, capsys):
    assert main(["recommend", str(fitted / "model.json"), "--segment", "rsj", "--region", "european", "--age", "young",
                 "--json", "-o", str(tmp_path / "rec.json")]) == 0
    rec = json.loads((tmp_path / "rec.json").read_text())
    assert rec["ranking"] == ["utc", "pdc", "sdc"] and rec["inputs"] == {"diameter_mm": 23.0, "friction": 0.0}
    capsys.readouterr()
    assert main(["surrogate", "plot", str(fitted / "model.json"), "--segment", "rsf", "--vs", "angle",
                 "--friction", "0.05", "-o", str(tmp_path / "angle.png")]) == 0
    assert (tmp_path / "angle.png").stat().st_size > 10_000


def test_out_of_domain_warns_then_strict_fails(fitted, capsys):
    args = ["predict", str(fitted / "model.json"), "--segment", "rsj", "--diameter", "45", "--friction", "0", "--scope", "sdc"]
    assert main(args) == 0
    captured = capsys.readouterr()
    assert "colonsim: warning: rsj diameter_mm 45 outside 23-36" in captured.err and "OUTSIDE" in captured.out
    assert main(args + ["--strict"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("colonsim: error:") and len(err.splitlines()) == 1


@pytest.mark.parametrize("args,message", [
    (["predict", "{m}", "--segment", "rsf", "--friction", "0"], "give angle_deg"),
    (["predict", "{m}", "--segment", "thf", "--angle", "30"], "no model of segment 'thf'"),
    (["predict", "{m}", "--segment", "rsf", "--angle", "30", "--friction", "0", "--sex", "woman"], "unknown sex"),
    (["predict", "{m}", "--segment", "rsf", "--angle", "30", "--friction", "0", "--scope", "huge"], "unknown scope"),
    (["predict", "{m}", "--segment", "rsf", "--angle", "30", "--friction", "0", "--target", "point_C_cm"], "rsf point_C_cm: 0 runs"),
    (["predict", "{d}/missing.json", "--segment", "rsf"], "not found"),
    (["surrogate", "fit", "{d}/missing.parquet", "-o", "{d}/x"], "not found"),
    (["recommend", "{m}", "--segment", "rsj", "--diameter", "30", "--friction", "0", "--scope", "utc"], "at least two"),
])
def test_bad_input_is_one_line_and_exit_2(fitted, args, message, capsys):
    args = [a.format(m=fitted / "model.json", d=fitted) for a in args]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("colonsim: error:") and message in err and len(err.splitlines()) == 1


def test_the_surrogate_runs_without_scikit_learn(tmp_path):
    """scikit-learn is a test dependency only: fit, info, predict, recommend and plot never import it."""
    import subprocess
    import sys

    synthetic_sweep(design="grid", noise_cm=0.02, seed=1).to_parquet(tmp_path / "results.parquet")
    script = ("import sys\n"
              "sys.modules['sklearn'] = None  # `import sklearn` raises ImportError from here on\n"
              "from colonsim.cli import main\n"
              "for args in (['surrogate', 'fit', 'results.parquet', '-o', 'model', '--restarts', '0'],\n"
              "             ['surrogate', 'info', 'model.json'], ['predict', 'model.json', '--segment', 'rsf', '--sex', 'female', '--age', 'young'],\n"
              "             ['recommend', 'model.json', '--segment', 'rsj', '--region', 'european', '--age', 'middle'],\n"
              "             ['surrogate', 'plot', 'model.json', '--segment', 'rsf', '--vs', 'angle', '--friction', '0.05',\n"
              "              '-o', 'f.png']):\n"
              "    assert main(args) == 0, args\n"
              "assert not [m for m in sys.modules if m.startswith('sklearn.')]\n")
    done = subprocess.run([sys.executable, "-c", script], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert (tmp_path / "f.png").is_file()
