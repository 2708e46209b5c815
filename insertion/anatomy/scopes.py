"""Colonoscopes of the study (docs/model.md, "Colonoscope"): named scopes or any diameter, as rods.

The scope is a slender linear-elastic cylinder with a hemispherical tip. The named scopes, their
diameters and the material constants are :data:`colonsim.catalog.NAMED_SCOPES`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from colonsim.catalog import (NAMED_SCOPES, SCOPE_DENSITY, SCOPE_POISSON, SCOPE_YOUNGS_MODULUS, parse_scope,
                              standard_scope)
from colonsim.errors import ColonsimError
from colonsim.insertion.engine.rod import Rod


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
        return self.diameter < standard_scope().diameter - 1e-9

    def check_fits(self, colon_diameter):
        """Raise if the scope cannot pass through a colon of inner diameter ``colon_diameter`` (m)."""
        if self.diameter >= colon_diameter:
            raise ColonsimError(
                f"scope {self.name} ({self.diameter * 1e3:.1f} mm) is as wide as or wider than the colon "
                f"({colon_diameter * 1e3:.1f} mm); choose a thinner scope or a larger --diameter"
            )

    def rod(self, start, direction, length, spacing=5e-3, damping_time=0.0, lateral_damping=0.0):
        """The scope as a straight :class:`colonsim.insertion.engine.rod.Rod` from ``start`` (proximal
        end), with its numerical damping (``damping_time``, s; ``lateral_damping``, 1/s)."""
        return Rod.straight(length, self.diameter, self.youngs_modulus, self.density, spacing=spacing,
                            start=start, direction=direction, name=f"scope {self.name}", damping_time=damping_time,
                            lateral_damping=lateral_damping)

    def describe(self) -> dict:
        return {"name": self.name, "diameter_mm": self.diameter * 1e3, "youngs_modulus_Pa": self.youngs_modulus,
                "density_kg_m3": self.density, "poisson": self.poisson,
                "flexural_rigidity_N_m2": self.flexural_rigidity, "small_caliber": self.small_caliber}


def colonoscope(spec) -> Colonoscope:
    """A scope from a spec :func:`colonsim.catalog.parse_scope` reads: a named scope (``utc``,
    ``pdc``, ``sdc``, any case), with its catalog material, or a diameter in mm (``"10.5"``, 10.5)."""
    name, diameter = parse_scope(spec)
    named = NAMED_SCOPES.get(name.lower())
    if named is None:
        return Colonoscope(name, diameter)
    return Colonoscope(name, diameter, named.youngs_modulus, named.density, named.poisson)
