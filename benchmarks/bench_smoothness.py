"""Is the roughness of the outputs against the scope diameter the model's or the numerics'?
(docs/model.md, "Time integration and damping", "What makes the outputs rough").

Reads sweep folders of the smoothness check's cases (RSJ D36, mu 0, scope 9.0-13.5 mm, each
folder run with other numerical settings: ``benchmarks/sweeps/smoothness.toml``,
``smoothness_faces.toml``, ``smoothness_2mm.toml``) and prints, per folder and output, the
validation report's measure (the largest departure from the least-squares cubic in the
diameter, as a share of the output's range; :func:`validation.smoothness.cubic_departures`) and
the largest deformation against the larger of the cubics of A and C
(:func:`validation.smoothness.larger_of_cubics`: the crease where one overtakes the other, which
no single cubic follows); then, per output, the correlation of the
departures between every two folders. A departure that the numerical settings do not move
(correlation near 1) is the model's own shape; one that changes sign with them is scatter.

Run: ``python benchmarks/bench_smoothness.py DIR [DIR ...]`` (folders of ``colonsim sweep``; the
records unpack to them: ``python -m validation.sweep_records unpack benchmarks/records/NAME DIR``).
"""

from __future__ import annotations

import argparse
import itertools
import sys
from pathlib import Path

import numpy as np

from colonsim.insertion.anatomy.scopes import colonoscope
from colonsim.insertion.study.sweep import read_results

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the validation package beside benchmarks/
from validation.smoothness import CUBIC_OUTPUTS, CUBIC_TOLERANCE, cubic_fit, larger_of_cubics  # noqa: E402


def departures(folder):
    """(diameters, {column: residuals of the cubic}, {column: range}) of a sweep folder's ok runs,
    and the largest deformation's departure from the larger of the cubics of A and C."""
    table = read_results(Path(folder))
    table = table[table["status"] == "ok"]
    d = np.array([colonoscope(s).diameter * 1e3 for s in table["scope"]])
    order = np.argsort(d)
    d = d[order]
    values = {c: table[c].to_numpy(dtype=float)[order] for c, _ in CUBIC_OUTPUTS}
    residuals = {c: cubic_fit(d, y)[1] for c, y in values.items()}
    ranges = {c: float(np.ptp(y)) for c, y in values.items()}
    crease = values["max_deformation_cm"] - larger_of_cubics(d, values["point_A_cm"], values["point_C_cm"])
    return d, residuals, ranges, crease


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("folders", nargs="+")
    args = parser.parse_args(argv)
    runs = {f: departures(f) for f in args.folders}
    for folder, (d, residuals, ranges, crease) in runs.items():
        print(f"{folder} ({len(d)} runs, scopes {d.min():g}-{d.max():g} mm): largest departure from the cubic / range "
              f"(pass under {CUBIC_TOLERANCE:.0%})")
        for column, label in CUBIC_OUTPUTS:
            r = residuals[column]
            print(f"  {label:10s} {100 * np.abs(r).max() / ranges[column]:5.2f} %  ({np.abs(r).max():.4f} cm; RMS "
                  f"{np.sqrt(np.mean(r ** 2)):.4f} cm; range {ranges[column]:.4f} cm)")
        print(f"  max [cm] against the larger of the cubics of A and C: "
              f"{100 * np.abs(crease).max() / ranges['max_deformation_cm']:.2f} %")
    if len(runs) > 1:
        print("correlation of the departures between folders (1: the same shape whatever the numerics)")
        for column, label in CUBIC_OUTPUTS:
            pairs = []
            for a, b in itertools.combinations(runs, 2):
                if np.array_equal(runs[a][0], runs[b][0]):
                    c = np.corrcoef(runs[a][1][column], runs[b][1][column])[0, 1]
                    pairs.append(f"{Path(a).name} / {Path(b).name} {c:+.2f}")
            print(f"  {label:10s} " + ", ".join(pairs))


if __name__ == "__main__":
    main()
