"""Finite-element model of the clamped tensile specimen (docs/model.md), built on scikit-fem.

The strip is a thin incompressible sheet in plane stress (:mod:`colonsim.identification.membrane`). By
symmetry only a quarter is meshed: ``0 <= X <= L/2`` (X = 0 is the mid-length plane, which does
not move axially when the grips move by -d/2 and +d/2) and ``0 <= Y <= W/2`` (Y = 0 is the
centre line, which does not move laterally). The grip at X = L/2 moves axially by d/2; with
``grips="clamped"`` it cannot contract laterally, with ``grips="sliding"`` it can (which makes
the state homogeneous and reproduces :func:`colonsim.identification.uniaxial.homogeneous_force`).

Why it is fast: scikit-fem supplies the mesh, the quadratic (P2) basis and the quadrature once;
the Newton loop then works on precomputed shape-function gradients with vectorised numpy (the
stress and tangent of every quadrature point in one call) and a precomputed sparse pattern, so
one assembly is a few einsum calls and a ``bincount``. Load steps start from a quadratic
extrapolation of the previous solutions, so Newton needs two or three iterations per step.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu
from skfem import Basis, ElementTriP1, ElementTriP2, MeshTri

from colonsim.errors import ColonsimError
from colonsim.laws import get_wall_law
from colonsim.identification.membrane import membrane_stress


class FEConvergenceError(ColonsimError):
    """Newton failed to converge even with load-step cutting (usually unphysical parameters)."""


class ClampedStripModel:
    """Quarter-symmetric plane-stress FE model of a strip pulled between two grips.

    Parameters
    ----------
    length, width, thickness : float
        Free length between the grips, width and wall thickness of the strip, m.
    law : Law, OgdenLaw or str
        Hyperelastic law (:data:`colonsim.laws.WALL_LAWS`, Ogden's included), default 3-parameter
        Mooney-Rivlin.
    grips : {"clamped", "sliding"}
        Clamped grips forbid lateral motion at the gripped edges (the real test).
    n_length, n_width : int
        Element divisions of the quarter along the length and the half-width. The default 8 x 3
        (P2) is within 0.1 % in force of the mesh-converged value at 60 % strain
        (``benchmarks/bench_calibration.py`` prints the convergence table).
    grading : float
        Ratio of the first to the last element length along X; < 1 refines towards the grip,
        where the clamp perturbs the uniaxial state.
    order : {1, 2}
        Polynomial order of the triangles.
    """

    def __init__(self, length, width, thickness, law="mooney_rivlin_3", grips="clamped",
                 n_length=8, n_width=3, grading=0.35, order=2):
        for name, value in (("length", length), ("width", width), ("thickness", thickness)):
            if not np.isfinite(value) or value <= 0:
                raise ColonsimError(f"specimen {name} must be positive, got {value!r} m")
        if grips not in ("clamped", "sliding"):
            raise ColonsimError(f"grips must be 'clamped' or 'sliding', got {grips!r}")
        self.length, self.width, self.thickness = float(length), float(width), float(thickness)
        self.law = get_wall_law(law) if isinstance(law, str) else law
        self.grips = grips
        self.n_length, self.n_width, self.order = int(n_length), int(n_width), int(order)

        half_l, half_w = 0.5 * self.length, 0.5 * self.width
        # Geometric grading: element lengths shrink towards X = L/2 (the grip).
        ratios = grading ** (np.arange(self.n_length) / max(self.n_length - 1, 1))
        x = np.concatenate([[0.0], np.cumsum(ratios)]) / ratios.sum() * half_l
        y = np.linspace(0.0, half_w, self.n_width + 1)
        self.mesh = MeshTri.init_tensor(x, y)
        element = ElementTriP2() if self.order == 2 else ElementTriP1()
        basis = Basis(self.mesh, element, intorder=4 if self.order == 2 else 2)
        self.n_elements = self.mesh.t.shape[1]

        # Shape-function gradients (nel, nqp, nbf, 2), quadrature weights (nel, nqp), and the
        # strain-displacement matrix B[e, q, 2i + j, 2a + k] = delta_ik dphi_a,j (dF_ij / du_ak).
        self._dphi = np.stack([np.moveaxis(basis.basis[a][0].grad, 0, -1) for a in range(basis.Nbfun)], axis=2)
        self._w = basis.dx
        nel, nqp, nbf, _ = self._dphi.shape
        B = np.zeros((nel, nqp, 2, 2, nbf, 2))
        for i in range(2):
            B[:, :, i, :, :, i] = np.swapaxes(self._dphi, 2, 3)
        self._B = B.reshape(nel, nqp, 4, 2 * nbf)
        self._Bt = np.ascontiguousarray(np.swapaxes(self._B, 2, 3))
        n_scalar = basis.N
        self.n_dofs = 2 * n_scalar
        edofs = basis.element_dofs.T  # (nel, nbf)
        self._edofs = (2 * edofs[:, :, None] + np.arange(2)[None, None, :]).reshape(self.n_elements, -1)

        X, Y = basis.doflocs
        tol = 1e-9 * self.length
        grip = np.isclose(X, half_l, atol=tol)
        mid = np.isclose(X, 0.0, atol=tol)
        centre = np.isclose(Y, 0.0, atol=tol)
        fixed = np.zeros(self.n_dofs, dtype=bool)
        fixed[2 * np.flatnonzero(mid)] = True
        fixed[2 * np.flatnonzero(grip)] = True
        fixed[2 * np.flatnonzero(centre) + 1] = True
        if grips == "clamped":
            fixed[2 * np.flatnonzero(grip) + 1] = True
        self._grip_x = 2 * np.flatnonzero(grip)
        self._fixed = fixed
        self._free = np.flatnonzero(~fixed)
        self._prepare_sparsity()

    def describe(self) -> dict:
        """Model settings for result files."""
        return {"model": "scikit-fem plane-stress incompressible strip, quarter symmetry",
                "law": self.law.name, "grips": self.grips, "element": f"P{self.order} triangles",
                "n_length": self.n_length, "n_width": self.n_width, "n_dofs": self.n_dofs}

    # ------------------------------------------------------------------ assembly
    def _prepare_sparsity(self):
        nd = self._edofs.shape[1]
        rows = np.repeat(self._edofs, nd, axis=1).ravel()
        cols = np.tile(self._edofs, (1, nd)).ravel()
        free_index = -np.ones(self.n_dofs, dtype=np.int64)
        free_index[self._free] = np.arange(self._free.size)
        r, c = free_index[rows], free_index[cols]
        keep = (r >= 0) & (c >= 0)
        nf = self._free.size
        key = r[keep] * nf + c[keep]
        unique, inverse = np.unique(key, return_inverse=True)
        self._keep = keep
        self._inverse = inverse
        self._n_unique = unique.size
        self._csr_indices = (unique % nf).astype(np.int32)
        self._csr_indptr = np.searchsorted(unique // nf, np.arange(nf + 1)).astype(np.int32)

    def _gradient(self, u):
        ue = u[self._edofs].reshape(self.n_elements, -1, 2)  # (nel, nbf, 2)
        H = np.einsum("eai,eqaj->eqij", ue, self._dphi)
        F = H.reshape(*H.shape[:2], 4)
        F[..., 0] += 1.0
        F[..., 3] += 1.0
        return F

    def _residual_tangent(self, u, params, tangent=True):
        """Internal force vector (N, thickness included) and the free-free tangent (CSR)."""
        F = self._gradient(u)
        if np.any(F[..., 0] * F[..., 3] - F[..., 1] * F[..., 2] <= 0.0):
            raise FEConvergenceError("an element inverted during Newton iterations")
        out = membrane_stress(F, self.law, params, tangent=tangent)
        P, A = (out if tangent else (out, None))
        tw = (self.thickness * self._w)[..., None]
        Re = (self._Bt @ (P * tw)[..., None])[..., 0].sum(axis=1)
        R = np.bincount(self._edofs.ravel(), weights=Re.ravel(), minlength=self.n_dofs)
        if not tangent:
            return R, None
        Ke = (self._Bt @ ((A * tw[..., None]) @ self._B)).sum(axis=1).reshape(self.n_elements, -1)
        data = np.bincount(self._inverse, weights=Ke.ravel()[self._keep], minlength=self._n_unique)
        nf = self._free.size
        K = sp.csr_matrix((data, self._csr_indices, self._csr_indptr), shape=(nf, nf))
        return R, K

    # ------------------------------------------------------------------ solution
    def _solve_step(self, u, grip_disp, params, force_scale):
        u = u.copy()
        u[self._grip_x] = grip_disp
        free = self._free
        for _ in range(25):
            R, K = self._residual_tangent(u, params)
            res = R[free]
            du = splu(K.tocsc()).solve(-res)
            u[free] += du
            if np.max(np.abs(du)) < 1e-10 * self.length and np.max(np.abs(res)) < 1e-6 * force_scale:
                # The grip reaction of R is that of the state before this last correction of
                # < 1e-10 L: its error is below 1e-8 of the force scale, so no extra assembly.
                return u, R
        raise FEConvergenceError("Newton did not converge in 25 iterations")

    def solve(self, params, displacements, return_fields=False):
        """Reaction force of the whole strip at each grip displacement.

        Parameters
        ----------
        params : sequence or mapping
            Law parameters in Pa.
        displacements : array_like
            Increasing grip-to-grip displacements, m (the moving grip travels this far).

        Returns
        -------
        forces : ndarray
            Axial reaction force on the moving grip, N (full strip, both symmetry halves).
        fields : list of ndarray, optional
            Quarter-model displacement vectors, one per displacement (``return_fields=True``).
        """
        d = np.asarray(displacements, dtype=float)
        if d.ndim != 1 or np.any(np.diff(d) <= 0) or d[0] < 0:
            raise ColonsimError("displacements must be a non-negative, strictly increasing 1-D array (m)")
        mu0 = self.law.initial_shear_modulus(params)
        if not np.isfinite(mu0) or mu0 <= 0:
            raise FEConvergenceError(f"initial shear modulus {mu0!r} Pa is not positive")
        force_scale = mu0 * self.width * self.thickness
        history = [(0.0, np.zeros(self.n_dofs))]
        forces, fields = [], []
        for target in d:
            u, R = self._advance(history, 0.5 * target, params, force_scale)
            forces.append(2.0 * R[self._grip_x].sum())
            if return_fields:
                fields.append(u.copy())
        forces = np.asarray(forces)
        return (forces, fields) if return_fields else forces

    def _advance(self, history, grip_disp, params, force_scale, depth=0):
        """Reach ``grip_disp`` from the last converged state, cutting the step on failure."""
        s1 = history[-1][0]
        try:
            u, R = self._solve_step(_extrapolate(history, grip_disp), grip_disp, params, force_scale)
        except FEConvergenceError:
            if depth >= 6:
                raise
            self._advance(history, 0.5 * (s1 + grip_disp), params, force_scale, depth + 1)
            u, R = self._solve_step(_extrapolate(history, grip_disp), grip_disp, params, force_scale)
        history.append((grip_disp, u))
        del history[:-3]
        return u, R


def _extrapolate(history, s):
    """Quadratic (Lagrange) extrapolation of the displacement field in the load parameter."""
    pts = history[-3:]
    if len(pts) == 1:
        return pts[0][1].copy()
    guess = np.zeros_like(pts[0][1])
    for i, (si, ui) in enumerate(pts):
        wgt = 1.0
        for j, (sj, _) in enumerate(pts):
            if j != i:
                wgt *= (s - sj) / (si - sj)
        guess += wgt * ui
    return guess
