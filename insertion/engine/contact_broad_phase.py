"""Broad phase of the rod-shell contact: candidate (contact point, rod segment) pairs.

Broad phase: candidate (contact point of the wall, segment) pairs within radius + offset + skin,
found with a uniform cell hash of the inflated segment boxes (sorted cell keys, one binary search
per point; the points are the wall's nodes or points on its faces,
:mod:`colonsim.insertion.engine.contact_points`); rebuilt only when the nodes have moved more
than the skin since the last build, so the per-step cost scales with the number of candidates,
not with all pairs. The narrow phase runs
on threads for large candidate lists (``parallel_min_candidates``), serially otherwise.
"""

import math

import numba
import numpy as np

from colonsim.insertion.engine.contact_kernel import point_segment

_OFF = 1 << 20
_BASE = 1 << 21


@numba.njit(cache=True)
def _cell_key(ix, iy, iz):
    return ((ix + _OFF) * _BASE + (iy + _OFF)) * _BASE + (iz + _OFF)


def segment_cell_table(xr, seg, cutoff, cell):
    """Sorted cell keys of the segments' inflated bounding boxes and the matching segment ids.

    With ``cell`` at least the longest segment and twice ``cutoff``, a box spans at most three
    cells per axis, so 27 offsets from its lower cell cover it (numpy: a rod has few segments).
    """
    a = xr[seg[:, 0]]
    b = xr[seg[:, 1]]
    lo = np.floor((np.minimum(a, b) - cutoff) / cell).astype(np.int64)
    hi = np.floor((np.maximum(a, b) + cutoff) / cell).astype(np.int64)
    off = np.stack(np.meshgrid(np.arange(3), np.arange(3), np.arange(3), indexing="ij"), axis=-1).reshape(-1, 3)
    cells = lo[:, None, :] + off[None, :, :]
    valid = np.all(cells <= hi[:, None, :], axis=2)
    cells = cells[valid]
    ids = np.broadcast_to(np.arange(len(seg), dtype=np.int64)[:, None], valid.shape)[valid]
    keys = ((cells[:, 0] + _OFF) * _BASE + (cells[:, 1] + _OFF)) * _BASE + (cells[:, 2] + _OFF)
    order = np.argsort(keys, kind="stable")
    return np.ascontiguousarray(keys[order]), np.ascontiguousarray(ids[order])


@numba.njit(cache=True)
def candidate_counts(xs, xr, seg, keys, ids, cutoff, cell, counts):
    """Number of segments within ``cutoff`` of each point of ``xs``, into ``counts``.

    Serial: it runs only when the list is rebuilt (every few hundred steps) and costs a hash
    lookup per point."""
    n = xs.shape[0]
    c2 = cutoff * cutoff
    for i in range(n):
        key = _cell_key(int(math.floor(xs[i, 0] / cell)), int(math.floor(xs[i, 1] / cell)),
                        int(math.floor(xs[i, 2] / cell)))
        lo = np.searchsorted(keys, key, side="left")
        hi = np.searchsorted(keys, key, side="right")
        m = 0
        for j in range(lo, hi):
            s = ids[j]
            d2, _ = point_segment(xs, i, xr, seg[s, 0], seg[s, 1])
            if d2 < c2:
                m += 1
        counts[i] = m


@numba.njit(cache=True)
def candidate_fill(xs, xr, seg, keys, ids, cutoff, cell, nodes, ptr, out):
    """Segment ids near each listed point into ``out[ptr[c]:ptr[c + 1]]`` (serial, see
    :func:`candidate_counts`)."""
    c2 = cutoff * cutoff
    for c in range(nodes.shape[0]):
        i = nodes[c]
        key = _cell_key(int(math.floor(xs[i, 0] / cell)), int(math.floor(xs[i, 1] / cell)),
                        int(math.floor(xs[i, 2] / cell)))
        lo = np.searchsorted(keys, key, side="left")
        hi = np.searchsorted(keys, key, side="right")
        p = ptr[c]
        for j in range(lo, hi):
            s = ids[j]
            d2, _ = point_segment(xs, i, xr, seg[s, 0], seg[s, 1])
            if d2 < c2:
                out[p] = s
                p += 1


@numba.njit(cache=True)
def max_displacement_at(x, x_ref, nodes):
    """Largest distance between x and x_ref over ``nodes``, m (0 for none; NaN if any is). The
    squares are summed in the order NumPy sums a row of three, so it equals
    ``sqrt(((x[nodes] - x_ref[nodes]) ** 2).sum(axis=1).max())`` to the bit, without its copies."""
    worst = 0.0
    for j in range(nodes.shape[0]):
        i = nodes[j]
        d0 = x[i, 0] - x_ref[i, 0]
        d1 = x[i, 1] - x_ref[i, 1]
        d2 = x[i, 2] - x_ref[i, 2]
        s = d0 * d0 + d1 * d1 + d2 * d2
        if s > worst or s != s:  # NaN wins, as in NumPy's max
            worst = s
    return math.sqrt(worst)


@numba.njit(cache=True)
def max_displacement(x, x_ref):
    """Largest nodal distance between x and x_ref, m (serial: a few flops per node)."""
    worst = 0.0
    for i in range(x.shape[0]):
        d0 = x[i, 0] - x_ref[i, 0]
        d1 = x[i, 1] - x_ref[i, 1]
        d2 = x[i, 2] - x_ref[i, 2]
        worst = max(worst, d0 * d0 + d1 * d1 + d2 * d2)
    return math.sqrt(worst)
