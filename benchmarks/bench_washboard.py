"""The wall's washboard: how the colon deformation of an RSJ insertion steps as the scope's tip
slides over the wall's mesh, and what each discretization does to it (docs/model.md, "Time
integration and damping", "What makes the outputs rough").

RSJ, D = 36 mm, mu = 0, the 11.0 mm scope, run at the defaults and with one discretization
changed at a time: the contact on the wall's faces instead of its nodes, scope nodes 2.5 mm apart
instead of 5, wall triangles of 2 mm instead of 3. For each it prints the RMS of the colon
deformation about its moving average over 1 cm of push while the tip goes round the sigmoid
(over 17-24 cm of push, where the deformation falls from A to B), the push distance that RMS
repeats over (:func:`colonsim.insertion.case.outcomes.ringing_wavelength` on the deformation),
the tip's advance over that distance, and the final and largest deformation, and draws the
deformation and the push force against the pushed depth (``--figure``).

Run: ``NUMBA_NUM_THREADS=1 python benchmarks/bench_washboard.py [--variants ...] [--figure FILE]
[--out CSV]`` (about 10 minutes on one core).
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import pandas as pd

from colonsim.insertion.case.insertion_case import InsertionCase
from colonsim.insertion.case.ringing import ringing_ratio, ringing_wavelength
from colonsim.insertion.case.scenario import run_insertion

CASE = {"segment": "rsj", "scope": "11.0", "diameter_mm": 36.0, "friction": 0.0}
VARIANTS = {
    "default": {},
    "faces": {"contact_surface": "faces"},
    "scope nodes 2.5 mm": {"scope_spacing_mm": 2.5},
    "wall 2 mm": {"element_size_mm": 2.0},
}
SPAN_M = (0.17, 0.24)  # pushed depth over which the tip rounds the sigmoid, from A towards B


def washboard(ts):
    """(RMS of the deformation about its 1 cm trend over :data:`SPAN_M`, m; the push distance it
    repeats over, m; the tip's advance per unit push there) of a run's time series: the measures
    of the push force's ringing (:func:`ringing_ratio`, :func:`ringing_wavelength`) taken of the
    deformation."""
    pushing = ts["phase"].to_numpy() != "settle"
    depth = ts["depth_m"].to_numpy()[pushing]
    span = (depth >= SPAN_M[0]) & (depth <= SPAN_M[1])
    depth = depth[span]
    u = ts["deformation_m"].to_numpy()[pushing][span]
    tip = ts["tip_arc_m"].to_numpy()[pushing][span]
    everywhere = np.ones(depth.size, dtype=bool)
    rms = ringing_ratio(depth, u, everywhere)["rms_N"]
    advance = float((tip[-1] - tip[0]) / (depth[-1] - depth[0]))
    return rms, ringing_wavelength(depth, u, everywhere), advance


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    parser.add_argument("--figure", default=None, help="PNG of deformation and push force against depth")
    parser.add_argument("--out", default=None, help="CSV of the table")
    args = parser.parse_args(argv)
    rows, series = [], {}
    for name in args.variants:
        t0 = time.perf_counter()
        result = run_insertion(InsertionCase(**CASE, **VARIANTS[name]))
        ts = result.timeseries
        rms, wavelength, advance = washboard(ts)
        s = result.summary
        rows.append({"variant": name, "washboard_rms_mm": rms * 1e3, "repeats_every_mm": wavelength * 1e3,
                     "tip_advance_per_push": advance, "tip_advance_per_repeat_mm": wavelength * advance * 1e3,
                     "final_cm": s["final_deformation_cm"], "max_cm": s["max_deformation_cm"],
                     "ringing_ratio": s["quasi_static"]["ringing_ratio"], "wall_s": time.perf_counter() - t0})
        series[name] = ts
        r = rows[-1]
        print(f"{name}: deformation rings by {r['washboard_rms_mm']:.4f} mm RMS about its 1 cm average over "
              f"{SPAN_M[0] * 100:g}-{SPAN_M[1] * 100:g} cm of push, every {r['repeats_every_mm']:.2f} mm of push "
              f"({r['tip_advance_per_repeat_mm']:.2f} mm of tip advance); final {r['final_cm']:.4f} cm, largest "
              f"{r['max_cm']:.4f} cm, ringing ratio {r['ringing_ratio']:.3f} ({r['wall_s']:.0f} s)", flush=True)
    if args.out:
        pd.DataFrame(rows).to_csv(args.out, index=False)
        print(f"-> {args.out}")
    if args.figure:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(2, 1, figsize=(10, 7), sharex=True)
        for name, ts in series.items():
            depth = ts["depth_m"] * 100
            keep = depth > 14
            ax[0].plot(depth[keep], ts["deformation_m"][keep] * 100, lw=0.9, label=name)
            ax[1].plot(depth[keep], ts["push_force_N"][keep], lw=0.6, label=name)
        ax[0].set_ylabel("colon deformation [cm]")
        ax[1].set_ylabel("push force [N]")
        ax[1].set_xlabel("pushed depth [cm]")
        ax[0].axvspan(SPAN_M[0] * 100, SPAN_M[1] * 100, color="0.9", zorder=0)
        ax[0].legend(fontsize=8)
        ax[0].set_title("RSJ D36, mu 0, 11.0 mm scope: the deformation steps as the tip slides over the wall")
        fig.tight_layout()
        fig.savefig(args.figure, dpi=110)
        print(f"-> {args.figure}")


if __name__ == "__main__":
    main()
