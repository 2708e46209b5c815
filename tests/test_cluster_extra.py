"""Dask is the optional ``cluster`` extra: a cluster sweep without it fails clearly, a local sweep never needs it."""

import sys

import pytest

from colonsim.cli import main
from colonsim.errors import ColonsimError
from colonsim.insertion.case.scenario import run_insertion
from colonsim.insertion.study.sweep import TABLE, run_sweep
from colonsim.insertion.study.sweep_spec import load_sweep

STRAIGHT = [c for c in load_sweep(preset="smoke").cases if c.segment == "straight"]
DASK = ("dask", "distributed")


@pytest.fixture
def without_dask(monkeypatch):
    """Imports of dask and distributed fail, as if the extra were not installed."""
    for name in [m for m in sys.modules if m.split(".")[0] in DASK]:
        monkeypatch.delitem(sys.modules, name)
    for name in DASK:
        monkeypatch.setitem(sys.modules, name, None)  # `import name` now raises ImportError


def test_cluster_sweep_without_dask_is_one_line_exit_2_and_writes_nothing(without_dask, tmp_path, capsys):
    out = tmp_path / "cluster"
    code = main(["sweep", "--preset", "smoke", "--scheduler", "tcp://127.0.0.1:8786", "--out", str(out),
                 "--no-progress"])
    captured = capsys.readouterr()
    assert code == 2 and captured.out == ""
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("colonsim: error: ")
    assert 'pip install "colonsim[cluster]"' in lines[0]
    assert not out.exists()
    # the workflow function refuses the same way when called directly
    with pytest.raises(ColonsimError, match=r"colonsim\[cluster\]"):
        run_sweep(STRAIGHT, out, scheduler="tcp://127.0.0.1:8786", progress=False)
    assert not out.exists()


def dask_free_runner(case):
    """The real run, refused if the worker process has imported dask."""
    loaded = sorted(m for m in DASK if m in sys.modules)
    if loaded:
        raise RuntimeError(f"the local worker imported {', '.join(loaded)}")
    return run_insertion(case)


def test_local_sweep_runs_without_dask(without_dask, tmp_path):
    report = run_sweep(STRAIGHT, tmp_path / "local", workers=1, runner=dask_free_runner, progress=False)
    assert (report.ran, report.ok) == (1, 1), report.table["error"].tolist()
    assert (tmp_path / "local" / TABLE).is_file()
    assert not any(m in sys.modules and sys.modules[m] is not None for m in DASK)
