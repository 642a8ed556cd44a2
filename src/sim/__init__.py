"""sim: event-driven simulation of hard disks in two dimensions."""

import os
import zlib


def __getattr__(name):
    """``sim.__version__``, looked up when first asked for: importing ``sim`` stays quick
    (``os`` and ``zlib`` only), so that the command line takes Ctrl-C almost from its first
    moment."""
    if name != "__version__":
        raise AttributeError(f"module 'sim' has no attribute {name!r}")
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("sim")
    except PackageNotFoundError:  # running from a source tree that is not installed
        return "0+unknown"


def _numba_cache_dir():
    """A compiled-code cache per version of the sources.

    numba checks only the timestamp of the file that defines a cached function, not of the
    files whose functions it inlined, so an edit to ``kinematics.py`` would leave a stale
    ``run_events`` in the cache. Keying the cache folder by a hash of every module with
    compiled code avoids it. The key is a CRC-32 and an Adler-32 of those sources (zlib
    loads in a fraction of a millisecond, hashlib's OpenSSL in about 20). Every module of the
    package and its subpackages that uses numba enters the key, with its path.
    """
    crc, adler = 0, 1
    here = os.path.dirname(os.path.abspath(__file__))
    for folder, _, files in sorted(os.walk(here)):
        for name in sorted(n for n in files if n.endswith(".py")):
            with open(os.path.join(folder, name), "rb") as module:
                source = module.read()
            if b"@njit" in source or b"numba" in source:
                path = os.path.relpath(os.path.join(folder, name), here)
                for part in (path.encode(), source):
                    crc, adler = zlib.crc32(part, crc), zlib.adler32(part, adler)
    base = os.environ.get("XDG_CACHE_HOME", os.path.join(os.path.expanduser("~"), ".cache"))
    return os.path.join(base, "sim", "numba", f"{crc:08x}{adler:08x}")


if "NUMBA_CACHE_DIR" not in os.environ:
    os.environ["NUMBA_CACHE_DIR"] = _numba_cache_dir()
