"""Wall materials drawn for a sweep ([material] section): the posterior's draws, their truncation and
seeds, the population's specimens, the TOML errors, the case field and the results columns."""

import json
import math

import numpy as np
import pytest
from scipy import stats

from colonsim.catalog import WALL_C11, WALL_MU0
from colonsim.data import REFERENCE_MATERIAL_PATH
from colonsim.errors import ColonsimError
from colonsim.insertion.case.scenario import InsertionCase, build_insertion
from colonsim.insertion.study.material_samples import Posterior, material_columns, read_posterior, tissue_columns
from colonsim.insertion.study.sweep import result_row
from colonsim.insertion.study.sweep_spec import parse_sweep

NAMES = ("C10", "C01", "C11")
# a posterior like a calibration's (sd 3-10 % of the values, C10/C01 correlation -0.9), far from 0
MEAN = np.array([20_000.0, 30_000.0, 150_000.0])
SD = np.array([2_000.0, 1_500.0, 5_000.0])
CORR = np.array([[1.0, -0.9, 0.3], [-0.9, 1.0, -0.2], [0.3, -0.2, 1.0]])
COV = CORR * np.outer(SD, SD)
FAILED = {"status": "failed", "error": "x", "wall_time_s": 1.0, "finished_at": "t"}


def material_file(folder, mean=MEAN, cov=COV, name="material.json", law="mooney_rivlin_3", names=NAMES):
    """A material.json as colonsim calibrate writes it (parameters, correlation names, covariance_Pa2)."""
    path = folder / name
    path.write_text(json.dumps({"format": "colonsim-material/1", "law": law, "units": "Pa",
                                "parameters": dict(zip(names, map(float, mean))),
                                "correlation": {"names": list(names), "matrix": None},
                                "covariance_Pa2": None if cov is None else np.asarray(cov).tolist()}))
    return path


def population_file(folder, values):
    rows = [{"specimen": f"s{i}", **{f"{n}_Pa": float(v) for n, v in zip(NAMES, row)}} for i, row in enumerate(values)]
    path = folder / "population.json"
    path.write_text(json.dumps({"format": "colonsim-material/1", "law": "mooney_rivlin_3", "units": "Pa",
                                "parameters": dict(zip(NAMES, np.mean(values, axis=0).tolist())), "specimens": rows}))
    return path


def sweep(material, extra=""):
    return f"""
[fixed]
element_size_mm = 7.5
[[grid]]
segment = "straight"
scope = ["utc", "sdc"]
{extra}
[material]
{material}
"""


def test_draws_reproduce_the_posterior_mean_and_covariance(tmp_path):
    n = 20_000
    x = read_posterior(material_file(tmp_path)).draw(n, seed=1)
    # the sample mean has sd SD / sqrt(n); a sample covariance entry has sd sqrt((S_ii S_jj + S_ij^2) / n)
    # (normal data): 5 sd bounds fail with probability below 1e-5 per entry
    assert (np.abs(x.mean(axis=0) - MEAN) < 5 * SD / math.sqrt(n)).all()
    S = np.cov(x.T)
    assert (np.abs(S - COV) < 5 * np.sqrt((np.outer(np.diag(COV), np.diag(COV)) + COV**2) / n)).all()


def test_draws_are_truncated_to_non_negative_parameters(tmp_path):
    # C10 half a standard deviation above 0, independent of the others: a truncated normal
    mean, sd = np.array([1_000.0, 30_000.0, 150_000.0]), np.array([2_000.0, 1_500.0, 5_000.0])
    x = read_posterior(material_file(tmp_path, mean, np.diag(sd**2))).draw(20_000, seed=2)
    assert (x >= 0).all() and len(x) == 20_000
    expected = stats.truncnorm(-mean[0] / sd[0], np.inf, loc=mean[0], scale=sd[0])
    assert abs(x[:, 0].mean() - expected.mean()) < 5 * expected.std() / math.sqrt(len(x))
    assert abs(x[:, 1].mean() - mean[1]) < 5 * sd[1] / math.sqrt(len(x))  # the others are untouched


def test_a_posterior_mostly_below_zero_is_refused():
    post = Posterior("mooney_rivlin_3", NAMES, np.array([-1e5, 1e4, 1e4]), np.diag([1e6, 1e6, 1e6]), "m.json")
    with pytest.raises(ColonsimError, match="cannot be truncated by rejection"):
        post.draw(10, seed=0)


def test_a_calibration_that_leaves_a_combination_free_is_not_sampled(tmp_path):
    """A posterior unbounded along a direction the data do not fix (identification/uncertainty.py)
    cannot be drawn from: refused in one line naming the combination."""
    path = material_file(tmp_path)
    doc = json.loads(path.read_text())
    doc["uncertainty"] = {"unidentified": [{"direction_in_bound_widths": {"C10": 0.71, "C01": -0.71, "C11": 0.0}}]}
    path.write_text(json.dumps(doc))
    with pytest.raises(ColonsimError, match=r"does not identify \+0.71 C10, -0.71 C01") as err:
        read_posterior(path)
    assert "\n" not in str(err.value)


def test_seeds_make_draws_reproducible(tmp_path):
    post = read_posterior(material_file(tmp_path))
    assert np.array_equal(post.draw(50, 3), post.draw(50, 3)) and not np.array_equal(post.draw(50, 3), post.draw(50, 4))
    text = sweep(f'file = "{tmp_path / "material.json"}"\nsamples = 4\nseed = 7')
    keys = [c.key() for c in parse_sweep(text).cases]
    assert keys == [c.key() for c in parse_sweep(text).cases]
    assert keys != [c.key() for c in parse_sweep(text.replace("seed = 7", "seed = 8")).cases]
    # without its own seed the section takes the [sweep] seed
    plain = sweep(f'file = "{tmp_path / "material.json"}"\nsamples = 4')
    assert [c.key() for c in parse_sweep("[sweep]\nseed = 7\n" + plain).cases] == keys


def test_every_case_is_crossed_with_every_draw(tmp_path):
    path = material_file(tmp_path)
    cases = parse_sweep(sweep('file = "material.json"\nsamples = 3'), base=tmp_path).cases
    assert len(cases) == 6 and len({c.key() for c in cases}) == 6
    assert {c.material for c in cases} == {str(path.resolve())}
    assert [c.material_parameters for c in cases[:3]] == [c.material_parameters for c in cases[3:]]
    assert all(set(c.material_parameters) == set(NAMES) for c in cases)
    # the default keys do not move when a field is added at its default (existing sweep folders
    # resume); they moved with the quasi-static defaults (0.3 m/s push, the scope's damping): those
    # are other runs, with the end at rest (stopped at once, brought to rest, stop_distance_mm 0), and
    # with the hold until the run has come to rest (settle_max_s, settle_lateral_damping 20 1/s), and
    # with the held push (held_push_share 0.5 behind a tip the distal resistance holds), and with the
    # 0.15 m/s push, and with the defaults of 2026-11-28 (the held push 50 mm before the exit, the
    # relax until at rest, the shortest closing hold 0.5 s)
    assert InsertionCase(time_step_estimate="bounds").key() == "d1aafd84d442"  # ... and at the global time-step
    assert InsertionCase().key() == "fecd8bb9070e"  # estimate, the default since 2026-12-07 (the bounds' keep theirs)
    assert InsertionCase(segment="rsf", scope="utc", angle_deg=30, friction=0.05,
                         time_step_estimate="bounds").key() == "cbf520e7eee8"
    assert InsertionCase(segment="rsf", scope="utc", angle_deg=30, friction=0.05).key() == "7e90c80d1d57"


def test_population_uses_each_specimen_once_or_a_seeded_subset(tmp_path):
    values = np.array([[10_000.0, 35_000.0, 140_000.0], [15_000.0, 30_000.0, 160_000.0],
                       [20_000.0, 25_000.0, 200_000.0], [5_000.0, 40_000.0, 180_000.0]])
    population_file(tmp_path, values)
    cases = parse_sweep(sweep('population = "population.json"'), base=tmp_path).cases
    drawn = [tuple(c.material_parameters[n] for n in NAMES) for c in cases[:4]]
    assert len(cases) == 8 and drawn == [tuple(v) for v in values]
    subset = parse_sweep(sweep('population = "population.json"\nsamples = 2\nseed = 1'), base=tmp_path).cases
    assert len(subset) == 4 and {tuple(c.material_parameters.values()) for c in subset} <= set(map(tuple, values))
    with pytest.raises(ColonsimError, match="holds 4 specimens"):
        parse_sweep(sweep('population = "population.json"\nsamples = 5'), base=tmp_path)


@pytest.mark.parametrize("section,extra,message", [
    (f'file = "{REFERENCE_MATERIAL_PATH}"\nsamples = 3', "",
     "calibrate with colonsim calibrate, which writes covariance_Pa2"),
    ('file = "material.json"\nsamples = 0', "", "samples = 0; give the number of materials"),
    ('file = "material.json"\nsamples = true', "", "samples = True"),
    ('file = "material.json"', "", "needs samples = N"),
    ('file = "material.json"\npopulation = "population.json"\nsamples = 3', "", "one of them"),
    ("samples = 3", "", "one of them"),
    ('file = "material.json"\nsample = 3', "", "did you mean 'samples'"),
    ('file = "material.json"\nsamples = 3\nseed = -1', "", "seed = -1"),
    ('file = "missing.json"\nsamples = 3', "", "not found"),
    ('file = "material.json"\nsamples = 3', 'material = ["a.json"]', "material is set in [grid]"),
    ('file = "material.json"\nsamples = 3', "material_parameters = 1", "unknown key 'material_parameters'"),
    ('file = "bad_cov.json"\nsamples = 3', "", "not a symmetric positive semi-definite"),
    ('file = "short_cov.json"\nsamples = 3', "", "must be a finite 3 x 3 matrix"),
    ('file = "material.json"\nsamples = 20001', "", "more than the 20,000 a sweep may hold"),
])
def test_bad_material_sections_are_one_line_errors(tmp_path, section, extra, message):
    material_file(tmp_path)
    material_file(tmp_path, cov=np.diag([-1e6, 1e6, 1e6]), name="bad_cov.json")
    material_file(tmp_path, cov=np.eye(2), name="short_cov.json")
    with pytest.raises(ColonsimError, match=None) as err:
        parse_sweep(sweep(section, extra), base=tmp_path)
    assert message in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("params,message", [
    ({"C10": 600.0, "C01": 40_000.0}, "must name exactly the parameters of law mooney_rivlin_3"),
    ({"C10": -1.0, "C01": 40_000.0, "C11": 1e5}, "must be finite and >= 0"),
    ({"C10": math.nan, "C01": 40_000.0, "C11": 1e5}, "must be finite and >= 0"),
    ({"C10": 0.0, "C01": 0.0, "C11": 1e5}, "mu0 = 0.0 Pa must be > 0"),
    ([1.0, 2.0, 3.0], "must name exactly"),
])
def test_case_material_parameters_are_validated(params, message):
    with pytest.raises(ColonsimError, match="material_parameters") as err:
        InsertionCase(material_parameters=params).validate()
    assert message in str(err.value)


def test_the_run_uses_the_drawn_parameters_with_the_file_law():
    params = {"C10": 1_000.0, "C01": 50_000.0, "C11": 100_000.0}
    model = build_insertion(InsertionCase(segment="straight", element_size_mm=7.5, material_parameters=params))
    assert model.shell.material.law == "mooney_rivlin_3" and model.shell.material.named_parameters == params


def test_results_rows_carry_the_material_columns(tmp_path):
    default = result_row(InsertionCase(), FAILED)
    assert default["material_parameters"] == ""
    assert default[WALL_MU0] == pytest.approx(2 * (652.01 + 42835.25) / 1e3) and default[WALL_C11] == 219.1203
    params = {"C10": 1_000.0, "C01": 50_000.0, "C11": 100_000.0}
    row = result_row(InsertionCase(material_parameters=params), FAILED)
    assert json.loads(row["material_parameters"]) == params
    assert row[WALL_MU0] == pytest.approx(102.0) and row[WALL_C11] == pytest.approx(100.0)
    # a law without a C11 term: NaN there (the surrogate leaves such an input out)
    yeoh = material_file(tmp_path, [30_000.0, 1_000.0, 100.0], None, "yeoh.json", "yeoh", ("C10", "C20", "C30"))
    row = material_columns(InsertionCase(material=str(yeoh)))
    assert row[WALL_MU0] == pytest.approx(60.0) and math.isnan(row[WALL_C11])
    # Ogden: mu0 = 1/2 sum mu_p alpha_p
    ogden = material_file(tmp_path, [20_000.0, 2.0, -10_000.0, -2.0], None, "ogden.json", "ogden_2",
                          ("mu1", "alpha1", "mu2", "alpha2"))
    row = material_columns(InsertionCase(material=str(ogden)))
    assert row[WALL_MU0] == pytest.approx(30.0) and math.isnan(row[WALL_C11])


def test_tissue_columns_are_the_laws_small_strain_modulus():
    rows = np.array([[1_000.0, 2_000.0, 3_000.0], [4_000.0, 5_000.0, 6_000.0]])
    cols = tissue_columns("mooney_rivlin_3", rows)
    assert np.allclose(cols[WALL_MU0], [6.0, 18.0]) and np.allclose(cols[WALL_C11], [3.0, 6.0])
    assert np.allclose(tissue_columns("neo_hookean", [[5_000.0]])[WALL_MU0], 10.0)


def test_the_material_sections_of_the_documentation_parse(tmp_path):
    """docs/sweeps.md's [material] snippets, added to a grid, with the calibration files they name."""
    import re
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "sweeps.md").read_text()
    snippets = re.findall(r"```\n(\[material\].*?)```", text, flags=re.S)
    (tmp_path / "calibration").mkdir()
    material_file(tmp_path / "calibration")
    population_file(tmp_path / "calibration", np.array([[10_000.0 + 1e3 * i, 30_000.0, 150_000.0] for i in range(8)]))
    grid = '[[grid]]\nsegment = "straight"\nscope = ["utc", "pdc", "sdc"]\n'
    sizes = [len(parse_sweep(grid + snippet, base=tmp_path).cases) for snippet in snippets]
    assert sizes == [3 * 20, 3 * 5]
