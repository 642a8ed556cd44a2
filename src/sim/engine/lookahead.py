"""Prefetching for the events ahead: while one event is worked on, the CPU is asked to load
what the next ones will read (hints only: no result changes; :mod:`sim.engine.prefetch`)."""

from numba import njit

from sim.engine.codes import SHELL_EXIT
from sim.engine.neighbours import list_start, prefetch_cells, shell_centre
from sim.engine.prefetch import prefetch
from sim.engine.queue import HEAP_SIZE, prefetch_next_block


@njit(cache=True, inline="always")
def prefetch_next(partner, slots, deeper, disks, schedule, neighbours):
    """Ask the CPU to start loading the row, next partner and list start of the partner of
    this event and of the disks in heap slots 1 … ``slots`` − 1, which the next events read
    (hints only: no result changes); ``deeper`` (with the look-ahead): also the rows, stamps
    and next event times of the partner's neighbours, and the stamps, queue links and list
    lengths of those disks."""
    table, stamp, nb, nb_count = disks.table, disks.stamp, neighbours.nb, neighbours.nb_count
    event_partner, heap, links = schedule.event_partner, schedule.heap, schedule.links
    if partner >= 0:
        prefetch(table, partner)
        prefetch(stamp, partner)
        prefetch(links, partner)
        start = list_start(neighbours.nb_start, partner)
        prefetch(nb, start)
        if deeper:
            for k in range(start, start + nb_count[partner]):
                prefetch(table, nb[k])
                prefetch(stamp, nb[k])
                prefetch(schedule.event_time, nb[k])
    for slot in range(1, min(slots, schedule.calendar[HEAP_SIZE])):
        c = heap[slot]
        prefetch(table, c)
        prefetch(event_partner, c)
        prefetch(nb, list_start(neighbours.nb_start, c))
        if deeper:
            prefetch(schedule.event_stamp, c)
            prefetch(stamp, c)
            prefetch(links, c)
            prefetch(nb_count, c)


@njit(cache=True, inline="always")
def prefetch_upcoming(partner, walker, walker_block, disks, schedule, neighbours, box):
    """Ask the CPU to start loading what the next events will read while this one is worked on,
    for states larger than the caches (hints only: no result changes). A disk's data is hinted
    in stages, one event apart, each stage reading what the one before brought in: the partner
    of this event and its neighbours' rows and stamps; the disks of the next three in the heap
    (:func:`prefetch_next`, deeper); for the next two the rows their predictions read (their
    neighbours' rows and stamps), their partners' data, or, for a shell exit, the cells it
    scans, its own cell links and the lists and counts of its neighbours, which its rebuild
    edits; and the bucket that becomes the heap next
    (:func:`sim.engine.queue.prefetch_next_block`: one of its disks per event, whose row,
    partner and list are hinted too, for the first events of the next block would otherwise
    reach the heap top with nothing fetched). Returns the bucket walk's state.

    The loop calls it only for a scene of :data:`sim.engine.sizing.LOOKAHEAD_MIN_DISKS` disks
    or more, and otherwise :func:`prefetch_next` for heap slots 1 and 2 (``slots`` = 3, not
    deeper): the look-ahead is a variant of the loop of its own, and a smaller scene compiles
    none of this function (3.5 s of the first compilation of the default scene).

    Against :func:`prefetch_next` alone (``benchmarks/compare_builds.py``, φ = 0.5): 1.49
    at N = 1e5, 1.39 at 1e6, 1.11 at 5e4, but 0.94 at 3e4, where the state still sits mostly
    in cache (hence :data:`sim.engine.sizing.LOOKAHEAD_MIN_DISKS`). The hints for the walked disks'
    rows, partners and lists, with blocks of 8 mean event times instead of 4
    (:data:`sim.engine.queue.BLOCK_EVENTS`), against neither: 1.07, 1.12 and 1.11 at N = 1e5
    (quartiles of rounds 0.98–1.17, 1.04–1.22, 1.05–1.17), 1.05 at 1e6 (1.02–1.12). The
    hints for the neighbours' collision counts, the list lengths and a shell exit's cell links
    and edited lists, with the loop's :func:`sim.engine.queue.prefetch_bucket`, against none of
    them (on a day a miss took 200 ns): 1.135 at N = 1e5 (1.03–1.20), 1.26 at φ = 0.1, 1.20
    at 1e6 (1.13–1.33). The hints for the neighbours' next event times, which a prediction
    reads since it looks for a pair's event only before the neighbour's own
    (:func:`sim.engine.loop.predict`), against none: 1.06 at N = 1e6 (1.02–1.18; without them
    the bound's reads had cost 2 % there), 1.02 at 1e5 (1.00–1.04).
    """
    table, stamp = disks.table, disks.stamp
    event_partner, event_stamp, heap, links = (schedule.event_partner, schedule.event_stamp,
                                               schedule.heap, schedule.links)
    nb_start, nb_count, nb = neighbours.nb_start, neighbours.nb_count, neighbours.nb
    prefetch_next(partner, 4, True, disks, schedule, neighbours)
    size = schedule.calendar[HEAP_SIZE]
    for slot in range(1, min(3, size)):
        c = heap[slot]
        partner_c = event_partner[c]
        start = list_start(nb_start, c)
        for k in range(start, start + nb_count[c]):
            prefetch(table, nb[k])
            prefetch(stamp, nb[k])
            prefetch(schedule.event_time, nb[k])
            if partner_c == SHELL_EXIT:
                prefetch(nb, list_start(nb_start, nb[k]))
                prefetch(nb_count, nb[k])
        if partner_c >= 0:
            prefetch(table, partner_c)
            prefetch(nb, list_start(nb_start, partner_c))
            prefetch(nb_count, partner_c)
            prefetch(stamp, partner_c)
            prefetch(event_stamp, partner_c)
        elif partner_c == SHELL_EXIT:
            prefetch(neighbours.cell_of, c)
            prefetch(neighbours.cell_prev, c)
            cx, cy = shell_centre(c, table, disks.delta, box)
            prefetch_cells(cx, cy, slot == 1, table, neighbours.cell_head, neighbours.cell_next,
                           box.geometry, box.grid)
    walker, walker_block = prefetch_next_block(walker, walker_block, links, schedule.list_head,
                                               schedule.calendar, schedule.event_time)
    if walker >= 0:
        prefetch(table, walker)
        prefetch(event_partner, walker)
        prefetch(nb, list_start(nb_start, walker))
        prefetch(nb_count, walker)
    return walker, walker_block
