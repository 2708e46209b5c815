"""The sweep presets (``colonsim sweep --preset NAME``, docs/sweeps.md): TOML text in the format
:mod:`colonsim.insertion.study.sweep_spec` reads, one entry per preset.
"""

from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
from colonsim.insertion.case.insertion_case import InsertionCase

# The rate check's push speed: half the default (docs/model.md, "Time integration and damping").
HALF_SPEED = 0.5 * InsertionCase.push_speed

PRESETS = {
    # The source's Chapter V: RSJ D23/D36 x 3 scopes x mu 0/0.05/0.1 (18 runs); RSF alpha and THF
    # beta 0/30/45 x 3 scopes at mu 0 (18); fixed THF x 3 scopes (3). The scopes have the
    # diameters of the source's meshes (9.2 / 11.1 / 13.3 mm), not the catalogue's (9.2 / 11.3 / 12.8).
    "thesis": """
[sweep]
name = "thesis"
description = "Every insertion of the source's Chapter V: RSJ, RSF, THF and fixed THF, with the scope diameters of its meshes (9.2 / 11.1 / 13.3 mm)"

[[grid]]
segment = "rsj"
scope = ["9.2", "11.1", "13.3"]
diameter_mm = [23, 36]
friction = [0, 0.05, 0.1]

[[grid]]
segment = ["rsf", "thf"]
scope = ["9.2", "11.1", "13.3"]
angle_deg = [0, 30, 45]

[[grid]]
segment = "thf-fixed"
scope = ["9.2", "11.1", "13.3"]
""",
    # The validation report's own runs beside the thesis sweep: the mesh pair (2 mm against the
    # thesis sweep's 3 mm) of the thickest scope in one case per colon model, the rate check (half
    # the default push speed) of every scope in one case per colon model,
    # and the flexure-angle sensitivity of RSF/THF at alpha = beta = 45 deg (135 and 180 deg
    # against the default 90), for the thinnest and the thickest scope.
    "validation": f"""
[sweep]
name = "validation"
description = "Mesh pair, rate check and flexure-angle sensitivity beside the thesis sweep (scope meshes 9.2 / 11.1 / 13.3 mm)"

[[grid]]
segment = "rsj"
scope = "13.3"
diameter_mm = 36
element_size_mm = 2

[[grid]]
segment = "rsj"
scope = ["9.2", "11.1", "13.3"]
diameter_mm = 36
push_speed = {HALF_SPEED:g}

[[grid]]
segment = ["rsf", "thf"]
scope = "13.3"
angle_deg = 45
element_size_mm = 2

[[grid]]
segment = ["rsf", "thf"]
scope = ["9.2", "11.1", "13.3"]
angle_deg = 45
push_speed = {HALF_SPEED:g}

[[grid]]
segment = "thf-fixed"
scope = "13.3"
element_size_mm = 2

[[grid]]
segment = "thf-fixed"
scope = ["9.2", "11.1", "13.3"]
push_speed = {HALF_SPEED:g}

[[grid]]
segment = ["rsf", "thf"]
scope = ["9.2", "13.3"]
angle_deg = 45
flexure_angle_deg = [135, 180]
""",
    # The distal resistance study (docs/model.md, "Loading"): every colon model at the four clinical
    # levels 0 / 5 / 10 / 20 N, the source's angles and the three meshed scopes (132 runs), and
    # the rate check at 10 N (half the push speed) of the thickest scope in one case per model (4).
    "resistance": f"""
[sweep]
name = "resistance"
description = "Distal resistance 0 / 5 / 10 / 20 N: RSJ D23/D36, RSF alpha, THF and fixed THF beta 0/30/45, scopes 9.2 / 11.1 / 13.3 mm, and the rate check at 10 N"

[[grid]]
segment = "rsj"
scope = ["9.2", "11.1", "13.3"]
diameter_mm = [23, 36]
distal_resistance_N = [0, 5, 10, 20]

[[grid]]
segment = ["rsf", "thf", "thf-fixed"]
scope = ["9.2", "11.1", "13.3"]
angle_deg = [0, 30, 45]
distal_resistance_N = [0, 5, 10, 20]

[[grid]]
segment = "rsj"
scope = "13.3"
diameter_mm = 36
distal_resistance_N = 10
push_speed = {HALF_SPEED:g}

[[grid]]
segment = ["rsf", "thf", "thf-fixed"]
scope = "13.3"
angle_deg = 45
distal_resistance_N = 10
push_speed = {HALF_SPEED:g}
""",
    # A few runs of a few seconds each on a coarse wall mesh: for tests and for checking a setup.
    "smoke": f"""
[sweep]
name = "smoke"
description = "Three fast runs on a coarse {SMOKE_ELEMENT_MM:g} mm wall mesh, pushed at {SMOKE_PUSH_SPEED:g} m/s (tests, setup checks); not physics"

[fixed]
element_size_mm = {SMOKE_ELEMENT_MM}
scope_spacing_mm = {SMOKE_SCOPE_SPACING_MM}
push_speed = {SMOKE_PUSH_SPEED}

[[grid]]
segment = "straight"
scope = "pdc"

[[grid]]
segment = "rsj"
scope = ["utc", "sdc"]
friction = [0.05]
""",
}
