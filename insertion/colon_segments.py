"""The colon models of the study as simulation-ready geometry (SPEC.md 2.1).

:func:`colon_geometry` returns a :class:`ColonGeometry`: the wall mesh at the mid-surface (the
lumen diameter D plus one wall thickness, because contact acts half a thickness inside the
mid-surface), the node tags (fixed, mobile, end rings), the entry point and axis of the scope,
the centerline, and what the manoeuvre needs (where straightening ends, the axes of the
straight mobile pieces). A straight tube (``"straight"``) is kept for sanity checks.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from colonsim.errors import ColonsimError
from insertion.sheet_mesh import straight_tube


@dataclass
class ColonGeometry:
    """Wall mesh and tags of one colon model (SI units)."""

    name: str
    nodes: np.ndarray
    triangles: np.ndarray
    fixed: np.ndarray
    mobile: np.ndarray
    end_ring: np.ndarray
    entry_point: np.ndarray
    entry_axis: np.ndarray
    centerline_length: float
    centerline_points: object  # callable s -> (n, 3)
    straighten_depth: float | None = None
    mobile_axes: list = field(default_factory=list)

    def summary(self) -> dict:
        return {"segment": self.name, "wall_nodes": int(len(self.nodes)), "wall_triangles": int(len(self.triangles)),
                "fixed_nodes": int(self.fixed.sum()), "mobile_nodes": int(self.mobile.sum()),
                "end_ring_nodes": int(self.end_ring.sum()), "centerline_length_cm": self.centerline_length * 100}


def straight_colon(length, diameter, element_size, wall_thickness, fixed_length=0.0) -> ColonGeometry:
    """A straight tube along +x, mobile between ``fixed_length`` from each end (the sanity case)."""
    nodes, triangles, ring = straight_tube(length, diameter + wall_thickness, element_size)
    x = nodes[:, 0]
    end_ring = (ring == 0) | (ring == ring.max())
    fixed = (x < fixed_length) | (x > length - fixed_length)
    return ColonGeometry(
        "straight", nodes, triangles, fixed & ~end_ring, ~fixed & ~end_ring, end_ring,
        entry_point=np.zeros(3), entry_axis=np.array([1.0, 0.0, 0.0]), centerline_length=float(length),
        centerline_points=lambda s: np.column_stack([np.asarray(s, float), np.zeros(np.size(s)), np.zeros(np.size(s))]),
    )


def colon_geometry(segment, diameter, angle_deg, element_size, wall_thickness) -> ColonGeometry:
    """The geometry of ``segment`` ("rsj", "rsf", "thf", "thf-fixed", or "straight")."""
    if segment == "straight":
        return straight_colon(0.20, diameter, element_size, wall_thickness)
    raise ColonsimError(f"colon segment {segment!r} is not available yet; use straight")
