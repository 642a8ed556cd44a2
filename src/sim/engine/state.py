"""The engine's state: per-disk arrays in engine order, and their renumbering.

The engine keeps disks in its own order — sorted by neighbour-grid cell, so that disks close
in space are close in memory — and remembers each one's original index in ``order``. The
user sees the original order only (:class:`sim.engine.core.Engine` translates).

Per-disk arrays (n disks, engine order):
  table float64[n, DISK_COLUMNS] — one 64-byte row per disk: position and velocity, the
      disk's own time, radius, shell centre (columns in :mod:`sim.engine.kinematics`);
  delta float64[n] — neighbour-shell radius; mass float64[n]; species int32[n]; is_big bool[n];
  stamp int32[n] — staleness stamps, counted int32[n] — the stamp when contacts int64[n],
      each disk's contacts (disk and wall), was last brought up to date, at every clock
      rebase and whenever it is read (:mod:`sim.engine.stamps`);
  t_last float64[n], streak int32[n] — time of the last contact, collapse streak;
  event_time float64[n], event_partner int32[n], event_stamp int32[n] — scheduled event;
  links int32[n, 3] — place in the event queue (:mod:`sim.engine.queue`);
  nb_start int32[n], nb_cap int32[n], nb_count int32[n] — neighbour-list layout;
  cell_next, cell_prev, cell_of int32[n] — cell lists; order int32[n] — original index;
  images int32[n, 2] — periodic windings (:mod:`sim.engine.flight`), or None when not counted.
  spin float64[n] — angular velocities (:mod:`sim.effects.rotation`), or None when no disk
  turns.
  pair_event int32[n] — the name of each disk's pair event, reach float64[n] — each disk's
      reach, pair_state int32 (beside nb) — each neighbour pair's state: each None unless the
      scene's pair interaction has the rule that needs it (:mod:`sim.engine.pairs`).
Other arrays: nb int32 (neighbour lists), heap int32[n], list_head int32[B + 1],
calendar int64[3], block_rate float64[1], big int32[n_big], cell_head int32[cells],
system_time float64[1] (:mod:`sim.engine.system`).

All of them live in one buffer (:func:`one_buffer`), each starting on a cache line, the
buffer on a 2 MiB huge page.
"""

from dataclasses import dataclass, fields
from typing import Optional

import numpy as np

from sim.engine.neighbours import copy_lists, list_starts
from sim.engine.queue import NEXT, PREV

PER_DISK = ("table", "delta", "mass", "species", "is_big", "stamp", "counted", "contacts",
            "t_last", "streak", "event_time", "event_partner", "event_stamp", "links",
            "nb_start", "nb_cap", "nb_count", "cell_next", "cell_prev", "cell_of", "order")

CACHE_LINE = 64
HUGE_PAGE = 2 << 20


def one_buffer(layout):
    """Empty arrays, one per entry name → (shape, dtype) of ``layout``, in one buffer that
    starts on a 2 MiB huge page, each array on a 64-byte cache line.

    With 4 KiB pages a state of 29 MB (10⁵ disks) spans 7000 pages, more than the TLB holds,
    and a random access may wait for a page walk as well as for the line. numpy advises the
    kernel to back allocations of 4 MiB and more with 2 MiB pages (``MADV_HUGEPAGE``, Linux),
    but each per-disk array stays below that up to N ≈ 10⁶; one buffer gets them all.
    Measured with ``benchmarks/compare_builds.py`` against separate arrays: ×1.045 at
    N = 10⁵ (median of five comparisons, 1.02–1.09), 1.00 at 5·10⁴ and 10⁶.
    """
    sizes = {name: np.prod(shape, dtype=np.int64) * np.dtype(dtype).itemsize
             for name, (shape, dtype) in layout.items()}
    raw = np.empty(sum(-(-size // CACHE_LINE) * CACHE_LINE for size in sizes.values())
                   + HUGE_PAGE, dtype=np.uint8)
    offset = -raw.ctypes.data % HUGE_PAGE
    arrays = {}
    for name, (shape, dtype) in layout.items():
        arrays[name] = raw[offset:offset + sizes[name]].view(dtype).reshape(shape)
        offset += -(-sizes[name] // CACHE_LINE) * CACHE_LINE
    return arrays


@dataclass
class DiskArrays:
    table: np.ndarray
    delta: np.ndarray
    mass: np.ndarray
    species: np.ndarray
    is_big: np.ndarray
    stamp: np.ndarray
    counted: np.ndarray
    contacts: np.ndarray
    t_last: np.ndarray
    streak: np.ndarray
    event_time: np.ndarray
    event_partner: np.ndarray
    event_stamp: np.ndarray
    links: np.ndarray
    nb_start: np.ndarray
    nb_cap: np.ndarray
    nb_count: np.ndarray
    cell_next: np.ndarray
    cell_prev: np.ndarray
    cell_of: np.ndarray
    order: np.ndarray
    nb: np.ndarray
    heap: np.ndarray
    list_head: np.ndarray
    calendar: np.ndarray
    block_rate: np.ndarray
    big: np.ndarray
    cell_head: np.ndarray
    system_time: np.ndarray
    images: Optional[np.ndarray] = None
    spin: Optional[np.ndarray] = None
    pair_event: Optional[np.ndarray] = None
    reach: Optional[np.ndarray] = None
    pair_state: Optional[np.ndarray] = None

    def __post_init__(self):
        self.pack()

    def arrays(self):
        """Name → array, for every array there is."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if getattr(self, f.name) is not None}

    def pack(self):
        """Move every array into one fresh buffer (:func:`one_buffer`)."""
        for name, array in self._fresh_buffer().items():
            array[...] = getattr(self, name)
            setattr(self, name, array)

    def _fresh_buffer(self):
        return one_buffer({name: (array.shape, array.dtype)
                           for name, array in self.arrays().items()})

    @property
    def nbytes(self):
        return sum(array.nbytes for array in self.arrays().values())

    @property
    def queue(self):
        """The event-queue arrays in the order the compiled functions take them."""
        return self.heap, self.links, self.list_head, self.calendar, self.block_rate

    def permute(self, perm):
        """Renumber the disks: new disk k is old disk ``perm[k]``. Every id is remapped and
        the neighbour lists are laid out anew in the new order; the physics is untouched."""
        new_id = np.empty_like(perm)
        new_id[perm] = np.arange(perm.size)

        def remap(ids):
            ids[ids >= 0] = new_id[ids[ids >= 0]].astype(ids.dtype)

        old = self.arrays()
        new = self._fresh_buffer()
        for name in PER_DISK + tuple(name for name in OPTIONAL_PER_DISK + PAIR_PER_DISK
                                     if getattr(self, name) is not None):
            np.take(old[name], perm, axis=0, out=new[name])
        for name in ("heap", "list_head", "calendar", "block_rate", "big", "cell_head",
                     "system_time"):
            new[name][...] = old[name]
        for ids in (new["event_partner"], new["cell_next"], new["cell_prev"], new["cell_head"],
                    new["list_head"], new["links"][:, NEXT], new["links"][:, PREV], new["heap"],
                    new["big"]):
            remap(ids)
        new["big"].sort()
        # neighbour lists: the same contents, ids remapped, one segment per disk in new order
        new["nb_start"][:] = list_starts(new["nb_cap"])
        new["nb"][:] = -1
        if self.pair_state is not None:
            new["pair_state"][:] = 0
        copy_lists(perm, new_id, old["nb_start"], old["nb_count"], old["nb"], new["nb_start"],
                   new["nb"], old.get("pair_state"), new.get("pair_state"))
        for name, array in new.items():
            setattr(self, name, array)


#: per-disk arrays of a pair interaction (:mod:`sim.engine.pairs`), None unless it needs them
PAIR_PER_DISK = ("pair_event", "reach")

#: per-disk arrays of effects (the other fields that default to None, each a field of
#: :class:`sim.effects.Effects` too): None when the effect is off; the engine keeps its other
#: effect fields as attributes
OPTIONAL_PER_DISK = tuple(f.name for f in fields(DiskArrays)
                          if f.default is None and f.name not in PAIR_PER_DISK + ("pair_state",))
