"""The smoothness check's scale (validation/smoothness.py): what the largest departure
from a cubic in the scope diameter is when the runs only scatter about a smooth trend."""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the validation package

from validation import smoothness  # noqa: E402

DIAMETERS = np.arange(9.0, 13.51, 0.5)  # benchmarks/sweeps/smoothness.toml


def test_scatter_alone_gives_a_band_of_departures_and_a_crease_falls_outside_it():
    band = smoothness.scatter_alone_band(DIAMETERS, draws=2000)
    assert 0.5 < band["p05"] < band["p50"] < band["p95"] < 3.0
    # a cubic fitted to 10 runs leaves 6 degrees of freedom: the largest of 10 residuals of sd
    # about sqrt(6/10) is near 1.4 sd, and the band does not depend on the trend or the sd's unit
    assert 1.2 < band["p50"] < 1.7
    # a regime change (a square-root onset at 11 mm) under a scatter of 0.001 departs from the
    # cubic by far more than scatter alone: the comparison can come out the other way
    trend = 1.0 + 0.05 * DIAMETERS + 0.1 * np.sqrt(np.maximum(DIAMETERS - 11.0, 0.0))
    y = trend + np.random.default_rng(1).normal(0.0, 0.001, DIAMETERS.size)
    departure = np.max(np.abs(smoothness.cubic_fit(DIAMETERS, y)[1]))
    assert departure / 0.001 > band["p95"]


def test_the_larger_of_two_cubics_follows_the_crease_a_cubic_cannot(tmp_path):
    """benchmarks/bench_smoothness.py: the largest deformation as the larger of A and C is judged
    against the larger of their cubics; a crease fails the plain cubic and passes that, and a
    departure within A itself fails both."""
    import pandas as pd

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    import bench_smoothness

    a = 0.25 * DIAMETERS - 1.2  # rises through c
    c = 1.45 + 0.02 * (DIAMETERS - 9.0)
    from colonsim.insertion.case.insertion_case import InsertionCase
    from colonsim.insertion.study.sweep_rows import input_row

    cases = [InsertionCase(scope=f"{d:g}") for d in DIAMETERS]  # a results table's rows: its schema is checked
    table = pd.DataFrame([{**input_row(case), "key": case.key()} for case in cases]).assign(
        status="ok", point_A_cm=a, point_C_cm=c, max_deformation_cm=np.maximum(a, c), final_deformation_cm=c)
    table.to_parquet(tmp_path / "results.parquet")
    d, residuals, ranges, crease = bench_smoothness.departures(tmp_path)
    assert np.allclose(d, DIAMETERS)
    assert np.abs(residuals["max_deformation_cm"]).max() / ranges["max_deformation_cm"] > 0.02
    assert np.abs(crease).max() / ranges["max_deformation_cm"] < 1e-9
    bumped = a.copy()
    bumped[4] += 0.05  # a step in A at 11 mm
    table["point_A_cm"] = bumped
    table["max_deformation_cm"] = np.maximum(bumped, c)
    table.to_parquet(tmp_path / "results.parquet")
    _, _, ranges, crease = bench_smoothness.departures(tmp_path)
    assert np.abs(crease).max() / ranges["max_deformation_cm"] > 0.02


def test_the_report_row_of_the_crease_passes_a_crease_and_fails_a_step(tmp_path):
    """The validation report's row (cubic_departures, CREASE_LABEL): the larger of A and C passes
    against the larger of their cubics while the plain cubic fails it; a step in A fails both."""
    import pandas as pd

    from validation.sweeps import Sweep

    a = 0.25 * DIAMETERS - 1.2
    c = 1.45 + 0.02 * (DIAMETERS - 9.0)

    def rows(a):
        table = pd.DataFrame({"key": [f"run{i}" for i in range(DIAMETERS.size)], "scope": [f"{d:g}" for d in DIAMETERS],
                              "status": "ok", "point_A_cm": a, "point_C_cm": c, "max_deformation_cm": np.maximum(a, c),
                              "final_deformation_cm": c})
        out = smoothness.cubic_departures(Sweep("smoothness", tmp_path, [], table, True), tmp_path / "cubic.png")
        return {r["output"]: r for r in out["rows"]}

    crease = rows(a)
    assert crease["max [cm]"]["passed"] is False
    assert crease[smoothness.CREASE_LABEL]["passed"] is True
    bumped = a.copy()
    bumped[4] += 0.05  # a step in A at 11 mm
    step = rows(bumped)
    assert step[smoothness.CREASE_LABEL]["passed"] is False and step["max [cm]"]["passed"] is False
    assert step[smoothness.CREASE_LABEL]["at_scope_mm"] == 11.0
