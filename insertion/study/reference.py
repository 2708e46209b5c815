"""The source's reference numbers: LS-DYNA results of its Chapter V (X. He, MSc thesis, University of
Minnesota, 2018; docs/model.md, "Reference results").

Constants copied from the source; nothing here is computed by this project.
"""

from __future__ import annotations

import pandas as pd

# RSJ colon deformation (cm) at points A and C, mu = 0, per (scope, colon diameter mm).
# The source's final deformation equals the value at C.
SOURCE_RSJ_CM = {
    ("utc", 23.0): {"A": 1.353, "C": 2.575},
    ("utc", 36.0): {"A": 1.319, "C": 2.389},
    ("pdc", 23.0): {"A": 2.155, "C": 3.384},
    ("pdc", 36.0): {"A": 1.992, "C": 3.077},
    ("sdc", 23.0): {"A": 3.218, "C": 4.234},
    ("sdc", 36.0): {"A": 2.651, "C": 3.824},
}

# Run time of one insertion, minutes (LS-DYNA 17, 4-core i7-4600U laptop).
SOURCE_RUN_MINUTES = {
    ("rsj", "utc"): 50, ("rsj", "pdc"): 78, ("rsj", "sdc"): 100,
    ("rsf", "utc"): 150, ("rsf", "pdc"): 240, ("rsf", "sdc"): 380,
    ("thf", "utc"): 100, ("thf", "pdc"): 180, ("thf", "sdc"): 140,
}


def source_rsj_table() -> pd.DataFrame:
    """The source's RSJ numbers as rows of a sweep results table (``status`` ok, mu = 0)."""
    return pd.DataFrame([{"segment": "rsj", "scope": scope, "diameter_mm": d, "friction": 0.0, "angle_deg": 0.0,
                          "point_A_cm": v["A"], "point_C_cm": v["C"], "final_deformation_cm": v["C"], "status": "ok"}
                         for (scope, d), v in SOURCE_RSJ_CM.items()])

# Wall nodes and triangles of the source's colon meshes (None: not given), per (segment, colon
# diameter mm, angle deg).
SOURCE_MESHES = {
    ("rsj", 23.0, 0.0): (2064, 4076),
    ("rsj", 36.0, 0.0): (2792, 5504),
    ("rsf", 36.0, 0.0): (6632, 13188),
    ("thf", 36.0, 0.0): (4086, 7832),
    ("thf", 36.0, 30.0): (5324, None),
    ("thf", 36.0, 45.0): (5977, None),
}

