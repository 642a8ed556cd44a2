"""Each variant of the event loop compiled by one process, and numba's cache kept whole.

numba compiles :func:`sim.engine.loop.run_events` anew for every combination of its argument
types (a *variant*: the effects a scene uses, what is per disk), in about 20 s, and keeps it
in its cache folder (``NUMBA_CACHE_DIR``, one per version of the sources, :mod:`sim`).
Processes that start together on a cold cache — the jobs of a sweep, the figure stages, the
test workers — would each compile the same variant; and two processes that save to the cache
at once can each drop the other's entry from the function's index, or number their code files
alike and leave an entry pointing at the other's code. So:

* :func:`compile_once`: a process that does not hold a variant compiles it under a lock named
  after it in the cache folder; the others wait and then load it from the cache;
* numba's cache saves an entry (index and code) under a lock of the function's index.

numba keeps all variants of a function in one index, a pickle of their argument types: a
variant whose types are defined outside sim (a user's kind of system event, in a module only
their script imports) would make the index unreadable to every other process. Such variants
are compiled by a dispatcher without a cache (:func:`cacheable`), at every start of their
process; all of sim's own are cached, and a second start of a scene compiles nothing.

Both locks are ``flock(2)`` locks, released by the system when their process ends.
"""

import contextlib
import fcntl
import os
import time
import zlib

from numba.core import caching


@contextlib.contextmanager
def _held(path):
    """An exclusive ``flock`` on the file ``path`` (made, with its folder, if missing) for the
    block; none where it cannot be made (a read-only cache folder, where numba caches
    nothing either)."""
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        handle = open(path, "a")
    except OSError:
        yield
        return
    with handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        yield


def compile_once(function, arguments):
    """Compile, or load from the cache, the variant of the compiled ``function`` that
    ``arguments`` (a tuple) call, holding the lock of that variant, unless this process holds
    it already; returns the wall-clock seconds it took (waiting included; 0 when held).
    Typing the arguments takes about 0.3 ms: call it once per engine and list layout, not
    per call."""
    if not hasattr(function, "overloads"):
        return 0.0  # NUMBA_DISABLE_JIT: plain Python, nothing to compile
    signature = tuple(function.typeof_pyval(a) for a in arguments)
    if signature in function.overloads:
        return 0.0
    started = time.perf_counter()
    name = f"{function.__name__}-{zlib.crc32(str(signature).encode()):08x}.lock"
    with _held(os.path.join(os.environ["NUMBA_CACHE_DIR"], name)):
        function.compile(signature)
    return time.perf_counter() - started


def cacheable(*values):
    """Whether numba may cache a compiled function called with ``values``: each is None or
    of a type defined in sim."""
    return all(value is None or type(value).__module__.partition(".")[0] == "sim"
               for value in values)


def _saved_under_lock(save):
    """numba's ``IndexDataCacheFile.save`` (read the index, add the entry, write index and
    code) holding a lock beside the index."""

    def save_under_lock(self, key, data):
        with _held(self._index_path + ".lock"):
            save(self, key, data)

    save_under_lock.__wrapped__ = save
    return save_under_lock


if not hasattr(caching.IndexDataCacheFile.save, "__wrapped__"):
    caching.IndexDataCacheFile.save = _saved_under_lock(caching.IndexDataCacheFile.save)
