"""One run file, one process: a folder of its own for every run, a lock held for the run's
life, and a new run file that appears whole or not at all.

* :func:`new_folder` makes a folder that no other process has: ``base``, else ``base-2``,
  ``base-3``, … (``mkdir`` is atomic, so two runs started in the same second get two folders).
* :class:`RunLock` is an exclusive ``flock`` on the hidden file ``.run.h5.lock`` beside the
  run file (beside the file a symbolic link points to), taken before the run file is read or
  written and released when the run ends; the kernel releases it when the process dies, so a
  killed run never leaves a stale lock. A second process that asks for it is refused at once,
  naming the holder's pid. On a file system without file locks (some Lustre and NFS mounts)
  the run goes on with a warning.
* The run file itself, its device and inode whatever name or hard link reaches it, is locked
  too (:func:`held`): by HDF5 while the file is open, or, where ``HDF5_USE_FILE_LOCKING`` turns
  HDF5's locks off (usual on Lustre and NFS), by an ``flock`` of its own for as long as the
  run holds it. The two cannot be taken together: HDF5's lock and another ``flock`` on the
  same file exclude each other even within one process.
* A new run file is written under the hidden name ``.run.h5.part`` (:func:`part_path`) and
  linked into place once its header, first snapshot and first checkpoint are on disk
  (:func:`publish`): a run killed at any moment leaves a readable run file or none.
* :func:`locked` holds the lock for the pipeline: another process's lock is a config error,
  a folder where no lock file can be made a run file error (:func:`cannot_write`).
"""

import errno
import fcntl
import os
import warnings
from contextlib import contextmanager
from pathlib import Path

from sim.pipeline.config import ConfigError
from sim.storage.errors import RunFileError
from sim.storage.h5md import hdf5_reason
from sim.storage.run_lock import lock_path

#: flock's errors on a file system that has no file locks (some Lustre and NFS mounts)
NO_LOCKS = (errno.ENOLCK, errno.ENOSYS, errno.EOPNOTSUPP)


class FolderBusyError(RuntimeError):
    """Another live process holds the lock of this run file; ``holder`` names it."""

    def __init__(self, path, pid):
        self.path = path
        self.holder = f"process {pid}" if pid else "another process"
        super().__init__(f"{path} is being written by {self.holder}, a run still going; wait "
                         f"for it to end or choose another folder")


def new_folder(base):
    """Create and return a folder that did not exist: ``base``, else ``base-2``, … ."""
    base = Path(base)
    base.parent.mkdir(parents=True, exist_ok=True)
    for k in range(1, 10_000):
        folder = base if k == 1 else base.with_name(f"{base.name}-{k}")
        try:
            folder.mkdir()
            return folder
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, f"no free folder name next to {base}")


#: Whether HDF5 locks the files it opens. ``HDF5_USE_FILE_LOCKING`` set to ``FALSE`` or ``0``
#: turns its locks off; HDF5 reads it once, as the library starts (on importing h5py, before
#: this module), so it is read here once too.
HDF5_LOCKS_FILES = os.environ.get("HDF5_USE_FILE_LOCKING", "").strip().upper() not in ("FALSE",
                                                                                      "0")


@contextmanager
def held(path):
    """An exclusive ``flock`` on the file ``path`` itself, held inside the block, when HDF5's
    own file locks are off (:data:`HDF5_LOCKS_FILES`); :class:`FolderBusyError` when another
    process holds it, nothing where the file or the file system's locks are missing."""
    if HDF5_LOCKS_FILES:
        yield
        return
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)  # a named pipe: no wait for a writer
    except FileNotFoundError:
        yield
        return
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FolderBusyError(path, None) from None
        except OSError as error:
            if error.errno not in NO_LOCKS:
                raise
        yield
    finally:
        os.close(fd)


def part_path(path):
    """Where a new run file is written until :func:`publish` puts it in place."""
    return Path(path).with_name(f".{Path(path).name}.part")


class RunLock:
    """Exclusive lock on the run file ``path`` for this process (see the module docstring);
    a context manager. :class:`FolderBusyError` when another process holds it."""

    def __init__(self, path):
        self.path = Path(path)
        self.file = lock_path(path)
        self._fd = None
        self._run_file = None  # held(path), entered

    def __enter__(self):
        while True:
            fd = os.open(self.file, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
                self._fd = fd  # held: from here on __exit__ releases it, even mid-way
            except BlockingIOError:
                holder = os.read(fd, 32).decode(errors="replace").strip()
                os.close(fd)
                raise FolderBusyError(self.path, holder) from None
            except OSError as error:
                os.close(fd)
                if error.errno not in NO_LOCKS:
                    raise
                self.file.unlink(missing_ok=True)
                warnings.warn(f"the file system of {self.path} has no file locks: nothing "
                              f"stops a second run from writing there", RuntimeWarning,
                              stacklevel=2)
                part_path(self.path).unlink(missing_ok=True)
                return self
            # a releasing process unlinks the lock file: the one locked must still be there
            try:
                same = os.path.samestat(os.fstat(fd), os.stat(self.file))
            except FileNotFoundError:
                same = False
            if same:
                break
            self._fd = None
            os.close(fd)
        os.ftruncate(fd, 0)
        os.write(fd, str(os.getpid()).encode())
        # what a run killed before publishing left behind; only the lock's holder writes it
        part_path(self.path).unlink(missing_ok=True)
        run_file = held(self.path)
        try:
            run_file.__enter__()
        except BaseException:  # FolderBusyError: the file is in use under another name
            self.__exit__()
            raise
        self._run_file = run_file
        return self

    def __exit__(self, *exc):
        if self._run_file is not None:
            self._run_file.__exit__(None, None, None)
            self._run_file = None
        if self._fd is not None:
            self.file.unlink(missing_ok=True)
            os.close(self._fd)
            self._fd = None
        return False


def publish(part, path):
    """Put the finished header ``part`` in place as ``path`` (never over an existing file:
    :class:`FileExistsError`)."""
    try:
        os.link(part, path)
    except OSError as error:
        if error.errno not in (errno.EPERM, errno.ENOTSUP, errno.EXDEV, errno.EMLINK):
            raise  # FileExistsError among them
        # a file system without hard links: the lock keeps other runs away from ``path``
        if Path(path).exists():
            raise FileExistsError(errno.EEXIST, f"{path} exists") from error
        os.rename(part, path)
        return
    os.unlink(part)


def cannot_write(path, error, then=""):
    """:class:`RunFileError` for a run file that could not be made, and why."""
    return RunFileError(f"cannot write the run file {path}: {hdf5_reason(error)}{then}")


@contextmanager
def locked(path, key):
    """Hold the lock of the run file ``path`` (:class:`RunLock`): another process's lock is a
    :class:`ConfigError` on ``key``, a folder where no lock file can be made a
    :class:`RunFileError`."""
    lock = RunLock(path)
    try:  # released whatever ends the run, a signal inside the taking of the lock included
        try:
            lock.__enter__()
        except FolderBusyError as error:
            what = "run file" if key == "resume" else "folder"
            raise ConfigError(key, str(path if key == "resume" else path.parent),
                              f"a {what} that no other run is using: {error.holder} is "
                              f"writing {path}; wait for it to end, or choose another") from None
        except OSError as error:
            raise cannot_write(path, error) from error
        yield
    finally:
        lock.__exit__()
