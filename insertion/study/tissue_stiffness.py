"""The tissue's stiffness as one number: the factor on the reference wall law a material amounts to.

Definition: a wall of stiffness ``s`` is the reference material (``data/material_reference.json``,
the source's three-parameter Mooney-Rivlin law) with every parameter times ``s``, so its strain
energy, and its stress at every stretch, are ``s`` times the reference's; ``s = 1`` is the
reference. A sweep varies it through :attr:`InsertionCase.stiffness_factor`, which scales the
parameters of the case's material.

Mapping rule for any calibrated material (any law of :mod:`colonsim.laws`): ``s`` is the
least-squares factor between the material's nominal stress in uniaxial tension and the
reference's, over the stretches :data:`STRETCHES` (up to the tissue's failure stretch, 1.6, the
range the wall of an insertion lives in)::

    s = sum_i P(l_i) P_ref(l_i) / sum_i P_ref(l_i)^2

A scaled reference maps back to its factor exactly. A material whose curve has another shape
than the reference's keeps its level but not its shape; :func:`shape_mismatch` says how far
(the RMS of the residual over the RMS of its stress), and above :data:`MISMATCH_NOTE` a
prediction says so. The bundled synthetic specimens (``data/tensile/ground_truth.json``) map to
0.76-1.27 with mismatches of 0.1-3.4 %.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from colonsim.catalog import TISSUE_STIFFNESS
from colonsim.laws import OgdenLaw, get_wall_law
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, load_material

STIFFNESS = TISSUE_STIFFNESS  # the results-table column and surrogate input
# the stretches of the rule: 1 (exclusive) to the default failure stretch, in steps of 0.01
STRETCHES = np.round(np.arange(1.01, 1.6 + 1e-9, 0.01), 2)
MISMATCH_NOTE = 0.10  # a curve shape farther than this from the reference's is said


@lru_cache(maxsize=1)
def _reference_stress():
    reference = load_material(REFERENCE_MATERIAL_PATH)
    stress = reference.law_model.uniaxial_nominal_stress(STRETCHES, reference.parameters)
    stress.setflags(write=False)  # shared by every call
    return stress


def uniaxial_stress(law: str, parameters) -> np.ndarray:
    """Nominal uniaxial stress (Pa) of ``law`` at :data:`STRETCHES`, one row per parameter row (n, k).

    A law whose energy is linear in its parameters (every invariant law of :mod:`colonsim.laws`)
    is evaluated once per parameter and combined, checked on the first row: a tissue distribution
    maps its thousand draws in a millisecond instead of a fifth of a second."""
    model = get_wall_law(law)
    rows = np.atleast_2d(np.asarray(parameters, dtype=float))

    def one(row):
        return model.uniaxial_nominal_stress(STRETCHES, tuple(row))

    if len(rows) > 1 and not isinstance(model, OgdenLaw):  # Ogden's exponents are no linear parameters
        basis = np.array([one(unit) for unit in np.eye(rows.shape[1])])  # (p, k): each parameter's stress alone
        if np.allclose(rows[0] @ basis, one(rows[0]), rtol=1e-9, atol=0.0):
            return rows @ basis
    return np.array([one(row) for row in rows])


def stiffness_factor(law: str, parameters) -> np.ndarray:
    """The stiffness factor (n,) of parameter rows ``parameters`` (n, p) in Pa of ``law``."""
    reference = _reference_stress()
    return uniaxial_stress(law, parameters) @ reference / (reference @ reference)


def shape_mismatch(law: str, parameters) -> np.ndarray:
    """How far each material's stress curve is from the reference's shape (n,): the RMS of
    ``P - s P_ref`` over the RMS of ``P`` (0 for a scaled reference)."""
    reference = _reference_stress()
    stress = uniaxial_stress(law, parameters)
    factor = stress @ reference / (reference @ reference)
    residual = stress - factor[:, None] * reference[None, :]
    return np.sqrt(np.mean(residual**2, axis=1)) / np.sqrt(np.mean(stress**2, axis=1))
