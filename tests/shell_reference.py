"""Separate membrane and hinge forces of a shell, for tests only.

The solver uses one fused kernel (``Shell.internal_forces``); these element-by-element kernels
compute the two parts apart, so tests can check each against theory and the fused kernel
against their sum. Like the fused kernel, they compile in the membrane of every law (Ogden's
branch included) from shell_membrane.py: after editing that file delete ``tests/__pycache__``.
"""

import numba
import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.engine._scatter import gather, node_incidence
from colonsim.insertion.engine.shell_hinges import hinge_geometry
from colonsim.insertion.engine.shell_membrane import membrane_triangle


@numba.njit(parallel=True, cache=True)
def membrane_kernel(x, tri, dm_inv, area0, thickness, law, params, elem_f):
    """Per-triangle membrane forces into ``elem_f`` (nt, 3, 3); returns (energy J, inverted count)."""
    nt = tri.shape[0]
    energy = 0.0
    n_inverted = 0
    for e in numba.prange(nt):
        w, ok, h1, h2 = membrane_triangle(x, tri, dm_inv, thickness * area0[e], law, params, e)
        if not ok:
            n_inverted += 1
        energy += w
        for k in range(3):
            elem_f[e, 1, k] = h1[k]
            elem_f[e, 2, k] = h2[k]
            elem_f[e, 0, k] = -(h1[k] + h2[k])
    return energy, n_inverted


@numba.njit(parallel=True, cache=True)
def hinge_kernel(x, hinge, stiffness, theta0, elem_f):
    """Per-hinge bending forces into ``elem_f`` (nh, 4, 3); returns (energy J, degenerate count)."""
    nh = hinge.shape[0]
    energy = 0.0
    n_bad = 0
    for h in numba.prange(nh):
        theta, ok = hinge_geometry(x, hinge[h, 0], hinge[h, 1], hinge[h, 2], hinge[h, 3], elem_f, h)
        if ok:
            dth = theta - theta0[h]
            energy += stiffness[h] * dth * dth
            coef = -2.0 * stiffness[h] * dth
        else:
            n_bad += 1
            coef = 0.0
        for a in range(4):
            for k in range(3):
                elem_f[h, a, k] *= coef
    return energy, n_bad


def membrane_forces(shell, x, f):
    """Add the membrane forces of ``shell`` at positions x into f; return the membrane energy, J."""
    buf = np.zeros((len(shell.triangles), 3, 3))
    energy, n_inv = membrane_kernel(x, shell.triangles, shell.dm_inv, shell.area0, shell.thickness, shell._law,
                                    shell._law_params, buf)
    if n_inv:
        raise ColonsimError(f"{n_inv} wall triangle(s) are inverted or collapsed (det C <= 0)")
    gather(buf, *node_incidence(shell.triangles, shell.n_nodes), f)
    return energy


def bending_forces(shell, x, f):
    """Add the hinge forces of ``shell`` at positions x into f; return the bending energy, J."""
    buf = np.zeros((len(shell.hinges), 4, 3))
    energy, n_bad = hinge_kernel(x, shell.hinges, shell.hinge_stiffness, shell.theta0, buf)
    if n_bad:
        raise ColonsimError(f"{n_bad} bending hinge(s) have a collapsed triangle")
    gather(buf, *node_incidence(shell.hinges, shell.n_nodes), f)
    return energy
