"""Generate the bundled SYNTHETIC tensile data set (docs/model.md). Rerun: python -m colonsim.identification.synthetic_data

No public colon tensile data set exists, so the bundled curves are made here:
- 8 specimens whose Mooney-Rivlin parameters scatter (log-normal, 15 % sd) around the source's
  identified parameters (data/material_reference.json), free length 100 mm, width 25 mm,
  thickness drawn uniformly in 1.6-2.4 mm (an assumption: the source does not report it);
- each pulled at 10 mm/min to 60 mm (60 % strain, where the source's specimens tear), sampled
  at 5 Hz with a random start phase (so no two curves share abscissae), displacement rounded to
  1 um and force to 1 mN like a test machine export, with Gaussian load-cell noise of 0.05 N sd;
- forces from the clamped-grip FE model on a mesh 4x finer in each direction than the
  calibration default (so calibrating with the default model is not an inverse crime), solved
  at 121 displacements and interpolated with a cubic spline onto the samples;
- the mean curve: all 8 noisy curves interpolated onto a common 0.25 mm grid and averaged, with
  the mean thickness as its thickness.

The ground truth (per-specimen parameters and thickness, noise level, and the noise-free curves'
RMS deviation of the mean curve) goes to tensile/ground_truth.json beside the data.
"""

from __future__ import annotations

import json

import numpy as np
from scipy.interpolate import CubicSpline

from colonsim.data import data_path
from colonsim.identification.specimen import ClampedStripModel
from colonsim.identification.testdata import TensileCurve, write_curve

HERE = data_path()
OUT = HERE / "tensile"
SEED = 20181
N_SPECIMENS = 8
LENGTH, WIDTH = 0.100, 0.025  # m
THICKNESS_RANGE = (1.6e-3, 2.4e-3)  # m, assumption
RATE = 10e-3 / 60.0  # m/s (10 mm/min)
SAMPLE_HZ = 5.0
MAX_DISPLACEMENT = 0.060  # m
NOISE_SD = 0.05  # N
PARAM_SCATTER = 0.15  # log-normal sd
GENERATOR_MESH = dict(n_length=32, n_width=12)  # 4x the calibration default (8 x 3)
MEAN_GRID_STEP = 0.25e-3  # m


def main():
    rng = np.random.default_rng(SEED)
    reference = json.loads((HERE / "material_reference.json").read_text())["parameters"]
    names = ("C10", "C01", "C11")
    OUT.mkdir(exist_ok=True)
    truth = {"seed": SEED, "noise_sd_N": NOISE_SD, "parameter_scatter_lognormal_sd": PARAM_SCATTER,
             "reference_parameters_Pa": reference, "generator_mesh": GENERATOR_MESH,
             "units": {"parameters": "Pa", "geometry": "mm"}, "specimens": {}}
    manifest = ["specimen,file,length_mm,width_mm,thickness_mm"]
    mean_grid = np.arange(MEAN_GRID_STEP, MAX_DISPLACEMENT + 1e-12, MEAN_GRID_STEP)
    noisy_on_grid, clean_on_grid, thicknesses = [], [], []
    solve_at = np.linspace(0.0, MAX_DISPLACEMENT, 121)[1:]
    for k in range(1, N_SPECIMENS + 1):
        name = f"specimen_{k:02d}"
        params = {n: reference[n] * float(np.exp(PARAM_SCATTER * rng.standard_normal())) for n in names}
        thickness = float(rng.uniform(*THICKNESS_RANGE))
        model = ClampedStripModel(LENGTH, WIDTH, thickness, **GENERATOR_MESH)
        forces = model.solve([params[n] for n in names], solve_at)
        clean = CubicSpline(np.r_[0.0, solve_at], np.r_[0.0, forces])
        t0 = rng.uniform(0.0, 1.0 / SAMPLE_HZ)
        t = np.arange(t0, MAX_DISPLACEMENT / RATE, 1.0 / SAMPLE_HZ)
        d = np.round(RATE * t, 6)
        f = np.round(clean(d) + NOISE_SD * rng.standard_normal(d.size), 3)
        curve = TensileCurve(name, d, f, LENGTH, WIDTH, thickness)
        write_curve(OUT / f"{name}.csv", curve,
                    comment=f"SYNTHETIC colon strip tensile test (colonsim.identification.synthetic_data), {name}")
        manifest.append(f"{name},{name}.csv,{LENGTH * 1e3:.1f},{WIDTH * 1e3:.1f},{thickness * 1e3:.4f}")
        truth["specimens"][name] = {"parameters_Pa": params, "thickness_mm": thickness * 1e3}
        noisy_on_grid.append(np.interp(mean_grid, d, f))
        clean_on_grid.append(clean(mean_grid))
        thicknesses.append(thickness)
        print(f"{name}: t = {thickness * 1e3:.3f} mm, F(60 mm) = {clean(MAX_DISPLACEMENT):.2f} N, {d.size} samples")

    mean_force = np.mean(noisy_on_grid, axis=0)
    mean_clean = np.mean(clean_on_grid, axis=0)
    mean_t = float(np.mean(thicknesses))
    mean_curve = TensileCurve("mean_curve", mean_grid, mean_force, LENGTH, WIDTH, mean_t)
    write_curve(OUT / "mean_curve.csv", mean_curve,
                comment="SYNTHETIC mean of the 8 specimen curves on a 0.25 mm grid (colonsim.identification.synthetic_data)")
    (OUT / "manifest.csv").write_text("\n".join(manifest) + "\n")
    (OUT / "manifest_mean.csv").write_text(
        "specimen,file,length_mm,width_mm,thickness_mm\n"
        f"mean_curve,mean_curve.csv,{LENGTH * 1e3:.1f},{WIDTH * 1e3:.1f},{mean_t * 1e3:.4f}\n")
    (OUT / "manifest_mean_uniaxial.csv").write_text(  # the same curve as a test mode: Ogden's route
        "specimen,file,mode,length_mm,width_mm,thickness_mm\n"
        f"mean_curve,mean_curve.csv,uniaxial,{LENGTH * 1e3:.1f},{WIDTH * 1e3:.1f},{mean_t * 1e3:.4f}\n")
    truth["mean_curve"] = {
        "thickness_mm": mean_t * 1e3,
        "noise_rms_N": float(np.sqrt(np.mean((mean_force - mean_clean) ** 2))),
        "note": "The mean of curves with different parameters and thicknesses is not generated by one "
                "parameter set; judge a fit of it by its force residual against noise_rms_N.",
    }
    (OUT / "ground_truth.json").write_text(json.dumps(truth, indent=2) + "\n")
    print(f"mean curve: thickness {mean_t * 1e3:.3f} mm, noise rms {truth['mean_curve']['noise_rms_N']:.4f} N")


if __name__ == "__main__":
    main()
