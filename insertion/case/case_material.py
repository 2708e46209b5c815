"""The wall material of one insertion: its material file, with drawn parameters in place of the file's.

A sweep's ``[material]`` section (:mod:`colonsim.insertion.study.material_samples`) gives each case
the parameters of one draw (``InsertionCase.material_parameters``, {name: Pa}); the law stays that
of the case's material file, so a draw can never change the law, only its parameters.
"""

from __future__ import annotations

import math

from colonsim.errors import ColonsimError
from colonsim.laws import OgdenLaw
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, WallMaterial, load_material


def case_material(path=None, parameters=None, stiffness_factor=1.0) -> WallMaterial:
    """The material file at ``path`` (None: the reference material), with ``parameters`` replacing
    its parameters when given, and every parameter in Pa times ``stiffness_factor``.

    Parameters
    ----------
    path : str or None
        Material JSON (``colonsim calibrate`` output).
    parameters : dict or None
        {name: value in Pa} naming exactly the file's law's parameters; finite, >= 0, with a
        positive small-strain shear modulus (checked by :class:`WallMaterial`).
    stiffness_factor : float
        The wall's stiffness relative to the material (:mod:`colonsim.insertion.study.tissue_stiffness`):
        its strain energy and stress at every stretch times this factor. A parameter in Pa scales
        with it, a dimensionless one (Ogden's exponents) does not.
    """
    material = load_material(path or REFERENCE_MATERIAL_PATH)
    if parameters is None:
        return _scaled(material, stiffness_factor)
    names = material.law_model.parameter_names
    if not isinstance(parameters, dict) or set(parameters) != set(names):
        given = ", ".join(map(str, parameters)) if isinstance(parameters, dict) else repr(parameters)
        raise ColonsimError(f"material_parameters ({given}) must name exactly the parameters of law {material.law} of "
                            f"{path or REFERENCE_MATERIAL_PATH}: {', '.join(names)}, in Pa")
    try:
        return _scaled(WallMaterial(material.law, tuple(parameters[name] for name in names)), stiffness_factor)
    except ColonsimError as exc:
        raise ColonsimError(f"material_parameters: {exc}") from None


def _scaled(material: WallMaterial, factor) -> WallMaterial:
    if factor == 1.0:
        return material
    if not (isinstance(factor, (int, float)) and math.isfinite(factor) and factor > 0):
        raise ColonsimError(f"stiffness_factor = {factor!r}; give a positive number (1: the material as given)")
    model = material.law_model
    units = model.units if isinstance(model, OgdenLaw) else ("Pa",) * len(material.parameters)
    return WallMaterial(material.law, tuple(v * factor if unit == "Pa" else v
                                            for v, unit in zip(material.parameters, units)))
