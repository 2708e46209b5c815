"""The wall's internal forces: membrane and hinges in one parallel pass, in either of two loop
structures that do the same arithmetic.

:func:`internal_forces` splits the elements into one contiguous chunk per thread; chunk
``c`` adds the forces of its triangles and hinges into its own nodal array ``out[c]``, so no two
threads write the same memory (with one chunk ``out`` can be a view of the force array itself).
Within a chunk the elements go

- element by element (``blocked`` false, the engine's first structure): one triangle's update
  is a long chain of scalar operations fenced by the loads of its nodes and the adds onto them,
  so the compiler cannot run two elements side by side (only the hinges' arctangents run in
  blocks);
- by blocks (``blocked`` true, the default): a block of elements goes through three loops. The
  gather reads the nodes' edge vectors into contiguous block arrays, the compute loop
  (straight-line arithmetic on those arrays and the per-element reference quantities, with no
  indirect access) runs several elements at once in the vector registers, and the scatter adds
  the results onto the nodes (a hinge's forces, a few products of its angle and gradients, are
  formed there: 6 % faster than in a vector loop of their own). Each law has a blocked kernel of
  its own (:data:`BLOCKED_KERNELS`), which holds that law's compute loop alone with its branches
  folded away, and compiles on its first call.

Each element goes through the same operations in both, and its forces are added onto the nodes in
the same order, so the two give the same forces and energies to the last bit
(tests/test_shell_blocked.py; benchmarks/bench_solver.py ``--engines`` times them). The reference
quantities of each triangle (Dm_inv and the volume t A0) are computed once
(:func:`triangle_reference`), one quantity per row; the hinges' stiffness and rest angle are
arrays of their own.
"""

import math

import numba
import numpy as np

from colonsim import laws
from colonsim.insertion.engine._compile import with_constant
from colonsim.insertion.engine.shell_hinges import fast_atan, hinge_terms, hinge_terms_of_edges
from colonsim.insertion.engine.shell_membrane import membrane_terms

BLOCK = 64  # elements per block: its arrays (~11 kB for hinges) stay in L1 (32 and 128 measured slower or equal)


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


def _membrane_chunk(x, tri, ref, p, lo, hi, f):
    """Membrane forces of triangles lo..hi added onto f; returns (energy J, inverted count).

    The law is the global constant ``_LAW``, bound in each law's copy (:data:`BLOCKED_KERNELS`),
    where Numba drops the other laws' branches before compiling."""
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
        _membrane_block(d, ref, start, nb, _LAW, p, h, w, ok)  # noqa: F821
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
        for j in range(nb):  # the forces, formed and scattered
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


@numba.njit(cache=True, inline="always")
def _elementwise_chunk(x, tri, ref, law, p, hinge, stiffness, theta0, t_lo, t_hi, h_lo, h_hi, f):
    """Forces of triangles t_lo..t_hi and hinges h_lo..h_hi added onto f element by element;
    returns (membrane energy J, inverted count, bending energy J, collapsed count)."""
    e_mem = 0.0
    n_inv = 0
    for e in range(t_lo, t_hi):
        i0 = tri[e, 0]
        i1 = tri[e, 1]
        i2 = tri[e, 2]
        w, ok, h1, h2 = membrane_terms(x[i1, 0] - x[i0, 0], x[i1, 1] - x[i0, 1], x[i1, 2] - x[i0, 2],
                                       x[i2, 0] - x[i0, 0], x[i2, 1] - x[i0, 1], x[i2, 2] - x[i0, 2], ref[0, e],
                                       ref[1, e], ref[2, e], ref[3, e], ref[4, e], law, p)
        if not ok:
            n_inv += 1
        e_mem += w
        for k in range(3):
            f[i1, k] += h1[k]
            f[i2, k] += h2[k]
            f[i0, k] += -(h1[k] + h2[k])
    # Hinges in blocks: the angle arguments and gradients of a block first, then all its
    # arctangents in one tight loop (one long dependency chain each, which a loop of whole
    # hinges cannot overlap), then the forces.
    e_bend = 0.0
    n_bad = 0
    ys = np.empty(BLOCK)
    xs = np.empty(BLOCK)
    th = np.empty(BLOCK)
    g = np.empty((BLOCK, 9))
    for start in range(h_lo, h_hi, BLOCK):
        nb = min(BLOCK, h_hi - start)
        for j in range(nb):
            h = start + j
            sin_part, cos_part, ok, gc, gd, al1, al2 = hinge_terms(x, hinge[h, 0], hinge[h, 1], hinge[h, 2],
                                                                   hinge[h, 3])
            ys[j] = sin_part
            xs[j] = cos_part
            for k in range(3):
                g[j, k] = gc[k]
                g[j, 3 + k] = gd[k]
            g[j, 6] = al1
            g[j, 7] = al2
            g[j, 8] = 1.0 if ok else 0.0
        for j in range(nb):  # fast_atan2 without its branches
            t = fast_atan(ys[j] / xs[j])
            th[j] = t + math.copysign(math.pi, ys[j]) if xs[j] < 0.0 else t
        for j in range(nb):
            h = start + j
            if g[j, 8] == 0.0:
                n_bad += 1
                continue
            theta = th[j]
            if not (xs[j] > 0.0 or xs[j] < 0.0):  # cos_part 0 or NaN: as _atan2 does
                theta = math.atan2(ys[j], xs[j])
            dth = theta - theta0[h]
            e_bend += stiffness[h] * dth * dth
            coef = -2.0 * stiffness[h] * dth
            a = hinge[h, 0]
            b = hinge[h, 1]
            cc = hinge[h, 2]
            d = hinge[h, 3]
            al1 = g[j, 6]
            al2 = g[j, 7]
            for k in range(3):
                gc = g[j, k]
                gd = g[j, 3 + k]
                f[cc, k] += gc * coef
                f[d, k] += gd * coef
                f[a, k] += (-(1.0 - al1) * gc - (1.0 - al2) * gd) * coef
                f[b, k] += (-al1 * gc - al2 * gd) * coef
    return e_mem, n_inv, e_bend, n_bad


@numba.njit(cache=True, inline="always")
def _chunk(out, c, zero, nt, nh):
    """Chunk ``c``'s nodal forces (zeroed if ``zero``), triangles t_lo..t_hi and hinges h_lo..h_hi."""
    n_chunks = out.shape[0]
    f = out[c]
    if zero:
        f[:, :] = 0.0
    return f, c * nt // n_chunks, (c + 1) * nt // n_chunks, c * nh // n_chunks, (c + 1) * nh // n_chunks


@numba.njit(cache=True, inline="always")
def _store_chunk(energy, count, c, e_mem, n_inv, e_bend, n_bad):
    """Chunk ``c``'s energies and counts of bad elements."""
    energy[c, 0] = e_mem
    energy[c, 1] = e_bend
    count[c, 0] = n_inv
    count[c, 1] = n_bad


def _blocked_law(x, tri, ref, params, hinge, stiffness, theta0, out, zero, energy, count):
    """The blocked pass of :func:`internal_forces` with the law's ``_membrane_chunk`` bound in
    each law's copy (below)."""
    for c in numba.prange(out.shape[0]):
        f, t_lo, t_hi, h_lo, h_hi = _chunk(out, c, zero, tri.shape[0], hinge.shape[0])
        e_mem, n_inv = _membrane_chunk(x, tri, ref, params, t_lo, t_hi, f)
        e_bend, n_bad = _hinge_chunk(x, hinge, stiffness, theta0, h_lo, h_hi, f)
        _store_chunk(energy, count, c, e_mem, n_inv, e_bend, n_bad)


def _law_kernel(name, index):
    """The blocked kernel of one law: copies of :func:`_membrane_chunk` with ``_LAW`` bound to its
    index and of :func:`_blocked_law` calling that copy, each under a name of its own (its own
    cache entry)."""
    chunk = numba.njit(inline="always")(with_constant(_membrane_chunk, "_" + name, _LAW=index))
    return numba.njit(parallel=True, cache=True)(with_constant(_blocked_law, "_" + name, _membrane_chunk=chunk))


# One blocked kernel per law (law index -> kernel), each compiled on its first call: a kernel holding
# every law's loop and the element-by-element pass took 34-38 s to compile, one law's kernel about
# 9 s (on a loaded machine; docs/notes/2026-12-07-compile-time.md). Threaded even for one chunk: the
# same source compiled serially ran the benchmark tube's steps 1.4 times slower.
_LAW_INDICES = {**{name: law.index for name, law in laws.LAWS.items()}, "ogden": laws.OGDEN_INDEX}
BLOCKED_KERNELS = {index: _law_kernel(name, index) for name, index in _LAW_INDICES.items()}


@numba.njit(parallel=True, cache=True)
def elementwise_forces_kernel(x, tri, ref, law, params, hinge, stiffness, theta0, out, zero, energy, count):
    """The element-by-element pass of :func:`internal_forces` (the law a run-time value)."""
    for c in numba.prange(out.shape[0]):
        f, t_lo, t_hi, h_lo, h_hi = _chunk(out, c, zero, tri.shape[0], hinge.shape[0])
        e_mem, n_inv, e_bend, n_bad = _elementwise_chunk(x, tri, ref, law, params, hinge, stiffness, theta0,
                                                         t_lo, t_hi, h_lo, h_hi, f)
        _store_chunk(energy, count, c, e_mem, n_inv, e_bend, n_bad)


def internal_forces(x, tri, ref, law, params, hinge, stiffness, theta0, out, zero, energy, count, blocked=True):
    """Membrane and hinge forces of the wall onto per-thread nodal arrays, by blocks or element by
    element (``blocked``; module docstring).

    Parameters
    ----------
    ref : (5, nt) float64
        The triangles' reference quantities (:func:`triangle_reference`).
    law : int
        The wall law's index (:data:`colonsim.laws.LAWS`, Ogden's :data:`colonsim.laws.OGDEN_INDEX`).
    out : (n_chunks, n, 3) float64
        Per-chunk nodal forces, added to (set to zero first if ``zero``).
    energy : (n_chunks, 2) float64
        Membrane and bending strain energy of each chunk, J (written).
    count : (n_chunks, 2) int64
        Inverted triangles and collapsed hinges of each chunk (written).
    """
    if not blocked:
        elementwise_forces_kernel(x, tri, ref, law, params, hinge, stiffness, theta0, out, zero, energy, count)
        return
    kernel = BLOCKED_KERNELS.get(law)
    if kernel is None:
        raise ValueError(f"no wall law has the index {law}; the laws are {sorted(BLOCKED_KERNELS)}")
    kernel(x, tri, ref, params, hinge, stiffness, theta0, out, zero, energy, count)
