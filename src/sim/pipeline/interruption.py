"""SIGINT and SIGTERM (and, in a job on a cluster, the scheduler's warning of its time limit)
as a request to stop a run between compiled chunks; and what a pool's worker process does
with them before and between its runs (:func:`held_back`, :func:`between_jobs`)."""

import signal
import threading
from contextlib import contextmanager

from sim.pipeline import sweep_stop

#: the signals that ask a run, a study or a pool of workers to stop
STOPS = frozenset({signal.SIGINT, signal.SIGTERM})


def _run_pending_handlers():
    """Run the handlers of signals that another thread of this process received, now.

    The kernel gives a signal sent to the process to any thread that does not block it, and
    numpy's BLAS threads do not: on a busy machine SIGTERM mostly lands on one of them
    (seen with SLURM's ``scancel``). Python runs a handler only in the main thread, and
    for a signal another thread received only once the main thread next takes the GIL, which
    the event loop holds through its compiled chunks: the request waited until SIGKILL.
    ``signal.pthread_sigmask`` ends by running the pending handlers (CPython's
    ``PyErr_CheckSignals``); an empty set leaves the mask as it is."""
    signal.pthread_sigmask(signal.SIG_BLOCK, ())


class Interruption:
    """SIGINT (Ctrl-C) or SIGTERM (a batch scheduler's time limit) asks the run to stop: the
    engine finishes its compiled chunk, the runner writes a final snapshot and checkpoint,
    and the run ends with stop reason ``interrupted`` or ``terminated`` (``resume``
    continues it); in a sweep, so does the sweep's stop file (:attr:`sweep_dir`). A second
    signal acts at once: :attr:`at_second_signal` (the command line leaves the process
    there, as SIGKILL would; by default a KeyboardInterrupt is raised). Installed only in
    the main thread, and only for the run."""

    REASONS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}
    #: ``f(signal)`` called at a second signal; None: raise KeyboardInterrupt
    at_second_signal = None
    #: the signal a scheduler sends a job before its time limit, taken as SIGTERM (set in a
    #: job on a cluster, :mod:`sim.pipeline.cluster`); None elsewhere
    time_limit_warning = None
    #: the last signal that asked a run of this process to stop
    last_signal = None
    #: a signal that came to a job on a cluster before its run began (:meth:`take_early`):
    #: the run stops at its first chunk
    early = None
    #: the folder of the sweep this process runs a job of: its stop file
    #: (:mod:`sim.pipeline.sweep_stop`) asks the run to stop as a signal would; None outside
    #: a sweep
    sweep_dir = None

    def __init__(self):
        self.signal = None
        self._previous = {}

    @staticmethod
    def take_early(signum, frame):
        """The handler of a job on a cluster until its run begins (submitit's would pass
        SIGTERM over, and SLURM's SIGKILL would follow): the run stops at once."""
        Interruption.early = Interruption.last_signal = signal.Signals(signum)

    @property
    def requested(self):
        """Whether the run is asked to stop; asked between chunks, in the main thread."""
        _run_pending_handlers()
        if self.signal is None:
            self.signal = Interruption.early
        if self.signal is None and Interruption.sweep_dir is not None:
            self.signal = sweep_stop.requested(Interruption.sweep_dir)
        return self.signal is not None

    @property
    def reason(self):
        return self.REASONS.get(self.signal, "terminated")

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            taken = [*self.REASONS, *([self.time_limit_warning]
                                      if self.time_limit_warning is not None else [])]
            for number in taken:
                self._previous[number] = signal.signal(number, self._request)
        return self

    def _request(self, signum, frame):
        if self.signal is None:
            self.signal = Interruption.last_signal = signal.Signals(signum)
        elif Interruption.at_second_signal is not None:
            Interruption.at_second_signal(signal.Signals(signum))
        else:
            raise KeyboardInterrupt

    def __exit__(self, *exc):
        for number, previous in self._previous.items():
            signal.signal(number, previous)
        return False


@contextmanager
def held_back():
    """SIGINT and SIGTERM blocked in this thread for the block and delivered after it. A
    worker process started in the block (``ProcessPoolExecutor.submit`` starts them) begins
    with them blocked, so that Ctrl-C, which reaches the whole process group, cannot raise
    a KeyboardInterrupt out of its start-up; its initializer says what it does with them
    (:func:`between_jobs`)."""
    held = signal.pthread_sigmask(signal.SIG_BLOCK, STOPS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


def passed_over(signum, frame):
    """A handler that does nothing: the signal is passed over. Unlike ``SIG_IGN``, a process
    started from this one (a run) does not inherit it."""


def between_jobs(handler):
    """In a worker started under :func:`held_back`: ``handler`` for SIGINT and SIGTERM, then
    the two unblocked (one that came during the start-up is handled now). During a run, the
    run's own :class:`Interruption` takes them."""
    for number in STOPS:
        signal.signal(number, handler)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, STOPS)
