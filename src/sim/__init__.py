"""sim: event-driven simulation of hard disks in two dimensions."""

import hashlib
import os
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

try:
    __version__ = version("sim")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"


def _numba_cache_dir():
    """A compiled-code cache per version of the sources.

    numba checks only the timestamp of the file that defines a cached function, not of the
    files whose functions it inlined, so an edit to ``kinematics.py`` would leave a stale
    ``run_events`` in the cache. Keying the cache folder by a hash of every module with
    compiled code avoids it.
    """
    digest = hashlib.sha1()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        source = path.read_bytes()
        if b"@njit" in source:
            digest.update(path.name.encode())
            digest.update(source)
    base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
    return str(base / "sim" / "numba" / digest.hexdigest()[:16])


if "NUMBA_CACHE_DIR" not in os.environ:
    os.environ["NUMBA_CACHE_DIR"] = _numba_cache_dir()
