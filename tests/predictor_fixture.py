"""A SYNTHETIC patient-space table for the predictor's tests - not physics.

The outputs are a made-up smooth function of the patient-space inputs plus Gaussian noise; the
table has the columns a patient-space sweep writes (the tissue as a stiffness factor, with mu0 and
C11 of the reference law scaled by it). Tests fit a tiny model on it to exercise the predictor's
machinery; nothing here is shipped or says anything about colons.
"""

import numpy as np
import pandas as pd

from colonsim.catalog import TISSUE_STIFFNESS, WALL_C11, WALL_MU0

REFERENCE_MU0_KPA, REFERENCE_C11_KPA = 2 * (652.01 + 42835.25) / 1e3, 219.1203
RANGES = {"scope_diameter_mm": (9.0, 13.5), "angle_deg": (0.0, 60.0), "diameter_mm": (25.0, 40.0),
          "friction": (0.0, 0.1), "distal_resistance_N": (0.0, 20.0), TISSUE_STIFFNESS: (0.6, 1.6)}


def made_up_deformation(x):
    """SYNTHETIC largest deformation (cm) of input columns ``x`` (a mapping)."""
    return (1.0 + 0.3 * (x["scope_diameter_mm"] - 9.0) + 0.8 * np.sin(np.radians(x["angle_deg"]))
            - 0.02 * (x["diameter_mm"] - 30.0) + 3.0 * x["friction"] + 0.03 * x["distal_resistance_N"]
            - 0.5 * (x[TISSUE_STIFFNESS] - 1.0))


def synthetic_patient_table(n=40, seed=0, noise_cm=0.02, folded=0, bias_cm=0.0, shrink=0.0, segment="rsf",
                            ranges=None):
    """A SYNTHETIC results table of ``n`` runs of ``segment`` (inputs uniform in :data:`RANGES`,
    updated by ``ranges``, shrunk by ``shrink`` of each range at either end; a range (v, v) holds
    the input at v); ``folded`` runs end with a folded tip (and a wild value, which training must
    not see); ``bias_cm`` shifts every output."""
    rng = np.random.default_rng(seed)
    x = {k: rng.uniform(lo + shrink * (hi - lo), hi - shrink * (hi - lo), n)
         for k, (lo, hi) in {**RANGES, **(ranges or {})}.items()}
    largest = made_up_deformation(x) + bias_cm + rng.normal(0.0, noise_cm, n)
    final = 0.8 * largest + rng.normal(0.0, noise_cm, n)
    ended = np.array(["length_used"] * n, dtype=object)
    ended[:folded] = "tip_folded"
    largest[:folded] += 5.0
    return pd.DataFrame({
        "key": [f"{segment}-{seed}-{i:03d}" for i in range(n)], "status": "ok", "error": "", "wall_time_s": 1.0,
        "git_commit": "0123abc", "segment": segment, "scope": [f"{d:.3f}" for d in x["scope_diameter_mm"]],
        **{k: np.round(v, 3) for k, v in x.items()},
        WALL_MU0: REFERENCE_MU0_KPA * np.round(x[TISSUE_STIFFNESS], 3),
        WALL_C11: REFERENCE_C11_KPA * np.round(x[TISSUE_STIFFNESS], 3),
        "wall_thickness_mm": 2.0, "material": "", "element_size_mm": 3.0, "ended_by": ended,
        "max_deformation_cm": largest, "final_deformation_cm": final})
