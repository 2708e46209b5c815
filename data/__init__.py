"""The data colonsim ships, installed with it as package data (docs/architecture.md).

- ``material_reference.json``: the source's identified colon wall parameters, the material every
  insertion uses unless given another (docs/model.md, "Colon wall").
- ``tensile/``: the bundled SYNTHETIC tensile test set and its ground truth (``README.md`` here says
  how it was made; ``python -m colonsim.identification.synthetic_data`` regenerates it).
- ``treloar/``: Treloar's 1944 rubber data in three test modes (uniaxial, equibiaxial, planar), the
  public benchmark of multi-mode calibration, with a mode manifest (``README.md``: source, units).

This module is on the ground floor: it imports nothing of colonsim.
"""

from importlib import resources
from pathlib import Path


def data_path(*parts: str) -> Path:
    """Path of a bundled file, in a source checkout or an installed copy alike."""
    return Path(str(resources.files(__name__).joinpath(*parts)))


REFERENCE_MATERIAL_PATH = data_path("material_reference.json")
TENSILE_DIR = data_path("tensile")
BUNDLED_MANIFEST = TENSILE_DIR / "manifest.csv"
TRELOAR_MANIFEST = data_path("treloar", "manifest.csv")
