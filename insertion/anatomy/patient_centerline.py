"""A patient's centerline: the points of a CSV (:mod:`colonsim.insertion.anatomy.centerline_file`)
smoothed into a C2 curve, arc-length parametrised, with rotation-minimising frames (SI, m).

docs/model.md, "A patient's centerline", states the choices (**assumptions** marked):

- cubic smoothing splines x(u), y(u), z(u) of the chord-length parameter (scipy's
  ``make_smoothing_spline``, one penalty weight, so the curve is C2) whose root-mean-square
  distance from the points is the smoothing tolerance (**assumption** 1 mm by default, about the
  voxel of CT colonography: 0.6-0.8 mm in plane, 1-1.25 mm slices; ``centerline_smoothing_mm``).
  Segmentation noise of a voxel would otherwise show as bends of a few mm radius that no tube
  can follow. (A penalised spline keeps a knot at every point and spreads the smoothing along
  the curve; FITPACK's ``splprep`` meets a tolerance by dropping knots, which made the bend radius
  of a sampled arc wander more in a first trial);
- arc length by Gauss-Legendre quadrature of the spline's speed on a table of parameter values
  at most :data:`TABLE_STEP` apart, inverted by a cubic spline;
- frames by the double-reflection method (Wang, Juettler, Zheng & Liu 2008, ACM Trans. Graph.
  27(1):2), a rotation-minimising frame: the rings of a tube mesh placed with it do not twist;
  the first normal is the coordinate axis most nearly perpendicular to the first tangent;
- a labelled range starts at its first point's arc length; the lumen diameter profile is the
  file's per-point diameters, linear in arc length between the points.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline, make_smoothing_spline

from colonsim.errors import ColonsimError
from colonsim.insertion.anatomy.centerline import MAX_LENGTH, LabelledCenterline
from colonsim.insertion.anatomy.centerline_file import load_centerline_points

SMOOTHING_MM = 1.0  # assumption: RMS distance of the smoothed centerline from the points, ~ a CT voxel
SMOOTHING_RANGE_MM = (0.0, 20.0)  # beyond 2 cm the "centerline" would no longer follow the colon
TABLE_STEP = 5e-4  # m, spacing of the arc-length and frame table
_GAUSS = np.polynomial.legendre.leggauss(4)


@dataclass(frozen=True)
class Range:
    """A labelled range of a patient's centerline: ``tag`` fixed/mobile, ``name``, first file line."""

    tag: str
    name: str
    line: int


def _double_reflection(x0, t0, r0, x1, t1):
    """Normals at (x1, t1) transported from frames (x0, t0, r0) by double reflection (rows)."""
    v1 = x1 - x0
    c1 = np.einsum("ij,ij->i", v1, v1)[:, None]
    c1 = np.where(c1 > 0.0, c1, 1.0)
    r_l = r0 - (2.0 / c1) * np.einsum("ij,ij->i", v1, r0)[:, None] * v1
    t_l = t0 - (2.0 / c1) * np.einsum("ij,ij->i", v1, t0)[:, None] * v1
    v2 = t1 - t_l
    c2 = np.einsum("ij,ij->i", v2, v2)[:, None]
    r1 = r_l - np.where(c2 > 1e-30, 2.0 / np.where(c2 > 1e-30, c2, 1.0), 0.0) * np.einsum("ij,ij->i", v2, r_l)[:, None] * v2
    r1 -= np.einsum("ij,ij->i", r1, t1)[:, None] * t1  # round-off back to the normal plane
    return r1 / np.linalg.norm(r1, axis=1)[:, None]


def _smooth(u, p, tolerance):
    """Cubic smoothing splines x(u), y(u), z(u) (one penalty weight for all three) whose RMS
    distance from the points ``p`` (n, 3) is ``tolerance`` (m), found by bisection on the
    logarithm of the weight (the straightest fit when the points lie that close to a line;
    interpolation for a tolerance of 0)."""
    def fit(lam):
        return [make_smoothing_spline(u, p[:, k], lam=lam) for k in range(3)]

    def rms(splines):
        return float(np.sqrt(np.mean(sum((b(u) - p[:, k]) ** 2 for k, b in enumerate(splines)))))

    if tolerance == 0.0:
        return fit(0.0)
    # the penalty is on d2/du2 of the unit parameter: weights from ~interpolation to a straight line
    lo, hi = -30.0, 10.0
    if rms(fit(10.0**hi)) <= tolerance:
        return fit(10.0**hi)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if rms(fit(10.0**mid)) <= tolerance:
            lo = mid
        else:
            hi = mid
        if hi - lo < 0.02:
            break
    return fit(10.0**lo)


class PatientCenterline(LabelledCenterline):
    """A smoothed centerline through measured points (module docstring), with labelled ranges.

    Parameters
    ----------
    points : CenterlinePoints
        What :func:`colonsim.insertion.anatomy.centerline_file.read_centerline_points` read.
    smoothing_mm : float
        Largest RMS distance of the smoothed curve from the points, mm (0: interpolate).

    Attributes
    ----------
    pieces : list of Range
    s_start, s_end : (np,) float
        Arc length of each range, m.
    s_points : (n,) float
        Arc length of the curve's point nearest to each file point (its spline parameter), m.
    length : float
        m.
    """

    def __init__(self, points, smoothing_mm=SMOOTHING_MM):
        low, high = SMOOTHING_RANGE_MM
        if not (np.isfinite(smoothing_mm) and low <= smoothing_mm <= high):
            raise ColonsimError(f"centerline smoothing {smoothing_mm!r} mm is outside {low:g}-{high:g} mm; give the "
                                "RMS tolerance in mm (1 by default, about a CT voxel)")
        self.source = points
        self.smoothing_mm = float(smoothing_mm)
        p = points.points_mm * 1e-3
        chord = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
        n = len(p)
        u = chord / chord[-1]
        self._spline = _smooth(u, p, smoothing_mm * 1e-3)
        # arc-length table: Gauss-Legendre on parameter intervals of at most TABLE_STEP of chord
        m = max(int(np.ceil(chord[-1] / TABLE_STEP)), 4 * n)
        u_tab = np.linspace(0.0, 1.0, m + 1)
        nodes, weights = _GAUSS
        h = np.diff(u_tab)
        uq = (u_tab[:-1, None] + 0.5 * h[:, None] * (nodes[None, :] + 1.0)).ravel()
        speed = np.linalg.norm(self._eval(uq, 1), axis=1).reshape(len(h), -1)
        s_tab = np.concatenate([[0.0], np.cumsum(0.5 * h * (speed * weights).sum(axis=1))])
        self.length = float(s_tab[-1])
        if not (0.0 < self.length <= MAX_LENGTH):
            raise ColonsimError(f"{points.path}: the centerline is {self.length * 100:.1f} cm long; a colon is at most "
                                f"{MAX_LENGTH * 100:g} cm: give the coordinates in mm")
        self._u_of_s = CubicSpline(s_tab, u_tab)
        self._s_of_u = CubicSpline(u_tab, s_tab)
        self.s_points = self._s_of_u(u)
        # frame table (double reflection along the table)
        self._s_tab = s_tab
        x, t = self._curve(s_tab)
        r = np.empty_like(t)
        axis = np.eye(3)[np.argmin(np.abs(t[0]))]
        r[0] = axis - (axis @ t[0]) * t[0]
        r[0] /= np.linalg.norm(r[0])
        for i in range(len(s_tab) - 1):
            r[i + 1] = _double_reflection(x[i:i + 1], t[i:i + 1], r[i:i + 1], x[i + 1:i + 2], t[i + 1:i + 2])[0]
        self._x_tab, self._t_tab, self._r_tab = x, t, r
        self._ranges(points)
        d = points.diameters_mm
        self._diameter = None if d is None else (self.s_points, d * 1e-3)

    def _ranges(self, points):
        starts = [0] + [i for i in range(1, len(points.labels))
                        if (points.labels[i], points.names[i]) != (points.labels[i - 1], points.names[i - 1])]
        self.pieces = [Range(points.labels[i], points.names[i], points.lines[i]) for i in starts]
        s0 = [0.0] + [float(self.s_points[i]) for i in starts[1:]]
        self.s_start = np.array(s0)
        self.s_end = np.array(s0[1:] + [self.length])

    def _eval(self, u, der):
        """Derivative ``der`` of the spline at parameters ``u`` (k,), (k, 3)."""
        return np.column_stack([b(u, nu=der) for b in self._spline])

    def _curve(self, s):
        """Position and unit tangent of the spline at arc lengths ``s`` (k,)."""
        u = np.clip(self._u_of_s(s), 0.0, 1.0)
        x, d = self._eval(u, 0), self._eval(u, 1)
        return x, d / np.linalg.norm(d, axis=1)[:, None]

    def frame(self, s):
        """Position, unit tangent, normal and binormal at arc length ``s`` (m, clipped to [0, length]).

        Returns
        -------
        position, tangent, normal, binormal : (3,) or (k, 3) float
            A right-handed orthonormal, rotation-minimising frame (double reflection from the
            table's frame just before ``s``).
        """
        scalar = np.ndim(s) == 0
        s = np.clip(np.atleast_1d(np.asarray(s, dtype=float)), 0.0, self.length)
        x, t = self._curve(s)
        i = np.clip(np.searchsorted(self._s_tab, s, side="right") - 1, 0, len(self._s_tab) - 1)
        r = _double_reflection(self._x_tab[i], self._t_tab[i], self._r_tab[i], x, t)
        b = np.cross(t, r)
        if scalar:
            return x[0], t[0], r[0], b[0]
        return x, t, r, b

    def curvature_radius(self, s):
        """Bend radius of the smoothed centerline at arc length ``s`` (m; inf where straight)."""
        u = np.clip(self._u_of_s(np.atleast_1d(np.asarray(s, dtype=float))), 0.0, 1.0)
        d1, d2 = self._eval(u, 1), self._eval(u, 2)
        speed = np.linalg.norm(d1, axis=1)
        kappa = np.linalg.norm(np.cross(d1, d2), axis=1) / speed**3
        with np.errstate(divide="ignore"):
            radius = np.where(kappa > 0.0, 1.0 / kappa, np.inf)
        return radius if np.ndim(s) else float(radius[0])

    @property
    def min_radius(self):
        """Smallest bend radius on the arc-length table, m."""
        return float(np.min(self.curvature_radius(self._s_tab)))

    def diameter_at(self, s):
        """Lumen diameter of the file's profile at arc length ``s`` (m), or None without one."""
        if self._diameter is None:
            return None
        return np.interp(s, *self._diameter)

    @property
    def diameter_profile(self):
        """(s, D) of the file's points, m, or None without a diameter column."""
        return self._diameter

    @property
    def median_diameter_mm(self):
        """Median of the file's per-point lumen diameters, rounded to 0.1 mm (None without them):
        the ``diameter_mm`` an insertion case on this file states."""
        d = self.source.diameters_mm
        return None if d is None else round(float(np.median(d)), 1)

    def check_case_diameter(self, diameter):
        """Raise unless a case's lumen ``diameter`` (m) may run on this file: with a diameter
        profile it must be the profile's median (to 0.05 mm), since the profile is what runs."""
        median = self.median_diameter_mm
        if median is not None and abs(diameter * 1e3 - median) > 0.05 + 1e-9:
            raise ColonsimError(
                f"{self.source.path} gives the lumen diameter per point (median {median:g} mm), and that profile is "
                f"what runs; set the case's diameter_mm = {median:g} (colonsim insert fills it in), not "
                f"{diameter * 1e3:g}, or drop the file's diameter_mm column to run a constant diameter")

    def line_at(self, s) -> int:
        """File line of the point nearest (in arc length) to ``s``."""
        return self.source.lines[int(np.argmin(np.abs(self.s_points - s)))]

    def check_bend(self, radius_at, what):
        """Raise where the bend radius is at most ``radius_at(s)`` (m): the tube ``what`` cannot follow it."""
        s = self._s_tab
        radius, limit = self.curvature_radius(s), radius_at(s)
        bad = radius <= limit
        if bad.any():
            i = int(np.argmax(bad))
            worst = int(np.argmin(radius - limit))
            raise ColonsimError(
                f"{self.source.path}: the centerline bends with radius {radius[worst] * 1e3:.1f} mm "
                f"at {s[worst] * 100:.1f} cm (near line {self.line_at(s[worst])}; tight from {s[i] * 100:.1f} cm), "
                f"tighter than {what} of radius {limit[worst] * 1e3:.1f} mm can follow; check the "
                "points there, raise the smoothing tolerance (centerline_smoothing_mm) or use a smaller diameter")

    def check_tube(self, diameter):
        """Raise if a tube of ``diameter`` (m: a number, or a callable of s) cannot follow this
        centerline: a bend radius at most D/2, or two parts of the curve closer than D."""
        diameter_at = diameter if callable(diameter) else (lambda s: np.full(np.shape(s), float(diameter)))
        d = diameter_at(self._s_tab)
        if not (np.all(np.isfinite(d)) and 1e-3 <= d.min() and d.max() <= 0.12):
            raise ColonsimError(f"tube diameter {d.min():.4g}-{d.max():.4g} m must lie in 1-120 mm; fix the diameter.")
        self.check_bend(lambda s: 0.5 * diameter_at(s), "a tube")
        clash = self.first_clash(diameter_at)
        if clash is not None:
            s_i, s_j, dist = clash
            raise ColonsimError(
                f"{self.source.path}: the tube cuts itself: the centerline at {s_i * 100:.1f} cm (near line "
                f"{self.line_at(s_i)}) passes {dist * 1e3:.1f} mm from itself at {s_j * 100:.1f} cm (near line "
                f"{self.line_at(s_j)}), closer than the tube's {0.5 * (diameter_at(np.array([s_i]))[0] + diameter_at(np.array([s_j]))[0]) * 1e3:.1f} mm "
                "diameter; move the points apart or use a smaller diameter")


@lru_cache(maxsize=32)
def _smoothed(path: str, mtime_ns: int, size: int, smoothing_mm: float) -> PatientCenterline:
    return PatientCenterline(load_centerline_points(path), smoothing_mm)


def load_patient_centerline(path, smoothing_mm=SMOOTHING_MM) -> PatientCenterline:
    """Read ``path`` and smooth it, cached per file state (path, modification time, size) and
    tolerance: a case is validated, estimated and built from one reading (the points come from
    :func:`colonsim.insertion.anatomy.centerline_file.load_centerline_points`'s cache)."""
    load_centerline_points(path)  # its one-line errors for a missing or unreadable file
    path = Path(path).expanduser()
    stat = path.stat()
    return _smoothed(str(path), stat.st_mtime_ns, stat.st_size, float(smoothing_mm))
