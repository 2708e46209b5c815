"""Verification of the shell for every wall law: uniaxial tension and inflation in closed form.

Each law of :data:`colonsim.laws.WALL_LAWS` runs in the shell kernels through its own energy
function, so each is checked on the two homogeneous states whose answers follow from the law alone
(docs/model.md): a flat patch in uniaxial tension against the law's nominal stress
P = 2 (l - l^-2) (W1 + W2 / l), for Ogden P = sum mu_p (l^(alpha_p - 1) - l^(-alpha_p/2 - 1)), and a
plane-strain tube section inflated by the thin-wall pressure p(l) = (t / (R l^2)) (sigma_1 - sigma_3)
at the principal stretches (l, 1, 1/l): p(l) = (2 t / R) (1 - l^-4) (W1 + W2) at
I1 = I2 = l^2 + 1 + l^-2 for an invariant law, p(l) = (t / (R l^2)) sum mu_p (l^alpha_p - l^-alpha_p)
for Ogden (derivation in :mod:`colonsim.insertion.study.verification_shell`). The rows, tolerances
and reasons are in :mod:`colonsim.insertion.study.verification_table` (group ``law``).
"""

from __future__ import annotations

import numpy as np

from colonsim.insertion.engine.material import WallMaterial
from colonsim.insertion.engine.sheet_mesh import flat_sheet
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.statics import minimize_energy
from colonsim.insertion.study.verification import WALL_T, Comparison
from colonsim.insertion.study.verification_shell import TUBE_RADIUS, solve_section
from colonsim.laws import WALL_LAWS, OgdenLaw

# One material per law, all near the reference wall's small-strain shear modulus (87 kPa), with
# the stiffening terms large enough to double the stress of the linear part at the checked stretches.
CHECK_MATERIALS = {
    "mooney_rivlin_3": WallMaterial("mooney_rivlin_3", (652.01, 42835.25, 219120.3)),
    "mooney_rivlin_2": WallMaterial("mooney_rivlin_2", (15e3, 28e3)),
    "neo_hookean": WallMaterial("neo_hookean", (43e3,)),
    "yeoh": WallMaterial("yeoh", (43e3, 200e3, 100e3)),
    # Ogden (mu_p Pa, alpha_p): mu0 = 1/2 sum mu_p alpha_p = 45, 36 and 40 kPa; a high exponent
    # stiffens, and the three-term set has a negative exponent with a negative mu_p, as multi-mode
    # fits do (every term has mu_p alpha_p > 0: Drucker stable at every stretch).
    "ogden_1": WallMaterial("ogden_1", (10e3, 9.0)),
    "ogden_2": WallMaterial("ogden_2", (30e3, 2.0, 1e3, 12.0)),
    "ogden_3": WallMaterial("ogden_3", (20e3, 2.0, 2e3, 10.0, -10e3, -2.0)),
}
PATCH = (0.04, 0.02, 5e-3)  # m: length, width and mesh size of the uniaxial patch


def thin_wall_pressure(stretch, material: WallMaterial, radius=TUBE_RADIUS, thickness=WALL_T):
    """Inflation pressure of a thin incompressible tube in plane strain at hoop stretch ``stretch``, Pa."""
    l = np.asarray(stretch, dtype=float)
    law = material.law_model
    if isinstance(law, OgdenLaw):
        return thickness / (radius * l**2) * law.principal(l, 1.0, material.parameters)[1]
    i = l**2 + 1.0 + l**-2
    d = law(i, i, material.parameters)
    return 2.0 * thickness / radius * (1.0 - l**-4) * (d.W1 + d.W2)


def uniaxial_patch(law: str, stretch) -> Comparison:
    """A flat patch of ``law``'s check material stretched by ``stretch`` between grips that hold
    only the axial coordinate.

    The static solve finds the lateral contraction itself; the grip force over the reference
    section W t against the law's nominal stress.
    """
    material = CHECK_MATERIALS[law]
    length, width, h = PATCH
    nodes, tri = flat_sheet(length, width, h)
    shell = Shell(nodes, tri, WALL_T, material)
    grip = np.isclose(nodes[:, 0], length)
    fixed = np.isclose(nodes[:, 0], 0.0)
    free = np.ones(nodes.shape, dtype=bool)
    free[grip | fixed, 0] = False
    free[:, 2] = False  # in-plane: the hinges stay flat and carry nothing
    free[np.argmin(nodes[:, 0] + nodes[:, 1]), 1] = False  # no rigid sliding across
    start = shell.x0 * [stretch, 1.0, 1.0]
    expected = float(material.uniaxial_nominal_stress(stretch))
    x, _ = minimize_energy(start, free, shell.internal_forces, force_tol=1e-7 * expected * width * WALL_T)
    f = np.zeros_like(x)
    shell.internal_forces(x, f)
    measured = -f[grip, 0].sum() / (width * WALL_T)
    return Comparison(f"{material.law}: uniaxial nominal stress {uniaxial_formula(law)} at l = {stretch:g}",
                      expected, float(measured), "Pa")


def uniaxial_formula(law: str) -> str:
    """The closed form of ``law``'s uniaxial nominal stress, as the rows state it."""
    if isinstance(WALL_LAWS[law], OgdenLaw):
        return "sum mu_p (l^(alpha_p - 1) - l^(-alpha_p/2 - 1))"
    return "2 (l - l^-2)(W1 + W2 / l)"


def inflated_section(law: str, stretch, length=0.02) -> Comparison:
    """The periodic tube section of :func:`colonsim.insertion.study.verification_shell.solve_section`
    made of ``law``'s check material under its thin-wall pressure p(l): its mean hoop stretch
    against ``stretch``."""
    material = CHECK_MATERIALS[law]
    r = solve_section(lambda m: thin_wall_pressure(stretch, m), length, material)
    return Comparison(f"{law}: hoop stretch of a plane-strain section at p(l = {stretch:g})", float(stretch),
                      float(r.mean()))
