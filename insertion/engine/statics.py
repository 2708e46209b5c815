"""Static equilibrium by energy minimisation, for verification of the elastic bodies.

Explicit dynamics is the production path; this module finds the equilibrium of a conservative
problem directly (scipy's L-BFGS-B on the free coordinates) so that tests can compare the
kernels with closed-form static solutions without integrating in time.
"""

import numpy as np
from scipy.optimize import minimize

from colonsim.errors import ColonsimError


def minimize_energy(x_start, free, energy_and_forces, force_tol=1e-9, max_iter=20000):
    """Minimise a total potential energy over the free nodal coordinates.

    Parameters
    ----------
    x_start : (n, 3) float array
        Starting positions, m; the fixed coordinates keep these values.
    free : (n, 3) bool array
        True where a coordinate may move.
    energy_and_forces : callable
        ``energy_and_forces(x, f) -> energy``: total potential energy (J) at ``x`` and its
        negative gradient added into the zeroed array ``f`` (n, 3), N.
    force_tol : float
        Convergence when the largest free force component is below this, N.
    max_iter : int

    Returns
    -------
    x : (n, 3) float64
        Equilibrium positions.
    residual : float
        Largest free force component at ``x``, N.

    Raises
    ------
    ColonsimError
        The minimiser stopped before the forces fell below ``force_tol``.
    """
    x = np.array(x_start, dtype=np.float64, order="C")
    free = np.asarray(free, dtype=bool)
    f = np.zeros_like(x)

    def fun(q):
        x[free] = q
        f[:] = 0.0
        energy = energy_and_forces(x, f)
        return energy, -f[free]

    # L-BFGS-B's gradient test is on the projected gradient's max norm: that is force_tol.
    result = minimize(
        fun,
        x[free],
        jac=True,
        method="L-BFGS-B",
        options={"maxiter": max_iter, "maxfun": 2 * max_iter, "gtol": force_tol, "ftol": 0.0, "maxcor": 30},
    )
    x[free] = result.x
    f[:] = 0.0
    energy_and_forces(x, f)
    residual = float(np.max(np.abs(f[free]))) if free.any() else 0.0
    if not residual <= force_tol:
        raise ColonsimError(
            f"static solve did not converge: largest free force {residual:.3g} N > {force_tol:.3g} N "
            f"after {result.nit} iterations ({result.message}); loosen force_tol or raise max_iter."
        )
    return x, residual
