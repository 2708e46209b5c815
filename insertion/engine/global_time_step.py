"""The largest frequency of the coupled, linearised system by power iteration: the global time-step
estimate (docs/model.md, "Time integration and damping", "The global time-step estimate").

The solver's default step rests on bounds (:meth:`ExplicitSolver.stable_time_step`): each body's
element or exact bound, plus every contact spring's bound on that body added as if it acted where
the body's stiffest mode is. Measured on mid-push states (``benchmarks/bench_time_step.py``), the
coupled system stands 1.3-1.6 times the step those bounds allow. This estimate instead iterates on

    A = M^-1/2 K M^-1/2

over the integrated degrees of freedom: K is the bodies' tangent stiffness (central differences of
their internal forces), plus each contact penalty spring active at the last evaluation (``k n n^T``
between the wall node and the scope's point, along the contact normal) and the sheath lip's
lateral spring, each spring counted as ``k / r^2`` with ``r = sqrt(1 + zeta^2) - zeta`` for its
explicit damping, as the bounds count it. Held wall nodes are left out (their velocity is set,
never integrated); the scope's guided nodes are kept (a subspace can only lower the largest
eigenvalue, so keeping them errs on the safe side). The iteration is warm-started from the last
update's vector, so a few products per update follow the slowly changing top mode; the result is
never taken below the scope's own exact eigenvalue (adding the wall and the springs can only
raise the largest eigenvalue). A power iteration approaches the largest eigenvalue from below:
the solver's safety factor (0.9) and its limit on how fast the step may grow (5 % per update)
are what stand between that and an unstable step, and the divergence guard stops a run that
goes unstable anyway, naming the remedy.
"""

import math

import numpy as np


def _dot(a, b):
    """Sum of the elementwise products, by numpy rather than BLAS (which may start threads of its
    own beside a sweep's worker processes; a few microseconds for a wall's 14,000 numbers)."""
    return float(np.multiply(a, b).sum())


def stiffness_action(body, x, u):
    """K u of ``body``'s internal forces linearised at ``x`` (central differences, a displacement of
    1 nm at the largest component of ``u``), N."""
    peak = float(np.abs(u).max())
    if peak == 0.0:
        return np.zeros_like(x)
    eps = 1e-9 / peak
    fp = np.zeros_like(x)
    fm = np.zeros_like(x)
    body.internal_forces(np.ascontiguousarray(x + eps * u), fp)
    body.internal_forces(np.ascontiguousarray(x - eps * u), fm)
    return -(fp - fm) / (2.0 * eps)


FRESH_SHARE = 1e-3  # norm of the random vector added at each update (the iterate has norm 1)
TINY = 1e-100  # iterate components below this are set to zero


class GlobalTimeStep:
    """Warm-started power iteration for the largest squared frequency of a solver's coupled system.

    Parameters
    ----------
    iterations : int
        Products A v per update once the iteration has settled.
    first_iterations : int
        Products at the first update (from a random vector) and whenever the set of integrated
        wall nodes changes (a release).
    tolerance : float
        An update stops early once the Rayleigh quotient changes by less than this fraction.
    seed : int
        Seed of the starting vector (the estimate, and so the run, is reproducible).
    """

    def __init__(self, iterations=4, first_iterations=60, tolerance=1e-4, seed=0):
        self.iterations = int(iterations)
        self.first_iterations = int(first_iterations)
        self.tolerance = float(tolerance)
        self._rng = np.random.default_rng(seed)
        self._v = None
        self._free_key = None

    def _masks(self, solver):
        """Per body: a (n, 1) array 1 where a node is integrated, 0 where it is held."""
        masks = {}
        for b in solver.bodies:
            s = solver.state[b.name]
            masks[b.name] = (s.fixed == 0).astype(np.float64)[:, None]
        return masks

    def _product(self, solver, v, masks, inv_sqrt_m):
        """A v for the per-body vectors ``v`` (zero on held nodes)."""
        u = {n: v[n] * inv_sqrt_m[n] for n in v}
        ku = {b.name: stiffness_action(b, solver.state[b.name].x, u[b.name]) for b in solver.bodies}
        for c in solver.contacts:
            c.spring_action(solver.state, u, ku)
        return {n: ku[n] * inv_sqrt_m[n] * masks[n] for n in ku}

    def omega2(self, solver, floor=0.0):
        """Largest squared angular frequency of the solver's current linearised system, rad^2/s^2,
        never below ``floor`` (a lower bound known otherwise: the scope's own exact value)."""
        masks = self._masks(solver)
        inv_sqrt_m = {b.name: (1.0 / np.sqrt(b.mass))[:, None] for b in solver.bodies}
        key = tuple(int(m.sum()) for m in masks.values())
        n_it = self.iterations
        if self._v is None or key != self._free_key:
            n_it = self.first_iterations
            if self._v is None:
                self._v = {b.name: self._rng.standard_normal((len(b.x0), 3)) for b in solver.bodies}
        self._free_key = key
        # a little of a fresh random vector each update, so that a mode that has newly become the
        # stiffest (a new contact, a stretched element) is in the start vector, and components
        # decayed towards subnormal numbers (a hundred times slower arithmetic) are replaced
        fresh = {n: self._rng.standard_normal(a.shape) for n, a in self._v.items()}
        scale = FRESH_SHARE / math.sqrt(sum(_dot(a, a) for a in fresh.values()))
        v = {n: (np.where(np.abs(self._v[n]) < TINY, 0.0, self._v[n]) + scale * fresh[n]) * masks[n] for n in self._v}
        norm = math.sqrt(sum(_dot(a, a) for a in v.values()))
        if norm == 0.0:
            return floor
        v = {n: a / norm for n, a in v.items()}
        rq_prev = None
        rq = 0.0
        for _ in range(n_it):
            av = self._product(solver, v, masks, inv_sqrt_m)
            rq = sum(_dot(v[n], av[n]) for n in v)
            norm = math.sqrt(sum(_dot(a, a) for a in av.values()))
            if not norm > 0.0:
                break
            v = {n: a / norm for n, a in av.items()}
            if rq_prev is not None and abs(rq - rq_prev) <= self.tolerance * abs(rq):
                break
            rq_prev = rq
        self._v = v
        return max(rq, floor)
