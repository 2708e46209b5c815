"""Exporting cards from the command line: the card options and their ranges, the format check
before any fit, a folder whose cards and material.json describe one material, and readers that
refuse what is not a card in one line."""

import hashlib
import json
import re
import time

import pytest

from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.identification import card_conventions
from colonsim.identification.card_readers import read_card
from colonsim.identification.cards import FORMATS, card_material, card_text
from colonsim.identification.hyperelastic import calibration_law

OGDEN = dict(zip(calibration_law("ogden_3").parameter_names,
                 [537377.179417, 1.43686, 522.413859, 5.445874, -9812.720043, -2.036691]))
YEOH = dict(C10=1e5, C20=1e3, C30=10.0)


def _material(path, law, params):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"law": law, "units": "Pa", "parameters": params}))
    return path


def _digests(folder):
    return {p.name: hashlib.md5(p.read_bytes()).hexdigest() for p in sorted(folder.iterdir()) if p.is_file()}


def _one_error(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("colonsim: error:"), err
    return err[0]


def test_cli_export_writes_the_options_onto_the_cards(tmp_path, capsys):
    material = _material(tmp_path / "material.json", "ogden_3", OGDEN)
    assert main(["material", "export", str(material), "--format", *FORMATS, "--material-id", "17", "--density",
                 "1150", "--poisson", "0.49", "--deck"]) == 0
    for fmt, suffix in zip(FORMATS, ("k", "inp", "mac", "xml")):
        text = (tmp_path / f"material_{fmt}.{suffix}").read_text()
        assert "density: 1150 kg/m^3" in text and "K/mu0 = 49.6667 (poisson 0.49 given)" in text
        form = read_card(fmt, text)
        assert form["material_id"] == 17 and form["density"] == pytest.approx(1150.0)
    assert (tmp_path / "material_lsdyna.k").read_text().startswith("*KEYWORD")
    assert "<febio_spec" in (tmp_path / "material_febio.xml").read_text()


def test_the_default_bulk_modulus_is_stated_on_the_card():
    text = card_text("lsdyna", "yeoh", YEOH)
    assert "K/mu0 = 1000 (the default; the bulk-ratio or poisson option chooses another)" in text.replace("\n$  ", "")


@pytest.mark.parametrize("option,value,message", [
    ("--density", "0", "must be a positive number"), ("--density", "-1040", "must be a positive number"),
    ("--density", "1.04", r"looks like g/cm\^3; give kg/m\^3 \(1.04 g/cm\^3 = 1040 kg/m\^3\)"),
    ("--density", "1e6", "outside 100-5000"), ("--density", "nan", "must be a positive number"),
    ("--bulk-ratio", "5", "K/mu0 must lie in 10-100000"), ("--poisson", "0.5", "--poisson 0.5: K/mu0 must lie"),
    ("--poisson", "0.3", "--poisson 0.3: K/mu0 must lie"), ("--material-id", "0", "must be a whole number in 1-"),
    ("--material-id", "1.5", "'1.5' is not a whole number")])
def test_card_options_out_of_range_are_one_line(tmp_path, capsys, option, value, message):
    material = _material(tmp_path / "m" / "material.json", "yeoh", YEOH)
    out = tmp_path / "out"
    assert main(["material", "export", str(material), "--format", "lsdyna", "--out", str(out), option, value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and re.search(message, err[0]), err
    assert not out.exists()


def test_bulk_ratio_and_poisson_exclude_each_other(tmp_path, capsys):
    material = _material(tmp_path / "material.json", "yeoh", YEOH)
    assert main(["material", "export", str(material), "--format", "abaqus", "--bulk-ratio", "100",
                 "--poisson", "0.49"]) == 2
    assert "not allowed with argument" in capsys.readouterr().err


def test_the_format_check_comes_before_the_fit_for_the_default_law(tmp_path, capsys, monkeypatch):
    """A format that cannot hold the default law (here FEBio, with its table shortened) is refused
    before anything is fitted or written."""
    febio = dict(card_conventions.KEYWORDS["febio"])
    del febio["mooney_rivlin_3"]
    monkeypatch.setitem(card_conventions.KEYWORDS, "febio", febio)
    out = tmp_path / "cal"
    start = time.perf_counter()
    assert main(["calibrate", "--export", "febio", "--quick", "--no-progress", "--out", str(out)]) == 2
    assert time.perf_counter() - start < 1.0
    assert "febio cannot hold mooney_rivlin_3" in _one_error(capsys)
    assert not out.exists()
    # the same check for a multi-mode fit, and for every law --compare-laws may choose
    curve = tmp_path / "c.csv"
    curve.write_text("stretch,nominal_stress [MPa]\n1,0\n1.5,0.3\n2,0.7\n3,2.2\n")
    for extra in (["--curve", str(curve), "--mode", "uniaxial"], ["--compare-laws"]):
        assert main(["calibrate", *extra, "--export", "febio", "--quick", "--no-progress", "--out", str(out)]) == 2
        assert "febio cannot hold mooney_rivlin_3" in _one_error(capsys)
        assert not out.exists()


def test_card_options_without_export_are_refused(tmp_path, capsys):
    out = tmp_path / "cal"
    assert main(["calibrate", "--density", "1100", "--quick", "--no-progress", "--out", str(out)]) == 2
    assert "--density sets the material cards; add --export FORMAT" in _one_error(capsys)
    assert not out.exists()


def test_an_export_never_leaves_cards_that_disagree_with_the_folder(tmp_path, capsys):
    folder = tmp_path / "result"
    _material(folder / "material.json", "ogden_3", OGDEN)
    assert main(["material", "export", str(folder / "material.json"), "--format", "lsdyna", "abaqus"]) == 0
    before = _digests(folder)
    # another calibration's law into this folder: refused, the folder byte-identical
    other = _material(tmp_path / "other" / "material.json", "yeoh", YEOH)
    capsys.readouterr()
    assert main(["material", "export", str(other), "--format", "febio", "--out", str(folder)]) == 2
    assert "holds the material.json of another material (law ogden_3)" in _one_error(capsys)
    assert _digests(folder) == before
    # the folder's material.json refitted: exporting one format rewrites the stale other one too
    _material(folder / "material.json", "yeoh", YEOH)
    assert main(["material", "export", str(folder / "material.json"), "--format", "lsdyna"]) == 0
    printed = capsys.readouterr().out
    assert "material_abaqus.inp  (rewritten: it held another material's card)" in printed
    for card in ("material_lsdyna.k", "material_abaqus.inp"):
        assert card_material(folder / card) == ("yeoh", YEOH)


def test_a_calibration_into_a_folder_with_cards_replaces_them_or_is_refused(tmp_path, capsys):
    out = tmp_path / "cal"
    _material(out / "material.json", "ogden_3", OGDEN)
    assert main(["material", "export", str(out / "material.json"), "--format", "ansys"]) == 0
    before = _digests(out)
    curve = tmp_path / "c.csv"
    curve.write_text("stretch,nominal_stress [MPa]\n1,0\n1.5,0.3\n2,0.7\n3,2.2\n")
    fit = ["calibrate", "--curve", str(curve), "--mode", "uniaxial", "--law", "neo_hookean", "--quick", "--no-progress",
           "--out", str(out)]
    assert main(fit) == 2
    assert "holds material cards of the earlier fit (material_ansys.mac)" in _one_error(capsys)
    assert _digests(out) == before
    assert main([*fit, "--export", "lsdyna"]) == 0
    law = json.loads((out / "material.json").read_text())["law"]
    assert card_material(out / "material_ansys.mac")[0] == law == card_material(out / "material_lsdyna.k")[0]
    params = json.loads((out / "material.json").read_text())["parameters"]
    assert card_material(out / "material_ansys.mac")[1] == params


def test_per_specimen_fits_leave_the_folders_cards_alone(tmp_path):
    """--per-specimen writes no material.json of its own, so the folder's cards stay right."""
    import argparse

    from colonsim.cli_material import CARD_OPTIONS, check_export

    _material(tmp_path / "material.json", "yeoh", YEOH)
    assert main(["material", "export", str(tmp_path / "material.json"), "--format", "abaqus"]) == 0
    args = argparse.Namespace(export=None, out=tmp_path, law=None, compare_laws=False, **dict.fromkeys(CARD_OPTIONS))
    check_export(argparse.Namespace(**vars(args), per_specimen=True))
    with pytest.raises(ColonsimError, match="holds material cards of the earlier fit"):
        check_export(argparse.Namespace(**vars(args), per_specimen=False))


@pytest.mark.parametrize("doc,message", [
    ({"law": "yeoh", "units": "Pa", "parameters": {"C10": float("nan"), "C20": 0.0, "C30": 0.0}}, "parameter C10 is nan"),
    ({"law": "yeoh", "units": "Pa", "parameters": {"C10": -1e5, "C20": 0.0, "C30": 0.0}},
     "initial shear modulus -200000 Pa is not positive"),
    ({"law": "yeoh", "units": "Pa", "parameters": {"C10": "1e5", "C20": 0.0, "C30": 0.0}}, "parameter C10 is '1e5', not a finite number"),
    ({"law": "yeoh", "units": "kPa", "parameters": YEOH}, "has no parameters in Pa"),
    ({"law": "yeoh", "units": "Pa", "parameters": {"C10": 1e5, "C20": 0.0}}, "parameter C30 is None, not a finite number")])
def test_a_material_file_no_card_can_hold_is_refused(tmp_path, capsys, doc, message):
    material = tmp_path / "material.json"
    material.write_text(json.dumps(doc))
    assert main(["material", "export", str(material), "--format", "lsdyna"]) == 2
    assert message in _one_error(capsys)
    assert not (tmp_path / "material_lsdyna.k").exists()


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("text", ["", "garbage\n", "*HYPERELASTIC, YEOH\n", "TB,HYPER,1,,3,YEOH\n", "<Material/>",
                                  "*MAT_OGDEN_RUBBER\n"])
def test_readers_refuse_what_is_not_a_card_in_one_line(fmt, text):
    with pytest.raises(ColonsimError) as err:
        read_card(fmt, text)
    assert "\n" not in str(err.value)


def test_parameters_that_are_not_the_laws_are_one_line():
    with pytest.raises(ColonsimError, match="yeoh takes the numbers C10, C20, C30"):
        card_text("abaqus", "yeoh", {"C10": 1e5})
    with pytest.raises(ColonsimError, match="yeoh takes 3 parameters"):
        card_text("abaqus", "yeoh", [1e5, 1.0])


def test_unknown_formats():
    with pytest.raises(ColonsimError, match="unknown export format 'nastran'"):
        card_text("nastran", "yeoh", YEOH)
    with pytest.raises(ColonsimError, match="unknown card format 'nastran'"):
        read_card("nastran", "")


def test_lsdyna_warns_below_its_recommended_poisson_ratio():
    from colonsim.errors import ColonsimWarning
    from colonsim.identification.card_options import CardOptions

    with pytest.warns(ColonsimWarning, match=r"recommends PR >= 0.49 .* PR is 0.4754 \(K/mu0 20\)"):
        card_text("lsdyna", "yeoh", YEOH, CardOptions(bulk_ratio=20.0))
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        card_text("lsdyna", "yeoh", YEOH, CardOptions(bulk_ratio=50.0))
        card_text("abaqus", "yeoh", YEOH, CardOptions(bulk_ratio=20.0))
