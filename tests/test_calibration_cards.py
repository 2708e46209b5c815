"""Material cards (docs/calibration.md, "Material cards"): every card a law can have is re-read and
its own format's convention gives the fitted law's stress in the three modes to 1e-10; one card per
format is checked in as a fixture; a format that cannot hold a law is refused in one line."""

import json
from pathlib import Path

import numpy as np
import pytest

from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.identification.card_readers import nominal_stress, read_card
from colonsim.identification.cards import FORMATS, SUFFIX, card_text, write_cards
from colonsim.identification.hyperelastic import CALIBRATION_LAWS, MODES, calibration_law

FIXTURES = Path(__file__).parent / "data" / "cards"
# Treloar joint fits (relative residuals) and the source's colon wall, Pa
PARAMETERS = {"mooney_rivlin_3": [652.01, 42835.25, 219120.3], "mooney_rivlin_2": [191020.858792, 3138.88636],
              "neo_hookean": [204162.7133], "yeoh": [189935.169665, -1557.534932, 41.482321],
              "ogden_1": [180799.030589, 2.559482], "ogden_2": [4164409.408004, 0.206586, 11680.513414, 4.0],
              "ogden_3": [537377.179417, 1.43686, 522.413859, 5.445874, -9812.720043, -2.036691]}
FIXTURE_LAWS = {"lsdyna": "ogden_3", "abaqus": "yeoh", "ansys": "mooney_rivlin_3", "febio": "ogden_3"}
REFUSED = {("febio", "mooney_rivlin_3"), ("febio", "yeoh")}
STRETCH = np.linspace(1.01, 6.0, 40)


def _agree(fmt, law, card):
    form = read_card(fmt, card)
    for mode in MODES:
        ours = calibration_law(law).nominal_stress(mode, STRETCH, PARAMETERS[law])
        np.testing.assert_allclose(nominal_stress(form, mode, STRETCH), ours, rtol=1e-10, atol=0)


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("law", sorted(CALIBRATION_LAWS))
def test_every_card_round_trips_through_its_format_convention(fmt, law):
    if (fmt, law) in REFUSED:
        with pytest.raises(ColonsimError, match=f"{fmt} cannot hold {law}: .*; export it as lsdyna, abaqus, ansys"):
            card_text(fmt, law, PARAMETERS[law])
        return
    _agree(fmt, law, card_text(fmt, law, PARAMETERS[law]))


def test_the_round_trip_check_can_fail():
    # Abaqus's Ogden mu is mu_p alpha_p / 2: a card written with colonsim's mu_p would be off
    text = card_text("abaqus", "ogden_1", PARAMETERS["ogden_1"]).replace("0.23137593220499747", "0.180799030589")
    with pytest.raises(AssertionError):
        _agree("abaqus", "ogden_1", text)


@pytest.mark.parametrize("fmt", FORMATS)
def test_fixture_cards(fmt):
    law = FIXTURE_LAWS[fmt]
    fixture = FIXTURES / f"{law}.{SUFFIX[fmt]}"
    assert card_text(fmt, law, PARAMETERS[law]) == fixture.read_text()
    _agree(fmt, law, fixture)


def test_cli_export(tmp_path, capsys):
    material = tmp_path / "material.json"
    material.write_text(json.dumps({"law": "ogden_3", "units": "Pa",
                                    "parameters": dict(zip(calibration_law("ogden_3").parameter_names, PARAMETERS["ogden_3"]))}))
    assert main(["material", "export", str(material), "--format", "lsdyna", "febio"]) == 0
    assert (tmp_path / "material_lsdyna.k").is_file() and (tmp_path / "material_febio.xml").is_file()
    material.write_text(json.dumps({"law": "yeoh", "units": "Pa", "parameters": dict(C10=1e5, C20=1e3, C30=10.0)}))
    capsys.readouterr()
    assert main(["material", "export", str(material), "--format", "abaqus", "febio", "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "febio cannot hold yeoh" in err[0]
    assert not (tmp_path / "x" / "material_abaqus.inp").exists()  # all or none


def test_write_cards_names():
    with pytest.raises(ColonsimError, match="unknown export format 'nastran'"):
        write_cards(["nastran"], "yeoh", PARAMETERS["yeoh"], ".")
