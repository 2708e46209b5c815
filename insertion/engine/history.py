"""The time series an explicit run records (:meth:`colonsim.insertion.engine.solver.ExplicitSolver.run`)."""

import numpy as np


class History:
    """Time series recorded by :meth:`ExplicitSolver.run`.

    Attributes
    ----------
    time : (k,) array, s
    step : (k,) int array
    bodies : dict
        ``bodies[name][quantity]`` arrays: ``kinetic``, ``internal``, ``dissipated`` (damping),
        ``external_work`` (loads + constraint reactions), ``contact_work`` (work of contact forces on
        the body), ``positions`` (k, n, 3) if recorded.
    contacts : list of dict
        Per contact: ``energy`` (penalty), ``dissipated`` (contact damping + friction),
        ``friction_dissipated``, ``normal_force`` (sum of normal forces, N), ``force_on_rod`` (k, 3),
        ``n_active``, ``n_candidates``.
    reactions : list of (k, 3) arrays
        Total reaction force of each constraint (N), in the solver's constraint order.
    """

    def __init__(self):
        self._rows = []

    def _append(self, row):
        self._rows.append(row)

    def _finish(self, body_names, n_contacts, n_constraints):
        rows = self._rows
        self.time = np.array([r["time"] for r in rows])
        self.step = np.array([r["step"] for r in rows], dtype=np.int64)
        self.bodies = {}
        for name in body_names:
            d = {}
            for q in ("kinetic", "internal", "dissipated", "external_work", "contact_work"):
                d[q] = np.array([r["bodies"][name][q] for r in rows])
            if rows and "positions" in rows[0]["bodies"][name]:
                d["positions"] = np.array([r["bodies"][name]["positions"] for r in rows])
            self.bodies[name] = d
        self.contacts = []
        for c in range(n_contacts):
            keys = rows[0]["contacts"][c].keys() if rows else ()
            self.contacts.append({q: np.array([r["contacts"][c][q] for r in rows]) for q in keys})
        self.reactions = [np.array([r["reactions"][j] for r in rows]).reshape(-1, 3) for j in range(n_constraints)]
        return self

    def total_energy_balance(self):
        """Energy balance residual (k,), J: sum of kinetic + internal + dissipated energy of all bodies
        and contacts minus all external work; constant (its initial value) for a consistent run."""
        total = np.zeros_like(self.time)
        for d in self.bodies.values():
            total += d["kinetic"] + d["internal"] + d["dissipated"] - d["external_work"]
        for c in self.contacts:
            total += c["energy"] + c["dissipated"]
        return total
