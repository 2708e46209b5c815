"""Fault corpus, sizes and values: every size a user controls is checked against its documented
bound (colonsim.limits) before anything is allocated or run, options that could only fail late
fail first, and provenance reads git without taking its lock. Each case: exit 2, one line, in
seconds, nothing written.
"""

import os
import resource
import stat
import sys
import time

import pytest

from colonsim.cli import main
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH
from colonsim.limits import MESH_MAX, max_workers
from colonsim.provenance import code_version

SPECIMEN = ["--curve", "{data}/specimen_01.csv", "--length", "100", "--width", "25", "--thickness", "2"]


@pytest.fixture
def ws(tmp_path):
    from colonsim.data import TENSILE_DIR

    (tmp_path / "huge_material.toml").write_text(
        f'[sweep]\nname = "m"\n[[grid]]\nsegment = "straight"\nscope = ["utc"]\n'
        f'[material]\nfile = "{REFERENCE_MATERIAL_PATH}"\nsamples = 1000000000\n')
    (tmp_path / "huge_lhs.toml").write_text(
        '[sweep]\nname = "l"\n[fixed]\nsegment = "rsj"\n[lhs]\nsamples = 100000000\ndiameter_mm = [23, 36]\n')
    tmp_path.joinpath("data").symlink_to(TENSILE_DIR)
    return tmp_path


CASES = {
    "calibrate --points 1000000": (["calibrate", *SPECIMEN, "--points", "1000000"], "--points: 1000000 is outside 5-200"),
    "calibrate --mesh 3000x3000": (["calibrate", *SPECIMEN, "--mesh", "3000x3000"],
                                   f"3000x3000 is finer than {MESH_MAX[0]}x{MESH_MAX[1]}"),
    "calibrate --seed -1": (["calibrate", *SPECIMEN, "--seed", "-1"], "--seed: -1 is outside 0-4,294,967,295"),
    "calibrate --seed 2**32": (["calibrate", *SPECIMEN, "--seed", str(2**32)], "is outside 0-4,294,967,295"),
    "calibrate --length 1e-300": (["calibrate", "--curve", "{data}/specimen_01.csv", "--length", "1e-300", "--width",
                                   "25", "--thickness", "2"], "--length 1e-300 mm is outside 0.01-10000 mm"),
    "calibrate --width 1e300": (["calibrate", "--curve", "{data}/specimen_01.csv", "--length", "100", "--width",
                                 "1e300", "--thickness", "2"], "--width 1e+300 mm is outside"),
    "calibrate --workers 100000": (["calibrate", *SPECIMEN, "--per-specimen", "--workers", "100000"],
                                   f"100000 is more than the {max_workers()} processes"),
    "sweep --workers 100000": (["sweep", "--preset", "smoke", "--workers", "100000"], "100000 is more than the"),
    "sweep [material] samples = 1e9": (["sweep", "{ws}/huge_material.toml", "--dry-run"],
                                       "[material] samples = 1,000,000,000: more than the 20,000 a sweep may hold"),
    "sweep [lhs] samples = 1e8": (["sweep", "{ws}/huge_lhs.toml", "--dry-run"], "more than the 20,000 a sweep may hold"),
    "demo --element-size 1000": (["demo", "--element-size", "1000"], "element_size_mm = 1000 is outside [0.5, 20]"),
    "demo --workers 100000": (["demo", "--workers", "100000"], "100000 is more than the"),
    "surrogate fit --restarts 1000": (["surrogate", "fit", "{ws}/r.parquet", "-o", "{ws}/m", "--restarts", "1000"],
                                      "--restarts: 1000 is outside 0-50"),
    "surrogate fit --threads 100000": (["surrogate", "fit", "{ws}/r.parquet", "-o", "{ws}/m", "--threads", "100000"],
                                       "100000 is more than the"),
    "sweep --adaptive --budget 1e8": (["sweep", "{ws}/huge_lhs.toml", "--adaptive", "--budget", "100000000"],
                                      "--budget: 100000000 is outside 1-20,000"),
    "insert --friction 3": (["insert", "--segment", "straight", "--friction", "3"], "friction = 3 is outside [0, 1]"),
    "insert --diameter -30": (["insert", "--segment", "straight", "--diameter", "-30"], "diameter_mm = -30 is outside"),
}


def _names(folder):
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


@pytest.mark.parametrize("case", list(CASES))
def test_sizes_and_values_are_bounded_before_any_work(ws, case, capsys, monkeypatch):
    argv, message = CASES[case]
    monkeypatch.chdir(ws)  # default output folders would land here
    before = _names(ws)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    t0 = time.monotonic()
    code = main([a.replace("{ws}", str(ws)).replace("{data}", str(ws / "data")) for a in argv])
    elapsed = time.monotonic() - t0
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and err[0].startswith("colonsim: error: "), err
    assert message in err[0], err[0]
    assert elapsed < 10
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - rss < 500_000  # kB: nothing big was allocated
    assert _names(ws) == before


def test_vtu_without_meshio_fails_before_the_runs(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "meshio", None)  # `import meshio` raises ImportError
    t0 = time.monotonic()
    code = main(["insert", "--segment", "straight", "--vtu", "--no-progress", "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "VTU output needs meshio" in err[0], err
    assert time.monotonic() - t0 < 10  # no insertion ran
    assert not (tmp_path / "o").exists()


def test_vtu_snapshots_are_bounded_before_the_runs(tmp_path, capsys, monkeypatch):
    import types

    monkeypatch.setitem(sys.modules, "meshio", types.ModuleType("meshio"))  # present, never reached
    code = main(["insert", "--segment", "straight", "--vtu", "--snapshot-every", "1e-300", "--no-progress",
                 "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "--snapshot-every: 1e-300 is outside 0.001-10" in err[0], err
    assert not (tmp_path / "o").exists()


def test_provenance_reads_git_without_its_lock(tmp_path, monkeypatch):
    """Every git call runs with GIT_OPTIONAL_LOCKS=0 (git status otherwise refreshes the index under
    .git/index.lock, which makes a user's own commit at that moment fail)."""
    log = tmp_path / "git.log"
    fake = tmp_path / "bin" / "git"
    fake.parent.mkdir()
    fake.write_text(f'#!/bin/sh\necho "$GIT_OPTIONAL_LOCKS $*" >> {log}\necho 0123abc\n')
    fake.chmod(fake.stat().st_mode | stat.S_IEXEC)
    monkeypatch.setenv("PATH", f"{fake.parent}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.delenv("GIT_OPTIONAL_LOCKS", raising=False)
    version = code_version.__wrapped__()
    if not log.exists():
        pytest.skip("not a git checkout: provenance runs no git")
    calls = log.read_text().splitlines()
    assert any("status" in c for c in calls) and all(c.startswith("0 ") for c in calls), calls
    assert version["git_commit"] == "0123abc+modified"  # the fake's status output counts as changes
