"""What a material card needs beyond the fitted law: material id, density, bulk modulus, deck or
include; each with its range, checked where it is given.

colonsim's fit is incompressible and carries no bulk information, yet every solver needs a bulk
modulus K. The user chooses it as ``K / mu0`` (``--bulk-ratio``) or as the small-strain Poisson's
ratio (``--poisson``); :data:`BULK_RATIO_DEFAULT` when neither is given. Larger ratios follow the
incompressible fit more closely (the volume change is about mu0 / K of the shear strain) and cost
more: an explicit solver's stable step scales with the dilatational wave's transit time,
``h / sqrt((K + 4/3 mu0) / rho)``, and an implicit solver needs mixed (hybrid) elements above
Poisson's ratio 0.495 (K / mu0 about 100).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from colonsim.errors import ColonsimError

DENSITY_DEFAULT = 1040.0  # kg/m^3, the colon wall's (docs/model.md)
# Foams and hydrogels down to 100, filled rubbers up to about 2000; 5000 leaves room for any
# hyperelastic solid. A value in g/cm^3 (0.1-25) is named as such.
DENSITY_RANGE = (100.0, 5000.0)
BULK_RATIO_DEFAULT = 1000.0
# Below 10 (Poisson's ratio 0.45) the card's solid compresses by a tenth of its shear strain and
# no longer follows the incompressible fit; above 1e5 the 10-character field of LS-DYNA's Poisson's
# ratio (0.49999500) no longer resolves the ratio to 1 %.
BULK_RATIO_RANGE = (10.0, 1.0e5)
HYBRID_POISSON = 0.495  # above it, implicit solvers need mixed u-p (hybrid) elements
MATERIAL_ID_RANGE = (1, 99_999_999)  # fits LS-DYNA's 10-character MID field


def poisson_from_bulk_ratio(ratio) -> float:
    """Small-strain Poisson's ratio of a solid with K / mu = ``ratio``."""
    return (3.0 * ratio - 2.0) / (2.0 * (3.0 * ratio + 1.0))


def bulk_ratio_from_poisson(nu) -> float:
    """K / mu of a solid with small-strain Poisson's ratio ``nu`` (< 0.5)."""
    return 2.0 * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu))


def _range_text(low, high, given):
    return f"{given} is outside {low:g}-{high:g}"


def check_density(value) -> float:
    """``value`` (kg/m^3) if it is a density in :data:`DENSITY_RANGE`, else one line naming the fix."""
    low, high = DENSITY_RANGE
    v = float(value)
    if not math.isfinite(v) or v <= 0:
        raise ColonsimError(f"density {value!r} kg/m^3 must be a positive number (tissue and rubber: 900-2000)")
    if 0.1 <= v <= 25 and v < low:
        raise ColonsimError(f"density {v:g} kg/m^3 looks like g/cm^3; give kg/m^3 ({v:g} g/cm^3 = {v * 1000:g} kg/m^3)")
    if not low <= v <= high:
        raise ColonsimError(f"density {_range_text(low, high, f'{v:g}')} kg/m^3 (tissue and rubber: 900-2000)")
    return v


def check_bulk_ratio(ratio, given_as=None) -> float:
    """``ratio`` (K / mu0) if in :data:`BULK_RATIO_RANGE`; ``given_as`` names the option it came from."""
    low, high = BULK_RATIO_RANGE
    r = float(ratio)
    shown = given_as or f"--bulk-ratio {ratio!r}"
    if not math.isfinite(r) or not low <= r <= high:
        raise ColonsimError(f"{shown}: K/mu0 must lie in {low:g}-{high:g} (Poisson's ratio "
                            f"{poisson_from_bulk_ratio(low):.4f}-{poisson_from_bulk_ratio(high):.6f})")
    return r


def check_poisson(nu) -> float:
    """K / mu0 of Poisson's ratio ``nu``, in :data:`BULK_RATIO_RANGE`."""
    v = float(nu)
    if not math.isfinite(v) or not 0.0 < v < 0.5:
        return check_bulk_ratio(math.nan, f"--poisson {nu!r}")
    return check_bulk_ratio(bulk_ratio_from_poisson(v), f"--poisson {v:g}")


def check_material_id(value) -> int:
    low, high = MATERIAL_ID_RANGE
    if isinstance(value, bool) or not isinstance(value, int) or not low <= value <= high:
        raise ColonsimError(f"material id {value!r} must be a whole number in {low}-{high:,}")
    return value


@dataclass(frozen=True)
class CardOptions:
    """How the cards are written.

    Attributes
    ----------
    material_id : int
        LS-DYNA MID, ANSYS material number, FEBio material id, suffix of the Abaqus name.
    density : float
        kg/m^3 (written in tonne/mm^3).
    bulk_ratio : float
        K / mu0.
    bulk_given : str or None
        How the user chose it (``"--bulk-ratio 100"``, ``"--poisson 0.49"``); None: the default.
    deck : bool
        A stand-alone file (LS-DYNA ``*KEYWORD`` ... ``*END``, ANSYS ``/PREP7`` ... ``FINISH``,
        FEBio ``<febio_spec>``) instead of an include.
    """

    material_id: int = 1
    density: float = DENSITY_DEFAULT
    bulk_ratio: float = BULK_RATIO_DEFAULT
    bulk_given: str | None = None
    deck: bool = False

    def __post_init__(self):
        check_material_id(self.material_id)
        check_density(self.density)
        check_bulk_ratio(self.bulk_ratio, self.bulk_given)

    @property
    def poisson(self) -> float:
        return poisson_from_bulk_ratio(self.bulk_ratio)

    @property
    def density_tonne_per_mm3(self) -> float:
        return self.density * 1e-12
