"""A sweep stopped by a signal as a whole: every running job ends with its final snapshot and
checkpoint, and no job starts after.

SIGINT or SIGTERM to the sweep's process (``python -m sim … -m``), to a worker that runs its
jobs, or to all of them at once (Ctrl-C in a terminal, a scheduler's time limit) writes the
signal's name into the stop file :data:`STOP_FILE` of the sweep folder (:func:`request`). A
running job watches for it between compiled chunks as for a signal of its own
(:attr:`sim.pipeline.interruption.Interruption.sweep_dir`) and ends as ``interrupted`` or
``terminated``; a job that starts after it runs nothing. Stopped jobs return, not raise, so
that the launcher waits for the others (joblib ends a pool at a job's exception, killing the
jobs still writing); the sweep's process then exits with 128 + the signal's number, and
clears the stop file (:func:`clear`), as does the next sweep into the folder. A second
signal to the sweep's process ends it and its workers at once, as SIGKILL would.

The sweep's process takes both signals in a thread and a handler of its own
(:func:`guarded`), a job with another while it runs (:func:`job`). A joblib worker ignores
them outside its jobs, from its start (:func:`worker_started`): a worker that a signal ended
while it waited for a job would break joblib's pool, whose other workers are then killed
mid-run. A worker whose sweep process has ended (SIGKILL) stops its job as at SIGTERM
(:func:`requested`) rather than compute on for no one. The launcher starts no more workers
than jobs (:func:`worker_count`).
"""

import contextlib
import functools
import os
import signal
import threading
from contextlib import contextmanager
from multiprocessing import resource_tracker
from pathlib import Path

#: the stop file, in the sweep folder
STOP_FILE = ".sweep-stop"


def stop_file(sweep_dir):
    return Path(sweep_dir) / STOP_FILE


def request(sweep_dir, signum):
    """Ask every job of the sweep in ``sweep_dir`` to stop, for the signal ``signum`` (the
    first one asked for is kept)."""
    try:
        fd = os.open(stop_file(sweep_dir), os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o644)
    except FileExistsError:
        return
    with os.fdopen(fd, "w") as out:
        out.write(signal.Signals(signum).name)


def requested(sweep_dir):
    """The signal the sweep in ``sweep_dir`` was asked to stop for, or None; in a worker
    whose sweep process has ended, SIGTERM."""
    if orphaned():
        return signal.SIGTERM
    try:
        name = stop_file(sweep_dir).read_text().strip()
    except FileNotFoundError:
        return None
    return signal.Signals[name] if name in signal.Signals.__members__ else signal.SIGINT


def clear(sweep_dir):
    stop_file(sweep_dir).unlink(missing_ok=True)


#: the signals that stop a sweep
SIGNALS = {signal.SIGINT, signal.SIGTERM}

#: in a joblib worker of a sweep, the pid of the sweep's process (:func:`worker_started`)
SWEEP_PROCESS = None


def worker_started(sweep_process):
    """The start of a joblib worker of the sweep whose process is ``sweep_process`` (loky's
    initializer, :func:`use_sweep_workers`): SIGINT and SIGTERM are ignored outside its jobs
    (:func:`job` takes them in a job)."""
    global SWEEP_PROCESS
    SWEEP_PROCESS = sweep_process
    for number in SIGNALS:
        signal.signal(number, signal.SIG_IGN)  # also drops one pending since the start
    signal.pthread_sigmask(signal.SIG_UNBLOCK, SIGNALS)  # blocked from the start (guarded)


def orphaned():
    """Whether this process is a joblib worker whose sweep process has ended (SIGKILL)."""
    return SWEEP_PROCESS is not None and os.getppid() != SWEEP_PROCESS


def use_sweep_workers():
    """joblib's loky backend, which Hydra's joblib launcher asks for by name, made in this
    process with workers that begin with :func:`worker_started`."""
    from joblib import register_parallel_backend
    from joblib._parallel_backends import LokyBackend

    register_parallel_backend("loky", functools.partial(
        LokyBackend, initializer=worker_started, initargs=(os.getpid(),)))


@contextmanager
def guarded(sweep_dir, taken, at_second_signal):
    """The sweep's process inside the block, which runs its jobs: the first SIGINT or SIGTERM
    is ``taken(signal)`` and :func:`request`; a second ends the workers at once (SIGKILL)
    and is ``at_second_signal(signal)``.

    Inside the block the process's threads block both signals, and a thread of its own
    takes them (``sigtimedwait``): the workers, started from these threads, inherit the
    mask and so cannot die of a signal before :func:`worker_started` ignores it (the guard
    Python's own resource tracker uses, bpo-33613). The handlers and the mask are as they
    were after the block."""
    count = []

    def take(signum, frame=None):
        if count:  # at once, as for a single run: the workers too
            for pid in descendants(os.getpid()):
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, signal.SIGKILL)
            at_second_signal(signal.Signals(signum))
        count.append(signum)
        taken(signal.Signals(signum))
        request(sweep_dir, signum)

    def wait(over):
        while not over.is_set():
            if (received := signal.sigtimedwait(SIGNALS, 0.1)) is not None:
                take(received.si_signo)

    resource_tracker.ensure_running()  # started later, it would unblock this thread's mask
    # a thread that does not block them (one started before the block) still takes them
    previous = {number: signal.signal(number, take) for number in SIGNALS}
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, SIGNALS)
    over = threading.Event()
    waiting = threading.Thread(target=wait, args=(over,), name="sweep signals", daemon=True)
    waiting.start()
    try:
        yield
    finally:
        over.set()
        waiting.join()
        for number, handling in previous.items():
            signal.signal(number, handling)
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


def descendants(pid):
    """The pids of every process under ``pid`` (from /proc)."""
    children = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            parent = int(stat.read_text().rpartition(")")[2].split()[1])
        except (OSError, IndexError):  # ended meanwhile
            continue
        children.setdefault(parent, []).append(int(stat.parent.name))
    found, todo = [], [pid]
    while todo:
        under = children.get(todo.pop(), [])
        found += under
        todo += under
    return found


@contextmanager
def job(sweep_dir, at_second_signal):
    """A job of the sweep in ``sweep_dir``: SIGINT and SIGTERM inside the block ask the sweep
    to stop (:func:`request`; the run's :class:`sim.pipeline.interruption.Interruption`
    takes them while it runs); a second one to this process is
    ``at_second_signal(signal)``."""
    taken = []

    def handler(signum, frame):
        if taken:
            at_second_signal(signal.Signals(signum))
        taken.append(signum)
        request(sweep_dir, signum)

    main = threading.current_thread() is threading.main_thread()
    if main:
        previous = {number: signal.signal(number, handler) for number in SIGNALS}
    try:
        yield
    finally:
        if main:
            for number, handling in previous.items():
                signal.signal(number, handling)


def worker_count(n_jobs, jobs, cores):
    """Workers for ``jobs`` jobs with joblib's ``n_jobs`` (negative: cores + 1 + n_jobs) on
    ``cores`` cores: never more than the jobs."""
    wanted = cores + 1 + n_jobs if n_jobs < 0 else n_jobs
    return max(1, min(jobs, wanted))
