"""SYNTHETIC sweep tables for testing the regression machinery - not physics.

The outputs are a known smooth function of the inputs plus small Gaussian noise, loosely scaled
to the source's RSJ numbers (docs/model.md) so that tables look like real ones: deformation grows
with the scope diameter, falls with the colon diameter, grows with the angle and the friction.
Tests check that the surrogate recovers the function within its stated accuracy; the benchmark
times fits on such tables. Nothing here says anything about colons.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from colonsim.surrogate.table import NAMED_SCOPES_MM


def synthetic_deformation(scope_diameter_mm, diameter_mm, angle_deg, friction):
    """The known function: final colon deformation in cm (SYNTHETIC)."""
    sd, D, a, mu = (np.asarray(v, dtype=float) for v in (scope_diameter_mm, diameter_mm, angle_deg, friction))
    caliber = 0.40 * (sd - 9.2) + 0.03 * (sd - 9.2) ** 2
    return (2.4 + caliber * (1.0 + 0.25 * (36.0 - D) / 13.0) - 0.012 * (D - 36.0)
            + 0.9 * np.sin(np.radians(a)) * (0.6 + 0.4 * (sd - 9.2) / 3.6) + 4.0 * mu * (0.5 + 0.5 * (sd - 9.2) / 3.6))


def synthetic_outputs(segment, scope_diameter_mm, diameter_mm, angle_deg, friction):
    """All outputs of the table (SYNTHETIC), NaN where the contract leaves them undefined."""
    final = synthetic_deformation(scope_diameter_mm, diameter_mm, angle_deg, friction)
    rsj = segment == "rsj"
    nan = np.full_like(final, np.nan)
    # RSJ: the largest deformation is the larger of points A and C, as in real runs (colonsim.catalog.LARGER_OF)
    return {"final_deformation_cm": final, "max_deformation_cm": final if rsj else 1.05 * final,
            "point_A_cm": 0.55 * final if rsj else nan, "point_B_cm": 0.45 * final if rsj else nan,
            "point_C_cm": final if rsj else nan,
            "peak_contact_force_N": 0.5 + 0.08 * np.asarray(scope_diameter_mm) ** 1.5 * (1 + 3 * np.asarray(friction)),
            "peak_push_force_N": 1.0 + 2.0 * np.asarray(friction) + 0.05 * np.asarray(scope_diameter_mm),
            "max_wall_stretch": 1.05 + 0.03 * final}


def synthetic_sweep(n_runs=40, segments=("rsj", "rsf"), noise_cm=0.03, design="random", n_failed=1, seed=0, repeats=1):
    """A SYNTHETIC results table in the sweep's format.

    ``design="random"``: per segment ``n_runs`` runs with inputs drawn uniformly (scope 9.2-12.8 mm,
    RSJ diameter 23-36 mm, RSF/THF angle 0-45 deg, friction 0-0.1). ``design="grid"``: the sweep
    the project runs - UTC/PDC/SDC x diameters 23/36 (RSJ) or angles 0/30/45 x friction 0/0.05/0.1.
    ``noise_cm``: standard deviation of the noise added to the deformation outputs (others get
    a proportional share). ``n_failed`` runs per segment have status "failed" and NaN outputs.
    ``repeats``: each case of the design that many times, with its own scatter (a sweep that runs
    its cases again: with 2, the grid's 18 RSJ and 27 RSF runs become 36 and 54, enough for a
    model without replicate runs to state its error, ``validation.MIN_RUNS_PER_INPUT``).
    """
    rng = np.random.default_rng(seed)
    rows = []
    for segment in segments:
        angled = segment in ("rsf", "thf")
        if design == "grid":
            grid = [(name, d, D, a, mu) for name, d in NAMED_SCOPES_MM.items()
                    for D in ((23.0, 36.0) if segment == "rsj" else (36.0,))
                    for a in ((0.0, 30.0, 45.0) if angled else (0.0,)) for mu in (0.0, 0.05, 0.1)]
        else:
            grid = [("custom", round(rng.uniform(9.2, 12.8), 3), rng.uniform(23.0, 36.0) if segment == "rsj" else 36.0,
                     rng.uniform(0.0, 45.0) if angled else 0.0, rng.uniform(0.0, 0.1)) for _ in range(n_runs)]
        for i, (scope, d, D, a, mu) in enumerate(grid * int(repeats)):
            out = synthetic_outputs(segment, d, D, a, mu)
            noisy = {k: float(v) + (0.0 if np.isnan(v) else rng.normal(0.0, noise_cm) * (1.0 if k.endswith("_cm") else 0.2))
                     for k, v in out.items()}
            if segment == "rsj":  # C and the largest value are one sample; A can overtake it
                noisy["point_C_cm"] = noisy["max_deformation_cm"]
                noisy["max_deformation_cm"] = max(noisy["point_A_cm"], noisy["point_C_cm"])
            failed = i < n_failed
            rows.append({"key": f"{segment}-{i:04d}", "status": "failed" if failed else "ok",
                         "error": "SYNTHETIC failure" if failed else "", "wall_time_s": 1.0,
                         "timeseries_path": "", "finished_at": "2024-01-01T00:00:00",
                         "segment": segment, "scope": scope if scope != "custom" else f"{d:g}",
                         "scope_diameter_mm": float(d), "diameter_mm": float(D), "angle_deg": float(a), "friction": float(mu),
                         "wall_thickness_mm": 2.0, "material": "", "element_size_mm": 3.0,
                         **({k: np.nan for k in noisy} if failed else noisy),
                         "quasi_static": not failed, "simulated_time_s": 0.5})
    return pd.DataFrame(rows)
