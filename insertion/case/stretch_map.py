"""Where the wall is stretched: every wall triangle's largest in-plane principal stretch over the
run, and at points A, C and the end (docs/visualisation.md, "The wall-stretch map").

The recorder measures every triangle at every sample already (its largest value is the
``max_stretch`` column); :class:`WallStretch` keeps, from those same arrays, an element-wise
running maximum, the nodes the scope has touched, and the fields of the samples that can still
turn out to be point A or C (:func:`colonsim.insertion.case.outcomes.characteristic_points`): a
local maximum of the deformation is dropped once a later sample exceeds it (so it is not C) while
it has not stood out on both sides by the prominence A needs (so it is not A). The fields kept at
once are those of the local maxima no later sample has exceeded yet (the wiggles of a falling
deformation) and of the few that stood out. Held triangles (all three nodes fixed) stay at rest:
their stretch is 1.

The summary value (:func:`wall_stretch_summary`) is the wall area (in the rest configuration)
whose largest stretch over the run passed a threshold, by default
:data:`colonsim.catalog.STRETCHED_WALL_THRESHOLD` (**assumption**, docs/visualisation.md).

Files: ``stretch_map.npz`` (:func:`write_stretch_map`, read by :func:`read_stretch_map`) and,
with VTU output, ``vtu/colon_stretch.vtu`` (the rest mesh with the fields as cell data).
"""

from __future__ import annotations

import inspect
import math
from pathlib import Path

import numpy as np

from colonsim.catalog import STRETCHED_WALL_COLUMN, STRETCHED_WALL_THRESHOLD, STRETCHED_WALL_THRESHOLD_RANGE
from colonsim.errors import ColonsimError
from colonsim.files import atomic_path
from colonsim.insertion.case.outcomes import characteristic_points, mark_loaded

STRETCH_MAP = "stretch_map.npz"  # the map's file in a run folder
# the prominence a maximum needs to be point A, as characteristic_points judges it
PROMINENCE = inspect.signature(characteristic_points).parameters["prominence"].default
FIELDS = ("max", "A", "C", "end")  # the stretch fields of a map: over the run, at A, at C, at the end


class WallStretch:
    """Per-triangle stretch record of one run, fed by the recorder at every sample.

    Parameters
    ----------
    triangles : (nt, 3) int array
        The wall's triangles.
    dm_inv : (nt, 2, 2) array
        Their inverse reference edge matrices (:attr:`colonsim.insertion.engine.shell.Shell.dm_inv`).
    held : (n,) bool array
        Nodes held in place: triangles with three held nodes are not measured (stretch 1).
    """

    def __init__(self, triangles, dm_inv, held):
        moving = ~np.asarray(held, dtype=bool)[triangles].all(axis=1)
        self.n_triangles = len(triangles)
        self.measured = np.flatnonzero(moving) if moving.any() else np.array([0])
        self.triangles = np.ascontiguousarray(triangles[self.measured])
        self.dm_inv = np.ascontiguousarray(dm_inv[self.measured])
        self.touched = np.zeros(int(triangles.max()) + 1, dtype=bool)  # wall nodes the scope has pushed
        self.largest = None  # running element-wise maximum over the measured triangles
        self.last = None
        self._count = 0
        self._deformation = []
        self._previous = None  # (deformation, field) of the last sample
        self._candidates = {}  # sample index -> [deformation, lowest since, field, drop from the left base]
        self._highest = 0.0
        self._stack = []  # [deformation, lowest after it] of the samples no later one exceeded
        self._lowest = math.inf
        self._left_low = math.inf  # the left base of the last sample

    def sample(self, stretches, deformation, wall_contact_force=None):
        """Take one recorded sample: the measured triangles' largest stretches (a fresh array, kept
        by reference), the deformation of that sample (m) and the wall's contact forces (n, 3)."""
        if self.largest is None:
            self.largest = stretches.copy()
        else:
            np.maximum(self.largest, stretches, out=self.largest)
        if wall_contact_force is not None:
            mark_loaded(wall_contact_force, self.touched)
        u = float(deformation)
        i = self._count
        previous = self._deformation[i - 1] if i else None
        if i and (i == 1 or self._deformation[i - 2] < previous) and previous >= u:  # a local maximum at i - 1
            self._candidates[i - 1] = [previous, u, self._previous, previous - self._left_low]
        self._left_low = self._left_base(u)
        self._highest = max(self._highest, u)
        floor = PROMINENCE * self._highest
        for k in list(self._candidates):
            entry = self._candidates[k]
            entry[1] = min(entry[1], u)
            # exceeded (so not C) without standing out on both sides (so not A)
            if u > entry[0] and min(entry[0] - entry[1], entry[3]) < floor:
                del self._candidates[k]
        self._deformation.append(u)
        self._previous = stretches
        self.last = stretches
        self._count += 1

    def _left_base(self, u) -> float:
        """The lowest deformation since the last sample above ``u`` (or since the start), this one
        included: the left base of a peak at ``u`` as scipy's prominence takes it. A stack of the
        samples not yet exceeded, each with the lowest value between it and the next."""
        self._lowest = min(self._lowest, u)
        lowest = math.inf
        while self._stack and self._stack[-1][0] <= u:
            value, low = self._stack.pop()
            lowest = min(lowest, value, low)
        if self._stack:
            self._stack[-1][1] = min(self._stack[-1][1], lowest)
            base = min(self._stack[-1][1], u)
        else:
            base = self._lowest
        self._stack.append([u, math.inf])
        return base

    def at(self, index):
        """The measured field of sample ``index`` (the last sample, or a kept local maximum of the
        deformation; on a plateau, its first sample)."""
        if index == self._count - 1:
            return self.last
        if index in self._candidates:
            return self._candidates[index][2]
        u = self._deformation[index]
        kept = [k for k in self._candidates if k <= index and self._candidates[k][0] == u]
        if not kept:
            raise ColonsimError(f"no stretch field kept for sample {index}; report this as a bug")
        return self._candidates[max(kept)][2]

    def full(self, measured):
        """A measured field spread over every triangle (held ones at 1)."""
        out = np.ones(self.n_triangles)
        out[self.measured] = measured
        return out

    def fields(self, ts) -> dict:
        """The full fields ``max``, ``A``, ``C``, ``end`` of the run whose samples are ``ts``
        (the recorder's frame; NaN everywhere for a point the run does not have)."""
        if self.largest is None:
            raise ColonsimError("no sample recorded: the wall-stretch map is empty")
        time = ts["time_s"].to_numpy()
        points = characteristic_points(time, ts["depth_m"], ts["deformation_m"])
        out = {"max": self.full(self.largest), "end": self.full(self.last)}
        for name in ("A", "C"):
            p = points[name]
            out[name] = (np.full(self.n_triangles, np.nan) if p is None
                         else self.full(self.at(int(np.flatnonzero(time == p["time_s"])[0]))))
        return out


def attach(model, tracker):
    """Keep ``tracker`` with the built insertion ``model`` (the summary and the files read it there)."""
    model.wall_stretch = tracker


def tracker_of(model):
    """The :class:`WallStretch` of ``model``, or None (a model not run through the recorder)."""
    return getattr(model, "wall_stretch", None) if model is not None else None


def check_threshold(threshold) -> float:
    """``threshold`` as a float within :data:`colonsim.catalog.STRETCHED_WALL_THRESHOLD_RANGE`."""
    low, high = STRETCHED_WALL_THRESHOLD_RANGE
    value = float(threshold)
    if not low <= value <= high:
        raise ColonsimError(f"stretch threshold {value:g} is outside {low:g}-{high:g}; give the stretch above which "
                            f"the wall counts as stretched (default {STRETCHED_WALL_THRESHOLD:g})")
    return value


def area_above(stretch, area_m2, threshold) -> float:
    """Wall area (cm^2, rest configuration) of the triangles whose ``stretch`` passed ``threshold``."""
    return float(np.sum(np.asarray(area_m2)[np.asarray(stretch) > check_threshold(threshold)]) * 1e4)


def stretched_area_section(largest, area_m2, threshold=STRETCHED_WALL_THRESHOLD) -> dict:
    """The summary's stretched-area entries: the column value and its ``wall_stretch`` section."""
    area = area_above(largest, area_m2, threshold)
    return {STRETCHED_WALL_COLUMN: area,
            "wall_stretch": {"threshold": float(threshold), "area_above_cm2": area,
                             "wall_area_cm2": float(np.sum(area_m2) * 1e4),
                             "meaning": "wall area (rest configuration) whose largest in-plane principal stretch over "
                                        "the run passed the threshold (an assumption: a candidate pain measure); "
                                        f"per triangle in {STRETCH_MAP}",
                             "map": STRETCH_MAP}}


def wall_stretch_summary(model, ts) -> dict:
    """The summary entries of the stretch map of a run (``{}`` without a record): the area above
    the default threshold, and the largest stretch at A, C and the end."""
    tracker = tracker_of(model)
    if tracker is None:
        return {}
    fields = tracker.fields(ts)
    out = stretched_area_section(fields["max"], model.shell.area0)
    out["wall_stretch"]["largest"] = {name: (None if np.isnan(fields[name]).all() else float(np.nanmax(fields[name])))
                                      for name in FIELDS}
    return out


def restate_threshold(summary, result, threshold) -> None:
    """Recompute a run's stretched area in ``summary`` at another ``threshold``."""
    tracker = tracker_of(result.model)
    if tracker is None:
        return
    largest = summary.get("wall_stretch", {}).get("largest")
    summary.update(stretched_area_section(tracker.full(tracker.largest), result.model.shell.area0, threshold))
    if largest is not None:
        summary["wall_stretch"]["largest"] = largest


def centerline_samples(geometry):
    """The centerline of ``geometry`` sampled every 0.5 mm: arc lengths (m) and points (m)."""
    length = float(geometry.centerline_length)
    s = np.linspace(0.0, length, max(int(length / 5e-4), 2) + 1)
    return s, np.asarray(geometry.centerline_points(s), dtype=float)


def unrolled_nodes(geometry, x0):
    """Every wall node's position along the centerline (m) and angle around it (deg, -180 to 180).

    The angle is measured in a parallel-transport frame of the centerline sampled every 0.5 mm,
    starting from the direction out of the model's plane (the smallest principal axis of the rest
    wall), so 0 deg is one face of a planar model, 180 the other and +-90 its two sides."""
    s, points = centerline_samples(geometry)
    tangents = np.gradient(points, s, axis=0)
    tangents /= np.linalg.norm(tangents, axis=1)[:, None]
    spread = np.linalg.svd(x0 - x0.mean(axis=0), full_matrices=False)[2]
    normal = spread[2] - np.dot(spread[2], tangents[0]) * tangents[0]
    if np.linalg.norm(normal) < 1e-6:
        normal = spread[1] - np.dot(spread[1], tangents[0]) * tangents[0]
    normals = np.empty_like(points)
    normals[0] = normal / np.linalg.norm(normal)
    for k in range(1, len(s)):  # carried along: the component along the new tangent removed
        n = normals[k - 1] - np.dot(normals[k - 1], tangents[k]) * tangents[k]
        normals[k] = n / np.linalg.norm(n)
    from scipy.spatial import cKDTree

    nearest = cKDTree(points).query(x0)[1]
    d = x0 - points[nearest]
    binormals = np.cross(tangents[nearest], normals[nearest])
    angle = np.degrees(np.arctan2(np.einsum("ij,ij->i", d, binormals), np.einsum("ij,ij->i", d, normals[nearest])))
    return s[nearest], angle


def flexure_bounds(geometry) -> list:
    """Arc-length intervals (m) of the centerline pieces named as flexures."""
    centerline = getattr(getattr(geometry, "tube", None), "centerline", None)
    names = dict.fromkeys(p.name for p in getattr(centerline, "pieces", ()) if "flexure" in p.name)
    return [(name, *centerline.bounds(name)) for name in names]


def map_arrays(result) -> dict | None:
    """The arrays of a run's stretch map (None without a record): the four fields, per triangle
    its rest area, whether it is held and whether the scope touched it, the unrolled node
    coordinates and the flexures."""
    model = result.model
    tracker = tracker_of(model)
    if tracker is None:
        return None
    fields = tracker.fields(result.timeseries)
    triangles = model.shell.triangles
    held = np.zeros(len(model.shell.x0), dtype=bool)
    held[model.fixed_nodes] = True
    axial, angle = unrolled_nodes(model.geometry, np.asarray(model.shell.x0))
    flexures = flexure_bounds(model.geometry)
    return {**{f"stretch_{name}": fields[name].astype(np.float32) for name in FIELDS},
            "area_m2": model.shell.area0.astype(np.float32), "held": held[triangles].all(axis=1),
            "touched": tracker.touched[triangles].any(axis=1), "triangles": triangles.astype(np.int32),
            "axial_m": axial.astype(np.float32), "angle_deg": angle.astype(np.float32),
            "flexure_names": np.array([f[0] for f in flexures], dtype=str),
            "flexure_m": np.array([f[1:] for f in flexures], dtype=float).reshape(-1, 2)}


def write_stretch_map(arrays, folder) -> Path:
    """Write ``arrays`` (:func:`map_arrays`) as ``folder/stretch_map.npz``."""
    path = Path(folder) / STRETCH_MAP
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
    return path


def read_stretch_map(folder) -> dict:
    """The arrays of a run folder's ``stretch_map.npz``, without unpickling anything."""
    with np.load(Path(folder) / STRETCH_MAP, allow_pickle=False) as data:
        return {name: data[name] for name in data.files}


def write_stretch_vtu(arrays, rest_nodes, path):
    """The rest wall mesh with the stretch fields and the touched flag as cell data (needs meshio)."""
    import meshio

    cell_data = {f"stretch_{name}": [np.asarray(arrays[f"stretch_{name}"], dtype=float)] for name in FIELDS}
    cell_data["touched"] = [arrays["touched"].astype(np.int8)]
    cell_data["held"] = [arrays["held"].astype(np.int8)]
    with atomic_path(path) as tmp:
        meshio.Mesh(rest_nodes, [("triangle", arrays["triangles"])], cell_data=cell_data).write(tmp, file_format="vtu")
