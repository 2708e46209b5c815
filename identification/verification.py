"""Verification of the calibration chain: the specimen model against the closed form of
homogeneous uniaxial tension, its mesh convergence, and recovery of the known parameters of the
bundled synthetic specimens (``data/tensile/ground_truth.json``).

The ``*_check`` functions return the comparisons that the verification table
(:mod:`colonsim.insertion.study.verification_table`) judges; the recovery is asserted by
``tests/test_calibration.py`` and reported by ``validation/report.py``. Forces in N,
lengths in m, parameters in Pa.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from colonsim.data import TENSILE_DIR
from colonsim.laws import get_law
from colonsim.identification.membrane import membrane_stress
from colonsim.identification.pipeline import Budget, CalibrationResult
from colonsim.identification.population import calibrate_curve
from colonsim.identification.specimen import ClampedStripModel
from colonsim.identification.testdata import TensileCurve, read_manifest
from colonsim.identification.uniaxial import homogeneous_force
from colonsim.insertion.study.verification import Comparison

# docs/model.md: the source's identified parameters (C10, C01, C11), Pa.
REFERENCE = np.array([652.01, 42835.25, 219120.3])
# docs/model.md: free length and width of the source's strips, m; thickness 2 mm (an assumption).
STRIP = (0.1, 0.025, 0.002)
DISPLACEMENTS = np.linspace(3e-3, 60e-3, 6)  # up to 60 % strain, the end of the test
NAMES = ("C10", "C01", "C11")


@dataclass
class ForceCurve:
    """Force of a specimen model and of the homogeneous closed form at the same displacements."""

    displacement: np.ndarray  # m
    model: np.ndarray  # N
    closed_form: np.ndarray  # N

    @property
    def relative_difference(self) -> np.ndarray:
        return self.model / self.closed_form - 1.0


def specimen_against_closed_form(grips, params=REFERENCE, displacements=DISPLACEMENTS, strip=STRIP,
                                 law="mooney_rivlin_3") -> ForceCurve:
    """The FE strip with ``grips`` ("sliding": homogeneous, must equal the closed form;
    "clamped": the real test, a few percent stiffer) against :func:`homogeneous_force`."""
    length, width, thickness = strip
    d = np.asarray(displacements, dtype=float)
    fe = ClampedStripModel(length, width, thickness, law=law, grips=grips).solve(params, d)
    return ForceCurve(d, fe, homogeneous_force(d, length, width, thickness, get_law(law), params))


def membrane_uniaxial_stress(stretches, params=REFERENCE, law="mooney_rivlin_3"):
    """The plane-stress membrane law at F = diag(l, l^-1/2) against docs/model.md's closed form.

    Returns (axial nominal stress of the membrane, closed form, lateral stress of the membrane), Pa.
    """
    lam = np.asarray(stretches, dtype=float)
    F = np.zeros((lam.size, 4))
    F[:, 0], F[:, 3] = lam, lam**-0.5  # free lateral contraction of an incompressible sheet
    P = membrane_stress(F, get_law(law), params, tangent=False)
    return P[:, 0], get_law(law).uniaxial_nominal_stress(lam, params), P[:, 3]


def mesh_convergence(displacement=DISPLACEMENTS[-1], params=REFERENCE, strip=STRIP, fine=(24, 9)):
    """Force of the default 8 x 3 P2 mesh and of a finer one at ``displacement``; returns
    (default, fine), N."""
    length, width, thickness = strip
    coarse = ClampedStripModel(length, width, thickness).solve(params, [displacement])[0]
    finer = ClampedStripModel(length, width, thickness, n_length=fine[0], n_width=fine[1]).solve(params, [displacement])[0]
    return float(coarse), float(finer)


def membrane_uniaxial_check(stretches=tuple(np.linspace(1.05, 1.6, 8))) -> Comparison:
    """The membrane's nominal stress at the worst of ``stretches`` against the closed form, with
    the largest |lateral stress| over the largest axial stress as "lateral / axial stress"."""
    axial, closed, lateral = membrane_uniaxial_stress(stretches)
    k = int(np.argmax(np.abs(axial / closed - 1.0)))
    return Comparison("membrane law, F = diag(l, l^-1/2): nominal stress at the worst of l = 1.05..1.6",
                      float(closed[k]), float(axial[k]), "Pa",
                      extra={"lateral / axial stress": float(np.abs(lateral).max() / axial.max())})


def sliding_grips_check() -> Comparison:
    """Sliding grips: the FE force at the worst displacement against homogeneous tension, with
    that displacement (mm)."""
    c = specimen_against_closed_form("sliding")
    k = int(np.argmax(np.abs(c.relative_difference)))
    return Comparison("sliding grips: force at the worst of 3..60 mm vs homogeneous uniaxial tension",
                      float(c.closed_form[k]), float(c.model[k]), "N",
                      extra={"worst displacement, mm": float(c.displacement[k] * 1e3)})


def clamped_grips_check() -> Comparison:
    """Clamped grips: the largest force excess over the closed form (no analytic value: NaN), with
    the smallest as "smallest excess"."""
    excess = specimen_against_closed_form("clamped").relative_difference
    return Comparison("clamped grips: force excess over the closed form, largest over 3..60 mm", math.nan,
                      float(excess.max()), extra={"smallest excess": float(excess.min())})


def mesh_convergence_check(fine) -> Comparison:
    """Force at 60 mm of the default mesh against the ``fine`` (n_length, n_width) one."""
    coarse, finer = mesh_convergence(fine=fine)
    return Comparison(f"mesh convergence: force at 60 mm, default 8 x 3 P2 vs {fine[0]} x {fine[1]}", finer, coarse,
                      "N")


def ground_truth(data=TENSILE_DIR) -> dict:
    return json.loads((Path(data) / "ground_truth.json").read_text())


@dataclass
class SpecimenRecovery:
    """A calibration of one bundled synthetic specimen next to the parameters that generated it."""

    curve: TensileCurve
    result: CalibrationResult
    truth: np.ndarray  # generating parameters, Pa
    noise_sd: float  # load-cell noise put into the data, N

    @property
    def mu0(self) -> tuple[float, float, float]:
        """Small-strain shear modulus 2 (C10 + C01): identified, its standard deviation, true; Pa."""
        p = self.result.parameters
        sd = 2.0 * self.result.uncertainty.linear_combination_std([1.0, 1.0, 0.0])
        return 2.0 * (p[0] + p[1]), sd, 2.0 * (self.truth[0] + self.truth[1])

    @property
    def truth_in_region(self) -> bool:
        """Whether the generating parameters lie in the fit's 95 % joint confidence region."""
        return self.result.uncertainty.contains(self.truth)

    def table(self) -> list[dict]:
        """One row per parameter and for mu0: identified, sd, 95 % interval, true, error."""
        unc = self.result.uncertainty
        ci = unc.interval(0.95)
        rows = [{"parameter": n, "identified_Pa": float(v), "sd_Pa": float(s), "ci95_Pa": ci[i].tolist(),
                 "true_Pa": float(t), "error_in_sd": float((v - t) / s) if s > 0 else float("nan")}
                for i, (n, v, s, t) in enumerate(zip(self.result.names, self.result.parameters, unc.std, self.truth))]
        mu0, sd, true = self.mu0
        rows.append({"parameter": "mu0 = 2 (C10 + C01)", "identified_Pa": mu0, "sd_Pa": sd,
                     "ci95_Pa": [mu0 - 1.96 * sd, mu0 + 1.96 * sd], "true_Pa": true,
                     "error_in_sd": (mu0 - true) / sd if sd > 0 else float("nan")})
        return rows


def specimen_recovery(specimen="specimen_01", budget: Budget | None = None, seed=1, data=TENSILE_DIR) -> SpecimenRecovery:
    """Calibrate the bundled ``specimen`` with the FE pipeline (docs/model.md) at ``budget``."""
    truth_doc = ground_truth(data)
    curves = {c.name: c for c in read_manifest(Path(data) / "manifest.csv")}
    curve = curves[specimen]
    truth = np.array([truth_doc["specimens"][specimen]["parameters_Pa"][n] for n in NAMES])
    result = calibrate_curve(curve, budget=budget or Budget(), seed=seed)
    return SpecimenRecovery(curve, result, truth, float(truth_doc["noise_sd_N"]))
