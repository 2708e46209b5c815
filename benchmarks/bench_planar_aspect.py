"""What a planar (pure-shear) specimen's aspect ratio does to the closed form.

Run: python benchmarks/bench_planar_aspect.py

A planar test pulls a sheet of height h (grip to grip) and width w between clamped grips. The
closed form of pure shear assumes the width never shrinks; near the free side edges it does. The
clamped-strip FE model of the calibration (:class:`colonsim.identification.specimen.ClampedStripModel`,
a strip whose "length" is the height h) gives the real force; this prints it over the closed form
``P_planar(l) w t`` for a neo-Hookean sheet at stretches 1.5 and 2, for w/h from 1 to 20, on two
meshes (the second twice as fine each way) to show the numbers are mesh-converged.
"""

import time

import numpy as np

from colonsim.identification.hyperelastic import calibration_law
from colonsim.identification.specimen import ClampedStripModel

H, T, PARAMS = 0.01, 0.001, [0.2e6]
RATIOS = (1, 2, 4, 10, 20)


def force_ratio(stretch, ratio, refine=1):
    law = calibration_law("neo_hookean")
    w = ratio * H
    model = ClampedStripModel(H, w, T, "neo_hookean", n_length=6 * refine, n_width=max(4, 3 * ratio) * refine)
    force = model.solve(np.array(PARAMS), np.array([(stretch - 1.0) * H]))[-1]
    return force / (law.nominal_stress("planar", stretch, PARAMS) * w * T)


def main():
    law = calibration_law("neo_hookean")
    print("planar specimen of height h, width w, clamped grips, neo-Hookean: FE force / pure-shear closed form")
    for stretch in (1.5, 2.0):
        uni = law.nominal_stress("uniaxial", stretch, PARAMS) / law.nominal_stress("planar", stretch, PARAMS)
        print(f"stretch {stretch}: a free strip (uniaxial) would carry {uni:.3f} of it")
        for ratio in RATIOS:
            t0 = time.perf_counter()
            coarse, fine = force_ratio(stretch, ratio), force_ratio(stretch, ratio, refine=2)
            print(f"  w/h {ratio:>3}: {coarse:.4f} (mesh 2x finer: {fine:.4f}), {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
