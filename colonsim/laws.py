"""Incompressible isotropic hyperelastic laws of the colon wall: one pure energy function per law.

Two kinds. Each invariant law (:data:`LAWS`) maps the invariants ``I1``, ``I2`` of the right
Cauchy-Green tensor (``J = 1``) and its parameter sequence ``p`` (Pa, in the order of
:attr:`Law.parameter_names`) to the strain-energy density ``W`` (J/m^3) and its partial derivatives
``(W, W1, W2, W11, W12, W22)``. Every stress and tangent of such a law is built from these six
numbers: the calibration's uniaxial and membrane models (numpy arrays) and the shell kernels of the
insertion solver, where numba compiles the same functions
(:mod:`colonsim.insertion.engine.shell_membrane`). The functions are plain arithmetic on ``I1 - 3``
and ``I2 - 3`` so that both work unchanged; the physics is in docs/model.md.

Adding an invariant law takes three steps: its function here, its entry in :data:`LAWS` (the next
free ``index``), and its branch in :func:`colonsim.insertion.engine.shell_membrane.law_derivatives`.
The kernels dispatch on the index because a jitted function passed as a kernel argument misses numba's
cache in every new process. tests/test_wall_laws.py checks that every registered law is dispatched
and that the compiled derivatives equal these.

Ogden's law (:data:`OGDEN_LAWS`, 1 to 3 terms) is written in the principal stretches instead, in
Ogden's own convention (1972), the one the calibration fits and the insertion shell runs:
``W = sum_p mu_p / alpha_p (l1^alpha_p + l2^alpha_p + l3^alpha_p - 3)``, parameters
``(mu1, alpha1, mu2, alpha2, ...)`` with ``mu_p`` in Pa and ``alpha_p`` dimensionless, small-strain
shear modulus ``mu0 = 1/2 sum_p mu_p alpha_p``. :func:`ogden` and :func:`ogden_hessian` serve numpy
and numba alike (the calibration's FE strip, the shell's forces and its time step); all
Ogden laws share one kernel index (the kernels read the number of terms from the parameter array).
Other codes write the same law with other constants (:mod:`colonsim.identification.cards`).
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


def ogden(l1, l2, p):
    """Ogden's law with ``len(p) // 2`` terms, ``p = (mu1, alpha1, mu2, alpha2, ...)``, at in-plane
    principal stretches ``l1``, ``l2`` of an incompressible solid (``l3 = 1 / (l1 l2)``).

    Returns ``(W, t1, t2)``: the energy density ``W = sum_p mu_p / alpha_p (l1^a + l2^a + l3^a - 3)``
    (J/m^3) and the principal stress differences ``t_i = sigma_i - sigma_3 = l_i dW/dl_i - l3 dW/dl3
    = sum_p mu_p (l_i^alpha_p - l3^alpha_p)`` (Pa), the stresses of a sheet whose thickness
    (direction 3) is free of traction.
    """
    l3 = 1.0 / (l1 * l2)
    w = 0.0 * l1
    t1 = 0.0 * l1
    t2 = 0.0 * l1
    for k in range(len(p) // 2):
        mu = p[2 * k]
        alpha = p[2 * k + 1]
        w = w + mu / alpha * (l1**alpha + l2**alpha + l3**alpha - 3.0)
        t1 = t1 + mu * (l1**alpha - l3**alpha)
        t2 = t2 + mu * (l2**alpha - l3**alpha)
    return w, t1, t2


def ogden_hessian(l1, l2, p):
    """Second derivatives ``(W_11, W_12, W_22)`` of Ogden's reduced energy W(l1, l2, 1 / (l1 l2))
    in the in-plane stretches (the thickness free of traction); its first derivatives are
    ``W_i = t_i / l_i`` with ``t_i`` of :func:`ogden`:
    ``W_ii = sum_p mu_p ((alpha_p - 1) l_i^(alpha_p - 2) + (alpha_p + 1) l3^alpha_p / l_i^2)``,
    ``W_12 = sum_p mu_p alpha_p l3^alpha_p / (l1 l2)``.
    """
    l3 = 1.0 / (l1 * l2)
    w11 = 0.0 * l1
    w12 = 0.0 * l1
    w22 = 0.0 * l1
    for k in range(len(p) // 2):
        mu = p[2 * k]
        alpha = p[2 * k + 1]
        l3a = l3**alpha
        w11 = w11 + mu * ((alpha - 1.0) * l1 ** (alpha - 2.0) + (alpha + 1.0) * l3a / (l1 * l1))
        w22 = w22 + mu * ((alpha - 1.0) * l2 ** (alpha - 2.0) + (alpha + 1.0) * l3a / (l2 * l2))
        w12 = w12 + mu * alpha * l3a / (l1 * l2)
    return w11, w12, w22


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


@dataclass(frozen=True)
class OgdenLaw:
    """Ogden's law with ``terms`` terms (:func:`ogden`), as :class:`Law` offers an invariant law.

    Attributes
    ----------
    name : str
        ``ogden_1``, ``ogden_2`` or ``ogden_3``.
    terms : int
    index : int
        The kernels' dispatch number, :data:`OGDEN_INDEX` for every number of terms.
    """

    name: str
    terms: int
    index: int

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """``(mu1, alpha1, mu2, alpha2, ...)``: ``mu_p`` in Pa, ``alpha_p`` dimensionless."""
        return tuple(n for i in range(1, self.terms + 1) for n in (f"mu{i}", f"alpha{i}"))

    @property
    def units(self) -> tuple[str, ...]:
        return ("Pa", "1") * self.terms

    def values(self, params) -> tuple[float, ...]:
        """The parameters as floats in :attr:`parameter_names` order, from a sequence or a mapping."""
        if isinstance(params, dict):
            return tuple(float(params[name]) for name in self.parameter_names)
        return tuple(float(v) for v in params)

    def principal(self, l1, l2, params):
        """``(W, t1, t2)`` of :func:`ogden` at in-plane principal stretches ``l1``, ``l2`` (arrays)."""
        return ogden(np.asarray(l1, dtype=float), np.asarray(l2, dtype=float), np.asarray(params, dtype=float))

    def hessian(self, l1, l2, params):
        """``(W_11, W_12, W_22)`` of :func:`ogden_hessian` at ``l1``, ``l2`` (arrays)."""
        return ogden_hessian(np.asarray(l1, dtype=float), np.asarray(l2, dtype=float), np.asarray(params, dtype=float))

    def initial_shear_modulus(self, params) -> float:
        """Small-strain shear modulus mu0 = 1/2 sum_p mu_p alpha_p, Pa."""
        p = np.asarray(self.values(params))
        return float(0.5 * np.sum(p[0::2] * p[1::2]))

    def shear_modulus_gradient(self, params) -> np.ndarray:
        """d mu0 / d params: 1/2 (alpha_p, mu_p) per term."""
        p = np.asarray(self.values(params))
        g = np.empty_like(p)
        g[0::2], g[1::2] = 0.5 * p[1::2], 0.5 * p[0::2]
        return g

    def uniaxial_nominal_stress(self, stretch, params):
        """Nominal stress of incompressible uniaxial tension, Pa: P = sum_p mu_p (l^(a-1) - l^(-a/2-1)),
        i.e. t1 / l at stretches (l, l^-1/2)."""
        l = np.asarray(stretch, dtype=float)
        return self.principal(l, l**-0.5, params)[1] / l


LAWS = {
    law.name: law
    for law in (
        Law("mooney_rivlin_3", 0, mooney_rivlin_3, ("C10", "C01", "C11")),
        Law("mooney_rivlin_2", 1, mooney_rivlin_2, ("C10", "C01")),
        Law("neo_hookean", 2, neo_hookean, ("C10",)),
        Law("yeoh", 3, yeoh, ("C10", "C20", "C30")),
    )
}


DEFAULT_LAW = "mooney_rivlin_3"  # the source's law; what a calibration fits when no law is named

OGDEN_INDEX = 1 + max(law.index for law in LAWS.values())
OGDEN_LAWS = {f"ogden_{n}": OgdenLaw(f"ogden_{n}", n, OGDEN_INDEX) for n in (1, 2, 3)}
# every law the insertion shell runs and a material file may name
WALL_LAWS: dict[str, Law | OgdenLaw] = {**LAWS, **OGDEN_LAWS}


def get_wall_law(name: str) -> Law | OgdenLaw:
    """Look a law of :data:`WALL_LAWS` up by name, with an error listing them."""
    try:
        return WALL_LAWS[name]
    except (KeyError, TypeError):
        raise ColonsimError(f"unknown hyperelastic law {name!r}; use one of {', '.join(WALL_LAWS)}") from None


def get_law(name: str) -> Law:
    """Look a law up by name, with an error listing the known ones."""
    if isinstance(name, str) and name in OGDEN_LAWS:
        raise ColonsimError(f"law {name!r} is fitted through a manifest (--manifest FILE with a mode column, "
                            f"docs/calibration.md); a single curve fits {', '.join(sorted(LAWS))}")
    try:
        return LAWS[name]
    except (KeyError, TypeError):
        raise ColonsimError(
            f"unknown hyperelastic law {name!r}; use one of {', '.join(sorted(LAWS))}"
        ) from None
