"""A built wheel holds exactly one top-level package, ``colonsim``, with the data the code reads.

(Installing it into a fresh environment and running ``colonsim insert`` / ``colonsim demo``
from outside the checkout is the release check in docs/architecture.md; building the wheel is
the part that fails when a package folder or a data file is left out of pyproject.toml.)
"""

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib
PACKAGE_FOLDERS = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-dir"].values())


@pytest.fixture(scope="module")
def wheel_names(tmp_path_factory):
    # built from a copy: setuptools leaves a build/ folder in the tree it builds
    source = tmp_path_factory.mktemp("source")
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(ROOT / name, source / name)
    for folder in PACKAGE_FOLDERS:
        shutil.copytree(ROOT / folder, source / folder, ignore=shutil.ignore_patterns("__pycache__"))
    out = tmp_path_factory.mktemp("wheel")
    done = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(out), str(source)],
                          capture_output=True, text=True)
    if done.returncode != 0:
        pytest.fail(f"building the wheel failed: {done.stderr.strip()[-2000:]}")
    (wheel,) = out.glob("colonsim-*.whl")
    with zipfile.ZipFile(wheel) as z:
        return z.namelist()


def test_one_top_level_package(wheel_names):
    top = {n.split("/")[0] for n in wheel_names}
    assert {t for t in top if not t.endswith(".dist-info")} == {"colonsim"}


def test_package_data_ships(wheel_names):
    for name in ("colonsim/data/material_reference.json", "colonsim/data/tensile/manifest.csv",
                 "colonsim/data/tensile/specimen_01.csv", "colonsim/data/tensile/ground_truth.json",
                 "colonsim/data/anatomy/sigmoid_loop.csv", "colonsim/data/treloar/manifest.csv",
                 "colonsim/data/treloar/planar.csv"):
        assert name in wheel_names
    for name in ("colonsim/insertion/engine/solver.py", "colonsim/identification/pipeline.py",
                 "colonsim/surrogate/model.py", "colonsim/insertion/study/sweep.py"):
        assert name in wheel_names
