"""A short movie of one insertion (docs/visualisation.md, "The animation"): the far half of the
colon wall seen from across the model's plane, coloured by its displacement, the scope over it,
the pushed depth and the time, and the push force against the depth growing beside it.

Frames come from the snapshots the run kept (a snapshot interval given to the run) and its final
shape: nothing runs again. Matplotlib draws them (Agg, off screen), Pillow writes the GIF, and an
``ffmpeg`` on the path also writes an MP4. Plotting only, never called from the solver's loop.
"""

from __future__ import annotations

import io
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import TriMesh
from matplotlib.figure import Figure
from matplotlib.tri import Triangulation

from colonsim.errors import ColonsimError, ColonsimWarning
from colonsim.files import atomic_path
from colonsim.insertion.anatomy.manoeuvre import SETTLE
from colonsim.insertion.case.stretch_map import centerline_samples

MAX_FRAMES = 60  # snapshots beyond this are thinned evenly (the first and the last kept)
FRAME_SECONDS = 0.12  # each frame's display time in the GIF
SIZE_IN, DPI = (7.2, 3.2), 90  # 648 x 288 pixels: legible at the width a README shows
GIF, MP4 = "insertion.gif", "insertion.mp4"


def frame_states(result, max_frames=MAX_FRAMES) -> list:
    """(time s, wall positions, scope positions) of the frames: the snapshots, thinned evenly to
    ``max_frames``, and the final shape when the last snapshot is not the end of the run."""
    states = list(result.snapshots)
    end = float(result.timeseries["time_s"].iloc[-1])
    if result.final_shape is not None and (not states or states[-1][0] < end - 1e-9):
        states.append((end, result.final_shape["colon_m"], result.final_shape["scope_m"]))
    if len(states) < 2:
        raise ColonsimError("the animation needs snapshots of the run: run it with a snapshot interval "
                            "(colonsim insert --animate keeps them)")
    keep = np.unique(np.round(np.linspace(0, len(states) - 1, min(max_frames, len(states)))).astype(int))
    return [states[k] for k in keep]


def view_of(rest_nodes, centerline_points):
    """The projection of the movie: the wall's two principal axes span the picture and the third
    points at the viewer; returns the (3, 3) axes and, per node, whether it lies on the far side
    of the centerline (the half of the wall drawn)."""
    from scipy.spatial import cKDTree

    axes = np.linalg.svd(rest_nodes - rest_nodes.mean(axis=0), full_matrices=False)[2]
    nearest = cKDTree(centerline_points).query(rest_nodes)[1]
    far = (rest_nodes - centerline_points[nearest]) @ axes[2] < 0.0
    return axes, far


def _scene(result):
    """What every frame shares: the far triangles in drawing order and the projection."""
    model = result.model
    x0 = np.asarray(model.shell.x0)
    axes, far = view_of(x0, centerline_samples(model.geometry)[1])
    tri = model.shell.triangles[far[model.shell.triangles].all(axis=1)]
    tri = tri[np.argsort((x0[tri] @ axes[2]).mean(axis=1))]  # the deepest drawn first
    return x0, tri, axes[:2].T


def animation_frames(result, max_frames=MAX_FRAMES, title=""):
    """Yield the movie's frames as (height, width, 3) uint8 arrays; ``title`` names the run."""
    x0, tri, plane = _scene(result)
    ts = result.timeseries
    depth_cm, push_N, time = ts["depth_m"].to_numpy() * 100, ts["push_force_N"].to_numpy(), ts["time_s"].to_numpy()
    states = frame_states(result, max_frames)
    top_mm = max(float(ts["deformation_m"].max()) * 1e3, 1.0)

    fig = Figure(figsize=SIZE_IN, dpi=DPI)
    canvas = FigureCanvasAgg(fig)
    left = fig.add_axes((0.01, 0.17, 0.6, 0.72))
    bar_ax = fig.add_axes((0.16, 0.1, 0.3, 0.03))
    right = fig.add_axes((0.72, 0.17, 0.26, 0.68))
    flat = x0 @ plane
    mesh = Triangulation(flat[:, 0].copy(), flat[:, 1].copy(), tri)  # moved in place every frame
    wall = TriMesh(mesh, cmap="viridis")  # one Gouraud-shaded call per frame
    wall.set_array(np.zeros(len(x0)))
    wall.set_clim(0.0, top_mm)
    left.add_collection(wall)
    colour_bar = fig.colorbar(wall, cax=bar_ax, orientation="horizontal")
    colour_bar.set_label("wall displacement [mm]", fontsize=8, labelpad=1)
    colour_bar.ax.tick_params(labelsize=7)
    scope, = left.plot([], [], "-", color="w", lw=4.5, solid_capstyle="round")
    scope_core, = left.plot([], [], "-", color="0.1", lw=2.5, solid_capstyle="round")
    lo, hi = (x0 @ plane).min(axis=0), (x0 @ plane).max(axis=0)
    pad = 0.04 * (hi - lo).max()
    left.set_xlim(lo[0] - pad, hi[0] + pad)
    left.set_ylim(lo[1] - pad, hi[1] + pad)
    left.set_aspect("equal")
    left.set_axis_off()
    label = left.text(0.0, 1.02, "", transform=left.transAxes, fontsize=10, va="bottom")
    right.set_xlim(0.0, max(float(depth_cm.max()), 1.0) * 1.02)
    pushing = push_N[(ts["phase"] != SETTLE).to_numpy()] if (ts["phase"] != SETTLE).any() else push_N
    low, high = min(float(pushing.min()), 0.0), max(float(pushing.max()), 0.1)  # the settle's braking left out
    right.set_ylim(low - 0.05 * (high - low), high + 0.08 * (high - low))
    right.set_title(title, fontsize=9)
    right.set_xlabel("pushed depth [cm]", fontsize=8)
    right.set_ylabel("push force [N]", fontsize=8)
    right.tick_params(labelsize=7)
    curve, = right.plot([], [], color="tab:red", lw=1.2)
    now, = right.plot([], [], "o", color="tab:red", ms=4)
    moving = (wall, scope, scope_core, label, curve, now)
    for artist in moving:  # drawn over a background drawn once (blitting)
        artist.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    for t, wall_x, scope_x in states:
        flat = np.asarray(wall_x) @ plane
        mesh.x[:], mesh.y[:] = flat[:, 0], flat[:, 1]
        wall.set_array(np.linalg.norm(np.asarray(wall_x) - x0, axis=1) * 1e3)
        xy = np.asarray(scope_x) @ plane
        for line in (scope, scope_core):
            line.set_data(xy[:, 0], xy[:, 1])
        k = int(np.searchsorted(time, t - 1e-12))
        k = min(k, len(time) - 1)
        curve.set_data(depth_cm[:k + 1], push_N[:k + 1])
        now.set_data([depth_cm[k]], [push_N[k]])
        label.set_text(f"depth {depth_cm[k]:5.1f} cm    t {t:5.2f} s")
        canvas.restore_region(background)
        for artist in moving:
            artist.axes.draw_artist(artist)
        yield np.asarray(canvas.buffer_rgba())[:, :, :3].copy()


def gif_bytes(frames) -> bytes:
    """The frames as an endlessly looping GIF."""
    from PIL import Image

    # one palette from the first, middle and last frames for all: quantising each frame on its own
    # took ten times longer and wrote a larger file (measured, docs/visualisation.md)
    palette = Image.fromarray(np.concatenate([frames[0], frames[len(frames) // 2], frames[-1]])).quantize(colors=128)
    images = [Image.fromarray(f).quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], loop=0,
                   duration=int(FRAME_SECONDS * 1e3), optimize=True)
    return buffer.getvalue()


def write_animation(result, folder, max_frames=MAX_FRAMES, title="", gif=None) -> dict:
    """Write ``folder/insertion.gif`` (and ``insertion.mp4`` when ``ffmpeg`` is on the path); return
    their paths. ``gif``: the GIF already made (:func:`gif_bytes`, by a sweep's worker), written
    as it is."""
    folder = Path(folder)
    paths = {"animation": folder / GIF}
    frames = None if gif is not None else list(animation_frames(result, max_frames, title))
    with atomic_path(paths["animation"]) as tmp:
        tmp.write_bytes(gif if gif is not None else gif_bytes(frames))
    if frames is None:
        return paths
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is not None:
        movie = write_mp4(ffmpeg, frames, folder / MP4)
        if movie is not None:
            paths["movie"] = movie
    return paths


def write_mp4(ffmpeg, frames, path):
    """Pipe the raw frames through ``ffmpeg`` into an H.264 MP4 at ``path``; return it, or None
    (and a warning) when ffmpeg fails."""
    height, width = frames[0].shape[:2]
    with atomic_path(path) as tmp:
        command = [ffmpeg, "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{width}x{height}",
                   "-r", f"{1.0 / FRAME_SECONDS:g}", "-i", "-", "-pix_fmt", "yuv420p", "-vcodec", "libx264",
                   "-f", "mp4", str(tmp)]
        done = subprocess.run(command, input=b"".join(f.tobytes() for f in frames), capture_output=True)
    if done.returncode != 0:  # the movie is extra: the run's other files are kept
        path.unlink(missing_ok=True)
        said = " ".join(done.stderr.decode(errors="replace").split())[:200]
        warnings.warn(f"ffmpeg could not write {path.name} ({said}); the GIF is written", ColonsimWarning)
        return None
    return path
