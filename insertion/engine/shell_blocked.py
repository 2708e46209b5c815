"""The wall's internal forces in blocks: gather, compute in vector registers, scatter.

:func:`blocked_forces_kernel` gives the same membrane and hinge forces as the element-by-element
kernel :func:`colonsim.insertion.engine.shell.internal_forces_kernel`, to the last bit: each
element goes through the same arithmetic, and its forces are added onto the nodes in the same
order. What differs is the loop structure. Element by element, one triangle's update is a long
chain of scalar operations fenced by the loads of its nodes and the adds onto them, so the
compiler cannot run two elements side by side. Here a block of elements goes through three
loops: the gather reads the nodes' edge vectors into contiguous block arrays, the compute loop
(straight-line arithmetic on those arrays and the per-element reference quantities, with no
indirect access) runs several elements at once in the vector registers, and the scatter adds the
results onto the nodes. The law is chosen once per block, so each law's compute loop is compiled
apart with its branch folded away.

The reference quantities of each element (Dm_inv, the volume t A0, the hinge stiffness and rest
angle) are computed once (:func:`triangle_reference`), laid out one quantity per row.
"""

import math

import numba
import numpy as np

from colonsim import laws
from colonsim.insertion.engine.shell_hinges import fast_atan, hinge_terms_of_edges
from colonsim.insertion.engine.shell_membrane import membrane_terms

BLOCK = 64  # elements per block: its arrays (~11 kB for hinges) stay in L1 (32 and 128 measured slower or equal)
_OGDEN = laws.OGDEN_INDEX
_MOONEY_RIVLIN_3 = laws.LAWS["mooney_rivlin_3"].index
_MOONEY_RIVLIN_2 = laws.LAWS["mooney_rivlin_2"].index
_NEO_HOOKEAN = laws.LAWS["neo_hookean"].index
_YEOH = laws.LAWS["yeoh"].index


def triangle_reference(dm_inv, area0, thickness):
    """(5, nt) rows Dm_inv[0, 0], Dm_inv[0, 1], Dm_inv[1, 0], Dm_inv[1, 1] and the volume t A0 (m^3)
    of each triangle: what the compute loop reads, contiguous per quantity."""
    return np.ascontiguousarray(np.vstack([dm_inv[:, 0, 0], dm_inv[:, 0, 1], dm_inv[:, 1, 0], dm_inv[:, 1, 1],
                                           thickness * area0]))


@numba.njit(cache=True, inline="always")
def _membrane_block(d, ref, start, nb, law, p, h, w, ok):
    """Forces h (6, nb) on nodes 1 and 2, energies w and ok flags (1.0 / 0.0) of the block's
    triangles from their edges d (6, nb); ``law`` a constant at each call site."""
    for j in range(nb):
        e = start + j
        wj, okj, h1, h2 = membrane_terms(d[0, j], d[1, j], d[2, j], d[3, j], d[4, j], d[5, j], ref[0, e], ref[1, e],
                                         ref[2, e], ref[3, e], ref[4, e], law, p)
        w[j] = wj
        ok[j] = 1.0 if okj else 0.0
        h[0, j] = h1[0]
        h[1, j] = h1[1]
        h[2, j] = h1[2]
        h[3, j] = h2[0]
        h[4, j] = h2[1]
        h[5, j] = h2[2]


@numba.njit(cache=True, inline="always")
def _membrane_chunk(x, tri, ref, law, p, lo, hi, f):
    """Membrane forces of triangles lo..hi added onto f; returns (energy J, inverted count)."""
    d = np.empty((6, BLOCK))
    h = np.empty((6, BLOCK))
    w = np.empty(BLOCK)
    ok = np.empty(BLOCK)
    e_mem = 0.0
    n_inv = 0
    for start in range(lo, hi, BLOCK):
        nb = min(BLOCK, hi - start)
        for j in range(nb):
            e = start + j
            i0 = tri[e, 0]
            i1 = tri[e, 1]
            i2 = tri[e, 2]
            for k in range(3):
                d[k, j] = x[i1, k] - x[i0, k]
                d[3 + k, j] = x[i2, k] - x[i0, k]
        if law == _MOONEY_RIVLIN_3:
            _membrane_block(d, ref, start, nb, _MOONEY_RIVLIN_3, p, h, w, ok)
        elif law == _MOONEY_RIVLIN_2:
            _membrane_block(d, ref, start, nb, _MOONEY_RIVLIN_2, p, h, w, ok)
        elif law == _NEO_HOOKEAN:
            _membrane_block(d, ref, start, nb, _NEO_HOOKEAN, p, h, w, ok)
        elif law == _YEOH:
            _membrane_block(d, ref, start, nb, _YEOH, p, h, w, ok)
        else:
            _membrane_block(d, ref, start, nb, law, p, h, w, ok)  # Ogden's (and NaN for an unknown law)
        for j in range(nb):
            e = start + j
            if ok[j] == 0.0:
                n_inv += 1
            e_mem += w[j]
            i0 = tri[e, 0]
            i1 = tri[e, 1]
            i2 = tri[e, 2]
            for k in range(3):
                f[i1, k] += h[k, j]
                f[i2, k] += h[3 + k, j]
                f[i0, k] += -(h[k, j] + h[3 + k, j])
    return e_mem, n_inv


@numba.njit(cache=True, inline="always")
def _hinge_chunk(x, hinge, stiffness, theta0, lo, hi, f):
    """Bending forces of hinges lo..hi added onto f; returns (energy J, collapsed count)."""
    q = np.empty((9, BLOCK))  # edge e and wings u, v
    g = np.empty((8, BLOCK))  # gradients on c and d, the edge shares al1, al2
    ys = np.empty(BLOCK)
    xs = np.empty(BLOCK)
    th = np.empty(BLOCK)
    ok = np.empty(BLOCK)
    e_bend = 0.0
    n_bad = 0
    for start in range(lo, hi, BLOCK):
        nb = min(BLOCK, hi - start)
        for j in range(nb):
            hh = start + j
            a = hinge[hh, 0]
            b = hinge[hh, 1]
            c = hinge[hh, 2]
            dd = hinge[hh, 3]
            for k in range(3):
                q[k, j] = x[b, k] - x[a, k]
                q[3 + k, j] = x[c, k] - x[a, k]
                q[6 + k, j] = x[dd, k] - x[a, k]
        for j in range(nb):  # the angles' arguments and gradients; the arctangent without branches
            sin_part, cos_part, okj, gc, gd, al1, al2 = hinge_terms_of_edges(
                q[0, j], q[1, j], q[2, j], q[3, j], q[4, j], q[5, j], q[6, j], q[7, j], q[8, j])
            ys[j] = sin_part
            xs[j] = cos_part
            t = fast_atan(sin_part / cos_part)
            th[j] = t + math.copysign(math.pi, sin_part) if cos_part < 0.0 else t
            ok[j] = 1.0 if okj else 0.0
            for k in range(3):
                g[k, j] = gc[k]
                g[3 + k, j] = gd[k]
            g[6, j] = al1
            g[7, j] = al2
        for j in range(nb):  # cos_part 0 or NaN: as math.atan2 does (rare)
            if not (xs[j] > 0.0 or xs[j] < 0.0):
                th[j] = math.atan2(ys[j], xs[j])
        for j in range(nb):  # the forces, scattered (computed here rather than in a vector loop: 6 % faster)
            if ok[j] == 0.0:
                n_bad += 1
                continue
            hh = start + j
            dth = th[j] - theta0[hh]
            e_bend += stiffness[hh] * dth * dth
            coef = -2.0 * stiffness[hh] * dth
            al1 = g[6, j]
            al2 = g[7, j]
            a = hinge[hh, 0]
            b = hinge[hh, 1]
            c = hinge[hh, 2]
            dd = hinge[hh, 3]
            for k in range(3):
                gc = g[k, j]
                gd = g[3 + k, j]
                f[c, k] += gc * coef
                f[dd, k] += gd * coef
                f[a, k] += (-(1.0 - al1) * gc - (1.0 - al2) * gd) * coef
                f[b, k] += (-al1 * gc - al2 * gd) * coef
    return e_bend, n_bad


@numba.njit(parallel=True, cache=True)
def blocked_forces_kernel(x, tri, ref, law, params, hinge, stiffness, theta0, out, zero, energy, count):
    """Membrane and hinge forces of the wall, by blocks, onto per-thread nodal arrays.

    The same contract as :func:`colonsim.insertion.engine.shell.internal_forces_kernel` (chunk
    ``c`` of the elements adds into ``out[c]``, set to zero first if ``zero``; energies and
    counts per chunk), with the triangles' reference quantities ``ref`` of
    :func:`triangle_reference` in place of Dm_inv, A0 and t.
    """
    n_chunks = out.shape[0]
    nt = tri.shape[0]
    nh = hinge.shape[0]
    for c in numba.prange(n_chunks):
        f = out[c]
        if zero:
            f[:, :] = 0.0
        e_mem, n_inv = _membrane_chunk(x, tri, ref, law, params, c * nt // n_chunks, (c + 1) * nt // n_chunks, f)
        e_bend, n_bad = _hinge_chunk(x, hinge, stiffness, theta0, c * nh // n_chunks, (c + 1) * nh // n_chunks, f)
        energy[c, 0] = e_mem
        energy[c, 1] = e_bend
        count[c, 0] = n_inv
        count[c, 1] = n_bad
