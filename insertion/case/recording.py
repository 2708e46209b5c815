"""What an insertion records at every sample (docs/model.md, "Outputs"), as a solver callback.

Columns (SI): time_s, depth_m (pushed distance), deformation_m (largest nodal displacement of
the mobile colon part), max_stretch (largest in-plane principal stretch of the wall), tip_displacement_m,
tip_arc_m (tip position along the centerline: the arc length of its nearest point,
:func:`colonsim.insertion.case.outcomes.arc_along`), tip_past_end_m
(signed distance of the tip past the end plane of the run: >= 0 once it has passed the fixed end),
lag_m (the scope's lag: pushed depth minus the tip's advance along the centerline), tip_heading_deg
(the angle between the scope's last segment and the lumen's direction at the tip: 0 on along it,
above 90 turned back, :func:`colonsim.insertion.case.outcomes.tip_heading`), distal_force_N
(the distal resistance holding the tip back, :mod:`colonsim.insertion.engine.tip_resistance`; 0
without one), contact_force_N (sum of normal contact forces),
push_force_N (drive reaction along the sheath axis), contact_nodes, kinetic/internal energy
of each body (J), kinetic_scope_sliding_J (the scope's kinetic energy relative to sliding along
itself at the push speed, :func:`colonsim.insertion.case.outcomes.sliding_kinetic_energy`), contact_energy_J, dt_s, step.

Beside the rows: snapshots of the wall and the scope (with a snapshot interval: VTU files, the
animation) and the wall-stretch record (:class:`colonsim.insertion.case.stretch_map.WallStretch`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from colonsim.insertion.case.outcomes import (JAM_PUSH, arc_along, jammed, principal_stretches,
                                             sliding_kinetic_energy, tip_heading)
from colonsim.insertion.case.stretch_map import WallStretch, attach
from colonsim.insertion.engine.contact_broad_phase import max_displacement_at


class InsertionRecorder:
    """Solver callback collecting one row per recorded sample (and optional snapshots)."""

    def __init__(self, model, snapshot_interval=None):
        self.model = model
        self.rows = []
        self.snapshots = []  # (time, colon positions, scope positions)
        self.snapshot_interval = snapshot_interval
        self._next_snapshot = 0.0
        g = model.geometry
        self._mobile = np.ascontiguousarray(model.mobile_nodes, dtype=np.int64)
        # held triangles stay at rest (stretch 1): the largest stretch is that of the others, and
        # the wall-stretch map keeps each one's largest over the run from the same measurement
        held = np.zeros(len(model.shell.x0), dtype=bool)
        held[model.fixed_nodes] = True
        self.wall = WallStretch(model.shell.triangles, model.shell.dm_inv, held)
        attach(model, self.wall)
        self._tip = model.rod.tip_node
        self._tip0 = model.rod.x0[self._tip].copy()
        s = np.linspace(0.0, g.centerline_length, max(200, int(g.centerline_length / 1e-3)))
        self._arc = s
        self._arc_points = np.ascontiguousarray(g.centerline_points(s), dtype=np.float64)
        tangents = np.gradient(self._arc_points, s, axis=0)
        self._arc_tangents = tangents / np.linalg.norm(tangents, axis=1)[:, None]
        # the plane whose crossing by the tip ends the run
        ends = np.clip([model.tip_end - 1e-4, model.tip_end, model.tip_end + 1e-4], 0.0, g.centerline_length)
        p = np.asarray(g.centerline_points(ends))
        self._end_point = p[1]
        self._end_axis = (p[2] - p[0]) / np.linalg.norm(p[2] - p[0])

    def __call__(self, solver):
        m = self.model
        colon = solver.state["colon"]
        scope = solver.state[m.rod.name]
        deformation = max_displacement_at(colon.x, m.shell.x0, self._mobile)
        tip = scope.x[self._tip]
        depth = m.push.depth(solver.time)
        tip_arc = float(arc_along(self._arc_points, self._arc, self._arc_tangents, tip))
        stretches = principal_stretches(colon.x, self.wall.triangles, self.wall.dm_inv)
        self.wall.sample(stretches, deformation, colon.f_con)
        row = {
            "time_s": solver.time,
            "step": solver.step,
            "dt_s": solver.dt,
            "depth_m": depth,
            "deformation_m": deformation,
            "max_stretch": float(stretches.max()),
            "tip_displacement_m": float(np.linalg.norm(tip - self._tip0)),
            "tip_arc_m": tip_arc,
            "tip_past_end_m": float(np.dot(tip - self._end_point, self._end_axis)),
            "lag_m": depth - tip_arc,
            "tip_heading_deg": tip_heading(scope.x, self._tip, self._arc, self._arc_tangents, tip_arc),
            "distal_force_N": float(m.resistance.force) if m.resistance is not None else 0.0,
            "contact_force_N": float(m.contact.normal_force),
            "contact_nodes": int(m.contact.n_active),
            "push_force_N": float(np.dot(m.drive.reaction, m.entry_axis)),
            "kinetic_colon_J": colon.kinetic,
            "internal_colon_J": colon.internal,
            "kinetic_scope_J": scope.kinetic,
            "kinetic_scope_sliding_J": sliding_kinetic_energy(scope.x, scope.v, m.rod.mass, m.push.speed(solver.time)),
            "internal_scope_J": scope.internal,
            "contact_energy_J": float(m.contact.energy),
            "phase": m.push.phase_at(solver.time).name,
        }
        self.rows.append(row)
        if self.snapshot_interval is not None and solver.time >= self._next_snapshot - 1e-12:
            self.snapshots.append((solver.time, colon.x.copy(), scope.x.copy()))
            self._next_snapshot += self.snapshot_interval

    def jammed(self) -> bool:
        """Has the tip jammed at the last sample (:func:`colonsim.insertion.case.outcomes.jammed`)?"""
        if not self.rows:
            return False
        depth = self.rows[-1]["depth_m"]
        tail = []
        for row in reversed(self.rows):  # the samples of the last window of push
            tail.append(row)
            if row["depth_m"] <= depth - JAM_PUSH:
                break
        tail.reverse()
        return jammed([r["depth_m"] for r in tail], [r["tip_arc_m"] for r in tail], [r["push_force_N"] for r in tail])

    def frame(self) -> pd.DataFrame:
        return pd.DataFrame(self.rows)
