"""Incompressible isotropic hyperelastic laws as pure functions of the invariants.

Each law maps the first and second invariants of the right Cauchy-Green tensor, ``I1`` and
``I2`` (with ``J = 1``), and keyword parameters in Pa to an :class:`EnergyDerivatives` tuple:
the strain-energy density ``W`` (J/m^3) and its first and second partial derivatives. Every
quantity a model needs (uniaxial stress, plane-stress membrane stress and tangent) is built from
these six numbers, so a new law is one small function plus an entry in :data:`LAWS`.

All functions broadcast over numpy arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np


class EnergyDerivatives(NamedTuple):
    """``W`` and its partial derivatives with respect to ``I1`` and ``I2``."""

    W: np.ndarray
    W1: np.ndarray
    W2: np.ndarray
    W11: np.ndarray
    W12: np.ndarray
    W22: np.ndarray


def _zeros_like(a):
    return np.zeros_like(np.asarray(a, dtype=float))


def mooney_rivlin_3(I1, I2, C10, C01, C11):
    """Three-parameter Mooney-Rivlin: W = C10 (I1-3) + C01 (I2-3) + C11 (I1-3)(I2-3)."""
    a = np.asarray(I1, dtype=float) - 3.0
    b = np.asarray(I2, dtype=float) - 3.0
    z = _zeros_like(a)
    return EnergyDerivatives(
        W=C10 * a + C01 * b + C11 * a * b,
        W1=C10 + C11 * b,
        W2=C01 + C11 * a,
        W11=z,
        W12=z + C11,
        W22=z,
    )


def mooney_rivlin_2(I1, I2, C10, C01):
    """Two-parameter Mooney-Rivlin: W = C10 (I1-3) + C01 (I2-3)."""
    return mooney_rivlin_3(I1, I2, C10, C01, 0.0)


def neo_hookean(I1, I2, C10):
    """Neo-Hookean: W = C10 (I1-3), shear modulus 2 C10."""
    return mooney_rivlin_3(I1, I2, C10, 0.0, 0.0)


def yeoh(I1, I2, C10, C20, C30):
    """Yeoh: W = C10 (I1-3) + C20 (I1-3)^2 + C30 (I1-3)^3 (no I2 dependence)."""
    a = np.asarray(I1, dtype=float) - 3.0
    z = _zeros_like(a) + 0.0 * np.asarray(I2, dtype=float)
    return EnergyDerivatives(
        W=C10 * a + C20 * a**2 + C30 * a**3,
        W1=C10 + 2.0 * C20 * a + 3.0 * C30 * a**2,
        W2=z,
        W11=2.0 * C20 + 6.0 * C30 * a,
        W12=z,
        W22=z,
    )


@dataclass(frozen=True)
class Law:
    """A named hyperelastic law: its energy function and parameter names (all in Pa)."""

    name: str
    energy: Callable[..., EnergyDerivatives]
    parameter_names: tuple[str, ...]

    def __call__(self, I1, I2, params) -> EnergyDerivatives:
        """Evaluate with ``params`` a sequence in :attr:`parameter_names` order or a mapping."""
        if isinstance(params, dict):
            return self.energy(I1, I2, **params)
        return self.energy(I1, I2, *params)

    def initial_shear_modulus(self, params) -> float:
        """Small-strain shear modulus mu0 = 2 (W1 + W2) at the undeformed state, Pa."""
        d = self(3.0, 3.0, params)
        return float(2.0 * (d.W1 + d.W2))


LAWS = {
    "mooney_rivlin_3": Law("mooney_rivlin_3", mooney_rivlin_3, ("C10", "C01", "C11")),
    "mooney_rivlin_2": Law("mooney_rivlin_2", mooney_rivlin_2, ("C10", "C01")),
    "neo_hookean": Law("neo_hookean", neo_hookean, ("C10",)),
    "yeoh": Law("yeoh", yeoh, ("C10", "C20", "C30")),
}


def get_law(name: str) -> Law:
    """Look a law up by name, with an error listing the known ones."""
    from colonsim.errors import ColonsimError

    try:
        return LAWS[name]
    except KeyError:
        raise ColonsimError(
            f"unknown hyperelastic law {name!r}; use one of {', '.join(sorted(LAWS))}"
        ) from None
