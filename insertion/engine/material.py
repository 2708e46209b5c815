"""Colon wall material: the incompressible three-parameter Mooney-Rivlin law read from JSON.

The calibration workflow writes a material file (``"law": "mooney_rivlin_3"`` or one of the
other :data:`SOLVER_LAWS`, parameters in Pa); the insertion model reads it here. A reference copy
holding the source's identified parameters ships with the repository
(:data:`REFERENCE_MATERIAL_PATH`).
"""

import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

from colonsim.data import REFERENCE_MATERIAL_PATH
from colonsim.errors import ColonsimError, ColonsimWarning
from colonsim.identification.laws import get_law

LAW = "mooney_rivlin_3"
PARAMETER_NAMES = ("C10", "C01", "C11")
# The calibrated laws the wall model runs. It is the three-parameter Mooney-Rivlin, so a law runs
# when it is a special case of it: the parameters it lacks are zero. ``colonsim calibrate
# --compare-laws`` fits exactly these; a law of another form (yeoh) needs its own wall model first.
SOLVER_LAWS = ("mooney_rivlin_3", "mooney_rivlin_2", "neo_hookean")
# Small-strain shear modulus below which a wall is softer than any soft tissue: the softest
# (brain, fat) are near 1 kPa, the reference colon wall 87 kPa. Below this, parameters were most
# likely given in the wrong unit.
SOFTEST_TISSUE_MU0_PA = 100.0


class SoftWallWarning(ColonsimWarning):
    """A wall material softer than any soft tissue (probably parameters in the wrong unit)."""


def solver_law_gap(law):
    """Why the insertion solver cannot run ``law`` (None when it can)."""
    if law in SOLVER_LAWS:
        return None
    return (f"the insertion solver's wall law is {LAW}; {law} is not a special case of it (the solver runs "
            f"{', '.join(SOLVER_LAWS)})")


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
    """Read a material file of one of the :data:`SOLVER_LAWS`.

    Parameters
    ----------
    path : str or Path
        JSON file with ``"law"`` (e.g. ``"mooney_rivlin_3"``), ``"units": "Pa"`` and
        ``"parameters"`` of that law (``{"C10": .., "C01": .., "C11": ..}``); the Mooney-Rivlin
        parameters a simpler law lacks are zero.

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
    if law not in SOLVER_LAWS:
        raise ColonsimError(
            f"material file {path} has law {law!r}; the insertion solver runs {', '.join(SOLVER_LAWS)}: "
            "recalibrate with one of them."
        )
    names = get_law(law).parameter_names
    units = data.get("units", "Pa")
    if units != "Pa":
        raise ColonsimError(
            f"material file {path} has units {units!r}; parameters must be in 'Pa', "
            "convert them."
        )
    params = data.get("parameters")
    if not isinstance(params, dict):
        raise ColonsimError(
            f"material file {path} lacks a 'parameters' object with {', '.join(names)} in Pa; "
            "fix or regenerate the file."
        )
    missing = [name for name in names if name not in params]
    if missing:
        raise ColonsimError(
            f"material file {path} misses parameter(s) {', '.join(missing)}; "
            f"give {', '.join(names)} in Pa."
        )
    foreign = [name for name in params if name not in names]
    if foreign:
        raise ColonsimError(
            f"material file {path}: parameter(s) {', '.join(foreign)} do not belong to law {law}; "
            f"give only {', '.join(names)} or change the law."
        )
    try:
        material = MooneyRivlin(*(params.get(name, 0.0) for name in PARAMETER_NAMES))
    except ColonsimError as exc:
        raise ColonsimError(f"material file {path}: {exc}") from None
    if material.mu0 < SOFTEST_TISSUE_MU0_PA:
        warnings.warn(f"material file {path}: small-strain shear modulus 2 (C10 + C01) = {material.mu0:.3g} Pa is "
                      f"softer than any soft tissue (the softest, brain and fat, are near 1 kPa); are the parameters "
                      "in Pa?", SoftWallWarning)
    return material
