"""The catalog (colonsim/catalog.py): each colon model, named scope and results-table column is one
entry that the geometry, the insertion case, the sweep, the surrogate and the CLI help read."""

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from colonsim import catalog, options
from colonsim.catalog import COLON_MODELS, COLUMNS, NAMED_SCOPES, ColonModel, NamedScope
from colonsim.data import data_path
from colonsim.insertion.anatomy.patient_centerline import load_patient_centerline
from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.colon_segments import colon_geometry
from colonsim.insertion.anatomy.scopes import colonoscope
from colonsim.insertion.case.scenario import InsertionCase, build_insertion, run_insertion
from colonsim.insertion.study.sweep import IDENTITY, OUTPUTS, SweepStore, input_columns, result_row
from colonsim.insertion.study.sweep_spec import parse_sweep
from colonsim.surrogate.patients import patient_inputs
from colonsim.surrogate.table import (INPUTS, NOT_SETTINGS, TARGET_LABELS, TARGETS, check_results, scope_diameter_mm,
                                      solver_settings, target_unit)

SWEEPS_DOC = Path(__file__).resolve().parents[1] / "docs" / "sweeps.md"
COARSE_MM = 10.0  # wall mesh of the build checks: a third of the 36 mm colon at most


def _middle_angle(model):
    return 0.0 if model.angle_limits_deg is None else 0.5 * sum(model.angle_limits_deg)


EXAMPLE_CENTERLINE = str(data_path("anatomy", "sigmoid_loop.csv"))


def _anatomy(model):
    """Case fields of ``model``'s geometry: a model that reads a centerline gets the bundled example."""
    if not model.reads_centerline:
        return {"diameter_mm": 36.0}
    return {"centerline": EXAMPLE_CENTERLINE,
            "diameter_mm": load_patient_centerline(EXAMPLE_CENTERLINE).median_diameter_mm}


def _table(segments, scopes=("sdc",)):
    """A minimal results table as the surrogate reads it, one ok run per segment and scope."""
    rows = [{"key": f"{s}-{c}", "status": "ok", "segment": s, "scope": c, "scope_diameter_mm": scope_diameter_mm(c),
             "diameter_mm": 36.0, "final_deformation_cm": 1.0, "git_commit": "abc"}
            for s in segments for c in scopes]
    return pd.DataFrame(rows)


@pytest.mark.parametrize("name", list(COLON_MODELS))
def test_every_colon_model_builds_and_its_facts_reach_the_case(name):
    model = COLON_MODELS[name]
    angle = _middle_angle(model)
    anatomy = _anatomy(model)
    centerline = load_patient_centerline(anatomy["centerline"]) if model.reads_centerline else None
    g = colon_geometry(name, anatomy["diameter_mm"] * 1e-3, angle, COARSE_MM * 1e-3, 2e-3, centerline=centerline)
    assert g.name == name and len(g.triangles) > 0
    assert (g.straighten_depth is not None) == model.straightens
    if model.straightens:
        assert g.mobile_axes and g.straighten_depth == g.mobile_end
    assert (g.end_depth < g.centerline_length) == (model.end_rule == catalog.PAST_MOBILE_END)
    case = InsertionCase(segment=name, angle_deg=angle, element_size_mm=COARSE_MM, **anatomy)
    built = build_insertion(case)
    length = model.scope_length_for(g.centerline_length, case.sheath_reserve_mm * 1e-3)
    assert built.rod.rest_length.sum() == pytest.approx(length, rel=1e-12)
    assert (model.scope_length is None) == model.reads_centerline
    phases = [p.name for p in built.push.phases]
    assert phases == (["straighten", "stop", "relax", "push", "settle"] if model.straightens else ["push", "settle"])


def test_colon_model_facts_reach_sweep_and_surrogate():
    names = list(COLON_MODELS)
    shaped = [n for n in names if not COLON_MODELS[n].reads_centerline]  # the others need their file
    spec = parse_sweep(f'[grid]\nsegment = {shaped!r}\nelement_size_mm = {COARSE_MM}'.replace("'", '"'))
    assert [c.segment for c in spec.cases] == shaped
    table = check_results(_table([n.upper() for n in names]))
    assert list(table["segment"]) == names
    for name, model in COLON_MODELS.items():
        assert ("angle_deg" in patient_inputs(name, sex="female")) == model.surrogate_angle
    for name in names:
        assert name in options.segment_help()


def test_a_new_colon_model_is_one_entry(monkeypatch, tmp_path):
    tube = dataclasses.replace(COLON_MODELS["straight"], name="tube", title="a second straight tube", scope_length=0.35)
    monkeypatch.setitem(COLON_MODELS, "tube", tube)
    g = colon_geometry("tube", 0.036, 0.0, COARSE_MM * 1e-3, 2e-3)
    assert g.name == "tube"
    case = InsertionCase(segment="tube", element_size_mm=7.5, push_speed=catalog.SMOKE_PUSH_SPEED)
    case.validate()
    assert build_insertion(case).rod.rest_length.sum() == pytest.approx(0.35, rel=1e-12)
    result = run_insertion(case)
    assert result.summary["ended_by"] == "far_end" and result.summary["mesh"]["segment"] == "tube"
    spec = parse_sweep('[grid]\nsegment = ["tube", "straight"]\nscope = ["utc", "sdc"]')
    assert sorted({c.segment for c in spec.cases}) == ["straight", "tube"] and len(spec.cases) == 4
    assert set(check_results(_table(["tube", "rsj"]))["segment"]) == {"tube", "rsj"}
    assert "tube" in options.segment_help() and "tube" in options.angle_help()


def test_a_new_straightened_model_gets_the_manoeuvre_and_its_rules(monkeypatch):
    long_rsf = dataclasses.replace(COLON_MODELS["rsf"], name="rsf-long", scope_length=0.75)
    monkeypatch.setitem(COLON_MODELS, "rsf-long", long_rsf)
    built = build_insertion(InsertionCase(segment="rsf-long", angle_deg=30.0, element_size_mm=COARSE_MM))
    reference = build_insertion(InsertionCase(segment="rsf", angle_deg=30.0, element_size_mm=COARSE_MM))
    assert built.rod.rest_length.sum() == pytest.approx(0.75, rel=1e-12)
    assert [p.name for p in built.push.phases] == [p.name for p in reference.push.phases]
    # the same centerline up to the exit, which takes the longer scope's extra 5 cm
    assert built.geometry.exit_start == pytest.approx(reference.geometry.exit_start, abs=1e-12)
    assert built.geometry.centerline_length == pytest.approx(reference.geometry.centerline_length + 0.05, abs=1e-9)
    assert all(np.allclose(a[0], b[0]) for a, b in zip(built.geometry.mobile_axes, reference.geometry.mobile_axes))
    assert "rsf-long" in options.angle_help()
    with pytest.raises(ColonsimError, match="outside 0-60 deg"):
        colon_geometry("rsf-long", 0.036, 70.0, COARSE_MM * 1e-3, 2e-3)


def test_a_new_named_scope_is_one_entry(monkeypatch, tmp_path):
    xtc = NamedScope("xtc", "extra-thin colonoscope", 7.0e-3, 7.2e-3, youngs_modulus=20e6)
    monkeypatch.setitem(NAMED_SCOPES, "xtc", xtc)
    scope = colonoscope("XTC")
    assert (scope.name, scope.diameter, scope.youngs_modulus) == ("XTC", 7.0e-3, 20e6) and scope.small_caliber
    case = InsertionCase(scope="xtc", element_size_mm=COARSE_MM)
    case.validate()
    spec = parse_sweep('[grid]\nsegment = "rsj"\nscope = ["XTC", "sdc"]')
    assert [c.scope for c in spec.cases] == ["xtc", "sdc"]
    row = result_row(spec.cases[0], {"status": "failed", "error": "not run", "wall_time_s": math.nan,
                                     "finished_at": "2026-01-01T00:00:00+00:00"})
    assert row["scope_diameter_mm"] == 7.0
    assert scope_diameter_mm("xtc") == 7.0 and scope_diameter_mm("Xtc") == 7.0
    assert check_results(_table(["rsj"], scopes=("xtc", "sdc")))["scope_diameter_mm"].tolist() == [7.0, 12.8]
    assert catalog.scope_role(7.2) == "xtc" and catalog.meshed_diameters()["xtc"] == 7.2e-3
    assert "xtc" in options.scope_help() and "xtc" in catalog.small_caliber_scopes()


@pytest.mark.parametrize("spec,expected", [("utc", ("UTC", 9.2e-3)), (" SDC ", ("SDC", 12.8e-3)),
                                           ("10.5", ("10.5 mm", 10.5e-3)), ("10.5mm", ("10.5 mm", 10.5e-3)),
                                           (11.1, ("11.1 mm", 11.1e-3))])
def test_one_scope_parser(spec, expected):
    assert catalog.parse_scope(spec) == expected


@pytest.mark.parametrize("spec,message", [("gastroscope", "unknown scope 'gastroscope'; use utc, pdc, sdc"),
                                          ("25", "outside 3-20 mm"), ("nan", "outside 3-20 mm")])
def test_scope_parser_errors_are_one_line(spec, message):
    for parse in (catalog.parse_scope, colonoscope, scope_diameter_mm):
        with pytest.raises(ColonsimError, match=message) as info:
            parse(spec)
        assert "\n" not in str(info.value)


def test_scope_facts():
    assert catalog.standard_scope().name == "sdc" and catalog.small_caliber_scopes() == ("utc", "pdc")
    assert catalog.meshed_diameters() == {"utc": 9.2e-3, "pdc": 11.1e-3, "sdc": 13.3e-3}
    roles = [catalog.scope_role(d) for d in (9.2, 11.1, 11.3, 12.8, 13.3, 10.5)]
    assert roles == ["utc", "pdc", "pdc", "sdc", "sdc", None]


def test_bad_entries_are_refused_with_one_line():
    with pytest.raises(ColonsimError, match="manoeuvre 'wiggle'"):
        dataclasses.replace(COLON_MODELS["rsj"], manoeuvre="wiggle")
    with pytest.raises(ColonsimError, match="mobile_piece"):
        dataclasses.replace(COLON_MODELS["rsf"], mobile_piece=None)
    with pytest.raises(ColonsimError, match="angle_limits_deg"):
        dataclasses.replace(COLON_MODELS["rsj"], angle=catalog.ALPHA)
    with pytest.raises(ColonsimError, match="lower-case name"):
        NamedScope("XTC", "x", 7e-3, 7e-3)
    with pytest.raises(ColonsimError, match="kind 'result'"):
        catalog.Column("x", "result", "", "x")


def test_a_missing_builder_is_named(monkeypatch):
    broken = ColonModel("broken", "no builder", "colonsim.insertion.anatomy.colon_segments:nothing", 0.3)
    monkeypatch.setitem(COLON_MODELS, "broken", broken)
    with pytest.raises(ColonsimError, match="builder 'colonsim.insertion.anatomy.colon_segments:nothing' not found"):
        colon_geometry("broken", 0.036, 0.0, COARSE_MM * 1e-3, 2e-3)


def test_columns_are_the_sweep_table():
    assert set(catalog.columns(catalog.INPUT) + catalog.columns(catalog.SETTING)) == set(input_columns())
    assert IDENTITY == catalog.columns(catalog.PROVENANCE) and OUTPUTS == catalog.columns(catalog.OUTPUT)
    assert set(SweepStore("unused").table().columns) == set(COLUMNS)
    case = InsertionCase()
    row = result_row(case, {"status": "failed", "error": "x", "wall_time_s": 1.0, "finished_at": "t"})
    assert set(row) == set(COLUMNS)


def test_columns_are_what_the_surrogate_reads():
    assert set(INPUTS) <= set(catalog.columns(catalog.INPUT)) and set(TARGETS) <= set(TARGET_LABELS)
    assert set(TARGET_LABELS) <= set(catalog.columns(catalog.OUTPUT))
    assert NOT_SETTINGS.isdisjoint(catalog.columns(catalog.SETTING))
    table = _table(["rsj", "rsf"]).assign(element_size_mm=3.0, git_commit=["a", "b"])
    settings, varying = solver_settings(table)
    assert set(settings) == {"element_size_mm"} and varying == []  # provenance (git_commit) is no setting
    units = [target_unit(t) for t in ("final_deformation_cm", "peak_push_force_N", "max_wall_stretch")]
    assert units == ["cm", "N", ""]


def test_units_follow_the_column_names():
    suffix_units = {"cm": "cm", "mm": "mm", "N": "N", "deg": "deg", "s": "s"}
    for column in COLUMNS.values():
        suffix = column.name.rsplit("_", 1)[-1]
        if suffix in suffix_units:
            assert column.unit == suffix_units[suffix], column.name


def _doc_column_rows():
    text = SWEEPS_DOC.read_text(encoding="utf-8")
    rows = re.findall(r"^\| `([^`]+)` \| (\w+) \| ([^|]*) \| (.*) \|$", text, flags=re.M)
    return [(name, kind, unit.strip(), description.strip()) for name, kind, unit, description in rows]


def test_docs_list_the_catalog_columns():
    expected = [(c.name, c.kind, c.unit, c.description.replace("|", "\\|")) for c in COLUMNS.values()]
    shown = "\n".join(f"| `{n}` | {k} | {u} | {d} |" for n, k, u, d in expected)
    assert _doc_column_rows() == expected, f"docs/sweeps.md's column table should read:\n{shown}"
