"""The error of a run file that cannot be read or written: one class for both, so that a
caller catches one name."""


class RunFileError(OSError):
    """A run file that cannot be read (missing, a folder, not HDF5, not a run file of sim,
    damaged, or held by a run still writing it) or written (read-only folder, full disk, a
    failed write); the message names the file and why."""
