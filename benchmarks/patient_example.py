"""The bundled example anatomy (data/anatomy/sigmoid_loop.csv) and its figure.

``python benchmarks/patient_example.py csv`` writes the CSV: a 3-D rectum, sigmoid loop and start
of the descending colon built from published dimensions (data/README.md, "anatomy/"), sampled
from colonsim's own straight and arc pieces every ~1.5 cm. ``python benchmarks/patient_example.py
figure RUN_FOLDER...`` draws docs/figures/patient_example.png from the folders of
``colonsim insert --centerline data/anatomy/sigmoid_loop.csv --scope utc sdc --out OUT`` (each run
folder's ``final_shape.npz``, ``summary.json`` and ``timeseries.csv``).

Axes of the CSV: x to the patient's left, y anterior, z cranial, in mm, the anal verge at the
origin.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CSV = ROOT / "data" / "anatomy" / "sigmoid_loop.csv"
FIGURE = ROOT / "docs" / "figures" / "patient_example.png"
SPACING = 0.015  # m between the file's points

# (name, label, lumen diameter mm, pieces): lengths in m, angles in degrees, roll in degrees
SEGMENTS = [
    ("rectum", "fixed", 45.0, [("straight", 0.04), ("arc", 0.08, 40.0, 0.0), ("straight", 0.035)]),
    ("sigmoid", "mobile", 40.0, [("arc", 0.05, 60.0, 90.0), ("straight", 0.02), ("arc", 0.045, 150.0, 120.0),
                                 ("straight", 0.01), ("arc", 0.05, 70.0, 240.0)]),
    ("descending", "fixed", 45.0, [("arc", 0.06, 40.0, 180.0), ("straight", 0.08)]),
]
HEADER = """\
# Example anatomy for colonsim (NOT a patient): rectum, sigmoid loop and start of the descending colon.
# Built by benchmarks/patient_example.py from straight and arc pieces; sources and assumptions in
# data/README.md ("anatomy/"). Axes: x to the patient's left, y anterior, z cranial; mm; anal verge at 0.
# rectum {rectum:.0f} cm, fixed: the sigmoid take-off lies 12.6 +- 1.8 cm from the anal verge (MRI, 100 patients,
#   Colorectal Dis. 2018, doi:10.1111/codi.14398); lumen 45 mm (assumption: no rectal diameter found)
# sigmoid {sigmoid:.0f} cm, mobile: about 25 cm long, about 5 cm wide (anatomy texts); descending and sigmoid colon
#   4-5 cm when distended (radiology texts): lumen 40 mm; its 3-D loop shape is an assumption
# descending colon {descending:.0f} cm, fixed, lumen 45 mm (4-5 cm, as above); its length here is an assumption
"""


def build_points():
    from colonsim.insertion.anatomy.centerline import Arc, Centerline, Straight

    pieces = []
    for name, label, _, parts in SEGMENTS:
        for part in parts:
            if part[0] == "straight":
                pieces.append(Straight(part[1], label, name))
            else:
                pieces.append(Arc(part[1], np.radians(part[2]), label, name, roll=np.radians(part[3])))
    # start at the anal verge heading cranially (+z), the first bend posterior (-y)
    c = Centerline(pieces, start=(0.0, 0.0, 0.0), tangent=(0.0, 0.0, 1.0), normal=(0.0, -1.0, 0.0))
    rows = []
    for (name, label, diameter, _), in zip(SEGMENTS):
        s0, s1 = c.bounds(name)
        n = max(2, int(round((s1 - s0) / SPACING)))
        for k, s in enumerate(np.linspace(s0, s1, n + 1)[:-1] if name != SEGMENTS[-1][0] else np.linspace(s0, s1, n + 1)):
            # the diameter at every point: blank cells would be interpolated between the ranges
            rows.append((c.position(s) * 1e3, label if k == 0 else "", diameter, name if k == 0 else ""))
    return c, rows


def write_csv():
    c, rows = build_points()
    lengths = {name: (c.bounds(name)[1] - c.bounds(name)[0]) * 100 for name, *_ in SEGMENTS}
    lines = [HEADER.format(**lengths).rstrip("\n"), "x_mm,y_mm,z_mm,label,diameter_mm,name"]
    for p, label, diameter, name in rows:
        d = "" if diameter is None else f"{diameter:g}"
        lines.append(f"{p[0]:.1f},{p[1]:.1f},{p[2]:.1f},{label},{d},{name}")
    CSV.parent.mkdir(parents=True, exist_ok=True)
    CSV.write_text("\n".join(lines) + "\n")
    print(f"{CSV}: {len(rows)} points, centerline {c.length * 100:.1f} cm "
          f"({', '.join(f'{k} {v:.1f} cm' for k, v in lengths.items())})")


def draw_figure(folders):
    import json

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import pandas as pd

    from colonsim.insertion.case.results import RUN_SERIES, RUN_SUMMARY, read_final_shape
    from colonsim.insertion.case.scenario import InsertionCase, build_insertion

    folders = [Path(f) for f in folders]
    fig, axes = plt.subplots(len(folders), 3, figsize=(13, 4.2 * len(folders)), squeeze=False,
                             gridspec_kw={"width_ratios": [1, 1, 1.3]})
    for row, folder in zip(axes, folders):
        summary = json.loads((folder / RUN_SUMMARY).read_text())
        case = InsertionCase(**summary["inputs"])
        model = build_insertion(case)
        shape = read_final_shape(folder)
        x0, x = model.shell.x0 * 100, shape["colon_m"] * 100
        disp = np.linalg.norm(x - x0, axis=1)
        scope = shape["scope_m"] * 100
        for ax, (i, j, title) in zip(row[:2], ((0, 2, "front view (x left, z cranial)"), (1, 2, "side view (y anterior)"))):
            ax.scatter(x0[:, i], x0[:, j], s=0.5, c="0.85")
            art = ax.scatter(x[:, i], x[:, j], s=1.0, c=disp, cmap="magma_r", vmin=0)
            inside = scope[:, 2] > -2.0
            ax.plot(scope[inside, i], scope[inside, j], "k-", lw=2)
            ax.set_aspect("equal")
            ax.set_xlabel(f"{'xyz'[i]} [cm]")
            ax.set_ylabel(f"{'xyz'[j]} [cm]")
            ax.set_title(f"{summary['scope']['name']}: {title}", fontsize=9)
        fig.colorbar(art, ax=row[1], label="wall displacement [cm]", shrink=0.8)
        ts = pd.read_csv(folder / RUN_SERIES)
        row[2].plot(ts["depth_cm"], ts["deformation_cm"], "k-")
        row[2].set_xlabel("insertion depth [cm]")
        row[2].set_ylabel("colon deformation [cm]")
        row[2].set_title(f"final {summary['final_deformation_cm']:.2f} cm, max {summary['max_deformation_cm']:.2f} cm; "
                         f"ended: {summary['ended_by']}", fontsize=9)
    fig.suptitle("data/anatomy/sigmoid_loop.csv: deformed colon at the end of the push (grey: at rest)", fontsize=10)
    fig.tight_layout()
    FIGURE.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURE, dpi=110)
    print(f"wrote {FIGURE}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["csv"]:
        write_csv()
    elif sys.argv[1:2] == ["figure"] and len(sys.argv) > 2:
        draw_figure(sys.argv[2:])
    else:
        sys.exit(__doc__)
