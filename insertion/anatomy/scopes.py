"""Colonoscopes of the study (docs/model.md, "Colonoscope"): named scopes or any diameter, as rods.

The scope is a slender linear-elastic cylinder, E = 16 MPa (from the flexural rigidity of a
3-point bending test), density 2944 kg/m^3, Poisson 0.3 (only used to report the shear modulus:
a rod pushed axially without torsion does not need it), with a hemispherical tip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.rod import Rod

SCOPE_YOUNGS_MODULUS = 16e6  # Pa
SCOPE_DENSITY = 2944.0  # kg/m^3
SCOPE_POISSON = 0.3
# Catalogue diameters, as the source's introduction and results name them; "small caliber" = UTC and PDC.
NAMED_SCOPES = {
    "utc": ("ultrathin colonoscope", 9.2e-3),
    "pdc": ("pediatric colonoscope", 11.3e-3),
    "sdc": ("standard colonoscope", 12.8e-3),
}
# The diameters the source's scope meshes had (its runs, and the runs that reproduce them).
MESHED_DIAMETERS = {"utc": 9.2e-3, "pdc": 11.1e-3, "sdc": 13.3e-3}


def scope_role(diameter_mm):
    """``"utc"``, ``"pdc"`` or ``"sdc"`` for a catalogue or source-mesh diameter (mm), else None."""
    for name, (_, catalogue) in NAMED_SCOPES.items():
        if any(abs(diameter_mm - d * 1e3) < 0.05 for d in (catalogue, MESHED_DIAMETERS[name])):
            return name
    return None
# Plausible range of an insertion tube's outer diameter, m: outside it a number is a unit slip.
DIAMETER_RANGE = (3e-3, 20e-3)


@dataclass(frozen=True)
class Colonoscope:
    """An insertion tube: name, outer diameter (m) and material (SI)."""

    name: str
    diameter: float
    youngs_modulus: float = SCOPE_YOUNGS_MODULUS
    density: float = SCOPE_DENSITY
    poisson: float = SCOPE_POISSON

    @property
    def flexural_rigidity(self):
        """EI of the solid circular section, N m^2."""
        return self.youngs_modulus * math.pi * self.diameter**4 / 64.0

    @property
    def wave_speed(self):
        """Axial wave speed sqrt(E / rho), m/s (about 74 m/s)."""
        return math.sqrt(self.youngs_modulus / self.density)

    @property
    def small_caliber(self):
        return self.diameter < NAMED_SCOPES["sdc"][1] - 1e-9

    def check_fits(self, colon_diameter):
        """Raise if the scope cannot pass through a colon of inner diameter ``colon_diameter`` (m)."""
        if self.diameter >= colon_diameter:
            raise ColonsimError(
                f"scope {self.name} ({self.diameter * 1e3:.1f} mm) is as wide as or wider than the colon "
                f"({colon_diameter * 1e3:.1f} mm); choose a thinner scope or a larger --diameter"
            )

    def rod(self, start, direction, length, spacing=5e-3):
        """The scope as a straight :class:`colonsim.insertion.engine.rod.Rod` from ``start`` (proximal end)."""
        return Rod.straight(length, self.diameter, self.youngs_modulus, self.density, spacing=spacing,
                            start=start, direction=direction, name=f"scope {self.name}")

    def describe(self) -> dict:
        return {"name": self.name, "diameter_mm": self.diameter * 1e3, "youngs_modulus_Pa": self.youngs_modulus,
                "density_kg_m3": self.density, "poisson": self.poisson,
                "flexural_rigidity_N_m2": self.flexural_rigidity, "small_caliber": self.small_caliber}


def colonoscope(spec) -> Colonoscope:
    """A scope from a name (``utc``, ``pdc``, ``sdc``, any case) or a diameter in mm (``"10.5"``, 10.5)."""
    key = str(spec).strip().lower()
    if key in NAMED_SCOPES:
        return Colonoscope(key.upper(), NAMED_SCOPES[key][1])
    try:
        d_mm = float(key.removesuffix("mm"))
    except ValueError:
        raise ColonsimError(f"unknown scope {spec!r}; use utc, pdc, sdc or a diameter in mm such as 10.5") from None
    d = d_mm * 1e-3
    if not (np.isfinite(d) and DIAMETER_RANGE[0] <= d <= DIAMETER_RANGE[1]):
        raise ColonsimError(
            f"scope diameter {d_mm!r} mm is outside {DIAMETER_RANGE[0] * 1e3:g}-{DIAMETER_RANGE[1] * 1e3:g} mm; "
            "give the outer diameter in mm"
        )
    return Colonoscope(f"{d_mm:g} mm", d)
