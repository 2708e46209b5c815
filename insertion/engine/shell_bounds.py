"""The wall's two time-step bounds with its held elements counted once (docs/model.md, "Time
integration and damping").

The membrane's element bound is the largest of the triangles' bounds, and the hinges' Gershgorin
bound the largest row sum over the nodes' masses (:meth:`colonsim.insertion.engine.shell.Shell.frequency_bounds`).
A colon model holds most of its wall at rest (RSF: 22,560 triangles, of which a quarter are free),
and a held element's bound does not change while its nodes stay where they are. So the bounds are
split: the held triangles' largest bound, and the largest row of the nodes all of whose hinges are
held, are kept from the last time the held nodes' positions and masses were seen, and only the free
triangles and the rows of the other nodes (each summed over all of its hinges, in the same order as
before) are evaluated again. A maximum does not depend on how it is split, and each element and row
goes through the same operations, so the bounds are the same to the last bit; the check of the held
nodes' positions and masses (a comparison per call) keeps them so for any positions asked about.
"""

import numpy as np

from colonsim.insertion.engine._scatter import gather, node_incidence
from colonsim.insertion.engine.shell_hinges import hinge_rowsum_kernel, max_row_over_mass
from colonsim.insertion.engine.shell_membrane import membrane_omega2_kernel


def _largest(values) -> float:
    """The largest of ``values`` as numpy's max takes it (NaN wins); -inf for none."""
    return float(np.max(values)) if len(values) else -np.inf


class SplitBounds:
    """The membrane and hinge bounds of a shell whose held elements are ``tri_on`` / ``hinge_on``
    False (bool masks over its triangles and hinges; with none held, every element is evaluated at
    each call, as the kept part is then empty)."""

    def __init__(self, shell, tri_on, hinge_on):
        self.shell = shell
        n = len(shell.x0)
        self._free_triangles = np.ascontiguousarray(shell.triangles[tri_on])
        self._free_dm_inv = np.ascontiguousarray(shell.dm_inv[tri_on])
        self._tri_held = np.flatnonzero(~tri_on)
        hinges = shell.hinges
        free_nodes = np.zeros(n, dtype=bool)
        free_nodes[hinges[hinge_on].ravel()] = True
        self._row_nodes = np.flatnonzero(free_nodes)  # rows evaluated again: nodes on a free hinge
        self._still_rows = np.flatnonzero(~free_nodes)
        near = np.flatnonzero(free_nodes[hinges].any(axis=1)) if len(hinges) else np.zeros(0, dtype=np.int64)
        # every hinge of those nodes, in the original order
        self._near = tuple(np.ascontiguousarray(a[near]) for a in (hinges, shell.hinge_stiffness, shell.theta0))
        self._near_ptr, self._near_slots = node_incidence(hinges[near].reshape(-1, 4), n)
        self._near_buf = np.zeros((len(near), 4, 3))
        self._rows = np.zeros((n, 3))
        # the nodes whose positions and masses the kept values read
        self._kept_nodes = np.unique(np.concatenate((shell.triangles[self._tri_held].ravel(),
                                                     hinges[~hinge_on].ravel())))
        self._kept_key = None
        self._kept = None

    def _keep(self, x, scale):
        """The held triangles' largest bound and the largest row of the nodes on held hinges only."""
        s = self.shell
        key = (x[self._kept_nodes], s.mass[self._kept_nodes], scale[self._kept_nodes])
        if self._kept_key is not None and all(np.array_equal(a, b) for a, b in zip(key, self._kept_key)):
            return self._kept
        held = self._tri_held
        omega2 = np.zeros(len(held))
        membrane_omega2_kernel(x, np.ascontiguousarray(s.triangles[held]), np.ascontiguousarray(s.dm_inv[held]),
                               s.thickness, s.density, s._law, s._law_params, scale, omega2)
        rows = np.zeros((len(x), 3))
        if len(s.hinges):
            buf = np.zeros((len(s.hinges), 4, 3))
            hinge_rowsum_kernel(x, s.hinges, s.hinge_stiffness, s.theta0, buf)
            gather(buf, s._hinge_ptr, s._hinge_slots, rows)
        still = self._still_rows
        self._kept = (_largest(omega2), max_row_over_mass(np.ascontiguousarray(rows[still]), s.mass[still]))
        self._kept_key = tuple(a.copy() for a in key)
        return self._kept

    def bounds(self, x, scale):
        """(membrane, hinges) squared-frequency bounds at x, rad^2/s^2; ``scale`` the nodes' mass
        factors over their lumped masses."""
        s = self.shell
        membrane_held, rows_held = self._keep(x, scale)
        omega2 = np.zeros(len(self._free_triangles))
        membrane_omega2_kernel(x, self._free_triangles, self._free_dm_inv, s.thickness, s.density, s._law,
                               s._law_params, scale, omega2)
        membrane = float(np.max((membrane_held, _largest(omega2))))
        if not len(s.hinges):
            return membrane, 0.0
        hinge_rowsum_kernel(x, *self._near, self._near_buf)
        rows = self._rows
        rows[:] = 0.0
        gather(self._near_buf, self._near_ptr, self._near_slots, rows)
        nodes = self._row_nodes
        return membrane, max(rows_held, max_row_over_mass(np.ascontiguousarray(rows[nodes]), s.mass[nodes]))
