"""Sweep descriptions: TOML and presets -> validated insertion cases (no simulation runs here)."""

import dataclasses
import json
import re
from pathlib import Path

import numpy as np
import pytest

from colonsim.catalog import SMOKE_ELEMENT_MM
from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH
from colonsim.insertion.case.scenario import InsertionCase
from colonsim.insertion.study.sweep_spec import PRESETS, latin_hypercube, load_sweep, parse_sweep


def test_thesis_preset_holds_every_case_of_chapter_v():
    cases = load_sweep(preset="thesis").cases
    by_segment = {s: [c for c in cases if c.segment == s] for s in ("rsj", "rsf", "thf", "thf-fixed")}
    assert len(cases) == 39 and len({c.key() for c in cases}) == 39
    meshed = ("9.2", "11.1", "13.3")  # the source's scope meshes, not the catalogue's 9.2 / 11.3 / 12.8 mm
    rsj = {(c.scope, c.diameter_mm, c.friction) for c in by_segment["rsj"]}
    assert rsj == {(s, d, mu) for s in meshed for d in (23.0, 36.0) for mu in (0.0, 0.05, 0.1)}
    for segment in ("rsf", "thf"):
        assert {(c.scope, c.angle_deg) for c in by_segment[segment]} == {
            (s, a) for s in meshed for a in (0.0, 30.0, 45.0)}
        assert all(c.friction == 0 and c.diameter_mm == 36 for c in by_segment[segment])
    assert {c.scope for c in by_segment["thf-fixed"]} == set(meshed)
    assert all(c.flexure_angle_deg == 90.0 and c.exit_length_mm == 100.0 for c in cases)


def test_validation_preset_pairs_each_model_with_the_thesis_runs():
    """Each validation run differs from a thesis run in exactly one input: the mesh, the push speed
    or the flexure angle, so the report can pair them."""
    thesis = {c.key(): c for c in load_sweep(preset="thesis").cases}
    cases = load_sweep(preset="validation").cases
    assert len(cases) == 24 and len({c.key() for c in cases}) == 24
    changes = {}
    for c in cases:
        base = {"element_size_mm": 3.0, "push_speed": InsertionCase().push_speed, "flexure_angle_deg": 90.0}
        varied = [k for k, v in base.items() if getattr(c, k) != v]
        assert len(varied) == 1
        partner = InsertionCase(**{**c.to_dict(), varied[0]: base[varied[0]]})
        assert partner.key() in thesis
        changes.setdefault(varied[0], set()).add(c.segment)
    assert changes["element_size_mm"] == changes["push_speed"] == {"rsj", "rsf", "thf", "thf-fixed"}
    # the rate check halves the default speed for every scope of one case per model
    halved = [c for c in cases if c.push_speed != InsertionCase().push_speed]
    assert {c.push_speed for c in halved} == {0.5 * InsertionCase().push_speed} and len(halved) == 12
    assert changes["flexure_angle_deg"] == {"rsf", "thf"}


def test_smoke_preset_is_small_and_coarse():
    cases = load_sweep(preset="smoke").cases
    assert 3 <= len(cases) <= 4 and all(c.element_size_mm == SMOKE_ELEMENT_MM > 3.0 for c in cases)
    assert {c.segment for c in cases} == {"straight", "rsj"}


def test_numbers_are_typed_like_the_dataclass_so_keys_are_stable():
    """23 and 23.0 must give the same run key (resume depends on it)."""
    a = parse_sweep('[grid]\nsegment = "rsj"\ndiameter_mm = 23\nscope = "SDC"').cases[0]
    b = InsertionCase(segment="rsj", diameter_mm=23.0, scope="sdc")
    assert a.key() == b.key() and isinstance(a.diameter_mm, float)


def test_grid_blocks_union_fixed_values_and_duplicates_run_once():
    spec = parse_sweep("""
[fixed]
element_size_mm = 5
[[grid]]
scope = ["utc", "sdc"]
friction = [0, 0.1]
[[grid]]
friction = 0
scope_diameter_mm = 10.5
""")
    assert [(c.scope, c.friction) for c in spec.cases] == [("utc", 0.0), ("utc", 0.1), ("sdc", 0.0), ("sdc", 0.1),
                                                           ("10.5", 0.0)]
    assert all(c.element_size_mm == 5.0 for c in spec.cases)
    again = parse_sweep('[[grid]]\nscope = ["utc", "utc"]\n[[grid]]\nscope = "utc"')
    assert len(again.cases) == 1


def test_latin_hypercube_is_seeded_stratified_and_crossed_with_the_grid():
    text = """
[sweep]
seed = 7
[grid]
segment = "rsj"
scope = ["utc", "sdc"]
[lhs]
samples = 8
diameter_mm = [30, 40]
friction = [0, 0.1]
"""
    a, b = parse_sweep(text).cases, parse_sweep(text).cases
    assert [c.key() for c in a] == [c.key() for c in b] and len(a) == 16
    d = np.array([c.diameter_mm for c in a if c.scope == "utc"])
    # one sample per stratum of width (40 - 30) / 8
    assert sorted(np.floor((d - 30) / 10 * 8).astype(int)) == list(range(8))
    assert [c.diameter_mm for c in a if c.scope == "sdc"] == list(d)
    assert [c.key() for c in parse_sweep(text.replace("seed = 7", "seed = 8")).cases] != [c.key() for c in a]
    u = latin_hypercube(5, 2, 0)
    assert u.shape == (5, 2) and np.all((u >= 0) & (u < 1))


def test_scope_diameter_range_in_the_hypercube_gives_diameter_scopes():
    cases = parse_sweep('[lhs]\nsamples = 4\nscope_diameter_mm = [9, 13]').cases
    assert all(9 <= float(c.scope) <= 13 for c in cases)


def test_material_paths_are_read_from_the_toml_folder(tmp_path):
    (tmp_path / "m.json").write_text(REFERENCE_MATERIAL_PATH.read_text())
    (tmp_path / "s.toml").write_text('[grid]\nmaterial = ["m.json", ""]\n')
    cases = load_sweep(tmp_path / "s.toml").cases
    assert cases[0].material == str((tmp_path / "m.json").resolve()) and cases[1].material is None
    assert load_sweep(tmp_path / "s.toml").name == "s"


@pytest.mark.parametrize("text, message", [
    ('[grid]\nsegmnt = "rsj"', "unknown key 'segmnt' in [grid]; did you mean 'segment'?"),
    ('[sweeps]\nname = "x"', "unknown key 'sweeps' in [top level]"),
    ('[sweep]\nseed = -1\n[grid]\nscope = "utc"', "seed"),
    ('[fixed]\nfriction = [0, 0.1]', "put varying values in a [[grid]] block"),
    ('[fixed]\nfriction = 0.1\n[grid]\nfriction = [0]', "in both [fixed] and [grid]"),
    ('[grid]\nscope = "utc"\nscope_diameter_mm = 9', "same axis"),
    ('[grid]\ndiameter_mm = "wide"', "diameter_mm = 'wide'; give a number"),
    ('[grid]\nscope = "sdc"\ndiameter_mm = 12', "case (scope=sdc, diameter_mm=12.0): scope SDC"),
    ('[grid]\nsegment = "rsx"', "unknown colon segment 'rsx'"),
    ('[grid]\nfriction = []', "empty list"),
    ("[lhs]\nsamples = 0\nfriction = [0, 0.1]", "samples = 0"),
    ("[lhs]\nsamples = 3\nfriction = [0.1, 0]", "low < high"),
    ('[lhs]\nsamples = 3\nsegment = [1, 2]', "not a continuous input"),
    ('[fixed]\nmaterial = "absent.json"\n[grid]\nscope = "utc"', "not found"),
    ("[grid\n", "not valid TOML"),
    ("", "describes no runs"),
])
def test_bad_descriptions_raise_one_actionable_line(text, message):
    with pytest.raises(ColonsimError) as err:
        parse_sweep(text)
    assert message in str(err.value) and "\n" not in str(err.value)


def test_field_list_comes_from_the_dataclass():
    """A field added to InsertionCase is a valid sweep key without touching the sweep code."""
    every = {f.name: f.default for f in dataclasses.fields(InsertionCase)}
    text = "[[grid]]\n" + "\n".join(f"{k} = {json.dumps(v)}" for k, v in every.items()
                                    if v is not None and k not in ("scope", "segment"))
    assert parse_sweep(text).cases[0].key() == InsertionCase().key()


def test_presets_parse_as_toml_documents():
    for name, text in PRESETS.items():
        assert parse_sweep(text).name == name


def test_cli_rejects_bad_sweeps_with_exit_code_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[grid]\nscope = ["utc", "huge"]\n')
    for args, message in (([str(bad)], "unknown scope 'huge'"),
                          (["--preset", "nope"], "unknown preset 'nope'"),
                          ([str(tmp_path / "none.toml")], "not found"),
                          ([], "give a sweep TOML file or --preset"),
                          ([str(bad), "--preset", "smoke"], "one of the two"),
                          (["--preset", "smoke", "--workers", "0"], "at least 1"),
                          (["--preset", "smoke", "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "--workers is for local runs")):
        capsys.readouterr()
        assert main(["sweep", *args, "--out", str(tmp_path / "out"), "--no-progress"]) == 2, args
        err = capsys.readouterr().err.strip()
        assert message in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "out").exists()


def test_cli_dry_run_lists_the_cases(tmp_path, capsys):
    assert main(["sweep", "--preset", "thesis", "--dry-run", "--out", str(tmp_path / "t")]) == 0
    out = capsys.readouterr().out
    assert "39 runs, 0 already in" in out and "thf-fixed" in out
    assert not (tmp_path / "t").exists()


def test_the_sweep_files_of_the_documentation_parse():
    """Every TOML block of docs/sweeps.md is a valid sweep (no run)."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "sweeps.md").read_text()
    blocks = re.findall(r"```toml\n(.*?)```", text, flags=re.S)
    sizes = [len(parse_sweep(block).cases) for block in blocks]
    assert sizes == [4 * 2 * 3 + 2 * 2 * 3, 2 * 20]
