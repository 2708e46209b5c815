"""What Numba's compilation costs a fresh install: one insertion from an empty compile cache.

A fresh clone (the README's demo, CI, a sweep worker on a new machine) compiles every kernel an
insertion calls before its first step; later processes load them from Numba's on-disk cache. This
prints the wall time of the smoke-size RSJ insertion (SDC, D = 36 mm; ``colonsim.catalog``'s smoke
mesh, scope spacing and push speed) in a child process with an empty cache directory
(``NUMBA_CACHE_DIR``), then again with the cache that run wrote, and the kernels that took longest
to compile (a kernel's time includes the kernels it calls that were compiled with it).

Run: ``python benchmarks/bench_compile.py [--repeat N] [--top K] [--baseline-python PYTHON]``

``--baseline-python`` names the Python of an environment where an earlier checkout is installed:
its cold and warm runs alternate with this checkout's, and the ratio of the compile times
(cold minus warm) is printed. One Numba thread throughout.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def child(top: int) -> dict:
    """Run the smoke insertion in this process, timing it and each compilation."""
    from numba.core import event

    from colonsim.catalog import SMOKE_ELEMENT_MM, SMOKE_PUSH_SPEED, SMOKE_SCOPE_SPACING_MM
    from colonsim.insertion.case.scenario import InsertionCase, run_insertion

    case = InsertionCase(segment="rsj", scope="sdc", diameter_mm=36.0, element_size_mm=SMOKE_ELEMENT_MM,
                         scope_spacing_mm=SMOKE_SCOPE_SPACING_MM, push_speed=SMOKE_PUSH_SPEED)
    with event.install_recorder("numba:compile") as recorder:
        t0 = time.perf_counter()
        run = run_insertion(case)
        seconds = time.perf_counter() - t0
    started, compiled = {}, {}
    for stamp, e in recorder.buffer:
        dispatcher = e.data["dispatcher"]
        key = (id(dispatcher), str(e.data["args"]))
        if e.is_start:
            started[key] = stamp
        else:
            name = f"{dispatcher.py_func.__module__}.{dispatcher.py_func.__qualname__}"
            compiled[name] = compiled.get(name, 0.0) + stamp - started.pop(key, stamp)
    longest = sorted(compiled.items(), key=lambda kv: -kv[1])[:top]
    return {"seconds": seconds, "steps": int(run.summary["steps"]), "kernels": len(compiled), "longest": longest}


def timed(python, cache: Path, top: int) -> dict:
    """The smoke insertion under ``python`` with the compile cache ``cache``, in a child process."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "NUMBA_NUM_THREADS": "1"}
    out = subprocess.run([str(python), __file__, "--serve", str(top)], capture_output=True, text=True, env=env)
    if out.returncode:
        sys.exit(f"{python}: the smoke insertion failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=1, help="cold and warm runs per environment (default 1)")
    parser.add_argument("--top", type=int, default=8, help="kernels listed by compile time (default 8)")
    parser.add_argument("--baseline-python", type=Path, default=None,
                        help="the Python of an environment with an earlier checkout installed")
    parser.add_argument("--serve", type=int, default=None, help=argparse.SUPPRESS)  # the child
    args = parser.parse_args(argv)
    if args.serve is not None:
        print(json.dumps(child(args.serve)))
        return 0
    engines = {"today": sys.executable, **({"baseline": args.baseline_python} if args.baseline_python else {})}
    compile_s = {name: [] for name in engines}
    for r in range(args.repeat):
        for name, python in engines.items():
            with tempfile.TemporaryDirectory(prefix="numba_cache_") as cache:
                cold = timed(python, Path(cache), args.top)
                warm = timed(python, Path(cache), args.top)
            compile_s[name].append(cold["seconds"] - warm["seconds"])
            print(f"{name:>8} run {r + 1}: cold cache {cold['seconds']:.1f} s ({cold['kernels']} kernels compiled), "
                  f"warm {warm['seconds']:.1f} s, {cold['steps']} steps: compilation {compile_s[name][-1]:.1f} s")
            if r == 0:
                for kernel, seconds in cold["longest"]:
                    print(f"{'':>10}{seconds:6.1f} s  {kernel}")
    if args.baseline_python:
        today, base = (sorted(v)[len(v) // 2] for v in (compile_s["today"], compile_s["baseline"]))
        print(f"compilation today / baseline (medians): {today:.1f} / {base:.1f} s = {today / base:.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
