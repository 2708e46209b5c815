"""Files of an insertion run: time series CSV (cm, N, J at the edge), summary JSON, figures, VTU.

Layout of a run folder::

    timeseries.csv   time [s], depth [cm], deformation [cm], max wall stretch, tip displacement [cm],
                     contact and push force [N], kinetic/internal energy per body [J], ...
    summary.json     final/max deformation, points A/B/C, peak forces, quasi-static check, inputs
    insertion.png    deformation vs depth, forces, energy ratio, tip displacement
    final_shape.npz  wall and scope node positions at the end of the run, m (``colon_m``, ``scope_m``;
                     read with :func:`read_final_shape`; the rest shape follows from the inputs)
    stretch_map.npz  per wall triangle its largest stretch over the run, at A, C and the end, with
                     the unrolled mesh (:mod:`colonsim.insertion.case.stretch_map`); stretch_map.png
    insertion.gif    the movie of the run with --animate (insertion.mp4 too when ffmpeg is on the path)
    vtu/             colon_NNNN.vtu, scope_NNNN.vtu (+ .pvd collections), colon_stretch.vtu with --vtu
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from colonsim.catalog import STRETCHED_WALL_COLUMN, STRETCHED_WALL_THRESHOLD, TIP_FOLDED
from colonsim.files import atomic_path, save_figure, write_csv, write_json
from colonsim.insertion.case.outcomes import REST_WINDOW
from colonsim.insertion.case.ringing import RINGING_LIMIT
from colonsim.insertion.case.stretch_figure import stretch_map_figure
from colonsim.insertion.case.stretch_map import map_arrays, write_stretch_map, write_stretch_vtu

STRETCH_FIGURE = "stretch_map.png"


def user_units(ts: pd.DataFrame) -> pd.DataFrame:
    """The recorded SI columns in the units people read: cm for lengths."""
    out = pd.DataFrame({"time_s": ts["time_s"], "phase": ts["phase"], "depth_cm": ts["depth_m"] * 100,
                        "deformation_cm": ts["deformation_m"] * 100, "max_wall_stretch": ts["max_stretch"],
                        "tip_displacement_cm": ts["tip_displacement_m"] * 100, "tip_arc_cm": ts["tip_arc_m"] * 100,
                        "tip_past_end_cm": ts["tip_past_end_m"] * 100, "lag_cm": ts["lag_m"] * 100,
                        "tip_heading_deg": ts["tip_heading_deg"],
                        "distal_force_N": ts["distal_force_N"],
                        "contact_force_N": ts["contact_force_N"], "push_force_N": ts["push_force_N"],
                        "contact_nodes": ts["contact_nodes"]})
    for col in ("kinetic_colon_J", "internal_colon_J", "kinetic_scope_J", "kinetic_scope_sliding_J", "internal_scope_J",
                "contact_energy_J",
                "dt_s", "step"):
        out[col] = ts[col]
    return out


def quasi_static_words(qs: dict) -> str:
    """The quasi-static verdict of a summary's ``quasi_static`` section, for the command line."""
    ratio = qs.get("ringing_ratio")
    if ratio is None or not np.isfinite(ratio):
        return "quasi-static check undefined (too little push after the first contact)"
    verdict = "holds" if qs["holds"] else f"does NOT hold ({qs['cause']})"
    snaps = qs.get("snap_throughs") or {}
    left = (f"; {snaps['count']} snap-through(s) at {', '.join(f'{d:.1f}' for d in snaps['depths_cm'])} cm of push, "
            f"{snaps['left_out_share']:.0%} of the push left out" if snaps.get("count") else "")
    return f"ringing ratio {ratio:.3f} (limit {RINGING_LIMIT:g}){left}: quasi-static {verdict}"


def rest_words(rest: dict) -> str:
    """Whether the run came to rest before its final values were read (a summary's ``at_rest``),
    for the command line."""
    if rest["deformation_drift_mm"] is None:
        return f"final values read without coming to rest ({rest['meaning']})"
    if rest["came_to_rest"]:
        return f"came to rest {rest['held_s']:.2f} s after the push stopped"
    return (f"did NOT come to rest in {rest['held_s']:.2f} s: the deformation moved {rest['deformation_drift_mm']:.3f} mm "
            f"and the tip {rest['tip_drift_mm']:.3f} mm over the last {REST_WINDOW:g} s, so the final values are not "
            "settled (raise settle_max_s)")


def relax_words(relax: dict | None) -> str:
    """Whether the relax of RSF/THF came to rest before the final push (a summary's ``relax``;
    None: no relax held until at rest), for the command line."""
    if relax is None:
        return ""
    if relax["came_to_rest"]:
        return f"relaxed to rest {relax['held_s']:.2f} s after the release; "
    drift = relax["deformation_drift_mm"]
    moved = "" if drift is None else f" (the deformation still moved {drift:.3f} mm over {REST_WINDOW:g} s)"
    return f"the relax did NOT come to rest in {relax['held_s']:.2f} s{moved}: the push went on from motion (raise relax_max_s); "


def distal_words(summary: dict) -> str:
    """The distal resistance and the scope's lag of a summary, for the command line."""
    d = summary["distal_resistance"]
    lag = f"scope lag max {summary['max_lag_cm']:.1f} cm, final {summary['final_lag_cm']:.1f} cm"
    back = summary.get("tip_turned_back_cm")
    if summary.get("ended_by") == TIP_FOLDED:
        lag += (f"; the run ENDED at {summary['end']['depth_cm']:.1f} cm of push because the tip folded back on itself "
                "(outside the model: a real tip is steered); its outputs are those up to the fold")
    elif back is not None:
        lag += (f"; the tip TURNED BACK at {back:.1f} cm of push and stayed so: the final deformation and lag "
                "describe a fold of the scope, not a loop behind a held tip")
    if not d["acting"]:
        return f"no distal resistance; {lag}"
    return f"distal resistance {d['resistance_N']:g} N (holding {d['final_force_N']:.1f} N at the end); {lag}"


def comparison_table(results) -> pd.DataFrame:
    """One row of scalar outcomes per run (cm, N), for comparing scopes or cases."""
    return pd.DataFrame([{"segment": r.case.segment, "scope": r.summary["scope"]["name"],
                           "scope_diameter_mm": r.summary["scope"]["diameter_mm"], "colon_diameter_mm": r.case.diameter_mm,
                           "angle_deg": r.case.angle_deg, "flexure_angle_deg": r.case.flexure_angle_deg,
                           "friction": r.case.friction, "distal_resistance_N": r.case.distal_resistance_N,
                           "final_deformation_cm": r.summary["final_deformation_cm"],
                           "max_deformation_cm": r.summary["max_deformation_cm"],
                           **{f"point_{k}_cm": (None if v is None else v["deformation_cm"]) for k, v in r.summary["points_cm"].items()},
                           "peak_contact_force_N": r.summary["peak_contact_force_N"],
                           "peak_push_force_N": r.summary["peak_push_force_N"],
                           "max_wall_stretch": r.summary["max_wall_stretch"],
                           STRETCHED_WALL_COLUMN: r.summary.get(STRETCHED_WALL_COLUMN),
                           "max_lag_cm": r.summary["max_lag_cm"], "final_lag_cm": r.summary["final_lag_cm"],
                           "tip_turned_back_cm": r.summary.get("tip_turned_back_cm"),
                           "ringing_ratio": r.summary["quasi_static"]["ringing_ratio"],
                           "quasi_static": r.summary["quasi_static"]["holds"],
                           "snap_throughs": r.summary["quasi_static"]["snap_throughs"]["count"],
                           "came_to_rest": r.summary["at_rest"]["came_to_rest"],
                           "ended_by": r.summary["ended_by"], "wall_time_s": r.summary["wall_time_s"]}
                          for r in results])


def insertion_figure(results) -> Figure:
    """Deformation, forces, energy ratio and tip displacement of one or several runs."""
    fig = Figure(figsize=(11, 7.5))
    axes = fig.subplots(2, 2)
    for r in results:
        ts = r.timeseries
        label = f"{r.summary['scope']['name']} ({r.case.segment.upper()}, D {r.case.diameter_mm:g} mm, mu {r.case.friction:g})"
        line, = axes[0, 0].plot(ts["time_s"], ts["deformation_m"] * 100, label=label)
        colour = line.get_color()
        axes[0, 1].plot(ts["time_s"], ts["contact_force_N"], c=colour, label=f"{label}: contact")
        axes[0, 1].plot(ts["time_s"], ts["push_force_N"], "--", c=colour, lw=0.6, alpha=0.6, label=f"{label}: push")
        if ts["distal_force_N"].any():
            axes[0, 1].plot(ts["time_s"], ts["distal_force_N"], ":", c=colour, label=f"{label}: distal resistance")
        for body, style in (("colon", "-"), ("scope", ":")):
            # the ratio is meaningless before the body stores strain energy (round-off level)
            internal = ts[f"internal_{body}_J"].where(ts[f"internal_{body}_J"] > 1e-9)
            axes[1, 0].plot(ts["time_s"], ts[f"kinetic_{body}_J"] / internal, style, c=colour, label=f"{label}: {body}")
        axes[1, 1].plot(ts["time_s"], ts["tip_displacement_m"] * 100, c=colour, label=f"{label}: tip displacement")
        axes[1, 1].plot(ts["time_s"], ts["lag_m"] * 100, "--", c=colour, label=f"{label}: scope lag")
        for name, p in r.summary["points_cm"].items():
            if p is not None:
                axes[0, 0].annotate(name, (p["time_s"], p["deformation_cm"]), textcoords="offset points", xytext=(0, 6),
                                    ha="center", fontsize=9)
    axes[0, 0].set_ylabel("colon deformation [cm]")
    axes[0, 1].set_ylabel("force [N]")
    axes[1, 0].set_ylabel("kinetic / internal energy")
    axes[1, 0].axhline(0.1, c="0.5", lw=0.8)
    axes[1, 0].set_yscale("log")
    axes[1, 1].set_ylabel("tip displacement, scope lag [cm]")
    for ax in axes.ravel():
        ax.set_xlabel("time [s]")
        ax.legend(fontsize=7)
    return fig


def _write_vtu(path, points, cells, cell_type):
    import meshio

    with atomic_path(path) as tmp:
        meshio.Mesh(points, [(cell_type, cells)]).write(tmp, file_format="vtu")


def check_vtu_writer():
    """Refuse VTU output when meshio is missing (checked before the runs by the command line)."""
    try:
        import meshio  # noqa: F401
    except ImportError:
        from colonsim.errors import ColonsimError

        raise ColonsimError("VTU output needs meshio: pip install 'colonsim[io]' (or pip install meshio)") from None


def write_vtu_series(result, folder):
    """Deformed colon (triangles) and scope (lines) of every snapshot, with ParaView .pvd indexes."""
    check_vtu_writer()
    folder = Path(folder)
    entries = {"colon": [], "scope": []}
    for k, (t, xc, xs) in enumerate(result.snapshots):
        for name, x, cells, kind in (("colon", xc, result.model.shell.triangles, "triangle"),
                                     ("scope", xs, result.model.rod.segments, "line")):
            file = f"{name}_{k:04d}.vtu"
            _write_vtu(folder / file, x, cells, kind)
            entries[name].append((t, file))
    for name, items in entries.items():
        lines = ['<?xml version="1.0"?>', '<VTKFile type="Collection" version="0.1">', "<Collection>"]
        lines += [f'<DataSet timestep="{t:.6g}" file="{f}"/>' for t, f in items]
        lines += ["</Collection>", "</VTKFile>"]
        with atomic_path(folder / f"{name}.pvd") as tmp:
            tmp.write_text("\n".join(lines) + "\n")


# the files of a run folder, named once: the sweep, its records and the report read them by these names
RUN_SUMMARY, RUN_SERIES, RUN_SHAPE = "summary.json", "timeseries.csv", "final_shape.npz"


def write_insertion(result, out_dir, vtu=False, animate=False, visuals=None) -> dict:
    """Write the files of one run into ``out_dir``; return their paths. A fresh run (one with its
    model) also gets its wall-stretch map (``stretch_map.npz``, ``stretch_map.png``, with ``vtu``
    ``vtu/colon_stretch.vtu``), and with ``animate`` its movie (``insertion.gif``, needs the run's
    snapshots). ``visuals``: the map's arrays and the GIF made where the run ran (a sweep's worker,
    :func:`colonsim.insertion.study.sweep_worker.ok_outcome`), for a result without its model."""
    visuals = visuals or {}
    out = Path(out_dir)
    paths = {"timeseries": out / RUN_SERIES, "summary": out / RUN_SUMMARY, "plot": out / "insertion.png"}
    write_csv(paths["timeseries"], user_units(result.timeseries))
    write_json(paths["summary"], result.summary)
    save_figure(insertion_figure([result]), paths["plot"])
    if getattr(result, "final_shape", None) is not None:
        paths["final_shape"] = out / RUN_SHAPE
        with atomic_path(paths["final_shape"]) as tmp:
            np.savez_compressed(tmp, **result.final_shape)
    stretch = visuals.get("stretch_map") if visuals.get("stretch_map") is not None else map_arrays(result)
    if stretch is not None:
        paths["stretch_map"] = write_stretch_map(stretch, out)
        paths["stretch_figure"] = out / STRETCH_FIGURE
        threshold = result.summary.get("wall_stretch", {}).get("threshold", STRETCHED_WALL_THRESHOLD)
        save_figure(stretch_map_figure(stretch, threshold, run_title(result)), paths["stretch_figure"])
    if vtu:
        write_vtu_series(result, out / "vtu")
        paths["vtu"] = out / "vtu"
        if stretch is not None:
            write_stretch_vtu(stretch, result.model.shell.x0, out / "vtu" / "colon_stretch.vtu")
    if animate or visuals.get("animation") is not None:
        from colonsim.insertion.case.animation import write_animation

        paths.update(write_animation(result, out, title=run_title(result), gif=visuals.get("animation")))
    return paths


def run_title(result) -> str:
    """A run named for figures: model, scope, colon diameter."""
    angle = f" {result.case.angle_deg:g} deg" if result.case.angle_deg else ""
    return f"{result.case.segment.upper()}{angle}, {result.summary['scope']['name']}, D {result.case.diameter_mm:g} mm"


def read_final_shape(out_dir) -> dict:
    """The final wall and scope node positions of a run folder (m), without unpickling anything."""
    with np.load(Path(out_dir) / RUN_SHAPE, allow_pickle=False) as data:
        return {name: data[name] for name in data.files}
