"""The worker side of a sweep: one Numba thread per process, kernels warmed once, one run per call.

This module imports nothing heavy at the top so that a fresh worker process can still set
``NUMBA_NUM_THREADS=1`` before Numba is imported: worker processes share the cores, and two
processes with two Numba threads each on two cores run 30-40x slower. ``numba.set_num_threads``
is thread-local, so :func:`execute` sets it again in the thread that runs the case (Dask runs
tasks in a thread pool).
"""

from __future__ import annotations

import datetime
import os
import sys
import threading
import time
import warnings

_PREPARED = False
# Runs of one process go one at a time: the Numba threading layers are not all safe for
# kernels launched from several threads at once (Dask workers started with --nthreads > 1).
_RUN_LOCK = threading.Lock()


def _one_thread():
    if "numba" not in sys.modules:
        os.environ["NUMBA_NUM_THREADS"] = "1"
    import numba

    numba.set_num_threads(1)


def utc_now() -> str:
    """The current UTC time, ISO 8601 to the second (a results row's ``finished_at``)."""
    return datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")


def ok_outcome(result) -> dict:
    """The outcome fields of a run that finished (``result``: ``.summary``, ``.timeseries``, an
    optional ``.final_shape`` and, from a run with its model, the wall-stretch map's arrays and an
    optional movie, :mod:`colonsim.insertion.study.sweep_animation`), as the sweep's store records them."""
    from colonsim.insertion.case.stretch_map import map_arrays

    visuals = {"stretch_map": map_arrays(result) if getattr(result, "model", None) is not None else None,
               "animation": getattr(result, "animation_gif", None)}
    return {"status": "ok", "error": "", "summary": result.summary, "timeseries": result.timeseries,
            "final_shape": getattr(result, "final_shape", None), "visuals": visuals}


def warm_up_case():
    """A tiny insertion (coarse straight tube, fast push) that touches every kernel once."""
    from colonsim.insertion.case.scenario import InsertionCase

    return InsertionCase(segment="straight", scope="pdc", element_size_mm=12.0, scope_spacing_mm=20.0,
                         push_speed=5.0, ramp_s=0.01, record_interval_s=0.01)


def prepare_worker(warm_up=True):
    """Process initializer: 1 Numba thread, kernels loaded (compiled, or read from the cache) once.

    Idempotent; :func:`execute` calls it too, so workers that join a Dask cluster later are
    prepared by their first run (outside its timed part). ``warm_up`` False (the runs are a
    stand-in runner's, which simulates nothing) skips the kernels.
    """
    global _PREPARED
    _one_thread()
    from colonsim.errors import ColonsimWarning

    # the sweep's own process has shown these once, when it checked the cases; a worker would
    # repeat them for every run, in the raw warnings format
    warnings.simplefilter("ignore", ColonsimWarning)
    if not warm_up:
        return
    with _RUN_LOCK:
        if _PREPARED:
            return
        from colonsim.insertion.case.scenario import run_insertion

        run_insertion(warm_up_case())
        _PREPARED = True


def exit_with_parent():
    """Exit this process as soon as the process that started it dies.

    A pool worker waits on a queue that it holds both ends of, so the death of a sweep killed
    with SIGKILL (the out-of-memory killer) never reaches it: without this it idles forever. The
    parent's sentinel (a pipe the parent holds open) becomes readable when the parent dies, even
    while this process runs a case."""
    import multiprocessing
    from multiprocessing.connection import wait

    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch():
        wait([parent.sentinel])
        os._exit(1)  # no cleanup to wait for: the parent, which writes every file, is gone

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def start_worker(warm_up=True):
    """Initializer of a local pool process (must not raise: the pool would break); ``warm_up``:
    see :func:`prepare_worker`."""
    import signal

    # Ctrl-C reaches the whole process group: the parent stops the sweep and says so in one line;
    # a worker leaves at once and quietly (a KeyboardInterrupt would print its own traceback). The
    # pool starts workers with SIGINT held (sweep_outcomes.sigint_held): one that came while this
    # process was importing is delivered now, to the quiet exit.
    signal.signal(signal.SIGINT, lambda signum, frame: os._exit(130))
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    exit_with_parent()
    try:
        prepare_worker(warm_up)
    except (Exception, KeyboardInterrupt):  # the first run calls it again and records the error; Ctrl-C: quietly
        pass


def default_runner(case):
    from colonsim.insertion.case.scenario import run_insertion

    return run_insertion(case)


def execute(case, runner=None) -> dict:
    """Run one case and return its outcome (never raises for a failed simulation).

    Parameters
    ----------
    case : InsertionCase
    runner : callable(case) -> result with ``.summary`` and ``.timeseries``, or None
        The simulation (default :func:`colonsim.insertion.case.scenario.run_insertion`); tests inject failures here.

    Returns
    -------
    dict
        ``key``, ``status`` ("ok" | "failed"), ``error``, ``wall_time_s``, ``finished_at``, and for
        ok runs ``summary``, ``timeseries`` (SI DataFrame) and ``final_shape`` (node positions at
        the end, or None), which the client writes.
    """
    prepare_worker(warm_up=runner is None)
    _one_thread()
    runner = runner or default_runner
    with _RUN_LOCK:
        t0 = time.perf_counter()
        try:
            outcome = ok_outcome(runner(case))
        except Exception as exc:  # a failed run is a result too; the sweep goes on
            message = " ".join(str(exc).split()) or "(no message)"
            outcome = {"status": "failed", "error": f"{type(exc).__name__}: {message}"}
        wall = time.perf_counter() - t0
    return {"key": case.key(), "wall_time_s": wall, "finished_at": utc_now(), **outcome}
