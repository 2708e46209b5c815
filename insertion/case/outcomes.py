"""Scalar outcomes of an insertion from its time series (docs/model.md, "Outputs").

Plain functions of recorded arrays, so they apply equally to a fresh run and to a CSV read back.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from scipy.signal import find_peaks


def characteristic_points(time, depth, deformation, prominence=0.05):
    """Points A, B, C of an RSJ deformation curve (docs/model.md, "Outputs").

    A is the first maximum (the tip negotiating the angulation), B the minimum that follows, C
    the maximum after B (the tip passing the fixed end). A maximum counts only if it stands out
    by ``prominence`` times the curve's overall maximum, so recording noise is not taken for A.

    Parameters
    ----------
    time, depth, deformation : (n,) arrays
        Time (s), insertion depth (m) and colon deformation (m).

    Returns
    -------
    dict with keys "A", "B", "C", each ``{"time_s", "depth_m", "deformation_m"}`` or None when
    the curve has no such point (for instance a monotone curve has only C, its maximum).
    """
    t, z, u = (np.asarray(a, dtype=float) for a in (time, depth, deformation))
    points = {"A": None, "B": None, "C": None}
    if u.size < 3 or not np.all(np.isfinite(u)):
        return points

    def at(i):
        return {"time_s": float(t[i]), "depth_m": float(z[i]), "deformation_m": float(u[i])}

    scale = max(float(np.max(u)), 1e-12)
    peaks, _ = find_peaks(u, prominence=prominence * scale)
    if peaks.size:
        a = int(peaks[0])
        later = peaks[peaks > a]
        # B: the lowest point between A and the next prominent rise (or the end of the run).
        stop = int(later[0]) if later.size else u.size
        b = a + int(np.argmin(u[a:stop]))
        if b > a and u[b] < u[a]:
            points["A"], points["B"] = at(a), at(b)
            c = b + int(np.argmax(u[b:]))
            if c > b:
                points["C"] = at(c)
            return points
    points["C"] = at(int(np.argmax(u)))
    return points


PEAK_WINDOW = 0.005  # m of push: peak forces are maxima of the force averaged over this much push
# The other quasi-static checks (docs/model.md, "Time integration and damping"), which need more
# than one run: half the push speed or a 2 mm mesh may change a deformation by this fraction and a
# peak force by this one; forces below FORCE_FLOOR_N are not judged (nothing measurable).
DEFORMATION_TOLERANCE = 0.05
FORCE_TOLERANCE = 0.10
FORCE_FLOOR_N = 0.5


def depth_weights(depth):
    """Weight of each sample in an integral over the push: half the depth to its neighbours (m).

    A sample taken while the scope stands still (a pause) weighs nothing, and a run sampled at
    another push speed weighs its samples alike per millimetre of push."""
    z = np.asarray(depth, dtype=float)
    w = np.zeros_like(z)
    if z.size > 1:
        w[1:-1] = 0.5 * (z[2:] - z[:-2])
        w[0] = 0.5 * (z[1] - z[0])
        w[-1] = 0.5 * (z[-1] - z[-2])
    return w


def depth_trend(depth, values, window):
    """Depth-weighted moving average of ``values`` over [z - window/2, z + window/2] at every
    sample's depth z, and the push each average covers (m). ``depth`` non-decreasing."""
    z = np.asarray(depth, dtype=float)
    w = depth_weights(z)
    cw = np.concatenate(([0.0], np.cumsum(w)))
    cf = np.concatenate(([0.0], np.cumsum(w * np.asarray(values, dtype=float))))
    lo = np.searchsorted(z, z - 0.5 * window, side="left")
    hi = np.searchsorted(z, z + 0.5 * window, side="right")
    covered = cw[hi] - cw[lo]
    return (cf[hi] - cf[lo]) / np.maximum(covered, 1e-300), covered


def peak_trend(depth, values, window=PEAK_WINDOW):
    """Largest value of ``values`` averaged over ``window`` of push (docs/model.md, "Outputs"), or
    NaN when the push is shorter than the window.

    The largest recorded sample would be a statistic of the sampling, not of the push: a run
    sampled every millisecond at half the speed has twice the samples per millimetre, and a
    release (a tip slipping past a junction) puts a spike of a millisecond or two into the
    contact force that the sampling catches or misses. The average over 5 mm of push keeps every
    feature of the force along the push that is wider than that."""
    trend, covered = depth_trend(depth, values, window)
    full = covered >= 0.5 * window
    return float(trend[full].max()) if full.any() else float("nan")


def quasi_static_fraction(kinetic, internal, ratio=0.1, floor=1e-12):
    """Fraction of recorded samples with kinetic / internal energy below ``ratio``.

    Samples whose internal energy is below ``floor`` J (the very start, nothing deformed yet)
    are left out: the ratio is meaningless there.
    """
    k, w = np.asarray(kinetic, dtype=float), np.asarray(internal, dtype=float)
    keep = w > floor
    if not np.any(keep):
        return 0.0
    return float(np.mean(k[keep] < ratio * w[keep]))


def sliding_kinetic_energy(x, v, mass, speed):
    """Kinetic energy of a rod's motion relative to sliding along itself at ``speed`` (J).

    A scope pushed at constant speed along a fixed path moves like a tank tread: every node at
    ``speed`` along the local tangent. That motion is imposed kinematics, not inertia; its
    kinetic energy 1/2 m v^2 is of the order of the scope's bending energy at 0.6 m/s and would
    fail a kinetic/internal energy check however slowly the colon deforms. What is left after
    subtracting it (bowing, whipping, axial waves) is what a quasi-static check should see.

    Parameters
    ----------
    x, v : (n, 3) arrays
        Node positions (m) and velocities (m/s), nodes in order along the rod.
    mass : (n,) array
        Lumped node masses, kg.
    speed : float
        Push speed, m/s.
    """
    t = np.gradient(x, axis=0)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    rel = v - speed * t
    return float(0.5 * np.sum(mass * np.einsum("ij,ij->i", rel, rel)))


@numba.njit(cache=True)
def arc_along(points, arc, tangents, p):
    """Arc length (m) of the point of a sampled curve nearest to ``p`` (3,).

    ``points`` (k, 3) are the curve's samples at arc lengths ``arc`` (k,), ``tangents`` (k, 3) its
    unit tangents there. The nearest point C(s) is where (p - C(s)) . T(s) changes sign: that
    function is evaluated at the two samples around the nearest one and its root interpolated
    linearly between them, so the result moves continuously with ``p``, also across samples and
    off the curve (projecting onto the chords instead jumps by d h / R at a sample, for a point d
    off a bend of radius R sampled every h). On a circle the function is r sin(theta - theta_i)
    for a point at radius r and angle theta: the interpolation errs by O(h^3 / R^2) whatever r.
    Beyond the first or the last sample it returns their arc length. Compiled: the recorder
    calls it at every sample.
    """
    k = points.shape[0]
    i = 0
    best = math.inf
    for j in range(k):
        d2 = (points[j, 0] - p[0]) ** 2 + (points[j, 1] - p[1]) ** 2 + (points[j, 2] - p[2]) ** 2
        if d2 < best:
            best = d2
            i = j
    j = i if _ahead(points, tangents, p, i) >= 0.0 else i - 1  # the samples j, j + 1 around the root
    if j < 0:
        return arc[0]
    if j >= k - 1:
        return arc[k - 1]
    f0 = _ahead(points, tangents, p, j)
    f1 = _ahead(points, tangents, p, j + 1)
    w = min(max(f0 / (f0 - f1), 0.0), 1.0) if f0 > f1 else 0.0
    return arc[j] + w * (arc[j + 1] - arc[j])


@numba.njit(cache=True, inline="always")
def _ahead(points, tangents, p, j):
    """Coordinate of ``p`` along the tangent at sample ``j``, measured from the sample, m."""
    return ((p[0] - points[j, 0]) * tangents[j, 0] + (p[1] - points[j, 1]) * tangents[j, 1]
            + (p[2] - points[j, 2]) * tangents[j, 2])


TURNED_BACK_DEG = 90.0  # deg: a tip heading more than this away from the lumen's direction points back


def tip_heading(scope_x, tip, arc, tangents, tip_arc):
    """Angle (deg) between the scope's last segment (from the node before ``tip`` to it) and the
    lumen's direction where the tip is (``tip_arc`` m along the centerline, whose unit
    ``tangents`` are sampled at arc lengths ``arc``): 0 on along the lumen, 180 turned back."""
    d = scope_x[tip] - scope_x[tip - 1]
    k = min(int(np.searchsorted(arc, tip_arc)), len(arc) - 1)
    cosine = float(np.dot(d, tangents[k])) / float(np.linalg.norm(d))
    return math.degrees(math.acos(min(1.0, max(-1.0, cosine))))


def turned_back(depth, heading, limit=TURNED_BACK_DEG):
    """Pushed depth (m) from which the tip points back against the lumen (``heading`` above
    ``limit`` deg) through to the last sample; None when it does not at the last sample. A tip
    turned back no longer advances against a distal resistance: what is pushed after it goes into
    a fold, not into the colon (docs/model.md, "Distal resistance")."""
    heading = np.asarray(heading, dtype=float)
    if heading.size == 0 or not heading[-1] > limit:
        return None
    forward = np.flatnonzero(~(heading > limit))
    return float(np.asarray(depth, dtype=float)[forward[-1] + 1 if forward.size else 0])


@numba.njit(cache=True)
def principal_stretches(x, triangles, dm_inv):
    """Largest in-plane principal stretch of every triangle at positions ``x`` (n, 3), m.

    F = [x1 - x0, x2 - x0] Dm^-1 maps the reference plane into space (3 x 2); the stretches are
    the square roots of the eigenvalues of C = F^T F (closed form for 2 x 2). Compiled: the
    recorder measures every wall triangle at every sample, which in NumPy took about 6 % of a
    run (RSF, 22,560 triangles: 1.7 ms against 0.17 ms a sample).
    """
    out = np.empty(triangles.shape[0])
    f = np.empty((3, 2))
    for e in range(triangles.shape[0]):
        i0 = triangles[e, 0]
        i1 = triangles[e, 1]
        i2 = triangles[e, 2]
        for k in range(3):
            e1 = x[i1, k] - x[i0, k]
            e2 = x[i2, k] - x[i0, k]
            f[k, 0] = e1 * dm_inv[e, 0, 0] + e2 * dm_inv[e, 1, 0]
            f[k, 1] = e1 * dm_inv[e, 0, 1] + e2 * dm_inv[e, 1, 1]
        c00 = f[0, 0] * f[0, 0] + f[1, 0] * f[1, 0] + f[2, 0] * f[2, 0]
        c01 = f[0, 0] * f[0, 1] + f[1, 0] * f[1, 1] + f[2, 0] * f[2, 1]
        c11 = f[0, 1] * f[0, 1] + f[1, 1] * f[1, 1] + f[2, 1] * f[2, 1]
        half_trace = 0.5 * (c00 + c11)
        det = c00 * c11 - c01 * c01
        out[e] = math.sqrt(half_trace + math.sqrt(max(half_trace * half_trace - det, 0.0)))
    return out


@numba.njit(cache=True)
def mark_loaded(force, marks):
    """Set ``marks[i]`` where node i carries a force (any component of ``force`` (n, 3) non-zero)."""
    for i in range(force.shape[0]):
        if force[i, 0] != 0.0 or force[i, 1] != 0.0 or force[i, 2] != 0.0:
            marks[i] = True


JAM_PUSH = 0.01  # m of push over which the tip is watched
JAM_PROGRESS = 1e-3  # m: less tip progress than this over JAM_PUSH of push ...
JAM_FORCE = 43.0  # N: ... under at least this push force is a jam (the largest push measured in colonoscopy)


def jammed(depth, tip_arc, push_force, window=JAM_PUSH, progress=JAM_PROGRESS, force=JAM_FORCE):
    """Has the tip stopped advancing under the largest push an endoscopist applies, at the last sample?

    The tip jams when, over the last ``window`` of push, it advanced less than ``progress`` along
    the centerline while the push force, averaged over the last :data:`PEAK_WINDOW` of push (the
    drive reaction rings at the scope's axial frequencies), is at least ``force``: 43 N, the peak
    push of 4.4 kg measured in colonoscopy (Appleyard et al. 2000, docs/model.md "Loading"). A
    tip that stalls under less is not jammed: the scope bows behind it until the tip force carries
    it past what held it (measured, docs/model.md "Loading": THF tips stalled at the hepatic
    flexure for 2.4-5.7 cm of push under 2-10 N, then passed). A blocked tip takes the push past
    43 N within a centimetre (a 12.8 mm scope against a rigid iris: about 70 N per cm of push).

    Parameters
    ----------
    depth, tip_arc, push_force : (n,) arrays
        Pushed distance (m), tip position along the centerline (m) and push force (N) per sample.
    window, progress : float
        m (1 cm and 1 mm by default).
    force : float
        N (43 by default).
    """
    z = np.asarray(depth, dtype=float)
    if z.size < 3 or z[-1] - z[0] < window:
        return False
    start = int(np.searchsorted(z, z[-1] - window, side="right")) - 1
    if start < 0 or z[-1] - z[start] < window:
        return False
    arc = np.asarray(tip_arc, dtype=float)
    if arc[-1] - arc[start] >= progress:
        return False
    last = z >= z[-1] - PEAK_WINDOW
    w = depth_weights(z[last])
    pushed = np.sum(w)
    return bool(pushed > 0.0 and np.sum(w * np.asarray(push_force, dtype=float)[last]) >= force * pushed)


REST_WINDOW = 0.05  # s of the closing hold over which a run must be still to have come to rest
REST_TOLERANCE = 2e-5  # m: at rest, the deformation and the tip each move less than this over REST_WINDOW


def rest_drift(time, deformation, tip, window=REST_WINDOW):
    """How far the colon deformation and the tip moved over the last ``window`` of samples, m.

    A run has come to rest (docs/model.md, "Loading") when both drifts are below
    :data:`REST_TOLERANCE`: 0.02 mm over 0.05 s, a five-hundredth of the centimetre of deformation
    the study compares, where a loop still relaxing moves tenths of millimetres to millimetres
    (RSF alpha 45, 11.1 mm scope, 5 N, 0.3 m/s: 2.8 mm over the 0.05 s ending 0.25 s into the
    hold, 0.01 mm at 0.5 s). Stillness is not stability: a scope held near an unstable state
    leaves it slowly, and the same run settling with 200 1/s of lateral damping sat within
    0.003 mm for 0.1 s at 0.70 cm before it left for 0.96 cm; with the default 20 1/s it leaves
    such states within tenths of a second (docs/model.md, "Loading"). Returns
    ``(deformation_drift, tip_drift)``, or None when the samples span less than ``window``.

    Parameters
    ----------
    time, deformation, tip : (n,) arrays
        Sample time (s), largest displacement of the mobile wall (m) and the tip's displacement
        from its start (m), the samples of the hold.
    """
    t = np.asarray(time, dtype=float)
    if t.size < 2 or t[-1] - t[0] < window - 1e-9:
        return None
    start = int(np.searchsorted(t, t[-1] - window - 1e-9))
    u = np.asarray(deformation, dtype=float)[start:]
    w = np.asarray(tip, dtype=float)[start:]
    return float(u.max() - u.min()), float(w.max() - w.min())
