"""The colon wall as a thin hyperelastic shell: the body the solver integrates.

Membrane (:mod:`colonsim.insertion.engine.shell_membrane`, constant-strain triangles of any
calibrated law: the invariant laws and Ogden's in the principal stretches), bending (:mod:`colonsim.insertion.engine.shell_hinges`, discrete hinges) and a
follower pressure, with lumped masses and a stable time step; docs/model.md for the physics.

All kernels are ``numba`` functions over raw arrays; the per-element buffers are summed onto nodes
without races by :func:`colonsim.insertion.engine._scatter.gather`, or, for the internal forces,
by one fused kernel that gives each thread its own nodal array
(:mod:`colonsim.insertion.engine.shell_forces`, by blocks or element by element:
:attr:`Shell.force_kernel`).

Numba's cache checks only a kernel's own file (measured): the force kernel compiles in code from
shell_membrane.py, shell_hinges.py and colonsim/laws.py, so after editing those delete
``insertion/engine/__pycache__`` or the old compiled code keeps running (a fresh checkout, as in
CI, has no cache).
"""

import math

import numba
import numpy as np

from colonsim.errors import ColonsimError
from colonsim.insertion.engine._scatter import gather, node_incidence
from colonsim.insertion.engine.sheet_mesh import boundary_loops, hinges as mesh_hinges
from colonsim.insertion.engine.shell_bounds import SplitBounds
from colonsim.insertion.engine.shell_forces import internal_forces, triangle_reference
from colonsim.insertion.engine.shell_hinges import bending_stiffness, dihedral_angles, hinge_stiffness
from colonsim.insertion.engine.shell_membrane import check_dispatched, reference_frames

# ---------------------------------------------------------------------------------------------
# Internal forces: the per-thread arrays summed
# ---------------------------------------------------------------------------------------------


@numba.njit(parallel=True, cache=True)
def sum_chunks(out, f):
    """Add the per-chunk nodal forces ``out`` (n_chunks, n, 3) into ``f`` (n, 3)."""
    n_chunks = out.shape[0]
    for i in numba.prange(f.shape[0]):
        for k in range(3):
            s = 0.0
            for c in range(n_chunks):
                s += out[c, i, k]
            f[i, k] += s


# ---------------------------------------------------------------------------------------------
# Pressure and geometry
# ---------------------------------------------------------------------------------------------


@numba.njit(parallel=True, cache=True)
def area_vector_kernel(x, tri, scale, elem_f):
    """``scale`` times each triangle's area vector (1/2)(x1 - x0) x (x2 - x0), on each of its nodes.

    With ``scale = p / 3`` this is the follower pressure load (positive p pushes along the
    triangle normals); with ``scale = 1`` and a gather, the area-weighted nodal normals.
    """
    nt = tri.shape[0]
    for e in numba.prange(nt):
        i0 = tri[e, 0]
        i1 = tri[e, 1]
        i2 = tri[e, 2]
        a0 = x[i1, 0] - x[i0, 0]
        a1 = x[i1, 1] - x[i0, 1]
        a2 = x[i1, 2] - x[i0, 2]
        b0 = x[i2, 0] - x[i0, 0]
        b1 = x[i2, 1] - x[i0, 1]
        b2 = x[i2, 2] - x[i0, 2]
        s = 0.5 * scale
        n0 = s * (a1 * b2 - a2 * b1)
        n1 = s * (a2 * b0 - a0 * b2)
        n2 = s * (a0 * b1 - a1 * b0)
        for a in range(3):
            elem_f[e, a, 0] = n0
            elem_f[e, a, 1] = n1
            elem_f[e, a, 2] = n2


@numba.njit(parallel=True, cache=True)
def enclosed_volume(x, tri):
    """Signed volume sum (1/6) x0 . (x1 x x2) over the triangles, m^3.

    For a closed outward-oriented surface it is the enclosed volume. For a tube whose end rings are
    held fixed it differs from the lumen volume by a constant, and its gradient on the free nodes
    equals the follower pressure load per unit pressure, so -p V is the pressure's potential.
    """
    nt = tri.shape[0]
    vol = 0.0
    for e in numba.prange(nt):
        i0 = tri[e, 0]
        i1 = tri[e, 1]
        i2 = tri[e, 2]
        cx = x[i1, 1] * x[i2, 2] - x[i1, 2] * x[i2, 1]
        cy = x[i1, 2] * x[i2, 0] - x[i1, 0] * x[i2, 2]
        cz = x[i1, 0] * x[i2, 1] - x[i1, 1] * x[i2, 0]
        vol += x[i0, 0] * cx + x[i0, 1] * cy + x[i0, 2] * cz
    return vol / 6.0


# ---------------------------------------------------------------------------------------------
# Body
# ---------------------------------------------------------------------------------------------


class Shell:
    """Colon wall as a thin incompressible hyperelastic shell (body protocol of the solver).

    Parameters
    ----------
    nodes : (n, 3) float array
        Reference mid-surface node positions, m (the stress-free, bending-free state).
    triangles : (nt, 3) int array
        Consistently oriented triangles; for a tube, normals out of the lumen.
    thickness : float
        Reference wall thickness, m.
    material : colonsim.insertion.engine.material.WallMaterial
    density : float
        Wall density, kg/m^3.
    name : str

    Notes
    -----
    The instance owns work buffers, so one instance must not be evaluated from two threads.
    """

    #: The loop structure of the internal forces (:mod:`colonsim.insertion.engine.shell_forces`):
    #: "blocked" or "elementwise" (each element in turn, as the engine did first: the same forces
    #: to the last bit in 1.3-1.6 times the time; kept as the reference that
    #: tests/test_shell_blocked.py and the benchmarks compare against). Set on the class or on an
    #: instance.
    force_kernel = "blocked"

    def __init__(self, nodes, triangles, thickness, material, density=1040.0, name="colon"):
        nodes = np.ascontiguousarray(nodes, dtype=np.float64)
        triangles = np.ascontiguousarray(triangles, dtype=np.int64)
        if nodes.ndim != 2 or nodes.shape[1] != 3:
            raise ColonsimError(f"shell nodes must be an (n, 3) array, got shape {nodes.shape}; fix the mesh.")
        if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) == 0:
            raise ColonsimError(
                f"shell triangles must be a non-empty (nt, 3) array, got shape {triangles.shape}; fix the mesh."
            )
        if triangles.min() < 0 or triangles.max() >= len(nodes):
            raise ColonsimError("shell triangles reference nodes that do not exist; fix the mesh.")
        used = np.zeros(len(nodes), dtype=bool)
        used[triangles.ravel()] = True
        if not used.all():
            raise ColonsimError(
                f"{int((~used).sum())} shell node(s) belong to no triangle (zero mass); remove them."
            )
        if not (np.isfinite(thickness) and thickness > 0.0):
            raise ColonsimError(f"shell thickness = {thickness!r} m must be positive; fix it.")
        if not (np.isfinite(density) and density > 0.0):
            raise ColonsimError(f"shell density = {density!r} kg/m^3 must be positive; fix it.")

        self.name = name
        self.x0 = nodes
        self.triangles = triangles
        self.thickness = float(thickness)
        self.material = material
        # the wall law as the kernels take it: its dispatch index and float64 parameters
        self._law = material.law_model.index
        self._law_params = np.array(material.parameters, dtype=np.float64)
        check_dispatched(material.law_model, self._law_params)
        self.density = float(density)
        self.hinges = mesh_hinges(triangles)
        self._open_ends = None  # found when first asked (open_ends)

        self.dm_inv, self.area0 = reference_frames(nodes, triangles)
        self._lumped_mass = np.zeros(len(nodes))
        np.add.at(self._lumped_mass, triangles.ravel(), np.repeat(self.density * self.thickness * self.area0 / 3.0, 3))
        self.mass = self._lumped_mass.copy()

        self.bending_stiffness = bending_stiffness(material, self.thickness)
        h = self.hinges
        self.hinge_stiffness = hinge_stiffness(nodes, h, self.bending_stiffness)
        self.theta0 = dihedral_angles(nodes, h) if len(h) else np.zeros(0)

        self._tri_ptr, self._tri_slots = node_incidence(triangles, len(nodes))
        self._tri_buf = np.zeros((len(triangles), 3, 3))
        self._hinge_ptr, self._hinge_slots = node_incidence(h.reshape(-1, 4), len(nodes))
        self._mass_scale = np.ones(len(nodes))
        self._chunk_f = np.zeros((0,) + nodes.shape)  # per-thread nodal forces, sized on first use
        self._chunk_energy = np.zeros((0, 2))
        self._chunk_count = np.zeros((0, 2), dtype=np.int64)
        self.hold(np.zeros(len(nodes), dtype=bool))

    def hold(self, held):
        """Tell the shell which nodes are held at rest (bool (n,)): the internal forces then leave
        out the triangles and hinges all of whose nodes are held.

        Held nodes stay at their stress-free rest positions, so such an element carries no force
        (round-off apart), and what it would add lands on held nodes, whose velocity the solver
        sets to zero anyway: the motion of every free node is unchanged, to the last bit when the
        forces are added in one chunk (the elements keep their order). The colon models hold most
        of their wall (rectum, descending colon, flexures, exits), which then costs nothing."""
        held = np.asarray(held, dtype=bool)
        tri_on = ~held[self.triangles].all(axis=1)
        hinge_on = ~held[self.hinges].all(axis=1) if len(self.hinges) else np.zeros(0, dtype=bool)
        if tri_on.all() and hinge_on.all():
            self._active = (self.triangles, self.dm_inv, self.area0, self.hinges, self.hinge_stiffness, self.theta0)
        else:
            self._active = tuple(np.ascontiguousarray(a[on]) for a, on in (
                (self.triangles, tri_on), (self.dm_inv, tri_on), (self.area0, tri_on), (self.hinges, hinge_on),
                (self.hinge_stiffness, hinge_on), (self.theta0, hinge_on)))
        self._active_reference = triangle_reference(self._active[1], self._active[2], self.thickness)
        self._bounds = SplitBounds(self, tri_on, hinge_on)  # the held elements' part kept
        self._force_nodes = np.unique(np.concatenate((self._active[0].ravel(), self._active[3].ravel())))

    def force_nodes(self):
        """The nodes the internal forces may reach: those of the triangles and hinges not all held."""
        return self._force_nodes

    @property
    def n_nodes(self):
        return len(self.x0)

    def _check_x(self, x):
        if x.shape != self.x0.shape or x.dtype != np.float64 or not x.flags.c_contiguous:
            raise ColonsimError(
                f"shell positions must be a C-contiguous float64 array of shape {self.x0.shape}; "
                f"got {x.dtype} {x.shape}."
            )

    def internal_forces(self, x, f):
        """Add internal elastic forces (-dE/dx) for positions x into f (n, 3); return strain energy, J.

        Membrane and hinge forces in one fused kernel (:attr:`force_kernel`).
        """
        self._check_x(x)
        n_chunks = numba.get_num_threads()
        if self._chunk_energy.shape[0] != n_chunks:
            self._chunk_f = np.zeros((n_chunks,) + x.shape)
            self._chunk_energy = np.zeros((n_chunks, 2))
            self._chunk_count = np.zeros((n_chunks, 2), dtype=np.int64)
        # one chunk adds straight into f (a view), several into their own arrays summed below
        direct = n_chunks == 1 and f.dtype == np.float64 and f.flags.c_contiguous and f.shape == x.shape
        out = f.reshape((1,) + f.shape) if direct else self._chunk_f
        if self.force_kernel not in ("blocked", "elementwise"):
            raise ColonsimError(f"Shell.force_kernel = {self.force_kernel!r}: use 'blocked' or 'elementwise'.")
        tri, _, _, hinges, hinge_stiffness, theta0 = self._active  # the elements not all held
        internal_forces(x, tri, self._active_reference, self._law, self._law_params, hinges, hinge_stiffness, theta0,
                        out, not direct, self._chunk_energy, self._chunk_count, self.force_kernel == "blocked")
        n_inv, n_bad = self._chunk_count.sum(axis=0) if self._chunk_count.any() else (0, 0)
        if n_inv:
            raise ColonsimError(
                f"{n_inv} wall triangle(s) of '{self.name}' are inverted or collapsed (det C <= 0); "
                "the simulation diverged: reduce the time step or the loading rate."
            )
        if n_bad:
            raise ColonsimError(
                f"{n_bad} bending hinge(s) of '{self.name}' have a collapsed triangle; "
                "the simulation diverged: reduce the time step or the loading rate."
            )
        if not direct:
            sum_chunks(out, f)
        return float(self._chunk_energy.sum())

    def pressure_forces(self, x, pressure, f):
        """Add the follower load of an internal pressure (Pa, positive pushes along the outward
        normals) into f."""
        self._check_x(x)
        area_vector_kernel(x, self.triangles, pressure / 3.0, self._tri_buf)
        gather(self._tri_buf, self._tri_ptr, self._tri_slots, f)

    def enclosed_volume(self, x):
        """Signed volume term whose gradient is the pressure load per Pa (see :func:`enclosed_volume`), m^3."""
        self._check_x(x)
        return enclosed_volume(x, self.triangles)

    def open_ends(self):
        """The wall's boundary edges and the boundary loop of each
        (:func:`colonsim.insertion.engine.sheet_mesh.boundary_loops`), found once: the mesh's
        topology does not change."""
        if self._open_ends is None:
            self._open_ends = boundary_loops(self.triangles)
        return self._open_ends

    def node_normals(self, x):
        """Unit outward normals (n, 3), area-weighted over the incident triangles."""
        self._check_x(x)
        area_vector_kernel(x, self.triangles, 1.0, self._tri_buf)
        normals = np.zeros_like(x)
        gather(self._tri_buf, self._tri_ptr, self._tri_slots, normals)
        norm = np.linalg.norm(normals, axis=1)
        return normals / np.where(norm > 0.0, norm, 1.0)[:, None]

    def frequency_bounds(self, x):
        """The two bounds of the squared frequencies at configuration x, rad^2/s^2: the membrane's
        element bound (at the current stretches) and the Gershgorin bound of the hinge stiffness,
        both with the current nodal masses."""
        self._check_x(x)
        # The solver may replace or rescale self.mass (mass scaling); the membrane bound needs the
        # per-node scaling factor relative to the physical lumped mass.
        scale = self._mass_scale
        np.divide(self.mass, self._lumped_mass, out=scale)
        return self._bounds.bounds(x, scale)

    def critical_time_step(self, x):
        """Conservative stable central-difference time step at configuration x, s.

        2 / omega_max with omega_max^2 <= (membrane element bound at the current stretches)
        + (Gershgorin bound of the hinge stiffness): :meth:`frequency_bounds`.
        """
        membrane, hinges = self.frequency_bounds(x)
        omega2 = membrane + hinges
        if not np.isfinite(omega2):
            raise ColonsimError(
                f"wall of '{self.name}' has an inverted or collapsed triangle; no stable time step exists."
            )
        return 2.0 / math.sqrt(omega2)
