"""Patient-level queries: named presets for sex, age and region, next to raw parameters.

The mapping is the project's reading of the source (docs/model.md, "Patients"), not a clinical law; every
value can be overridden by a JSON file or by giving the raw parameter:

- sex -> the angle of the mobile part: alpha of the sigmoid (RSF) and beta of the transverse colon
  (THF), in the colon models whose catalog entry says so (``surrogate_angle``). The source: women
  have a lower sigmoid-descending fixation and longer, deeper transverse colons, i.e. larger
  angles. Reading: male-like 0 deg, intermediate 30 deg, female-like 45 deg (the three angles
  the source simulated). No effect on RSJ (fixed angulation) or fixed THF.
- age -> Coulomb friction between scope and wall (older patients, diverticular disease, more
  friction). Reading: young 0, middle 0.05, older 0.1 (the source's three values). The source
  also ties age to the fixed sigmoid angulation; the segments here keep that angulation fixed.
- region -> colon inner diameter, from Watters et al. 1985 for the RSJ: European 23 mm, African
  36 mm. The source gives no regional diameters for the other segments: there the preset leaves
  the diameter to the model (its fixed value, 36 mm by the model's assumption).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field

from colonsim.catalog import COLON_MODELS
from colonsim.errors import ColonsimError
from colonsim.inputs import read_input_text


@dataclass(frozen=True)
class PatientPresets:
    """Named patient categories -> model inputs (degrees, Coulomb mu, mm)."""

    sex_angle_deg: dict = field(default_factory=lambda: {"male": 0.0, "intermediate": 30.0, "female": 45.0})
    age_friction: dict = field(default_factory=lambda: {"young": 0.0, "middle": 0.05, "older": 0.1})
    region_diameter_mm: dict = field(default_factory=lambda: {"rsj": {"european": 23.0, "african": 36.0}})

    @classmethod
    def from_json(cls, path):
        """Presets with the entries of a JSON file (same keys as the attributes) replacing the defaults."""
        try:
            doc = json.loads(read_input_text(path, "presets file"))
        except json.JSONDecodeError as exc:
            raise ColonsimError(f"presets file {path} is not valid JSON ({exc})") from None
        if not isinstance(doc, dict):
            raise ColonsimError(f"presets file {path} must hold a JSON object (keys sex_angle_deg, age_friction, "
                                "region_diameter_mm)")
        unknown = sorted(set(doc) - {"sex_angle_deg", "age_friction", "region_diameter_mm"})
        if unknown:
            raise ColonsimError(f"presets file {path}: unknown key(s) {', '.join(unknown)}; use sex_angle_deg, "
                                "age_friction, region_diameter_mm")
        base = cls()
        return cls(**{k: {**getattr(base, k), **doc.get(k, {})} for k in ("sex_angle_deg", "age_friction",
                                                                          "region_diameter_mm")})

    def to_dict(self):
        return {"sex_angle_deg": self.sex_angle_deg, "age_friction": self.age_friction,
                "region_diameter_mm": self.region_diameter_mm}


def _lookup(table, value, what):
    key = str(value).strip().lower()
    if key not in table:
        raise ColonsimError(f"unknown {what} {value!r}; choose {', '.join(table)} (or give the raw parameter)")
    return table[key]


def patient_inputs(segment, sex=None, age=None, region=None, presets=None) -> dict:
    """Model inputs of a patient described by presets, for ``segment``.

    Returns only what the presets determine (angle_deg, friction, diameter_mm); raw parameters a
    caller also has take precedence (``{**patient_inputs(...), **raw}``)."""
    presets = presets or PatientPresets()
    segment = str(segment).lower()
    values = {}
    if sex is not None:
        angle = _lookup(presets.sex_angle_deg, sex, "sex")
        model = COLON_MODELS.get(segment)
        if model is not None and model.surrogate_angle:
            values["angle_deg"] = angle
    if age is not None:
        values["friction"] = _lookup(presets.age_friction, age, "age group")
    if region is not None:
        by_segment = presets.region_diameter_mm.get(segment)
        if by_segment is not None:
            values["diameter_mm"] = _lookup(by_segment, region, "region")
        else:
            # validate the name even where it maps to nothing, so a typo is not silently ignored
            names = {r for table in presets.region_diameter_mm.values() for r in table}
            if str(region).strip().lower() not in names:
                raise ColonsimError(f"unknown region {region!r}; choose {', '.join(sorted(names))}")
    return values


def describe_patient(segment, sex=None, age=None, region=None, presets=None) -> str:
    """A short text of how the presets map onto this segment's inputs."""
    v = patient_inputs(segment, sex, age, region, presets)
    parts = []
    if sex is not None:
        parts.append(f"sex {sex} -> angle {v['angle_deg']:g} deg" if "angle_deg" in v else f"sex {sex} (no angle in {segment})")
    if age is not None:
        parts.append(f"age {age} -> friction {v['friction']:g}")
    if region is not None:
        parts.append(f"region {region} -> diameter {v['diameter_mm']:g} mm" if "diameter_mm" in v
                     else f"region {region} (no regional diameter for {segment} in the source)")
    return ", ".join(parts)
