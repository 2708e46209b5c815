"""Fault corpus, surrogate files: a model JSON or arrays file edited, damaged or mixed with another
fit is refused on load in one line (exit 2), never answered with ``nan``, ``-inf`` or ``+- 0``.

The tampering keeps the checksum consistent where the audit did (it updated it), so each check
is what catches the case, not the checksum.
"""

import hashlib
import json

import numpy as np
import pytest

from colonsim.cli import main
from colonsim.surrogate.synthetic import synthetic_sweep

QUERY = ["--segment", "rsj", "--diameter", "30", "--friction", "0"]


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    ws = tmp_path_factory.mktemp("models")
    synthetic_sweep(design="grid", noise_cm=0.02, seed=1).to_parquet(ws / "results.parquet")
    assert main(["surrogate", "fit", str(ws / "results.parquet"), "-o", str(ws / "good" / "model"), "--restarts",
                 "0", "--targets", "final_deformation_cm", "max_deformation_cm"]) == 0
    return ws / "good"


def tampered(good, tmp_path, edit_doc=None, edit_arrays=None, name="model"):
    """A copy of the good model with its JSON and/or arrays edited (checksum updated)."""
    folder = tmp_path / "bad"
    folder.mkdir(exist_ok=True)
    doc = json.loads((good / "model.json").read_text())
    with np.load(good / "model.npz", allow_pickle=False) as npz:
        arrays = {k: npz[k] for k in npz.files}
    if edit_arrays:
        edit_arrays(arrays)
    np.savez(folder / f"{name}.npz", **arrays)
    doc["arrays"]["file"] = f"{name}.npz"
    doc["arrays"]["sha256"] = hashlib.sha256((folder / f"{name}.npz").read_bytes()).hexdigest()
    if edit_doc:
        edit_doc(doc)
    (folder / f"{name}.json").write_text(json.dumps(doc))  # json.dumps writes NaN / Infinity as the audit did
    return folder / name


def entry(doc, seg="rsj", target="final_deformation_cm"):
    return doc["segments"][seg]["models"][target]


def swap_segments(arrays):
    """rsf's arrays stored under rsj's names (and the reverse), as a foreign file would."""
    for target in ("final_deformation_cm", "max_deformation_cm"):
        for name in ("X_train", "y_train", "alpha", "L", "belongs_to"):
            a, b = f"rsj__{target}__{name}", f"rsf__{target}__{name}"
            arrays[a], arrays[b] = arrays[b], arrays[a]


def set_value(key, value):
    def edit(doc):
        entry(doc)[key] = value
    return edit


CASES = {
    "NaN noise level": (set_value("noise_level", float("nan")), None, "noise_level) = nan is not finite"),
    "infinite y_scale": (set_value("y_scale", float("inf")), None, "y_scale) = inf is not finite"),
    "negative signal variance": (set_value("constant", -1.0), None, "constant) = -1 must be positive"),
    "zero noise": (set_value("noise_level", 0.0), None, "noise_level) = 0 must be positive"),
    "text y_mean": (set_value("y_mean", "3 cm"), None, "y_mean) = '3 cm' is not a number"),
    "negative length scale": (lambda d: entry(d)["length_scale"].update({k: -1.0 for k in entry(d)["length_scale"]}),
                              None, "must be positive"),
    "x_span of another length": (set_value("x_span", [1.0]), None, "x_span must hold"),
    "another segment's arrays": (None, swap_segments, "belong to 'rsf final_deformation_cm', not to rsj"),
    "arrays of another output": (None, lambda a: a.__setitem__("rsj__final_deformation_cm__belongs_to",
                                                               np.array(["rsj", "max_deformation_cm"])),
                                 "belong to 'rsj max_deformation_cm'"),
    "no identity (older or edited)": (None, lambda a: a.pop("rsj__final_deformation_cm__belongs_to"),
                                      "does not say which fit its arrays belong to"),
    "truncated training inputs": (None, lambda a: a.__setitem__("rsj__final_deformation_cm__X_train",
                                                                a["rsj__final_deformation_cm__X_train"][:-1]),
                                  "array X_train has shape"),
    "NaN in alpha": (None, lambda a: a["rsj__final_deformation_cm__alpha"].__setitem__(0, np.nan),
                     "array alpha has shape"),
    "Cholesky factor with a negative diagonal": (None, lambda a: a["rsj__final_deformation_cm__L"].__setitem__(
        (0, 0), -1.0), "diagonal entry <= 0"),
    "arrays file outside the folder": (lambda d: d["arrays"].__setitem__("file", "../good/model.npz"), None,
                                       "outside the model's folder"),
    "absolute arrays file": (lambda d: d["arrays"].__setitem__("file", "/etc/passwd"), None,
                             "outside the model's folder"),
    "domain bound NaN": (lambda d: d["segments"]["rsj"]["domain"]["inputs"]["diameter_mm"].__setitem__(0, float("nan")),
                         None, "bounds that are not finite"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_tampered_model_is_refused_in_one_line(good, tmp_path, case, capsys):
    edit_doc, edit_arrays, message = CASES[case]
    model = tampered(good, tmp_path, edit_doc, edit_arrays)
    before = {p.name: p.read_bytes() for p in model.parent.iterdir()}
    code = main(["predict", str(model), *QUERY])
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert code == 2, captured.out
    assert len(err) == 1 and err[0].startswith("colonsim: error: "), err
    assert message in err[0], err[0]
    assert "nan" not in captured.out and "inf" not in captured.out
    assert {p.name: p.read_bytes() for p in model.parent.iterdir()} == before


def test_the_untampered_copy_predicts(good, tmp_path, capsys):
    """The control: the copy the cases edit loads and answers (so the checks are what refuse them)."""
    model = tampered(good, tmp_path)
    assert main(["predict", str(model), *QUERY]) == 0
    assert "final_deformation_cm" in capsys.readouterr().out


def test_a_damaged_arrays_file_is_one_line(good, tmp_path, capsys):
    model = tampered(good, tmp_path)
    data = (model.parent / "model.npz").read_bytes()
    (model.parent / "model.npz").write_bytes(data[: len(data) // 2])
    doc = json.loads((model.parent / "model.json").read_text())
    doc["arrays"]["sha256"] = hashlib.sha256(data[: len(data) // 2]).hexdigest()
    (model.parent / "model.json").write_text(json.dumps(doc))
    assert main(["predict", str(model), *QUERY]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "damaged" in err[0] and "refit the surrogate" in err[0], err


@pytest.mark.parametrize("argv,message", [
    (["predict", "{m}", "--segment", "rsj", "--diameter", "-30", "--friction", "0"], "diameter_mm = -30 is outside [10, 80]"),
    (["predict", "{m}", "--segment", "rsj", "--diameter", "30", "--friction", "-1"], "friction = -1 is outside [0, 1]"),
    (["recommend", "{m}", "--segment", "rsj", "--diameter", "30", "--friction", "3"], "friction = 3 is outside [0, 1]"),
    (["recommend", "{m}", "--segment", "rsj", "--diameter", "30", "--friction", "0", "--wall-thickness", "-2"],
     "wall_thickness_mm = -2 is outside"),
    (["surrogate", "plot", "{m}", "--segment", "rsj", "--vs", "friction", "--diameter", "-30", "-o", "{d}/p.png"],
     "diameter_mm = -30 is outside"),
])
def test_predict_and_recommend_refuse_what_insert_refuses(good, tmp_path, argv, message, capsys):
    code = main([a.replace("{m}", str(good / "model")).replace("{d}", str(tmp_path)) for a in argv])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert message in err[0], err[0]
    assert not (tmp_path / "p.png").exists()
    # the same values, given to insert, are refused by the same definition
    name, value = message.split(" = ")[0], message.split(" = ")[1].split()[0]
    option = {"diameter_mm": "--diameter", "friction": "--friction", "wall_thickness_mm": "--wall-thickness"}[name]
    assert main(["insert", "--segment", "rsj", option, value, "--out", str(tmp_path / "ins")]) == 2
    insert_err = capsys.readouterr().err
    assert f"{name} = {value} is outside" in insert_err
    assert not (tmp_path / "ins").exists()

