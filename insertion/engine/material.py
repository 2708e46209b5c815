"""Colon wall material: an incompressible hyperelastic law of :mod:`colonsim.laws` read from JSON.

The calibration workflow writes a material file (``"law"``: any of :data:`colonsim.laws.WALL_LAWS`,
the invariant laws and Ogden's with 1 to 3 terms; parameters in Pa, Ogden's exponents
dimensionless); the insertion model reads it here and its shell runs that law. A reference copy
holding the source's identified three-parameter Mooney-Rivlin parameters ships with the
repository (:data:`REFERENCE_MATERIAL_PATH`).
"""

import json
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

from colonsim.data import REFERENCE_MATERIAL_PATH
from colonsim.errors import ColonsimError, ColonsimWarning
from colonsim.laws import WALL_LAWS, Law, OgdenLaw, get_wall_law

# Small-strain shear modulus below which a wall is softer than any soft tissue: the softest
# (brain, fat) are near 1 kPa, the reference colon wall 87 kPa. Below this, parameters were most
# likely given in the wrong unit.
SOFTEST_TISSUE_MU0_PA = 100.0


class SoftWallWarning(ColonsimWarning):
    """A wall material softer than any soft tissue (probably parameters in the wrong unit)."""


@dataclass(frozen=True)
class WallMaterial:
    """An incompressible hyperelastic wall material: a registered law and its parameters.

    Parameters
    ----------
    law : str
        Name of the law, one of :data:`colonsim.laws.WALL_LAWS`.
    parameters : sequence of float
        The law's parameters in the order of its ``parameter_names`` (Pa; Ogden's exponents
        dimensionless), all finite, with a positive small-strain shear modulus. An invariant law's
        are non-negative (the strip calibration's bounds); Ogden's ``mu_p`` and ``alpha_p`` take
        either sign (a multi-mode fit's third term has a negative exponent), ``alpha_p`` not 0.
    """

    law: str
    parameters: tuple[float, ...]

    def __post_init__(self):
        model = get_wall_law(self.law)
        names = model.parameter_names
        signed = isinstance(model, OgdenLaw)
        values = tuple(self.parameters)
        if len(values) != len(names):
            raise ColonsimError(f"law {self.law} takes {len(names)} parameter(s) ({', '.join(names)}), got "
                                f"{len(values)}; fix the material parameters.")
        for name, value in zip(names, values):
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise ColonsimError(f"{self.law} parameter {name} must be a number in Pa, got {value!r}; "
                                    "fix the material parameters.")
            if signed and not math.isfinite(value):
                raise ColonsimError(f"{self.law} parameter {name} = {value!r} must be finite; fix the material "
                                    "parameters.")
            if signed and name.startswith("alpha") and value == 0.0:
                raise ColonsimError(f"{self.law} exponent {name} = 0 leaves its term undefined (mu / alpha); fix the "
                                    "material parameters.")
            if not signed and (not math.isfinite(value) or value < 0.0):
                raise ColonsimError(f"{self.law} parameter {name} = {value!r} Pa must be finite and >= 0; "
                                    "fix the material parameters.")
        object.__setattr__(self, "parameters", tuple(float(v) for v in values))
        if not self.mu0 > 0.0:
            raise ColonsimError(f"{self.law} small-strain shear modulus mu0 = {self.mu0!r} Pa must be > 0 (zero "
                                "small-strain stiffness); fix the material parameters.")

    @property
    def law_model(self) -> Law | OgdenLaw:
        """The law's registry entry (energy function, parameter names, kernel index)."""
        return WALL_LAWS[self.law]

    @property
    def named_parameters(self) -> dict:
        """``{name: value}`` in Pa, as a material file holds them."""
        return dict(zip(self.law_model.parameter_names, self.parameters))

    @property
    def mu0(self):
        """Small-strain shear modulus, Pa: 2 (W1 + W2) at rest, 1/2 sum mu_p alpha_p for Ogden."""
        return self.law_model.initial_shear_modulus(self.parameters)

    @property
    def E0(self):
        """Small-strain Young's modulus 3 mu0, Pa (incompressible)."""
        return 3.0 * self.mu0

    def uniaxial_nominal_stress(self, stretch):
        """Homogeneous uniaxial nominal (first Piola) stress at stretch ``stretch``, Pa."""
        return self.law_model.uniaxial_nominal_stress(stretch, self.parameters)


def read_material_document(path) -> dict:
    """The JSON object of a material file (``colonsim calibrate`` output: material.json, or
    population.json), unchecked beyond being one; one-line errors for a missing or broken file."""
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
    return data


def load_material(path):
    """Read a material file of any law of :data:`colonsim.laws.WALL_LAWS`.

    Parameters
    ----------
    path : str or Path
        JSON file with ``"law"`` (e.g. ``"mooney_rivlin_3"``, ``"ogden_3"``), ``"units": "Pa"`` and
        ``"parameters"`` of that law by name (``{"C10": .., "C01": .., "C11": ..}``,
        ``{"mu1": .., "alpha1": .., ...}``).

    Returns
    -------
    WallMaterial

    Raises
    ------
    ColonsimError
        Missing file, invalid JSON, unknown law or units, missing or invalid parameters.
    """
    path = Path(path)
    data = read_material_document(path)
    law = data.get("law")
    if not isinstance(law, str) or law not in WALL_LAWS:
        raise ColonsimError(
            f"material file {path} has law {law!r}; use one of {', '.join(WALL_LAWS)} (the laws the calibration fits)."
        )
    names = WALL_LAWS[law].parameter_names
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
        material = WallMaterial(law, tuple(params[name] for name in names))
    except ColonsimError as exc:
        raise ColonsimError(f"material file {path}: {exc}") from None
    if material.mu0 < SOFTEST_TISSUE_MU0_PA:
        warnings.warn(f"material file {path}: small-strain shear modulus mu0 = {material.mu0:.3g} Pa is "
                      f"softer than any soft tissue (the softest, brain and fat, are near 1 kPa); are the parameters "
                      "in Pa?", SoftWallWarning)
    return material
