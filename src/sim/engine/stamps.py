"""The staleness stamp of each disk, and its contact count.

A prediction of disk i's event with partner j records j's stamp (``Schedule.event_stamp``);
when it reaches the head of the queue with j's stamp changed since, j has moved otherwise than
i's prediction assumed, and the event is stale: dropped and predicted again. The loop bumps
both stamps at every collision and a disk's stamp at every wall contact, and nowhere else;
whatever else changes a disk's motion between its events (a system event's kick, a pair event
that is no contact) calls :func:`invalidate`, which bumps the stamp without counting a contact.

Arrays (n disks, :class:`sim.engine.groups.Disks`): ``stamp`` int32[n], wrapping at 2³²;
``counted`` int32[n], the stamp at which ``contacts`` int64[n] was last brought up to date
(:func:`count_contacts`).
"""

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def _count(i, stamp, counted, contacts):
    """Add to disk i's contacts the bumps of its stamp since it was last counted (modulo 2³²,
    so correct while no disk makes 2³² contacts between two counts)."""
    contacts[i] += (np.int64(stamp[i]) - counted[i]) & 0xFFFFFFFF
    counted[i] = stamp[i]


@njit(cache=True, inline="always")
def count_contacts(stamp, counted, contacts):
    """Bring the full contact counts ``contacts`` up to date with the stamps: every bump since
    a stamp was last counted is a contact (the loop calls it at every clock rebase)."""
    for i in range(stamp.shape[0]):
        _count(i, stamp, counted, contacts)


@njit(cache=True, _nrt=False, error_model="numpy")
def count_all_contacts(stamp, counted, contacts):
    """:func:`count_contacts`, called from Python."""
    count_contacts(stamp, counted, contacts)


@njit(cache=True, inline="always")
def invalidate(i, disks):
    """Make every prediction with disk i as partner stale, without counting a contact."""
    _count(i, disks.stamp, disks.counted, disks.contacts)
    disks.stamp[i] += 1
    disks.counted[i] = disks.stamp[i]
