"""How ``python -m sim`` ends: one line on stderr and an exit status (listed in
:mod:`sim.pipeline.cli`), the folders it made removed again when it refuses, a signal as a
stop, and h5py's own tracebacks of a failed write held back (:data:`PASSED_OVER`)."""

import os
import signal
import sys

from sim.pipeline.leaving import leave
from sim.storage.h5md import hdf5_reason

EXIT_BAD_CONFIG = 2
EXIT_RUN_FILE = 1
EXIT_BREAKDOWN = 3
#: the folders ``main`` made for this command (removed again, if empty, when it is refused)
MADE_FOLDERS = []
#: the signal that stopped the command before or between runs (SIGINT unless SIGTERM came)
STOPPED_BY = [signal.SIGINT]


def fail(message, status=EXIT_BAD_CONFIG):
    """Say ``message`` in one line, remove the folders made so far and exit with ``status``."""
    print(f"sim: {' '.join(str(message).split())}", file=sys.stderr, flush=True)
    remove_made_folders()
    sys.exit(status)


def remove_made_folders():
    """Remove the folders of :data:`MADE_FOLDERS` that are still empty."""
    for folder in reversed(MADE_FOLDERS):
        try:
            folder.rmdir()  # only if nothing was written into it
        except OSError:
            pass


def make_folder(folder):
    """``mkdir -p folder``, remembering in :data:`MADE_FOLDERS` each folder it made."""
    missing = [f for f in (folder, *folder.parents) if not f.exists()]
    folder.mkdir(parents=True, exist_ok=True)
    MADE_FOLDERS.extend(reversed(missing))


def first_line(error):
    """The innermost cause's first line: what the user needs, without Hydra's framing."""
    while error.__cause__ is not None:
        error = error.__cause__
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    return lines[0] if lines else type(error).__name__


def stopped_by(signum):
    """Take ``signum`` as the signal that stopped the command."""
    STOPPED_BY.append(signal.Signals(signum))


def terminate(signum, frame):
    stopped_by(signum)
    raise KeyboardInterrupt


def stopped():
    """How a signal stopped the command: ``interrupted`` or ``terminated``."""
    return "terminated" if STOPPED_BY[-1] == signal.SIGTERM else "interrupted"


def stopped_status():
    """The exit status of a command a signal stopped: 128 + the signal's number."""
    return 128 + STOPPED_BY[-1]


def stop_at_once(signum):
    """A second SIGINT or SIGTERM during a run: leave at once, as SIGKILL would (the run file
    keeps every snapshot up to its last flush)."""
    print(f"sim: {signum.name} again: stopped at once; the run file keeps every snapshot up "
          f"to its last flush, and resume= continues from its last checkpoint",
          file=sys.stderr, flush=True)
    os._exit(128 + signum)


def warn_in_one_line(message, category, filename, lineno, file=None, line=None):
    """Warnings as the command line's other messages: one line."""
    print(f"sim: warning: {' '.join(str(message).split())}", file=sys.stderr, flush=True)


def _failed_hdf5_write(error):
    return isinstance(error, (OSError, RuntimeError)) and "write failed" in str(error)


#: HDF5 write failures that h5py reported on its own (see :func:`quiet_hdf5_teardown`)
PASSED_OVER = []


def quiet_hdf5_teardown(unraisable):
    """HDF5 tries a failed write again as it releases the objects of that file (a dataset
    closed after a write it could not finish, wherever the writer's wall-clock flush left
    it), and h5py reports each failure: its traceback through ``sys.excepthook``, then
    "Exception ignored" through ``sys.unraisablehook``. Both hooks keep these in
    :data:`PASSED_OVER` instead: the run's one-line report of the failure, which ends the
    process, covers them; a process that ends without that report says the first of them
    in one line and ends with status 1 (:func:`report_passed_over`)."""
    if _failed_hdf5_write(unraisable.exc_value):
        PASSED_OVER.append(unraisable.exc_value)
    else:
        sys.__unraisablehook__(unraisable)


def quiet_hdf5_traceback(kind, error, traceback):
    if _failed_hdf5_write(error):
        PASSED_OVER.append(error)
    else:
        sys.__excepthook__(kind, error, traceback)


def report_passed_over():
    """At exit (after any uncaught exception): a failed write that nothing reported."""
    if PASSED_OVER:
        leave(f"sim: writing the run file failed: {hdf5_reason(PASSED_OVER[0])}",
              EXIT_RUN_FILE)
