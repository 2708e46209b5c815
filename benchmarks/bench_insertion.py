"""Insertion end to end: wall time of one RSJ insertion (13.3 mm scope, D = 36 mm, mu = 0, 3 mm
wall mesh) after a warm-up, its steps per second and element updates per second, and the six RSJ
cases at mu = 0 (the source's meshed scopes 9.2 / 11.1 / 13.3 mm x D 23 / 36 mm) next to the
source's points A and C (docs/model.md, "Reference results").

Run: ``python benchmarks/bench_insertion.py [--quick] [--threads N] [--time-step-estimate global]
[--profile]`` (``--quick``: the timed run only; ``--profile``: where the timed run's time goes, by
job, from the profiler's own time of each function, :data:`JOBS`). The validation report
(``validation/report.py``) reads the same cases from a sweep.
"""

import argparse
import cProfile
import math
import pstats
import time

import numba

from colonsim.catalog import meshed_diameters
from colonsim.insertion.study.reference import SOURCE_RSJ_CM
from colonsim.insertion.case.scenario import InsertionCase, run_insertion

TIMED = ("sdc", 36.0)
# where a run's time goes: each function's own time (the profiler's tottime) goes to the first
# job whose name fragment its "file:function" holds; the rest is Python around the kernels
JOBS = {
    "wall internal forces (compiled)": ("shell_forces.py:_blocked_", "shell_forces.py:elementwise_forces_kernel"),
    "wall and scope nodal updates (compiled)": ("integrator_kernels.py",),
    "scope's implicit update (compiled)": ("rod_damping.py:damped_rod_velocity",),
    "scope's internal forces (compiled)": ("rod.py:rod_kernel",),
    "contact (compiled)": ("contact_kernel.py", "contact_broad_phase.py"),
    "time-step bounds (compiled, scipy)": ("shell_membrane.py:membrane_omega2", "shell_hinges.py:hinge_rowsum",
                                           "_decomp.py:eig_banded", "rod.py:stiffness_band", "rod.py:rod_omega2"),
    "recording": ("recording.py", "outcomes.py"),
}


def time_by_job(profile: cProfile.Profile) -> dict:
    """Seconds of own time per :data:`JOBS` entry, the rest as "Python around the kernels"."""
    out = dict.fromkeys([*JOBS, "Python around the kernels"], 0.0)
    for (path, _, name), (_, _, tottime, _, _) in pstats.Stats(profile).stats.items():
        where = f"{path.rsplit('/', 1)[-1]}:{name}"
        job = next((j for j, parts in JOBS.items() if any(p in where for p in parts)), "Python around the kernels")
        out[job] += tottime
    return out


def rsj_case(scope, diameter_mm, **settings):
    """The RSJ case of a source scope mesh (utc / pdc / sdc) at mu = 0."""
    return InsertionCase(segment="rsj", scope=f"{meshed_diameters()[scope] * 1e3:g}", diameter_mm=diameter_mm,
                         **settings)


def point(summary, name):
    p = summary["points_cm"].get(name)
    return p["deformation_cm"] if p else math.nan


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="only the timed run")
    parser.add_argument("--threads", type=int, default=None, help="Numba threads (default: all)")
    parser.add_argument("--time-step-estimate", default=InsertionCase.time_step_estimate,
                        help="bounds (the default) or global")
    parser.add_argument("--profile", action="store_true", help="where the timed run's time goes, by job")
    args = parser.parse_args()
    if args.threads:
        numba.set_num_threads(args.threads)
    threads = numba.get_num_threads()
    run_insertion(InsertionCase(segment="straight", scope="sdc", element_size_mm=6.0))  # compile / cache warm-up

    profile = cProfile.Profile() if args.profile else None
    t0 = time.perf_counter()
    if profile:
        profile.enable()
    timed = run_insertion(rsj_case(*TIMED, time_step_estimate=args.time_step_estimate)).summary
    if profile:
        profile.disable()
    wall = time.perf_counter() - t0
    mesh = timed["mesh"]
    elements = mesh["wall_triangles"] + mesh["hinges"] + mesh["scope_nodes"] - 1
    steps = timed["steps"]
    print(f"RSJ D36, 13.3 mm scope, {threads} Numba thread(s): {wall:.1f} s wall (build {timed['build_time_s']:.1f} s), "
          f"{steps} steps, {steps / wall:.0f} steps/s, {elements * steps / wall / 1e6:.2f} M element updates/s "
          f"({mesh['wall_triangles']} triangles + {mesh['hinges']} hinges + {mesh['scope_nodes'] - 1} rod segments), "
          f"ended by {timed['ended_by']}, time step {args.time_step_estimate}")
    if profile:
        jobs = time_by_job(profile)
        total = sum(jobs.values())
        print(f"where the time goes (profiled: {total:.1f} s, the profiler adding its own to every Python call):")
        for job, seconds in jobs.items():
            print(f"  {job:42s} {seconds:6.1f} s  {100 * seconds / total:5.1f} %")
    if args.quick:
        return

    print("\nRSJ colon deformation [cm], mu = 0: this model vs the source (final of the source = its C)")
    print(f"{'case':>13} | {'A':>6} {'A src':>6} | {'C':>6} {'C src':>6} | {'final':>6} {'src/ours':>8} | ended by")
    for (scope, d), src in SOURCE_RSJ_CM.items():
        s = timed if (scope, d) == TIMED else run_insertion(rsj_case(scope, d)).summary
        final = s["final_deformation_cm"]
        case = f"{scope.upper()} {s['scope']['diameter_mm']:g} D{d:g}"
        print(f"{case:>13} | {point(s, 'A'):6.2f} {src['A']:6.3f} | {point(s, 'C'):6.2f} {src['C']:6.3f} | "
              f"{final:6.2f} {src['C'] / final:8.2f} | {s['ended_by']}")


if __name__ == "__main__":
    main()
