"""Fitting every hyperelastic law to one curve, and choosing one by BIC.

Each law of :data:`colonsim.laws.LAWS` (all of them run in the insertion solver) goes through the same pipeline; the laws are
ranked by the Bayesian information criterion, Drucker-stable laws first (:mod:`colonsim.identification.stability`, along
the three test modes from 0.5 to twice the strip's largest stretch), of their least-squares fit on the simulation
points (Gaussian errors of unknown variance: ``n ln(RSS / n) + k ln n``, AIC with ``2 k``). A
law with more parameters must lower the residual enough to pay for them, so a simpler law that
fits as well wins. Differences are read on Kass and Raftery's scale (JASA 90, 1995).

Layout of the output folder::

    material.json           the chosen law's, with a "law_selection" section saying why
    laws.csv, laws.png      one row per law; all fits on the data
    laws/<law>/             every fitted law's full calibration folder (material.json, history.csv, figures)
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from colonsim.files import save_figure, write_csv, write_json
from colonsim.identification.diagnostics import parameters_at_bounds, shear_modulus
from colonsim.identification.report import material_document, strip_stability, write_calibration
from colonsim.laws import LAWS

# Kass & Raftery's reading of a BIC difference (upper bound of each band).
_EVIDENCE = ((2.0, "not worth more than a bare mention"), (6.0, "positive"), (10.0, "strong"), (np.inf, "very strong"))


def information_criteria(e1, n, k) -> tuple[float, float]:
    """(AIC, BIC) of a least-squares fit with residual sum of squares ``e1`` on ``n`` points, ``k`` parameters."""
    fit_term = n * np.log(max(e1, np.finfo(float).tiny) / n)
    return float(fit_term + 2 * k), float(fit_term + k * np.log(n))


def evidence(delta_bic) -> str:
    return next(words for bound, words in _EVIDENCE if delta_bic <= bound)


@dataclass
class LawComparison:
    """Fits of several laws to one curve, their table and the law BIC chooses."""

    results: dict
    table: pd.DataFrame
    chosen: str
    reason: str

    @property
    def chosen_result(self):
        return self.results[self.chosen]

    def selection(self) -> dict:
        """The ``law_selection`` section of the chosen law's ``material.json``."""
        t = self.table
        return {"criterion": "Drucker-stable laws first, then BIC (lowest wins): n ln(RSS/n) + k ln n on the simulation points",
                "chosen": self.chosen, "reason": self.reason,
                "bic": dict(zip(t["law"], t["bic"])), "aic": dict(zip(t["law"], t["aic"])),
                "table": "laws.csv"}


def compare_laws(calibrate_law, laws=tuple(LAWS)) -> LawComparison:
    """Fit each of ``laws`` with ``calibrate_law(law) -> CalibrationResult``; choose by BIC."""
    results = {law: calibrate_law(law) for law in laws}
    rows = []
    for law, r in results.items():
        n, k = r.fit["n_points"], len(r.names)
        aic, bic = information_criteria(r.fit["e1_N2"], n, k)
        mu0, mu0_sd = shear_modulus(r)
        first = strip_stability(r).first()
        rows.append({"law": law, "n_parameters": k, "drucker_stable": first is None,
                     "first_unstable": "" if first is None else f"{first[0]} {first[1]} from {first[2]:.3g}",
                     **{f"{p}_Pa": v for p, v in r.parameter_dict.items()},
                     "rms_N": r.fit["rms_N"], "rms_over_noise": r.fit["rms_over_noise"], "aic": aic, "bic": bic,
                     "mu0_Pa": mu0, "mu0_sd_Pa": mu0_sd, "note": "; ".join(parameters_at_bounds(r))})
    table = pd.DataFrame(rows)
    table["delta_bic"] = table["bic"] - table["bic"].min()
    order = table.sort_values(["drucker_stable", "bic", "n_parameters"], ascending=[False, True, True]).reset_index(drop=True)
    chosen = order.loc[0, "law"]
    reason = f"lowest BIC ({order.loc[0, 'bic']:.1f})"
    unstable = order.loc[~order["drucker_stable"], "law"].tolist()
    if unstable and order.loc[0, "drucker_stable"]:
        reason += f" among the Drucker-stable laws (passed over: {', '.join(unstable)})"
        order = order[order["drucker_stable"]].reset_index(drop=True)
    if len(order) > 1:
        d = order.loc[1, "delta_bic"]
        reason += f"; next {order.loc[1, 'law']} at delta BIC {d:.1f} ({evidence(d)} evidence for {chosen})"
    if not results[chosen].fit["follows_curve"]:
        reason += (f"; but even {chosen} leaves {results[chosen].fit['rms_over_noise']:.1f} times the noise: "
                   "no law fitted follows this curve")
    table["chosen"] = table["law"] == chosen
    table.loc[table["chosen"], "note"] = "; ".join(filter(None, [reason, *table.loc[table["chosen"], "note"]]))
    parameter_columns = [f"{p}_Pa" for law in LAWS.values() for p in law.parameter_names]
    columns = ["law", "chosen", "n_parameters", "drucker_stable", "first_unstable", *dict.fromkeys(c for c in parameter_columns if c in table),
               "rms_N", "rms_over_noise", "aic", "bic", "delta_bic", "mu0_Pa", "mu0_sd_Pa", "note"]
    return LawComparison(results, table[columns], chosen, reason)


def laws_figure(comparison: LawComparison) -> Figure:
    """Every fitted law on the data, with the residuals below."""
    fig = Figure(figsize=(7, 6))
    ax, ax_r = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1.4]})
    first = next(iter(comparison.results.values()))
    c = first.curve
    ax.plot(c.displacement * 1e3, c.force, "-", c="0.75", lw=4, zorder=0, label=f"experiment ({c.name})")
    ax_r.axhline(0.0, c="0.6", lw=0.8)
    for law, r in comparison.results.items():
        f = r.fitted
        row = comparison.table.set_index("law").loc[law]
        label = f"{law}: RMS {r.fit['rms_N']:.3g} N ({r.fit['rms_over_noise']:.1f}x noise), BIC {row['bic']:.1f}" \
                + (" - chosen" if law == comparison.chosen else "")
        line, = ax.plot(f["displacement_mm"], f["force_fit_N"], "-", lw=1.6 if law == comparison.chosen else 1.0,
                        label=label)
        ax_r.plot(f["displacement_mm"], f["force_exp_N"] - f["force_fit_N"], "o-", ms=3, c=line.get_color())
    ax.set_ylabel("force [N]")
    ax.legend(fontsize=7)
    ax.set_title(f"hyperelastic laws fitted to {c.name}; BIC chooses {comparison.chosen}", fontsize=9)
    ax_r.set_xlabel("grip displacement [mm]")
    ax_r.set_ylabel("residual [N]")
    return fig


def write_law_comparison(comparison: LawComparison, out_dir) -> dict:
    """One folder per law, ``laws.csv``, ``laws.png`` and the chosen law's ``material.json`` in ``out_dir``."""
    out = Path(out_dir)
    for law, r in comparison.results.items():
        write_calibration(r, out / "laws" / law)
    paths = {"laws_table": out / "laws.csv", "laws_plot": out / "laws.png", "material": out / "material.json"}
    write_csv(paths["laws_table"], comparison.table)
    save_figure(laws_figure(comparison), paths["laws_plot"])
    write_json(paths["material"], material_document(comparison.chosen_result, selection=comparison.selection()))
    return paths
