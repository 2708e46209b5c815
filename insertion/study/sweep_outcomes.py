"""Where a sweep's runs execute: a local process pool (:class:`LocalPool`, :func:`local_outcomes`)
or an existing Dask distributed cluster (:func:`dask_outcomes`). Both yield ``(case, outcome)`` as
runs finish (the outcome of :func:`colonsim.insertion.study.sweep_worker.execute`, or a failed one
when a worker died or a task was lost); :mod:`colonsim.insertion.study.sweep` records them.
"""

from __future__ import annotations

import contextlib
import math
import multiprocessing
import signal
import threading
import uuid
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool

from colonsim.errors import ColonsimError
from colonsim.limits import SCHEDULER_CHECK_S
from colonsim.scheduler_address import check_scheduler
from colonsim.insertion.study.sweep_worker import execute, start_worker, utc_now

DIED = "worker process died during this run (killed or out of memory)"


def _failed(case, message) -> dict:
    return {"key": case.key(), "status": "failed", "error": message, "wall_time_s": math.nan, "finished_at": utc_now()}


class LocalPool:
    """Local worker processes that several sweeps can share (the rounds of an adaptive sweep), so
    each round does not spawn its workers and load their kernels again.

    Workers are spawned (not forked: the parent may hold Numba threads) with one Numba thread
    each, when first needed; a pool broken by a dying worker is replaced by a fresh one. Use it
    as a context manager: leaving the block shuts the processes down.
    """

    def __init__(self, workers, warm_up=True):
        self.workers = int(workers)
        self.warm_up = bool(warm_up)
        self._executor = None

    def executor(self):
        if self._executor is None:
            self._executor = ProcessPoolExecutor(max_workers=self.workers, mp_context=multiprocessing.get_context(
                "spawn"), initializer=start_worker, initargs=(self.warm_up,))
        return self._executor

    def discard(self, wait=False):
        """Shut the current processes down (``wait``: let them finish); the next use starts new ones."""
        if self._executor is not None:
            self._executor.shutdown(wait=wait, cancel_futures=True)
            self._executor = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.discard(wait=exc[0] is None)


def local_outcomes(cases, workers=2, runner=None, pool=None):
    """Run ``cases`` in a local process pool; yield ``(case, outcome)`` as runs finish.

    At most ``workers`` runs are in flight, so a worker that dies (killed, out of memory) costs
    only the runs it had: they are reported failed and a fresh pool takes the rest. ``pool``: a
    :class:`LocalPool` to run on and leave open (None: one of ``workers`` processes for these
    cases only).
    """
    pending = list(cases)
    own = pool is None
    if own:
        pool = LocalPool(workers, warm_up=runner is None)
    workers = min(workers, pool.workers)
    while pending:
        executor = pool.executor()
        in_flight = {}
        clean = False
        try:
            while pending or in_flight:
                while pending and len(in_flight) < workers:
                    case = pending.pop(0)
                    with sigint_held():  # submit may spawn a worker: it starts with Ctrl-C held
                        in_flight[executor.submit(execute, case, runner)] = case
                done, _ = wait(in_flight, return_when=FIRST_COMPLETED)
                broken = False
                for future in done:
                    case = in_flight.pop(future)
                    try:
                        outcome = future.result()
                    except BrokenProcessPool:
                        broken = True
                        outcome = _failed(case, DIED)
                    except Exception as exc:  # e.g. an outcome that could not be sent back
                        outcome = _failed(case, f"{type(exc).__name__}: {' '.join(str(exc).split())}")
                    yield case, outcome
                if broken:
                    for future, case in in_flight.items():
                        yield case, _failed(case, DIED)
                    in_flight.clear()
                    pool.discard()
                    break
            clean = True
        finally:
            if own or not clean:  # a shared pool stays open unless the sweep was stopped
                pool.discard(wait=clean)


@contextlib.contextmanager
def sigint_held():
    """Hold Ctrl-C (SIGINT) back from this thread for the block; one that arrives meanwhile is
    delivered when the block ends, none is lost.

    A worker process inherits the held signal: one still importing when Ctrl-C reaches the process
    group would print a ``KeyboardInterrupt`` traceback; held, the signal waits until
    :func:`~colonsim.insertion.study.sweep_worker.start_worker` has installed its quiet exit and
    releases it.

    The mask alone holds the signal back from this thread only: the kernel hands a process's
    SIGINT to any thread that does not block it (BLAS starts its threads at import), and Python
    then raises ``KeyboardInterrupt`` in the main thread wherever it is, such as between spawning
    a worker and writing the worker its start-up data (the worker then printed ``EOFError: Ran out
    of input``). So in the main thread Python's own handler is deferred for the block too.
    """
    if not hasattr(signal, "pthread_sigmask"):  # Windows: no signal masks (and no process groups)
        yield
        return
    deferred = threading.current_thread() is threading.main_thread()
    if deferred:
        came = []
        previous_handler = signal.signal(signal.SIGINT, lambda signum, frame: came.append(signum))
    previous_mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous_mask)  # one still pending arrives now
        if deferred:
            signal.signal(signal.SIGINT, previous_handler)  # runs a handler still due first
            if came:
                signal.raise_signal(signal.SIGINT)  # to the handler before the block


def dask_outcomes(cases, address, runner=None, log=print):
    """Send ``cases`` to the Dask distributed scheduler at ``address``; yield ``(case, outcome)``.

    Workers should run one task at a time (``dask worker ADDR --nthreads 1``, one worker per
    core): runs within a worker process are serialized anyway. Each worker loads the kernels
    once, at its first run (outside the timed part), which also covers workers that join late.
    """
    Client = dask_distributed().Client
    check_scheduler(address)  # an unroutable address or another server fails here, in seconds and one line
    try:  # connect now, so an unreachable scheduler fails before anything is written
        client = Client(address, timeout=f"{SCHEDULER_CHECK_S:g}s", set_as_default=False)
    except Exception as exc:  # OSError, TimeoutError, a handshake distributed could not read, ...
        raise ColonsimError(f"cannot reach the Dask scheduler at {address} ({type(exc).__name__}: "
                            f"{' '.join(str(exc).split())[:200]}); start one with `dask scheduler` and workers with "
                            f"`dask worker {address} --nthreads 1`") from None
    return _dask_stream(client, cases, address, runner, log)


def dask_distributed():
    """The ``distributed`` package (the ``cluster`` extra), or a one-line error naming the fix."""
    try:
        import distributed
    except ImportError as exc:
        raise ColonsimError(f'running on a Dask cluster (--scheduler) needs dask ({exc}); '
                            'pip install "colonsim[cluster]"') from None
    return distributed


def _dask_stream(client, cases, address, runner, log):
    as_completed = dask_distributed().as_completed

    with client:
        workers = client.scheduler_info().get("workers", {})
        if not workers:
            log(f"no Dask worker at {address} yet; the runs wait for one (`dask worker {address} --nthreads 1`)")
        threads = sorted({w.get("nthreads", 1) for w in workers.values()})
        if threads and threads[-1] > 1:
            log(f"note: Dask workers with {threads[-1]} threads run one insertion at a time; start them with "
                "--nthreads 1 and one worker per core for full use of the machine")
        token = uuid.uuid4().hex[:8]
        futures = {client.submit(execute, case, runner, key=f"insertion-{case.key()}-{token}"): case for case in cases}
        try:
            for future in as_completed(futures, loop=client.loop):
                case = futures[future]
                try:
                    outcome = future.result()
                except Exception as exc:  # the task itself failed: worker lost (KilledWorker), cancelled, ...
                    outcome = _failed(case, f"{type(exc).__name__}: {' '.join(str(exc).split())}")
                future.release()
                yield case, outcome
        finally:
            client.cancel(list(futures))
