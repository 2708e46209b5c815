"""Drucker stability of a fitted law along the three test paths.

Drucker's condition for an incompressible material: every small change of state does positive
work, ``d sigma : d eps > 0`` with ``eps`` the logarithmic strain. In principal axes with
``eps_3 = -eps_1 - eps_2`` the hydrostatic part drops out and the condition reads: the matrix

    D_ij = d t_i / d eps_j,   t_i = sigma_i - sigma_3,   i, j = 1, 2

is positive definite. For a hyperelastic law ``t_i = dW/d eps_i``, so D is the Hessian of the
energy in logarithmic strains (symmetric); it is evaluated here by central differences of the
law's closed-form stresses (an error ~1e-10 of D, far below any sign change that matters).

Each law is checked along uniaxial, equibiaxial and planar stretching over a stretch range
(default: 0.5 to twice the largest tested stretch); a law that fails is reported with the first
unstable stretch of each path, going outwards from the undeformed state in tension and in
compression, located by bisection.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from colonsim.errors import ColonsimError
from colonsim.identification.hyperelastic import MODES, CalibrationLaw, mode_stretches

# Points of the scan between the undeformed state and each end of the range (log-spaced), and
# the bisection's stretch tolerance.
SCAN_POINTS = 400
ONSET_TOLERANCE = 1e-4
_H = 1e-5  # logarithmic-strain step of the central differences


def drucker_matrix(law: CalibrationLaw, l1, l2, params):
    """D (..., 2, 2) = d(sigma_i - sigma_3)/d eps_j at stretches l1, l2 (symmetrised)."""
    e1, e2 = np.log(np.asarray(l1, dtype=float)), np.log(np.asarray(l2, dtype=float))
    cols = []
    for d1, d2 in ((_H, 0.0), (0.0, _H)):
        plus = law.stress_differences(np.exp(e1 + d1), np.exp(e2 + d2), params)
        minus = law.stress_differences(np.exp(e1 - d1), np.exp(e2 - d2), params)
        cols.append(np.stack([(p - m) / (2 * _H) for p, m in zip(plus, minus)], axis=-1))
    D = np.stack(cols, axis=-1)
    return 0.5 * (D + np.swapaxes(D, -1, -2))


def stable(law: CalibrationLaw, mode, stretch, params):
    """Whether the law is Drucker stable at each stretch of ``mode`` (bool array)."""
    l1, l2, _ = mode_stretches(mode, np.atleast_1d(stretch))
    D = drucker_matrix(law, l1, l2, params)
    return np.linalg.eigvalsh(D)[..., 0] > 0.0


def _onset(law, mode, params, start, end):
    """The first unstable stretch going from ``start`` (stable) towards ``end``, or None."""
    grid = np.geomspace(start, end, SCAN_POINTS)
    ok = stable(law, mode, grid, params)
    bad = np.flatnonzero(~ok)
    if bad.size == 0:
        return None
    i = int(bad[0])
    if i == 0:
        return float(grid[0])
    lo, hi = grid[i - 1], grid[i]
    while abs(hi - lo) > ONSET_TOLERANCE:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(law, mode, mid, params)[0] else (lo, mid)
    return float(hi)


@dataclass(frozen=True)
class StabilityCheck:
    """Where a law loses Drucker stability along each mode within ``stretch_range``."""

    law: str
    stretch_range: tuple
    onsets: dict  # {mode: {"tension": stretch or None, "compression": stretch or None}}

    @property
    def is_stable(self) -> bool:
        return all(v is None for o in self.onsets.values() for v in o.values())

    def first(self):
        """(mode, side, stretch) of the instability nearest the undeformed state (in log strain), tension
        first (the tests stretch; compression along one path is tension along another), or None."""
        found = [(side != "tension", abs(np.log(v)), mode, side, v) for mode, o in self.onsets.items()
                 for side, v in o.items() if v is not None]
        if not found:
            return None
        *_, mode, side, v = min(found)
        return mode, side, v

    def warning(self) -> str | None:
        """One line naming the first unstable stretch and mode, or None when the law is stable."""
        first = self.first()
        if first is None:
            return None
        mode, side, v = first
        others = [f"{m} {s} from {x:.3g}" for m, o in self.onsets.items() for s, x in o.items()
                  if x is not None and (m, s) != (mode, side)]
        also = f" (also {'; '.join(others)})" if others else ""
        return (f"{self.law} is Drucker unstable in {mode} {side} from stretch {v:.3g}{also}, within the checked range "
                f"{self.stretch_range[0]:.3g}-{self.stretch_range[1]:.3g}: predictions beyond it are not physical; fit more "
                "modes jointly or choose a stable law (--compare-laws prefers them)")

    def to_dict(self) -> dict:
        return {"criterion": "Drucker: d sigma : d eps > 0 (Hessian of W in logarithmic strains positive definite)",
                "stretch_range": list(self.stretch_range), "stable": self.is_stable,
                "first_unstable": None if self.first() is None else dict(zip(("mode", "side", "stretch"), self.first())),
                "onsets": self.onsets}


def default_range(max_tested_stretch, reached=None) -> tuple:
    """0.5 to twice the largest tested stretch, widened to ``reached`` (e.g. the insertion's)."""
    hi = 2.0 * float(max_tested_stretch)
    lo = 0.5
    if reached is not None:
        lo, hi = min(lo, reached[0]), max(hi, reached[1])
    return lo, hi


def check_stability(law: CalibrationLaw, params, stretch_range) -> StabilityCheck:
    """Drucker stability of ``law`` at ``params`` along every mode over ``stretch_range`` = (low, high)."""
    lo, hi = (float(v) for v in stretch_range)
    if not (0.0 < lo < 1.0 < hi) or not np.isfinite(hi):
        raise ColonsimError(f"stability range {lo:g}-{hi:g}: it must run from below 1 to above 1 (e.g. 0.5-4)")
    onsets = {mode: {"tension": _onset(law, mode, params, 1.0 + 1e-6, hi),
                     "compression": _onset(law, mode, params, 1.0 - 1e-6, lo)} for mode in MODES}
    return StabilityCheck(law.name, (lo, hi), onsets)
