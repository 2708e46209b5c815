"""The input ranges every command shares (an insertion, a sweep case, a surrogate query alike),
each defined once: outside them no patient lies, whatever the training domain of a surrogate says.
"""

from colonsim.catalog import SCOPE_DIAMETER_RANGE, TISSUE_STIFFNESS
from colonsim.errors import ColonsimError

# name -> (low, high, what to give)
INPUT_RANGES = {
    "diameter_mm": (10.0, 80.0, "colon inner diameter in mm (23 or 36 in the source)"),
    "wall_thickness_mm": (0.2, 10.0, "wall thickness in mm (2 assumed)"),
    "friction": (0.0, 1.0, "Coulomb friction coefficient (the source used 0, 0.05, 0.1)"),
    "flexure_angle_deg": (1.0, 180.0, "flexure turn in degrees (90 by default)"),
    "exit_length_mm": (0.0, 400.0, "fixed exit length in mm (100 by default)"),
    "distal_resistance_N": (0.0, 100.0, "distal resistance in N (5 by default; 0, 5, 10, 20 are the study's levels)"),
    "element_size_mm": (0.5, 20.0, "wall element size in mm (3 by default)"),
    "scope_diameter_mm": (SCOPE_DIAMETER_RANGE[0] * 1e3, SCOPE_DIAMETER_RANGE[1] * 1e3, "scope outer diameter in mm"),
    TISSUE_STIFFNESS: (0.05, 20.0, "tissue stiffness factor on the reference wall law (1: the reference)"),
    "stiffness_factor": (0.05, 20.0, "factor on the wall material's parameters in Pa (1: the material as given)"),
}


def check_input_range(name, value, where=""):
    """Refuse ``value`` of input ``name`` outside :data:`INPUT_RANGES` (no-op for other names).

    Raises
    ------
    ColonsimError
        Naming the input, the value, the range and what to give (``where``: a prefix, e.g. a query).
    """
    if name not in INPUT_RANGES:
        return
    low, high, what = INPUT_RANGES[name]
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = float("nan")
    if not low <= number <= high:
        shown = f"{number:g}" if number == number else repr(value)
        raise ColonsimError(f"{where}{name} = {shown} is outside [{low:g}, {high:g}]; give the {what}")
