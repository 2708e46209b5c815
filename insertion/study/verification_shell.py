"""Verification problems of the shell (the colon wall): inflation of a tube against thin-wall
theory, hinge bending of a sheet against plate theory. SI units.

Thin-wall inflation (axial stretch held at 1, i.e. ends fixed axially: plane strain along the
tube). A tube of mid-surface radius R and wall thickness t inflates to radius r = l R. The
principal stretches are l (hoop), 1 (axial) and 1/l (thickness), so I1 = I2 = I = l^2 + 1 + l^-2
and W(l) = (C10 + C01)(I - 3) + C11 (I - 3)^2. Per unit length the strain energy is 2 pi R t W(l)
and the enclosed volume pi R^2 l^2; equilibrium p dV = dE gives

    p(l) = t W'(l) / (l R) = (2 t / R) (1 - l^-4) [C10 + C01 + 2 C11 (l^2 + l^-2 - 2)],

the same as Laplace's law p r = sigma_theta t / l with the plane-stress Cauchy hoop stress
sigma_theta = l W'(l).

Discrete correction (exact, not fitted): the mesh's rings are m-gons inscribed in the circle. Under
uniform inflation each triangle's hoop stretch is exactly l, but the reference area is the
polygon's (perimeter 2 m R sin(pi/m)) and so is the volume ((m/2) r^2 sin(2 pi/m) per length), so
the discrete relation is p(l) / cos(pi / m) (+0.34 % for m = 38).
"""

from __future__ import annotations

import numpy as np

from colonsim.insertion.engine.sheet_mesh import flat_sheet, straight_tube
from colonsim.insertion.engine.shell import Shell
from colonsim.insertion.engine.shell_hinges import dihedral_angles
from colonsim.insertion.engine.statics import minimize_energy
from colonsim.insertion.study.verification import WALL_T, Comparison, reference_material

TUBE_RADIUS, TUBE_H = 0.018, 0.003  # m: mid-surface radius and mesh size of the inflated tube


def thin_wall_pressure(stretch, material=None, radius=TUBE_RADIUS, thickness=WALL_T):
    """Closed-form inflation pressure of a thin incompressible Mooney-Rivlin tube in plane strain
    (axial stretch 1) at hoop stretch ``stretch``, Pa (derivation in this module's docstring):

        p(l) = (2 t / R) (1 - l^-4) [C10 + C01 + 2 C11 (l^2 + l^-2 - 2)]
    """
    c = (material or reference_material()).named_parameters
    l = np.asarray(stretch, dtype=float)
    return 2.0 * thickness / radius * (1.0 - l**-4) * (c["C10"] + c["C01"] + 2.0 * c["C11"] * (l**2 + l**-2 - 2.0))


def inflation_tube(length, material=None):
    """Straight tube of radius TUBE_RADIUS; returns (shell, ring index per node, cos(pi / m)), the
    last being the exact correction of a ring of m chords inscribed in the circle."""
    nodes, tri, ring = straight_tube(length, 2.0 * TUBE_RADIUS, TUBE_H)
    shell = Shell(nodes, tri, WALL_T, material or reference_material())
    per_ring = int(np.sum(ring == 0))
    return shell, ring, np.cos(np.pi / per_ring)


def _closed_volume(shell, x, last_ring, length):
    """Volume enclosed by the tube and two flat end caps (axial coordinates held), m^3."""
    p = x[last_ring]
    order = np.argsort(np.arctan2(p[:, 2], p[:, 1]))
    y, z = p[order, 1], p[order, 2]
    cap_area = 0.5 * np.sum(y * np.roll(z, -1) - np.roll(y, -1) * z)
    return shell.enclosed_volume(x) + length * cap_area / 3.0


def solve_section(pressure_of, length=0.02, material=None):
    """Nodal radii / R of a periodic tube section (every axial coordinate fixed, closed by flat end
    caps) of ``material`` under ``pressure_of(material)`` / cos(pi/m), the inscribed ring's exact
    correction, solved statically."""
    shell, ring, cos_factor = inflation_tube(length, material)
    last = np.flatnonzero(ring == ring.max())
    free = np.ones(shell.x0.shape, dtype=bool)
    free[:, 0] = False
    pressure = float(pressure_of(shell.material)) / cos_factor

    def potential(x, f):
        energy = shell.internal_forces(x, f)
        shell.pressure_forces(x, pressure, f)
        return energy - pressure * _closed_volume(shell, x, last, length)

    x, _ = minimize_energy(shell.x0, free, potential, force_tol=1e-5 * pressure * TUBE_H**2)
    return np.hypot(x[:, 1], x[:, 2]) / TUBE_RADIUS


def inflate_section(stretch, length=0.02) -> Comparison:
    """The section of :func:`solve_section` under the thin-wall pressure p(l) of the reference
    material: the mean radius / R against ``stretch``, with the relative spread of the nodal
    radii (std / stretch) as "nodal spread"."""
    r = solve_section(lambda material: thin_wall_pressure(stretch, material), length)
    return Comparison(f"hoop stretch of a plane-strain section at p(l = {stretch:g})", float(stretch), float(r.mean()),
                      extra={"nodal spread": float(r.std() / stretch)})


def inflate_clamped_tube(stretches, length_radii) -> list[Comparison]:
    """A tube of ``length_radii`` radii with clamped end rings and fixed axial coordinates,
    inflated successively to each of ``stretches``; the middle ring's mean stretch against the
    plane-strain thin-wall value."""
    length = length_radii * TUBE_RADIUS
    shell, ring, cos_factor = inflation_tube(length)
    free = np.ones(shell.x0.shape, dtype=bool)
    free[:, 0] = False
    free[(ring == 0) | (ring == ring.max())] = False
    middle = ring == ring.max() // 2
    x = shell.x0
    out = []
    for stretch in stretches:
        pressure = float(thin_wall_pressure(stretch)) / cos_factor

        def potential(x, f, pressure=pressure):
            energy = shell.internal_forces(x, f)
            shell.pressure_forces(x, pressure, f)
            # End rings fixed: the open tube's signed volume is a valid potential.
            return energy - pressure * shell.enclosed_volume(x)

        x, _ = minimize_energy(x, free, potential, force_tol=1e-5 * pressure * TUBE_H**2)
        r = np.hypot(x[middle, 1], x[middle, 2]) / TUBE_RADIUS
        out.append(Comparison(f"middle-ring hoop stretch, clamped tube L = {length_radii:g} R, p(l = {stretch:g})",
                              float(stretch), float(r.mean())))
    return out


SHEET_SIDE, SHEET_H = 0.06, 0.003  # m: 516 nodes; the interior (2 h from the edges) holds ~900 hinges


def bending_sheet(material=None):
    """The flat near-equilateral sheet of the bending checks."""
    nodes, tri = flat_sheet(SHEET_SIDE, SHEET_SIDE, SHEET_H)
    return Shell(nodes, tri, WALL_T, material or reference_material())


def onto_cylinder(nodes, radius, angle):
    """Isometric map of the z = 0 sheet onto a cylinder whose axis makes ``angle`` (rad) with x."""
    axis = np.array([np.cos(angle), np.sin(angle), 0.0])
    across = np.array([-np.sin(angle), np.cos(angle), 0.0])
    p = nodes - [SHEET_SIDE / 2, SHEET_SIDE / 2, 0.0]
    s, a = p @ across, p @ axis
    x = a[:, None] * axis + (radius * np.sin(s / radius))[:, None] * across
    x[:, 2] = radius * (1.0 - np.cos(s / radius))
    return np.ascontiguousarray(x)


def onto_sphere(nodes, radius):
    """Map of the sheet onto a spherical cap (radial distances kept as arc lengths)."""
    p = nodes - [SHEET_SIDE / 2, SHEET_SIDE / 2, 0.0]
    rho = np.hypot(p[:, 0], p[:, 1])
    scale = np.where(rho > 0, radius * np.sin(rho / radius) / np.where(rho > 0, rho, 1.0), 1.0)
    return np.ascontiguousarray(np.column_stack((p[:, 0] * scale, p[:, 1] * scale, radius * (1 - np.cos(rho / radius)))))


def interior_energy_density(shell, x):
    """Hinge energy per unit area away from the sheet's edges, J/m^2.

    Each hinge stands for (A_1 + A_2)/3 of area. A rectangular window cuts the three edge
    directions of the mesh unequally, and for a cylinder the hinge angle depends on the edge
    direction, so the density is summed per direction class (mean energy of the class over the
    mean hinge area), which is what an unbounded mesh gives.
    """
    nodes, hinge = shell.x0, shell.hinges
    edge = nodes[hinge[:, 1]] - nodes[hinge[:, 0]]
    area_pair = 0.5 * (
        np.linalg.norm(np.cross(edge, nodes[hinge[:, 2]] - nodes[hinge[:, 0]]), axis=1)
        + np.linalg.norm(np.cross(nodes[hinge[:, 3]] - nodes[hinge[:, 0]], edge), axis=1)
    )
    direction = np.round(np.degrees(np.arctan2(edge[:, 1], edge[:, 0])) % 180.0 / 60.0).astype(int) % 3
    centre = nodes[hinge].mean(axis=1)
    inside = np.all((centre[:, :2] > 2 * SHEET_H) & (centre[:, :2] < SHEET_SIDE - 2 * SHEET_H), axis=1)
    energy = shell.hinge_stiffness * dihedral_angles(x, hinge) ** 2
    return sum(energy[inside & (direction == k)].mean() for k in range(3)) / area_pair[inside].mean()


def cylinder_bending(radius, angle_deg) -> Comparison:
    """Interior hinge energy density of the sheet rolled onto a cylinder against D / (2 R^2)."""
    shell = bending_sheet()
    x = onto_cylinder(shell.x0, radius, np.radians(angle_deg))
    return Comparison(f"bending energy density D / (2 R^2), cylinder R = {radius * 100:g} cm, axis at {angle_deg:g} deg",
                      shell.bending_stiffness / (2.0 * radius**2), float(interior_energy_density(shell, x)), "J/m^2")


def sphere_bending(radius) -> Comparison:
    """Interior hinge energy density on a spherical cap against the hinge model's own value
    (2/3) D / R^2 (intrinsic Poisson ratio -1/3, derived with the shell's hinge kernels)."""
    shell = bending_sheet()
    x = onto_sphere(shell.x0, radius)
    return Comparison(f"bending energy density (2/3) D / R^2 of the hinge model, sphere R = {radius * 100:g} cm",
                      2.0 / 3.0 * shell.bending_stiffness / radius**2, float(interior_energy_density(shell, x)), "J/m^2")

