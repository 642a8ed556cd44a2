"""An output file written whole or not at all (``sim-movie``, ``sim-export``): under a hidden
name beside it, made before any work so that an output that cannot be written is refused at
once (:class:`sim.pipeline.command.BadInput`, exit status 2), renamed once complete, removed
when anything fails."""

import os
from contextlib import contextmanager
from pathlib import Path

from sim.pipeline.command import BadInput


@contextmanager
def whole_file(out):
    """The hidden path beside ``out`` (the ``--out`` of the command) for the block to write:
    made empty before the block runs (so with the umask's permissions; gsd would make its file
    0640), renamed to ``out`` when the block ends, removed when it raises. :class:`BadInput`
    naming ``--out``, ``out`` and the OS's reason when ``out`` is a folder or another file
    that is not a regular one (a device such as /dev/null), its folder does not exist or the
    hidden file cannot be made there (a read-only folder or file system, /proc);
    nothing is left behind then."""
    out = Path(out)
    allowed = "a file in a folder that exists and may be written"
    if not out.parent.is_dir():
        raise BadInput(f"--out {out}: no folder {out.parent}; {allowed}")
    if out.is_dir():
        raise BadInput(f"--out {out}: a folder; {allowed}")
    if out.exists() and not out.is_file():  # renamed over, a device would be replaced
        raise BadInput(f"--out {out}: not a regular file (a device, pipe or socket); "
                       f"{allowed}")
    partial = out.with_name(f".{out.stem}.{os.getpid()}.part{out.suffix}")
    try:
        partial.touch()
    except OSError as error:  # never made: nothing to remove (on a read-only file system
        # even removing a file that is not there fails)
        raise BadInput(f"--out {out}: cannot write in {out.parent} "
                       f"({error.strerror or error}); {allowed}") from None
    try:
        yield partial
        os.replace(partial, out)
    except BaseException:
        partial.unlink(missing_ok=True)
        raise
