"""The engine's state: per-disk arrays in engine order, and their renumbering.

The engine keeps disks in its own order — sorted by neighbour-grid cell, so that disks close
in space are close in memory — and remembers each one's original index in ``order``. The
user sees the original order only (:class:`sim.engine.Engine` translates).

Per-disk arrays (n disks, engine order):
  position, velocity float64[n, 2] at each disk's own time t_disk float64[n];
  center float64[n, 2], delta float64[n] — neighbour shell (sim.neighbours);
  radius, mass float64[n]; species int32[n]; is_big bool[n];
  coll_count int64[n] — contacts (disk and wall) of each disk, also the staleness counter;
  t_last float64[n], streak int32[n] — time of last contact and collapse streak;
  event_time float64[n], event_partner int32[n], event_count int64[n] — scheduled event;
  slot int32[n] — position in the event queue;
  nb_start int64[n], nb_cap int32[n], nb_count int32[n] — neighbour-list layout;
  cell_next, cell_prev, cell_of int32[n] — cell lists.
Arrays holding disk ids: nb, heap, big, cell_head (and cell_next/cell_prev, event_partner ≥ 0).
"""

from dataclasses import dataclass, fields

import numpy as np

PER_DISK = ("position", "velocity", "t_disk", "center", "delta", "radius", "mass", "species",
            "is_big", "coll_count", "t_last", "streak", "event_time", "event_partner",
            "event_count", "slot", "nb_start", "nb_cap", "nb_count", "cell_next", "cell_prev",
            "cell_of", "order")


@dataclass
class DiskArrays:
    position: np.ndarray
    velocity: np.ndarray
    t_disk: np.ndarray
    center: np.ndarray
    delta: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    species: np.ndarray
    is_big: np.ndarray
    coll_count: np.ndarray
    t_last: np.ndarray
    streak: np.ndarray
    event_time: np.ndarray
    event_partner: np.ndarray
    event_count: np.ndarray
    slot: np.ndarray
    nb_start: np.ndarray
    nb_cap: np.ndarray
    nb_count: np.ndarray
    cell_next: np.ndarray
    cell_prev: np.ndarray
    cell_of: np.ndarray
    order: np.ndarray
    nb: np.ndarray
    heap: np.ndarray
    big: np.ndarray
    cell_head: np.ndarray

    @property
    def nbytes(self):
        return sum(getattr(self, f.name).nbytes for f in fields(self))

    def permute(self, perm):
        """Renumber the disks: new disk k is old disk ``perm[k]``. Every id is remapped and
        the neighbour lists are laid out anew in the new order; the physics is untouched."""
        new_id = np.empty_like(perm)
        new_id[perm] = np.arange(perm.size)
        old_start, old_count = self.nb_start, self.nb_count
        for name in PER_DISK:
            setattr(self, name, np.ascontiguousarray(getattr(self, name)[perm]))
        partner = self.event_partner
        partner[partner >= 0] = new_id[partner[partner >= 0]].astype(partner.dtype)
        for name in ("cell_next", "cell_prev"):
            links = getattr(self, name)
            links[links >= 0] = new_id[links[links >= 0]].astype(links.dtype)
        head = self.cell_head
        head[head >= 0] = new_id[head[head >= 0]].astype(head.dtype)
        self.heap = new_id[self.heap].astype(self.heap.dtype)
        self.big = np.sort(new_id[self.big]).astype(self.big.dtype)
        # neighbour lists: the same contents, ids remapped, one segment per disk in new order
        self.nb_start = np.zeros_like(self.nb_start)
        self.nb_start[1:] = np.cumsum(self.nb_cap[:-1], dtype=np.int64)
        index = np.repeat(old_start[perm], old_count[perm]) + _ranks(old_count[perm])
        target = np.repeat(self.nb_start, self.nb_count) + _ranks(self.nb_count)
        nb = np.full(int(self.nb_cap.sum()), -1, dtype=self.nb.dtype)
        nb[target] = new_id[self.nb[index]]
        self.nb = nb


def _ranks(counts):
    """0, 1, …, c_0 − 1, 0, 1, …, c_1 − 1, …"""
    total = int(counts.sum())
    starts = np.repeat(np.cumsum(counts) - counts, counts)
    return np.arange(total) - starts
