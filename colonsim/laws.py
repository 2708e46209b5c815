"""Incompressible isotropic hyperelastic laws of the colon wall: one pure energy function per law.

Each law maps the invariants ``I1``, ``I2`` of the right Cauchy-Green tensor (``J = 1``) and its
parameter sequence ``p`` (Pa, in the order of :attr:`Law.parameter_names`) to the strain-energy
density ``W`` (J/m^3) and its partial derivatives ``(W, W1, W2, W11, W12, W22)``. Every stress and
tangent of the project is built from these six numbers: the calibration's uniaxial and membrane
models (numpy arrays) and the shell kernels of the insertion solver, where numba compiles the same
functions (:mod:`colonsim.insertion.engine.shell_membrane`). The functions are plain arithmetic on
``I1 - 3`` and ``I2 - 3`` so that both work unchanged; the physics is in docs/model.md.

Adding a law takes three steps: its function here, its entry in :data:`LAWS` (the next free
``index``), and its branch in :func:`colonsim.insertion.engine.shell_membrane.law_derivatives`. The
kernels dispatch on the index because a jitted function passed as a kernel argument misses numba's
cache in every new process. tests/test_wall_laws.py checks that every registered law is dispatched
and that the compiled derivatives equal these.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple

import numpy as np

from colonsim.errors import ColonsimError


class EnergyDerivatives(NamedTuple):
    """``W`` and its partial derivatives with respect to ``I1`` and ``I2``."""

    W: np.ndarray
    W1: np.ndarray
    W2: np.ndarray
    W11: np.ndarray
    W12: np.ndarray
    W22: np.ndarray


def mooney_rivlin_3(i1, i2, p):
    """Three-parameter Mooney-Rivlin: W = C10 (I1-3) + C01 (I2-3) + C11 (I1-3)(I2-3)."""
    a = i1 - 3.0
    b = i2 - 3.0
    z = 0.0 * a  # a zero of the invariants' shape
    return (p[0] * a + p[1] * b + p[2] * a * b, p[0] + p[2] * b, p[1] + p[2] * a, z, z + p[2], z)


def mooney_rivlin_2(i1, i2, p):
    """Two-parameter Mooney-Rivlin: W = C10 (I1-3) + C01 (I2-3)."""
    a = i1 - 3.0
    b = i2 - 3.0
    z = 0.0 * a
    return (p[0] * a + p[1] * b, z + p[0], z + p[1], z, z, z)


def neo_hookean(i1, i2, p):
    """Neo-Hookean: W = C10 (I1-3), shear modulus 2 C10."""
    a = i1 - 3.0
    z = 0.0 * a
    return (p[0] * a, z + p[0], z, z, z, z)


def yeoh(i1, i2, p):
    """Yeoh: W = C10 (I1-3) + C20 (I1-3)^2 + C30 (I1-3)^3 (no I2 dependence)."""
    a = i1 - 3.0
    z = 0.0 * a
    return (p[0] * a + p[1] * a**2 + p[2] * a**3, p[0] + 2.0 * p[1] * a + 3.0 * p[2] * a**2, z,
            2.0 * p[1] + 6.0 * p[2] * a, z, z)


def uniaxial_invariants(stretch):
    """I1 and I2 of incompressible uniaxial stretch ``l``: I1 = l^2 + 2/l, I2 = 2 l + 1/l^2."""
    l = np.asarray(stretch, dtype=float)
    return l**2 + 2.0 / l, 2.0 * l + 1.0 / l**2


@dataclass(frozen=True)
class Law:
    """A registered hyperelastic law.

    Attributes
    ----------
    name : str
        The name material files and the calibration use.
    index : int
        The law's number in the shell kernels' dispatch.
    energy : callable
        ``energy(i1, i2, p) -> (W, W1, W2, W11, W12, W22)``, one of the functions above.
    parameter_names : tuple of str
        The parameters, all in Pa, in the order ``energy`` reads them.
    """

    name: str
    index: int
    energy: Callable[..., tuple]
    parameter_names: tuple[str, ...]

    def values(self, params) -> tuple[float, ...]:
        """The parameters as floats in :attr:`parameter_names` order, from a sequence or a mapping."""
        if isinstance(params, dict):
            return tuple(float(params[name]) for name in self.parameter_names)
        return tuple(float(v) for v in params)

    def __call__(self, I1, I2, params) -> EnergyDerivatives:
        """Evaluate at invariants ``I1``, ``I2`` (scalars or arrays) with ``params`` (see :meth:`values`)."""
        i1 = np.asarray(I1, dtype=float)
        i2 = np.asarray(I2, dtype=float)
        return EnergyDerivatives(*(np.broadcast_to(d, np.broadcast(i1, i2).shape) * 1.0
                                   for d in self.energy(i1, i2, self.values(params))))

    def initial_shear_modulus(self, params) -> float:
        """Small-strain shear modulus mu0 = 2 (W1 + W2) at the undeformed state, Pa."""
        d = self(3.0, 3.0, params)
        return float(2.0 * (d.W1 + d.W2))

    def uniaxial_nominal_stress(self, stretch, params):
        """Nominal (first Piola) stress of homogeneous incompressible uniaxial tension, Pa.

        P = 2 (l - l^-2) (W1 + W2 / l); for the three-parameter Mooney-Rivlin law this is
        docs/model.md's P = 2 (l - l^-2) [C10 + C11 (I2-3) + (C01 + C11 (I1-3)) / l].
        """
        l = np.asarray(stretch, dtype=float)
        d = self(*uniaxial_invariants(l), params)
        return 2.0 * (l - l**-2) * (d.W1 + d.W2 / l)


LAWS = {
    law.name: law
    for law in (
        Law("mooney_rivlin_3", 0, mooney_rivlin_3, ("C10", "C01", "C11")),
        Law("mooney_rivlin_2", 1, mooney_rivlin_2, ("C10", "C01")),
        Law("neo_hookean", 2, neo_hookean, ("C10",)),
        Law("yeoh", 3, yeoh, ("C10", "C20", "C30")),
    )
}


def get_law(name: str) -> Law:
    """Look a law up by name, with an error listing the known ones."""
    try:
        return LAWS[name]
    except (KeyError, TypeError):
        raise ColonsimError(
            f"unknown hyperelastic law {name!r}; use one of {', '.join(sorted(LAWS))}"
        ) from None
