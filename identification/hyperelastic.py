"""Every law the calibration fits, as principal stresses of an incompressible solid, and the
three homogeneous test modes of a thin sheet in closed form.

A law here gives the principal Cauchy stress differences ``t_i = sigma_i - sigma_3`` (i = 1, 2)
at principal stretches ``l1, l2, l3 = 1 / (l1 l2)``: everything else follows from them.

- The invariant laws of :data:`colonsim.laws.LAWS` (the ones the insertion solver runs):
  ``t_i = 2 W1 (li^2 - l3^2) - 2 W2 (li^-2 - l3^-2)`` from their energy derivatives.
- Ogden's law with 1 to 3 terms (:data:`colonsim.laws.OGDEN_LAWS`, which the insertion shell
  runs as well), in Ogden's own convention (1972), defined in :func:`colonsim.laws.ogden`::

      W = sum_p mu_p / alpha_p (l1^alpha_p + l2^alpha_p + l3^alpha_p - 3),  t_i = sum_p mu_p (li^alpha_p - l3^alpha_p)

  with small-strain shear modulus ``mu0 = 1/2 sum_p mu_p alpha_p``; ``mu_p`` in Pa, ``alpha_p``
  dimensionless. Other codes write the same law with other constants
  (:mod:`colonsim.identification.cards`).

The test modes stretch the sheet by ``l`` in direction 1 with the thickness (direction 3)
traction-free, so the nominal (first Piola) stress in direction 1 is ``P = t_1 / l``:

=============  ===============================  ============================================
mode           principal stretches              specimen
=============  ===============================  ============================================
uniaxial       ``l, l^-1/2, l^-1/2``            a long strip, free edges
equibiaxial    ``l, l, l^-2``                   a sheet pulled equally in two directions
planar         ``l, 1, 1/l``                    pure shear: a wide short sheet, width held
=============  ===============================  ============================================

A real planar specimen is only approximately in pure shear: near its free edges the width
contracts, and the force falls short of the closed form by about 0.1 h / w at stretch 1.5 for a
specimen of height h and width w (docs/calibration.md, benchmarks/bench_planar_aspect.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.laws import LAWS, OGDEN_LAWS, Law, OgdenLaw

MODES = ("uniaxial", "equibiaxial", "planar")


def mode_stretches(mode, stretch):
    """Principal stretches (l1, l2, l3) of ``mode`` at stretch ``stretch`` (arrays)."""
    l = np.asarray(stretch, dtype=float)
    if mode == "uniaxial":
        return l, l**-0.5, l**-0.5
    if mode == "equibiaxial":
        return l, l, l**-2.0
    if mode == "planar":
        return l, np.ones_like(l), 1.0 / l
    raise ColonsimError(f"unknown test mode {mode!r}; use one of {', '.join(MODES)}")


@dataclass(frozen=True)
class CalibrationLaw:
    """A law as the calibration sees it: its parameters and its principal stress differences.

    Attributes
    ----------
    name : str
    parameter_names : tuple of str
    units : tuple of str
        ``"Pa"`` or ``"1"`` (dimensionless) per parameter.
    invariant : colonsim.laws.Law or None
        The invariant law behind it; None for Ogden.
    ogden : colonsim.laws.OgdenLaw or None
        The Ogden law behind it; None for an invariant law.
    """

    name: str
    parameter_names: tuple
    units: tuple
    invariant: Law | None = None
    ogden: OgdenLaw | None = None

    @property
    def terms(self) -> int:
        """Ogden terms (0 for an invariant law)."""
        return 0 if self.ogden is None else self.ogden.terms

    def values(self, params) -> np.ndarray:
        if isinstance(params, dict):
            return np.array([float(params[n]) for n in self.parameter_names])
        return np.asarray(params, dtype=float)

    def stress_differences(self, l1, l2, params):
        """(t1, t2) = (sigma_1 - sigma_3, sigma_2 - sigma_3), Pa, at stretches l1, l2 (l3 = 1/(l1 l2))."""
        p = self.values(params)
        l1, l2 = np.asarray(l1, dtype=float), np.asarray(l2, dtype=float)
        l3 = 1.0 / (l1 * l2)
        if self.invariant is not None:
            i1 = l1**2 + l2**2 + l3**2
            i2 = l1**-2 + l2**-2 + l3**-2
            d = self.invariant(i1, i2, p)
            return tuple(2.0 * d.W1 * (li**2 - l3**2) - 2.0 * d.W2 * (li**-2 - l3**-2) for li in (l1, l2))
        return tuple(self.ogden.principal(l1, l2, p)[1:])

    def energy(self, l1, l2, params):
        """Strain-energy density W, J/m^3, at stretches l1, l2 (l3 = 1/(l1 l2))."""
        p = self.values(params)
        l1, l2 = np.asarray(l1, dtype=float), np.asarray(l2, dtype=float)
        l3 = 1.0 / (l1 * l2)
        if self.invariant is not None:
            return self.invariant(l1**2 + l2**2 + l3**2, l1**-2 + l2**-2 + l3**-2, p).W
        return self.ogden.principal(l1, l2, p)[0]

    def nominal_stress(self, mode, stretch, params):
        """Nominal (first Piola) stress along the stretch of ``mode``, Pa: P = (sigma_1 - sigma_3) / l1."""
        l1, l2, _ = mode_stretches(mode, stretch)
        return self.stress_differences(l1, l2, params)[0] / l1

    def initial_shear_modulus(self, params) -> float:
        """Small-strain shear modulus mu0, Pa."""
        p = self.values(params)
        if self.invariant is not None:
            return self.invariant.initial_shear_modulus(p)
        return self.ogden.initial_shear_modulus(p)

    def shear_modulus_gradient(self, params) -> np.ndarray:
        """d mu0 / d params (linear for the invariant laws, 1/2 (alpha_p, mu_p) per Ogden term)."""
        p = self.values(params)
        if self.invariant is not None:
            return np.array([self.invariant.initial_shear_modulus(e) for e in np.eye(p.size)])
        return self.ogden.shear_modulus_gradient(p)


CALIBRATION_LAWS = {
    **{name: CalibrationLaw(name, law.parameter_names, ("Pa",) * len(law.parameter_names), law) for name, law in LAWS.items()},
    **{name: CalibrationLaw(name, law.parameter_names, law.units, ogden=law) for name, law in OGDEN_LAWS.items()},
}


def calibration_law(name) -> CalibrationLaw:
    """Look a law up by name, with an error listing the known ones."""
    try:
        return CALIBRATION_LAWS[name]
    except (KeyError, TypeError):
        raise ColonsimError(f"unknown hyperelastic law {name!r}; use one of {', '.join(CALIBRATION_LAWS)}") from None
