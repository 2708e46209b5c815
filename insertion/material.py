"""Colon wall material: the incompressible three-parameter Mooney-Rivlin law read from JSON.

The calibration workflow writes a material file (``"law": "mooney_rivlin_3"``, parameters in Pa);
the insertion model reads it here. A reference copy holding the source's identified parameters
ships with the repository (:data:`REFERENCE_MATERIAL_PATH`).
"""

import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

from colonsim.errors import ColonsimError, ColonsimWarning

LAW = "mooney_rivlin_3"
PARAMETER_NAMES = ("C10", "C01", "C11")
# Small-strain shear modulus below which a wall is softer than any soft tissue: the softest
# (brain, fat) are near 1 kPa, the reference colon wall 87 kPa. Below this, parameters were most
# likely given in the wrong unit.
SOFTEST_TISSUE_MU0_PA = 100.0


class SoftWallWarning(ColonsimWarning):
    """A wall material softer than any soft tissue (probably parameters in the wrong unit)."""


def _reference_material_path():
    """Locate ``data/material_reference.json``: beside the package in a source tree, else as
    installed package data; never raise at import time."""
    path = Path(__file__).resolve().parents[1] / "data" / "material_reference.json"
    if path.is_file():
        return path
    try:
        from importlib import resources

        candidate = resources.files("colonsim") / "data" / "material_reference.json"
        if candidate.is_file():
            return Path(str(candidate))
    except Exception:  # noqa: BLE001 - any packaging failure just means "not installed as data"
        pass
    # Keep the source-tree path: load_material then names it in a clear "not found" error.
    return path


REFERENCE_MATERIAL_PATH = _reference_material_path()


@dataclass(frozen=True)
class MooneyRivlin:
    """Incompressible Mooney-Rivlin law W = C10 (I1-3) + C01 (I2-3) + C11 (I1-3)(I2-3).

    Parameters
    ----------
    C10, C01, C11 : float
        Material constants, Pa. All non-negative, with C10 + C01 > 0.
    """

    C10: float
    C01: float
    C11: float

    def __post_init__(self):
        for name in PARAMETER_NAMES:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ColonsimError(
                    f"Mooney-Rivlin parameter {name} must be a number in Pa, got {value!r}; "
                    "fix the material parameters."
                )
            if not math.isfinite(value) or value < 0.0:
                raise ColonsimError(
                    f"Mooney-Rivlin parameter {name} = {value!r} Pa must be finite and >= 0; "
                    "fix the material parameters."
                )
            object.__setattr__(self, name, float(value))
        if self.C10 + self.C01 <= 0.0:
            raise ColonsimError(
                f"Mooney-Rivlin C10 + C01 = {self.C10 + self.C01!r} Pa must be > 0 (zero "
                "small-strain stiffness); fix the material parameters."
            )

    @property
    def mu0(self):
        """Small-strain shear modulus 2 (C10 + C01), Pa."""
        return 2.0 * (self.C10 + self.C01)

    @property
    def E0(self):
        """Small-strain Young's modulus 6 (C10 + C01), Pa (incompressible)."""
        return 6.0 * (self.C10 + self.C01)

    def uniaxial_nominal_stress(self, stretch):
        """Homogeneous uniaxial nominal (first Piola) stress at stretch ``stretch``, Pa."""
        lam = stretch
        i1 = lam**2 + 2.0 / lam
        i2 = 2.0 * lam + 1.0 / lam**2
        return (
            2.0
            * (lam - lam**-2)
            * (self.C10 + self.C11 * (i2 - 3.0) + (self.C01 + self.C11 * (i1 - 3.0)) / lam)
        )


def load_material(path):
    """Read a ``mooney_rivlin_3`` material file.

    Parameters
    ----------
    path : str or Path
        JSON file with ``"law": "mooney_rivlin_3"``, ``"units": "Pa"`` and
        ``"parameters": {"C10": .., "C01": .., "C11": ..}``.

    Returns
    -------
    MooneyRivlin

    Raises
    ------
    ColonsimError
        Missing file, invalid JSON, unknown law or units, missing or invalid parameters.
    """
    path = Path(path)
    if not path.is_file():
        raise ColonsimError(
            f"material file {path} not found; pass the JSON written by the calibration "
            f"(reference copy: {REFERENCE_MATERIAL_PATH})."
        )
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ColonsimError(
            f"material file {path} is not valid JSON ({exc}); fix or regenerate the file."
        ) from None
    if not isinstance(data, dict):
        raise ColonsimError(
            f"material file {path} must hold a JSON object with 'law' and 'parameters'; "
            "fix or regenerate the file."
        )
    law = data.get("law")
    if law != LAW:
        raise ColonsimError(
            f"material file {path} has law {law!r}; only {LAW!r} is supported, "
            "recalibrate with that law."
        )
    units = data.get("units", "Pa")
    if units != "Pa":
        raise ColonsimError(
            f"material file {path} has units {units!r}; parameters must be in 'Pa', "
            "convert them."
        )
    params = data.get("parameters")
    if not isinstance(params, dict):
        raise ColonsimError(
            f"material file {path} lacks a 'parameters' object with C10, C01, C11 in Pa; "
            "fix or regenerate the file."
        )
    missing = [name for name in PARAMETER_NAMES if name not in params]
    if missing:
        raise ColonsimError(
            f"material file {path} misses parameter(s) {', '.join(missing)}; "
            "give C10, C01 and C11 in Pa."
        )
    try:
        material = MooneyRivlin(*(params[name] for name in PARAMETER_NAMES))
    except ColonsimError as exc:
        raise ColonsimError(f"material file {path}: {exc}") from None
    if material.mu0 < SOFTEST_TISSUE_MU0_PA:
        warnings.warn(f"material file {path}: small-strain shear modulus 2 (C10 + C01) = {material.mu0:.3g} Pa is "
                      f"softer than any soft tissue (the softest, brain and fat, are near 1 kPa); are the parameters "
                      "in Pa?", SoftWallWarning)
    return material
