"""The wall material of one insertion: its material file, with drawn parameters in place of the file's.

A sweep's ``[material]`` section (:mod:`colonsim.insertion.study.material_samples`) gives each case
the parameters of one draw (``InsertionCase.material_parameters``, {name: Pa}); the law stays that
of the case's material file, so a draw can never change the law, only its parameters.
"""

from __future__ import annotations

from colonsim.errors import ColonsimError
from colonsim.insertion.engine.material import REFERENCE_MATERIAL_PATH, WallMaterial, load_material


def case_material(path=None, parameters=None) -> WallMaterial:
    """The material file at ``path`` (None: the reference material), with ``parameters`` replacing
    its parameters when given.

    Parameters
    ----------
    path : str or None
        Material JSON (``colonsim calibrate`` output).
    parameters : dict or None
        {name: value in Pa} naming exactly the file's law's parameters; finite, >= 0, with a
        positive small-strain shear modulus (checked by :class:`WallMaterial`).
    """
    material = load_material(path or REFERENCE_MATERIAL_PATH)
    if parameters is None:
        return material
    names = material.law_model.parameter_names
    if not isinstance(parameters, dict) or set(parameters) != set(names):
        given = ", ".join(map(str, parameters)) if isinstance(parameters, dict) else repr(parameters)
        raise ColonsimError(f"material_parameters ({given}) must name exactly the parameters of law {material.law} of "
                            f"{path or REFERENCE_MATERIAL_PATH}: {', '.join(names)}, in Pa")
    try:
        return WallMaterial(material.law, tuple(parameters[name] for name in names))
    except ColonsimError as exc:
        raise ColonsimError(f"material_parameters: {exc}") from None
