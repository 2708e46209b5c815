"""``colonsim demo``: the three workflows end to end on the bundled data, in about 2 minutes on 2 idle cores.

1. calibrate Mooney-Rivlin parameters from the bundled SYNTHETIC tensile curves (reduced budget);
2. one live insertion with the material just calibrated: the standard colonoscope (SDC) through
   RSJ at ``colonsim insert``'s defaults (D = 36 mm, mu = 0, distal resistance 5 N), with its
   wall-stretch map and movie;
3. the predictor shipped with colonsim (:mod:`colonsim.surrogate.predictor`), asked about the
   calibrated material (its tissue stiffness factor, its parameter uncertainty in the intervals):
   each scope's deformation for two contrasting patients, with 95 % intervals, and the scopes
   ranked by the largest colon deformation over the run (the pain proxy, docs/surrogate.md;
   ``--target final_deformation_cm`` for the end value);
4. the live run beside the predictor's answer for the same case: its interval, and whether the
   live value lies inside.

When no predictor ships, steps 3 and 4 say so in one line; nothing is predicted. With ``--sweep``
the demo also runs a 12-run sweep of its own and fits a surrogate on it (:mod:`colonsim.demo_sweep`,
some minutes more). Everything goes to one folder (default ``colonsim_demo/``); ``report.md``
there lists what was run and where each file is (:mod:`colonsim.demo_report`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from colonsim.catalog import PAIN_PROXY


class Sections:
    """The demo's numbered section headings ("== 2/4 ..."), out of ``total``."""

    def __init__(self, total: int):
        self.total, self.done = total, 0

    def __call__(self, text: str):
        self.done += 1
        print(f"\n== {self.done}/{self.total} {text}", flush=True)


def calibrate_step(out: Path, show: bool, section, budget=None):
    """The calibration of the bundled data at the reduced budget of ``--quick`` (or ``budget``, an
    identification Budget)."""
    from colonsim.workflows import CalibrationRequest, calibrate

    section("calibrate Mooney-Rivlin parameters from the bundled SYNTHETIC tensile data (data/README.md); "
            + ("reduced budget (--quick)" if budget is None else "a smaller budget than --quick's"))
    return calibrate(CalibrationRequest(law="mooney_rivlin_3", quick=True, budget=budget, workers=1,
                                        show_progress=show), out)[0]


def run_size(element_size: float, scope_spacing: float, push_speed: float | None) -> dict:
    """The inputs of every demo insertion that set its cost: wall mesh and scope node spacing (mm)
    and, when given, the push speed (m/s; absent: the model's default, and the case keys of
    earlier demos)."""
    size = {"element_size_mm": element_size, "scope_spacing_mm": scope_spacing}
    if push_speed is not None:
        size["push_speed"] = push_speed
    return size


def live_step(material: Path, size: dict, out: Path, show: bool, section):
    """The live insertion: SDC through RSJ at the insertion's defaults, the calibrated material,
    with its movie."""
    from colonsim.insertion.case.scenario import InsertionCase
    from colonsim.workflows import insert

    # the material named as the demo sweep names it, so that this run is one of its cases
    case = InsertionCase(segment="rsj", scope="sdc", material=material.resolve().as_posix(), **size)
    section(f"live insertion: {case.scope.upper()} through {case.segment.upper()} (D = {case.diameter_mm:g} mm, "
            f"mu = {case.friction:g}, distal resistance {case.distal_resistance_N:g} N) with the calibrated material; "
            "docs/validation/report.md compares this model with the source")
    import numba

    # One thread: on a 2-core machine with anything else running, two Numba threads wait on each
    # other and a run takes up to 8x longer (measured: PDC 147 s instead of 17 s). `colonsim
    # insert --threads 2` is the faster choice on an idle machine.
    numba.set_num_threads(1)
    return insert([case], out, show=show, animate={case.key()})[0]


@dataclass(frozen=True)
class DemoOptions:
    """Where the demo writes, its wall mesh and scope node spacing (mm; None: the model's default),
    its push speed (m/s; None: the model's default), whether it runs its own sweep and fits a
    surrogate on it (``sweep``), the sweep's processes (None: up to 2 cores), bars, the
    deformation the summary and the rankings go by, and the calibration's budget (an
    identification Budget; None: the reduced one of ``calibrate --quick``; tests pass a smaller one,
    as they pass a coarser mesh)."""

    out: Path = Path("colonsim_demo")
    element_size_mm: float = 3.0
    scope_spacing_mm: float | None = None
    push_speed: float | None = None
    sweep: bool = False
    workers: int | None = None
    show_progress: bool = True
    target: str = PAIN_PROXY
    calibration_budget: object = None


def run_demo(options: DemoOptions) -> dict:
    """Run the demo's steps into ``options.out`` and print the summary; returns what each step
    made (``calibration``, ``live``, ``predicted``, ``swept``, ``size``, ``report``)."""
    from colonsim.demo_predictor import predictor_step
    from colonsim.demo_report import print_summary, write_report
    from colonsim.files import write_json

    out = Path(options.out)
    show = options.show_progress
    scope_spacing = options.scope_spacing_mm
    if scope_spacing is None:
        from colonsim.insertion.case.insertion_case import InsertionCase

        scope_spacing = InsertionCase.scope_spacing_mm  # the model's default
    size = run_size(options.element_size_mm, scope_spacing, options.push_speed)
    section = Sections(7 if options.sweep else 4)
    seconds = {}
    t0 = time.perf_counter()
    calibration = calibrate_step(out / "calibration", show, section, options.calibration_budget)
    seconds["calibration"] = time.perf_counter() - t0
    material = out / "calibration" / "material.json"
    t = time.perf_counter()
    live = live_step(material, size, out / "insertion", show, section)
    seconds["live insertion"] = time.perf_counter() - t
    t = time.perf_counter()
    predicted = predictor_step(material, live, options.target, section)
    if "no_predictions" in predicted:
        section.done += 1  # the comparison's section: nothing to compare with
    else:
        write_json(out / "predictions.json", predicted)
    seconds["predictions"] = time.perf_counter() - t
    swept = None
    if options.sweep:
        swept = sweep_steps(out, material, size, options, section, live, seconds)
    report = write_report(out, calibration, live, predicted, seconds, size, swept)
    print_summary(calibration, live, predicted, options.target, swept)
    print(f"\ndemo finished in {time.perf_counter() - t0:.0f} s; report: {report}; every file in {out}/")
    ask = ("`colonsim predict` and `colonsim recommend` ask the predictor about any patient in its domain"
           if "no_predictions" not in predicted else
           "`colonsim demo --sweep` fits a surrogate on a 12-run sweep of its own")
    print(f"Next: {ask}; `colonsim sweep --preset thesis` runs the source's 39 insertions.")
    return {"calibration": calibration, "live": live, "predicted": predicted, "swept": swept, "size": size,
            "report": report}


def sweep_steps(out: Path, material: Path, size: dict, options: DemoOptions, section, live, seconds: dict):
    """``--sweep``: the demo sweep (the live run recorded as one of its cases), its surrogate and
    that surrogate's recommendations; returns (sweep report, surrogate, recommendations)."""
    from colonsim.demo_sweep import recommend_step, surrogate_step, sweep_step
    from colonsim.workflows import available_cores

    workers = options.workers or min(2, available_cores())
    t = time.perf_counter()
    sweep = sweep_step(material, size, out / "sweep", workers, options.show_progress, section, [live])
    seconds["sweep"] = time.perf_counter() - t
    t = time.perf_counter()
    model, _, _ = surrogate_step(out / "sweep" / "results.parquet", out / "replicates" / "results.parquet", out, section)
    recs = recommend_step(model, out, options.target, section)
    seconds["surrogate and recommendations"] = time.perf_counter() - t
    return sweep, model, recs
