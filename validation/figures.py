"""Figures of the validation report's sweep sections: the RSJ deformation curves against the
source's levels, and the final shapes of RSF / THF runs (one panel per angle)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from colonsim.files import save_figure
from colonsim.insertion.study.reference import SOURCE_RSJ_CM
from colonsim.insertion.case.results import read_final_shape
from colonsim.insertion.case.scenario import insertion_geometry

from .sections import RSJ_DIAMETERS
from .sweeps import SCOPES, role

COLOURS = {"utc": "tab:blue", "pdc": "tab:orange", "sdc": "tab:red", None: "tab:gray"}


def rsj_deformation(curves, path):
    """Deformation against depth of the RSJ runs at mu = 0, points A/B/C and the tip's arrival at
    the sigmoid's fixed end (x) marked, the source's A (dotted) and C (dashed) as horizontal lines
    in the scope's colour."""
    fig = Figure(figsize=(11, 4.3))
    axes = dict(zip(RSJ_DIAMETERS, fig.subplots(1, len(RSJ_DIAMETERS), sharey=True)))
    for d, ax in axes.items():
        for scope in SCOPES:
            src = SOURCE_RSJ_CM[(scope, d)]
            ax.axhline(src["A"], c=COLOURS[scope], ls=":", lw=1)
            ax.axhline(src["C"], c=COLOURS[scope], ls="--", lw=1)
        ax.set_title(f"RSJ, D = {d:g} mm, mu = 0", fontsize=10)
        ax.set_xlabel("insertion depth [cm]")
        ax.grid(alpha=0.3)
    for c in curves:
        ax, colour = axes[c["diameter_mm"]], COLOURS[c["scope_role"]]
        ax.plot(c["depth_cm"], c["deformation_cm"], c=colour, lw=1.4, label=f"{c['scope_role'].upper()} (this model)")
        if c["junction_entry_depth_cm"] is not None:
            ax.plot(c["junction_entry_depth_cm"], c["junction_entry_deformation_cm"], "x", c=colour, ms=7)
        for name, p in c["points"].items():
            ax.plot(p["depth_cm"], p["deformation_cm"], "o", c=colour, ms=5)
            ax.annotate(name, (p["depth_cm"], p["deformation_cm"]), textcoords="offset points", xytext=(0, 5),
                        ha="center", fontsize=8, color=colour)
    axes[RSJ_DIAMETERS[0]].set_ylabel("colon deformation [cm]")
    last = axes[RSJ_DIAMETERS[-1]]
    shown = {}  # one entry per scope drawn in any panel
    for ax in axes.values():
        for handle, label in zip(*ax.get_legend_handles_labels()):
            shown.setdefault(label, handle)
    handles, labels = list(shown.values()), list(shown)
    handles += [Line2D([], [], c="k", ls="", marker="x"), Line2D([], [], c="k", ls=":", lw=1),
                Line2D([], [], c="k", ls="--", lw=1)]
    labels += ["tip reaches the sigmoid's fixed end", "source, point A", "source, point C = final"]
    last.legend(handles, labels, fontsize=7, loc="upper left")
    save_figure(fig, path)


def wall_outline(points, ring_size, rest_axis=None):
    """The tube's outline in the x-y plane: per ring, the two nodes farthest apart across it.

    A ring of the planar models projects onto x-y as a segment across the tube; its direction is
    the ring's principal axis. Returns the two sides, (rings, 2) each, and the axes (rings, 2),
    their signs following ``rest_axis`` (else each ring's neighbour) so the sides do not swap.
    """
    rings = points[:, :2].reshape(-1, ring_size, 2)
    centred = rings - rings.mean(axis=1, keepdims=True)
    _, vectors = np.linalg.eigh(np.einsum("rki,rkj->rij", centred, centred))
    axis = vectors[:, :, -1]  # largest eigenvalue last
    if rest_axis is None:
        for k in range(1, len(axis)):
            if axis[k] @ axis[k - 1] < 0:
                axis[k] = -axis[k]
    else:
        axis = np.where((np.einsum("ri,ri->r", axis, rest_axis) < 0)[:, None], -axis, axis)
    along = np.einsum("rki,ri->rk", centred, axis)
    take = np.arange(len(rings))
    return rings[take, along.argmax(axis=1)], rings[take, along.argmin(axis=1)], axis


def _masked(side, keep):
    out = side.copy()
    out[~keep] = np.nan  # breaks the line where the rings are not shown
    return out


def final_shapes(panels, path, title):
    """One panel per (angle, flexure): the colon's rest outline (grey), the mobile part's rest
    outline (black dashed) and final outline (scope colour), and each scope's final centerline.

    ``panels``: [(panel title, [(case, run folder)])]; returns the runs drawn and those without a
    final shape."""
    fig = Figure(figsize=(4.2 * max(len(panels), 1), 5.6))
    axes = np.atleast_1d(fig.subplots(1, max(len(panels), 1)))
    drawn, missing, shown = [], [], set()
    for ax, (name, runs) in zip(axes, panels):
        rest_drawn = False
        for case, folder in runs:
            g = insertion_geometry(case)  # the run's own colon, its exit lengthened as the run had it
            ring_size = int(g.end_ring.sum()) // 2  # the first and the last ring
            mobile = g.mobile.reshape(-1, ring_size).all(axis=1)
            left, right, axis = wall_outline(g.nodes, ring_size)
            if not rest_drawn:
                for side in (left, right):
                    ax.plot(*(100 * side).T, c="0.75", lw=0.8)
                    ax.plot(*(100 * _masked(side, mobile)).T, c="k", ls="--", lw=0.9, zorder=4)
                rest_drawn = True
            shape = _final_shape(folder, len(g.nodes))
            if shape is None:
                missing.append(case.key())
                continue
            colour = COLOURS[role(case)]
            f_left, f_right, _ = wall_outline(shape["colon_m"], ring_size, rest_axis=axis)
            for side in (f_left, f_right):
                ax.plot(*(100 * _masked(side, mobile)).T, c=colour, lw=1.3)
            ax.plot(*(100 * shape["scope_m"][:, :2]).T, c=colour, lw=1.0, ls="-.")
            drawn.append(case.key())
            shown.add(role(case))
        ax.set_title(name, fontsize=9)
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x [cm]")
        ax.grid(alpha=0.3)
        if rest_drawn:  # the colon's extent: the scope's straight part in the sheath lies outside it
            lo, hi = np.nanmin(100 * g.nodes[:, :2], axis=0) - 2.0, np.nanmax(100 * g.nodes[:, :2], axis=0) + 2.0
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
    axes[0].set_ylabel("y [cm]")
    handles = [Line2D([], [], c="0.75", lw=0.8), Line2D([], [], c="k", ls="--", lw=0.9)]
    labels = ["colon at rest", "mobile part at rest"]
    for scope in [s for s in (*SCOPES, None) if s in shown]:
        handles += [Line2D([], [], c=COLOURS[scope], lw=1.3)]
        labels += [f"{(scope or 'other scope').upper()}: mobile part at the end (scope: dash-dot)"]
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=3)
    fig.suptitle(title, fontsize=10)
    fig.subplots_adjust(bottom=0.2)
    save_figure(fig, path)
    return drawn, missing


def _final_shape(folder, n_nodes):
    """The run's final node positions, or None when the file is absent or is not this mesh."""
    try:
        shape = read_final_shape(folder)
    except (OSError, ValueError, KeyError):
        return None
    return shape if len(shape.get("colon_m", ())) == n_nodes and "scope_m" in shape else None
