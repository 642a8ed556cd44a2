"""The lock file of a run file, and who holds it: what a reader of a run file asks
(:mod:`sim.storage.inspect`) where HDF5's own locks may be off. The run takes and holds the
lock (:class:`sim.pipeline.run_folder.RunLock`)."""

import fcntl
import os
from pathlib import Path


def lock_path(path):
    """The lock file of the run file ``path``: beside the file its links lead to."""
    real = Path(os.path.realpath(path))
    return real.with_name(f".{real.name}.lock")


def writer_of(path):
    """Who holds the lock of the run file ``path`` (``process N``, or ``another process``),
    or None when no run does: a shared ``flock`` of its lock file, asked without waiting and
    let go at once. Readers ask it where HDF5's own locks may be off."""
    try:
        fd = os.open(lock_path(path), os.O_RDONLY)
    except OSError:  # no lock file: no run
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        fcntl.flock(fd, fcntl.LOCK_UN)
        return None
    except BlockingIOError:
        pid = os.read(fd, 32).decode(errors="replace").strip()
        return f"process {pid}" if pid else "another process"
    except OSError:  # a file system without locks: none to ask
        return None
    finally:
        os.close(fd)
