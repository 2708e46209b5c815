"""The surrogate keeps patient anatomies apart: one model per centerline file (surrogate/table.py)."""

import numpy as np
import pandas as pd
import pytest

from colonsim.errors import ColonsimError
from colonsim.surrogate import SweepSurrogate
from colonsim.surrogate.synthetic import synthetic_sweep
from colonsim.surrogate.table import check_results


def _patients(files, shift_cm):
    """A synthetic RSJ-like table relabelled as runs on patient files; each file's deformation shifted."""
    frames = []
    for i, (path, shift) in enumerate(zip(files, shift_cm)):
        t = synthetic_sweep(n_runs=12, segments=("rsj",), n_failed=0, seed=i)
        t["segment"], t["centerline"], t["key"] = "patient", path, [f"p{i}-{k}" for k in range(len(t))]
        t["max_deformation_cm"] += shift
        frames.append(t)
    rsj = synthetic_sweep(n_runs=12, segments=("rsj",), n_failed=0, seed=9)
    rsj["centerline"] = ""
    return pd.concat([*frames, rsj], ignore_index=True)


def test_each_centerline_file_gets_its_own_model():
    table = _patients(["/data/a/anna.csv", "C:\\cohort\\bert.csv"], [0.0, 2.0])
    model = SweepSurrogate(targets=("max_deformation_cm",), n_restarts=0).fit(table)
    assert set(model.domains_) == {"patient:anna", "patient:bert", "rsj"}
    query = {"scope_diameter_mm": 11.0, "diameter_mm": 30.0, "friction": 0.05}
    anna = model.predict(query, "patient:anna")[0]
    bert = model.predict(query, "patient:bert")[0]
    # the 2 cm shift of bert's runs is learnt by bert's model only (not averaged into one 'patient')
    assert bert - anna == pytest.approx(2.0, abs=0.3)


def test_two_files_with_one_name_are_refused():
    table = _patients(["/a/p.csv", "/b/p.csv"], [0.0, 1.0])
    with pytest.raises(ColonsimError, match="different centerline files named p;"):
        check_results(table)


def test_a_patient_run_without_its_file_is_refused():
    table = _patients(["/a/p.csv"], [0.0])
    table.loc[0, "centerline"] = np.nan
    with pytest.raises(ColonsimError, match="without a centerline"):
        check_results(table)


def test_tables_without_the_column_keep_their_segments():
    table = synthetic_sweep(n_runs=6, segments=("rsj", "rsf"), n_failed=0)
    assert set(check_results(table)["segment"]) == {"rsj", "rsf"}
