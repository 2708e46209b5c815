"""Calibration speed: one FE force-curve evaluation, mesh convergence, the full pipeline.

Run: python benchmarks/bench_calibration.py [--skip-pipeline]

Prints
- the force at 60 mm (60 % strain) of the clamped-strip model for meshes from 4x1 to 48x16
  quarter divisions (P2), with the difference to the finest mesh and the time of one 20-point
  force curve (median of repeated runs after a warm-up);
- the time of one objective evaluation with the calibration default mesh (8 x 3);
- the wall time of the full pipeline (100 designs, CMA-ES 300, Nelder-Mead 300 evaluations) on
  the bundled mean curve, with its result.
Targets of issue 2 on the 2-core machine: one evaluation <= 0.25 s, the pipeline <= 90 s.
"""

import argparse
import statistics
import time

import numpy as np

from colonsim.data import TENSILE_DIR
from colonsim.identification.objective import CurveObjective, make_model
from colonsim.identification.pipeline import Budget, calibrate
from colonsim.identification.specimen import ClampedStripModel
from colonsim.identification.testdata import mean_curve, read_manifest

REFERENCE = np.array([652.01, 42835.25, 219120.3])
MESHES = [(4, 1), (6, 2), (8, 3), (12, 4), (16, 6), (24, 8), (32, 12), (48, 16)]


def median_time(fn, repeat):
    fn()  # warm-up (imports, caches)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def naive_assembly_time(model, params, repeat=5):
    """Baseline: the same residual and tangent assembled the textbook scikit-fem way
    (``LinearForm``/``BilinearForm`` with the constitutive tangent evaluated inside the form
    and contracted by einsum), on the same mesh and state, full dof set."""
    from skfem import Basis, BilinearForm, ElementTriP2, ElementVector, LinearForm, asm

    from colonsim.identification.membrane import membrane_stress

    basis = Basis(model.mesh, ElementVector(ElementTriP2()), intorder=4)
    u = basis.zeros()
    u[basis.nodal_dofs[0]] = 0.3 * basis.doflocs[0, basis.nodal_dofs[0]]  # a stretched state

    def state(w):
        H = w["disp"].grad  # (2, 2, nel, nqp)
        F = np.moveaxis(H, (0, 1), (-2, -1)).reshape(*H.shape[2:], 4).copy()
        F[..., 0] += 1.0
        F[..., 3] += 1.0
        return membrane_stress(F, model.law, params)

    @BilinearForm
    def tangent(du, v, w):
        _, A = state(w)
        gu = np.moveaxis(du.grad, (0, 1), (-2, -1)).reshape(*du.grad.shape[2:], 4)
        gv = np.moveaxis(v.grad, (0, 1), (-2, -1)).reshape(*v.grad.shape[2:], 4)
        return model.thickness * np.einsum("...i,...ij,...j->...", gv, A, gu)

    @LinearForm
    def residual(v, w):
        P, _ = state(w)
        gv = np.moveaxis(v.grad, (0, 1), (-2, -1)).reshape(*v.grad.shape[2:], 4)
        return model.thickness * np.einsum("...i,...i->...", gv, P)

    def run():
        disp = basis.interpolate(u)
        asm(tangent, basis, disp=disp)
        asm(residual, basis, disp=disp)

    return median_time(run, repeat)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-pipeline", action="store_true")
    args = parser.parse_args()

    curve = mean_curve(read_manifest(TENSILE_DIR / "manifest.csv"))
    points = np.linspace(curve.max_displacement / 20, curve.max_displacement, 20)
    print(f"specimen: {curve.length * 1e3:.0f} x {curve.width * 1e3:.0f} x {curve.thickness * 1e3:.3f} mm, "
          f"reference parameters, 20 displacement points up to {points[-1] * 1e3:.2f} mm")
    print(f"{'mesh':>7} {'dofs':>6} {'F(end) [N]':>12} {'vs finest':>10} {'curve [s]':>10}")
    rows = []
    for nl, nw in MESHES:
        model = ClampedStripModel(curve.length, curve.width, curve.thickness, n_length=nl, n_width=nw)
        force = model.solve(REFERENCE, points)[-1]
        t = median_time(lambda: model.solve(REFERENCE, points), repeat=5 if nl <= 16 else 2)
        rows.append((f"{nl}x{nw}", model.n_dofs, force, t))
    finest = rows[-1][2]
    for name, dofs, force, t in rows:
        print(f"{name:>7} {dofs:>6} {force:12.5f} {100 * (force / finest - 1):+9.3f}% {t:10.4f}")

    model = ClampedStripModel(curve.length, curve.width, curve.thickness)
    u = np.zeros(model.n_dofs)
    t_fast = median_time(lambda: model._residual_tangent(u, REFERENCE), repeat=50)
    t_naive = naive_assembly_time(model, REFERENCE)
    print(f"\none residual + tangent assembly, default mesh: {t_fast * 1e3:.2f} ms (batched B-matrix products, "
          f"precomputed CSR pattern) vs {t_naive * 1e3:.1f} ms (textbook scikit-fem forms): {t_naive / t_fast:.0f}x")

    objective = CurveObjective(curve, make_model(curve))
    theta = np.array([2000.0, 40000.0, 200000.0])
    t_eval = median_time(lambda: objective(theta), repeat=30)
    print(f"\none objective evaluation (default mesh {objective.model.n_length}x{objective.model.n_width}, "
          f"20 points): {t_eval:.4f} s   (target <= 0.25 s)")

    if args.skip_pipeline:
        return
    t0 = time.perf_counter()
    r = calibrate(objective, budget=Budget(), seed=1)
    wall = time.perf_counter() - t0
    print(f"full pipeline on the mean curve: {wall:.1f} s wall, {r.fit['evaluations']} evaluations "
          f"({wall / r.fit['evaluations']:.3f} s each incl. optimiser)   (target <= 90 s)")
    print("  stages e1 [N^2]: " + ", ".join(f"{k} {v['e1']:.4g}" for k, v in r.stages.items()))
    print("  parameters [Pa]: " + ", ".join(f"{n} {v:.1f} +- {s:.1f}" for n, v, s in zip(r.names, r.parameters, r.uncertainty.std)))
    print(f"  fit: RMS {r.fit['rms_N']:.4f} N, R^2 {r.fit['r2']:.6f}")


if __name__ == "__main__":
    main()
