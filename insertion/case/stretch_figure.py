"""The wall-stretch map drawn unrolled (docs/visualisation.md): position along the centerline
against angle around it, every wall triangle coloured by its largest stretch over the run.

Plotting only: it reads the arrays of :func:`colonsim.insertion.case.stretch_map.map_arrays` (or a
run folder's ``stretch_map.npz``) and never runs anything.
"""

from __future__ import annotations

import numpy as np
from matplotlib.collections import PolyCollection
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from colonsim.catalog import STRETCHED_WALL_THRESHOLD
from colonsim.insertion.case.stretch_map import area_above

HELD_COLOUR = "0.82"


def unrolled_polygons(arrays):
    """Each triangle's corners in the unrolled plane, (nt, 3, 2): centerline position (cm) and
    angle (deg), the angles of a triangle taken on the side of its first corner (a triangle across
    the seam at +-180 deg reaches past it), and the copies of those triangles shifted by 360 deg so
    the map has no gap at the seam; returns the polygons and, for each, its triangle."""
    tri = arrays["triangles"]
    axial = arrays["axial_m"][tri] * 100.0
    angle = arrays["angle_deg"][tri].astype(float)
    angle[:, 1:] = angle[:, :1] + (angle[:, 1:] - angle[:, :1] + 180.0) % 360.0 - 180.0
    polygons = np.stack([axial, angle], axis=2)
    index = np.arange(len(tri))
    over, under = (angle > 180.0).any(axis=1), (angle < -180.0).any(axis=1)
    shifted = [polygons[over] - [0.0, 360.0], polygons[under] + [0.0, 360.0]]
    return np.concatenate([polygons, *shifted]), np.concatenate([index, index[over], index[under]])


def stretch_map_figure(arrays, threshold=STRETCHED_WALL_THRESHOLD, title="") -> Figure:
    """The unrolled map of the largest stretch over the run, with the held (fixed) wall in grey,
    the flexures shaded and named, the triangles the scope touched dotted, and the threshold
    marked on the colour bar."""
    polygons, owner = unrolled_polygons(arrays)
    stretch = np.asarray(arrays["stretch_max"], dtype=float)[owner]
    held = arrays["held"][owner]
    fig = Figure(figsize=(10, 4.2))
    ax = fig.subplots()
    top = max(float(np.max(stretch)), threshold + 0.02)
    free = PolyCollection(polygons[~held], array=stretch[~held], cmap="inferno", edgecolors="face",
                          linewidths=0.2)
    free.set_clim(1.0, top)
    ax.add_collection(free)
    ax.add_collection(PolyCollection(polygons[held], facecolors=HELD_COLOUR, edgecolors="face", linewidths=0.2))
    bar = fig.colorbar(free, ax=ax, pad=0.01)
    bar.set_label("largest principal stretch over the run")
    bar.ax.axhline(threshold, color="c", lw=2)
    for name, (s0, s1) in zip(arrays["flexure_names"], arrays["flexure_m"]):
        ax.axvspan(s0 * 100, s1 * 100, color="tab:blue", alpha=0.12, lw=0)
        ax.text(0.5 * (s0 + s1) * 100, 176, str(name), ha="center", va="top", fontsize=8, color="tab:blue",
                bbox={"facecolor": "w", "alpha": 0.7, "lw": 0, "pad": 1})
    touched = arrays["touched"]
    if touched.any():
        tri = arrays["triangles"][touched]
        angle = np.degrees(np.angle(np.exp(1j * np.radians(arrays["angle_deg"][tri])).mean(axis=1)))
        ax.plot(arrays["axial_m"][tri].mean(axis=1) * 100, angle, ".", ms=1.5, color="c", alpha=0.6)
    area = area_above(arrays["stretch_max"], arrays["area_m2"], threshold)
    handles = [Patch(color=HELD_COLOUR, label="held (fixed parts, end rings)"),
               Patch(color="c", label=f"touched by the scope; colour bar line: stretch {threshold:g}")]
    if len(arrays["flexure_names"]):
        handles.append(Patch(color="tab:blue", alpha=0.25, label="flexures"))
    ax.legend(handles=handles, loc="lower right", fontsize=7, framealpha=0.85)
    ax.set_xlim(float(arrays["axial_m"].min()) * 100, float(arrays["axial_m"].max()) * 100)
    ax.set_ylim(-180, 180)
    ax.set_yticks(range(-180, 181, 90))
    ax.set_xlabel("position along the centerline [cm]")
    ax.set_ylabel("angle around the centerline [deg]")
    ax.set_title(f"{title}{' - ' if title else ''}largest stretch {np.nanmax(arrays['stretch_max']):.3f}; "
                 f"{area:.1f} cm2 of wall above {threshold:g}", fontsize=10)
    return fig
