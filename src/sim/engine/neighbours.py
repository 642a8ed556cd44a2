"""Neighbour shells, their lists, and the cell grid used to build them.

Design after Smallenburg, Eur. Phys. J. E 45, 22 (2022): disk i owns a shell, the circle of
radius ``delta[i]`` around its centre c_i (set when the list was last built). Until its
shell-exit event, disk i stays inside the shell, so i and j can only have a pair event while
``|c_i - c_j| < a_i + a_j + δ_i + δ_j``, a_i the reach of disk i: its radius R_i for hard
disks, else what the pair interaction says (:func:`sim.engine.pairs.pair_reach`), frozen at
each rebuild of i's list (``reach[i]``). The neighbour lists hold exactly those pairs and are
kept symmetric: when i rebuilds, it leaves the lists of the neighbours it loses and joins the
lists of the ones it gains. A pair interaction that keeps a state per pair has it beside the
pair's two entries (``pair_state``, moved with them), 0 for a pair that joins the lists.

A new shell is centred a little ahead of its disk along its velocity (:func:`shell_centre`),
so that in a dilute gas a disk flies further before it leaves. The grid files disks by shell
centre, so a disk changes cell only when it rebuilds. Cells are sized for the ordinary
("small") disks. The few disks much larger than the rest ("big", e.g. a crater projectile)
are not filed in cells: every small disk checks them directly, and a big disk scans as many
cells as its reach needs. So one projectile never forces large cells on everyone.

Arrays (n disks), of which the compiled functions take ``neighbours`` and ``box`` as the groups
:class:`sim.engine.groups.Neighbours` and :class:`sim.engine.groups.Box`:
  table float64[n, DISK_COLUMNS] — the disk table of :mod:`sim.engine.kinematics`, whose columns
  CX, CY hold the shell centre; delta float64[n], or one float when every shell has the same
  radius (:func:`sim.engine.parameters.per_disk`);
  nb_start int32[n], nb_cap int32[n], nb_count int32[n], nb int32[sum(nb_cap)] — list of disk i
  is ``nb[nb_start[i] : nb_start[i] + nb_count[i]]``. When every list has the same capacity
  (no big disks), the compiled code gets that capacity instead of nb_start and nb_cap
  (:func:`list_start`, :func:`sim.engine.parameters.per_disk`): a list's start is then computed, not
  loaded, and the neighbours of a disk are one load closer;
  cell_head int32[ncx*ncy], cell_next int32[n], cell_prev int32[n], cell_of int32[n] (-1 big);
  big int32[n_big]; reach float64[n], or None for the radii (the table's column RADIUS);
  pair_state int32[sum(nb_cap)] beside ``nb``, or None for a pair interaction without state;
  geometry float64[6] and grid int64[4] — the box and its cells (:mod:`sim.engine.box`).
"""

import math

import numpy as np
from numba import njit, types
from numba.extending import overload

from sim.engine.box import CELL_SIDE, CELLS, LEAD, PERIODIC, REACH, fold, separation
from sim.engine.kinematics import (
    CX,
    CY,
    RADIUS,
    TINY_SPEED_SQUARED,
    VX,
    VY,
    X,
    Y,
)
from sim.engine.parameters import optional_entry, per_disk, set_optional_entry
from sim.engine.prefetch import prefetch


def list_start(nb_start, i):
    """Where the neighbour list of disk i starts in ``nb``: ``nb_start[i]``, or ``i * nb_start``
    when ``nb_start`` is the capacity shared by every list."""
    return nb_start[i] if isinstance(nb_start, np.ndarray) else i * nb_start


@overload(list_start, inline="always")
def _list_start(nb_start, i):
    if isinstance(nb_start, types.Array):
        return lambda nb_start, i: nb_start[i]
    return lambda nb_start, i: i * nb_start


#: Relative slack on the shell-overlap test, far above round-off and far below any physics.
SHELL_SLACK = 1e-9


@njit(cache=True, inline="always")
def cell_index(x, y, geometry, grid):
    """Cell holding the point (x, y); points on or beyond the box edge go to the edge cell."""
    ix = int(x / geometry[CELL_SIDE])
    iy = int(y / geometry[CELL_SIDE + 1])
    ix = min(max(ix, 0), grid[CELLS] - 1)
    iy = min(max(iy, 0), grid[CELLS + 1] - 1)
    return iy * grid[CELLS] + ix


@njit(cache=True, inline="always")
def _cell_insert(i, c, neighbours):
    """File disk i in cell c, at the head of its list."""
    cell_head, cell_next, cell_prev = (neighbours.cell_head, neighbours.cell_next,
                                       neighbours.cell_prev)
    head = cell_head[c]
    cell_next[i] = head
    cell_prev[i] = -1
    if head >= 0:
        cell_prev[head] = i
    cell_head[c] = i
    neighbours.cell_of[i] = c


@njit(cache=True, inline="always")
def _cell_remove(i, neighbours):
    """Take disk i out of the list of its cell."""
    cell_head, cell_next, cell_prev = (neighbours.cell_head, neighbours.cell_next,
                                       neighbours.cell_prev)
    c = neighbours.cell_of[i]
    nxt = cell_next[i]
    prv = cell_prev[i]
    if prv >= 0:
        cell_next[prv] = nxt
    else:
        cell_head[c] = nxt
    if nxt >= 0:
        cell_prev[nxt] = prv


@njit(cache=True, inline="always")
def _remove_from_list(owner, disk, neighbours):
    """Remove ``disk`` (which must be listed) from the list of ``owner``: the last entry
    (and its pair's state) takes its place. The whole short list is scanned with a select
    instead of stopping at the match, whose position the branch predictor cannot guess."""
    nb_count, nb, pair_state = neighbours.nb_count, neighbours.nb, neighbours.pair_state
    start = list_start(neighbours.nb_start, owner)
    last = start + nb_count[owner] - 1
    found = last
    for k in range(start, last):
        found = k if nb[k] == disk else found
    nb[found] = nb[last]
    set_optional_entry(pair_state, found, optional_entry(pair_state, last, 0))
    nb_count[owner] -= 1


@njit(cache=True, inline="always")
def _shells_overlap(box, dx, dy, reach_i, reach_j):
    """Whether two shells whose centres are (dx, dy) apart (NaN: never), one reaching
    ``reach_i`` = a_i + δ_i from its centre and the other ``reach_j`` = a_j + δ_j, overlap.

    The reaches are summed per disk first, and the separation only changes sign with the
    order, so the test gives the same answer for (i, j) and (j, i) to the last bit: the lists
    hold exactly the overlapping pairs, which the rebuild relies on.
    """
    dx, dy = separation(box, dx, dy)
    reach_ij = (reach_i + reach_j) * (1.0 + SHELL_SLACK)
    return dx * dx + dy * dy < reach_ij * reach_ij


@njit(cache=True, inline="always")
def shell_reach(i, table, delta, reach):
    """How far the shell of disk i reaches from its centre: a_i + δ_i, a_i the reach frozen at
    its last rebuild (``reach[i]``, the radius when ``reach`` is None)."""
    return optional_entry(reach, i, table[i, RADIUS]) + per_disk(delta, i)


@njit(cache=True, inline="always")
def axis_span(c, k, nc, periodic):
    """Cells c - k … c + k along an axis of nc cells: a half-open range of cell indices, which
    run beyond 0 … nc - 1 on a periodic axis (images, see :func:`_fold`)."""
    if periodic:
        if 2 * k + 1 >= nc:
            return 0, nc
        return c - k, c + k + 1
    return max(0, c - k), min(nc, c + k + 1)


@njit(cache=True, inline="always")
def _fold(a, nc):
    """Cell index of the image a (-nc ≤ a < 2 nc) along a periodic axis of nc cells; a compare
    and an add instead of the integer division of ``a % nc``."""
    if a < 0:
        return a + nc
    if a >= nc:
        return a - nc
    return a


@njit(cache=True, inline="always")
def _consider(j, found, search, table, delta, neighbours, free, room, box):
    """One candidate j for the ``search`` of :func:`_find_new_neighbours`: written into the
    next free slot, counted when it is new. Returns the new count, or -1 when a new neighbour
    does not fit the list."""
    i, cx, cy, reach_i, cx_old, cy_old, reach_old, first_candidate = search
    cx_j = table[j, CX]
    cy_j = table[j, CY]
    reach_j = shell_reach(j, table, delta, neighbours.reach)
    listed = _shells_overlap(box, cx_old - cx_j, cy_old - cy_j, reach_old, reach_j)
    new = ((j != i) & (j >= first_candidate) & (not listed)
           & _shells_overlap(box, cx - cx_j, cy - cy_j, reach_i, reach_j))
    if found < room:
        neighbours.nb[free + found] = j
    elif new:
        return -1
    return found + new


@njit(cache=True, inline="always")
def _prefetch_candidates(x_lo, x_hi, y_lo, y_hi, table, cell_head, cell_next, grid):
    """Hint the cache for the row of every disk filed in the cells of a scan (spans of
    :func:`axis_span`), before the scan reads them.

    The scan walks each cell's linked list and tests every disk it meets, so without hints
    its loads of the disks' rows wait one after another, as far as the CPU can run ahead of
    the tests. Walking the lists first, which costs little (``cell_next`` is small and mostly
    in cache), asks for all rows at once. Against the scan without it
    (``benchmarks/compare_builds.py``, on a day the machine waited 210–250 ns on memory beyond
    4 MiB): 1.18 at N = 1e5 and 1.16 at 1e6, φ = 0.5; 1.33 and 1.12 at 1e5, φ = 0.1 and 0.7;
    1.10, 1.19 and 1.02 at 1e4, φ = 0.5, 0.1 and 0.7. On a day memory answered in 6 ns up to
    0.5 MiB and 38 ns at 4 MiB, the scan without hints beat it while the state fits the
    caches: 1.10, 1.03 and 1.02 at 1e4, φ = 0.1, 0.5 and 0.7; 1.13 and 1.06 at 1e3, φ = 0.1
    and 0.5; 1.04 and 1.01 at 2e4; 1.00 and 0.99 at 3e4. Hence the hints only with the
    look-ahead (:data:`sim.engine.sizing.LOOKAHEAD_MIN_DISKS`).
    """
    ncx = grid[CELLS]
    ncy = grid[CELLS + 1]
    for ay in range(y_lo, y_hi):
        row = _fold(ay, ncy) * ncx
        for ax in range(x_lo, x_hi):
            j = cell_head[row + _fold(ax, ncx)]
            while j >= 0:
                prefetch(table, j)
                j = cell_next[j]


@njit(cache=True, _nrt=False, error_model="numpy")
def _find_new_neighbours(search, table, delta, neighbours, box, hint_candidates):
    """Append after the list of disk i (its count unchanged) every disk j ≥ first_candidate,
    j ≠ i, whose shell overlaps the shell of i centred at (cx, cy) and reaching a_i + δ_i =
    ``reach_i`` but not the one centred at (cx_old, cy_old) and reaching ``reach_old``; NaN
    for the old centre drops that condition. ``search`` is
    ``(i, cx, cy, reach_i, cx_old, cy_old, reach_old, first_candidate)``.

    Small disks scan the 3×3 cells around (cx, cy) and the big disks; a big disk scans the cells
    within its reach. Returns the number of disks found, or -1 when they do not fit the list.
    Every candidate is written into the next free slot and the number advances only on a hit:
    no branch on the test, whose outcome the branch predictor cannot guess.

    ``hint_candidates``: hint the rows of all candidates first (:func:`_prefetch_candidates`).

    Compiled once and called, not inlined, by :func:`rebuild_neighbours` and
    :func:`build_all_neighbours` (both pass ``i`` and ``first_candidate`` as int64 and
    ``hint_candidates`` as a bool from Python, never a literal, so that they share one
    specialisation): 3.5 s less of the first compilation, and 2.8 s more for a literal.
    """
    i, cx, cy, reach_i, _, _, _, _ = search
    geometry, grid = box.geometry, box.grid
    nb_count, cell_head, cell_next = (neighbours.nb_count, neighbours.cell_head,
                                      neighbours.cell_next)
    ncx = grid[CELLS]
    ncy = grid[CELLS + 1]
    c = cell_index(cx, cy, geometry, grid)
    if neighbours.cell_of[i] >= 0:
        kx = 1
        ky = 1
    else:
        reach = reach_i + geometry[REACH]
        kx = int(math.ceil(reach / geometry[CELL_SIDE]))
        ky = int(math.ceil(reach / geometry[CELL_SIDE + 1]))
    x_lo, x_hi = axis_span(c % ncx, kx, ncx, grid[PERIODIC] != 0)
    y_lo, y_hi = axis_span(c // ncx, ky, ncy, grid[PERIODIC + 1] != 0)
    free = list_start(neighbours.nb_start, i) + nb_count[i]
    room = per_disk(neighbours.nb_cap, i) - nb_count[i]
    if hint_candidates:
        _prefetch_candidates(x_lo, x_hi, y_lo, y_hi, table, cell_head, cell_next, grid)
    found = 0
    for ay in range(y_lo, y_hi):
        row = _fold(ay, ncy) * ncx
        for ax in range(x_lo, x_hi):
            j = cell_head[row + _fold(ax, ncx)]
            while j >= 0:
                found = _consider(j, found, search, table, delta, neighbours, free, room, box)
                if found < 0:
                    return -1
                j = cell_next[j]
    big = neighbours.big
    for b in range(big.shape[0]):
        found = _consider(big[b], found, search, table, delta, neighbours, free, room, box)
        if found < 0:
            return -1
    return found


@njit(cache=True, inline="always")
def prefetch_cells(x, y, members, table, cell_head, cell_next, geometry, grid):
    """Hint the cache for a rebuild of a small disk's list near (x, y), which scans the 3×3
    cells around it (:func:`_find_new_neighbours`). Without ``members``: the heads of those
    cells. With ``members``: the heads are read (they should be in cache by now) and for each
    cell the head and the disk numbered before it are hinted (after a renumbering by cell the
    disks of a cell carry consecutive numbers, so that one is mostly a cell-mate)."""
    ncx = grid[CELLS]
    ncy = grid[CELLS + 1]
    c = cell_index(x, y, geometry, grid)
    x_lo, x_hi = axis_span(c % ncx, 1, ncx, grid[PERIODIC] != 0)
    y_lo, y_hi = axis_span(c // ncx, 1, ncy, grid[PERIODIC + 1] != 0)
    for ay in range(y_lo, y_hi):
        row = _fold(ay, ncy) * ncx
        if not members:
            prefetch(cell_head, row + _fold(x_lo, ncx))
            prefetch(cell_head, row + _fold(x_hi - 1, ncx))
            continue
        for ax in range(x_lo, x_hi):
            j = cell_head[row + _fold(ax, ncx)]
            if j >= 0:
                prefetch(table, j)
                prefetch(cell_next, j)
                if j > 0:
                    prefetch(table, j - 1)


@njit(cache=True, inline="always")
def shell_centre(i, table, delta, box):
    """Centre (cx, cy) of a new shell for disk i: ahead of the disk along its velocity by
    λ δ_i, λ = ``geometry[LEAD]`` < 1, wrapped into a periodic box.

    Any centre within δ_i of the disk is valid; one ahead of a disk in free flight lets it
    cross (1 + λ) δ_i instead of δ_i before it leaves the shell, so a dilute gas, whose disks
    fly further than δ between collisions, rebuilds fewer lists. A disk at rest, or too slow
    ever to reach its shell (``TINY_SPEED_SQUARED``), is centred on itself.
    """
    vx = table[i, VX]
    vy = table[i, VY]
    speed_squared = vx * vx + vy * vy
    lead = (box.geometry[LEAD] * per_disk(delta, i) / math.sqrt(speed_squared)
            if speed_squared > TINY_SPEED_SQUARED else 0.0)
    return fold(box, table[i, X] + lead * vx, 0), fold(box, table[i, Y] + lead * vy, 1)


@njit(cache=True, inline="always")
def _full_list(first, found, neighbours):
    """The first disk among ``nb[first : first + found]`` whose list is full, or -1."""
    for k in range(first, first + found):
        j = neighbours.nb[k]
        if neighbours.nb_count[j] >= per_disk(neighbours.nb_cap, j):
            return j
    return -1


@njit(cache=True, _nrt=False, error_model="numpy")
def rebuild_neighbours(i, a_i, table, delta, neighbours, box, hint_candidates):
    """New shell for disk i centred on its current position, reaching a_i + δ_i (a_i: its
    reach from now on, :func:`sim.engine.pairs.pair_reach`), and its new list.

    Only the differences are written. The lists hold exactly the pairs of overlapping shells,
    so a disk near the new centre is new to the list when its shell overlaps the new shell but
    not the old one; an old neighbour is dropped when its shell misses the new one. A shell
    moves by δ between rebuilds, so most neighbours stay and their lists are not touched.

    First the new neighbours are found and every list they join is checked for room; only then
    are lists changed and the shell moved. On overflow (returned disk id ≥ 0) nothing has
    changed, and calling again after enlarging the lists does the rebuild.
    ``hint_candidates``: see :func:`_find_new_neighbours`.
    """
    nb_start, nb_count, nb = neighbours.nb_start, neighbours.nb_count, neighbours.nb
    cell_of, pair_state = neighbours.cell_of, neighbours.pair_state
    cx, cy = shell_centre(i, table, delta, box)
    start = list_start(nb_start, i)
    old = nb_count[i]
    reach_i = a_i + per_disk(delta, i)
    reach_old = shell_reach(i, table, delta, neighbours.reach)
    found = _find_new_neighbours(
        (np.int64(i), cx, cy, reach_i, table[i, CX], table[i, CY], reach_old, np.int64(0)),
        table, delta, neighbours, box, hint_candidates)
    if found < 0:
        return i
    full = _full_list(start + old, found, neighbours)
    if full >= 0:
        return full
    kept = start
    for k in range(start, start + old):
        j = nb[k]
        if _shells_overlap(box, cx - table[j, CX], cy - table[j, CY], reach_i,
                           shell_reach(j, table, delta, neighbours.reach)):
            nb[kept] = j
            set_optional_entry(pair_state, kept, optional_entry(pair_state, k, 0))
            kept += 1
        else:
            _remove_from_list(j, i, neighbours)
    for k in range(start + old, start + old + found):
        j = nb[k]
        nb[kept] = j
        set_optional_entry(pair_state, kept, 0)
        kept += 1
        m = list_start(nb_start, j) + nb_count[j]
        nb[m] = i
        set_optional_entry(pair_state, m, 0)
        nb_count[j] += 1
    nb_count[i] = kept - start
    set_optional_entry(neighbours.reach, i, a_i)
    table[i, CX] = cx
    table[i, CY] = cy
    if cell_of[i] >= 0:
        c = cell_index(cx, cy, box.geometry, box.grid)
        if c != cell_of[i]:
            _cell_remove(i, neighbours)
            _cell_insert(i, c, neighbours)
    return -1


@njit(cache=True, _nrt=False, error_model="numpy")
def build_all_neighbours(table, delta, is_big, neighbours, box, hint_candidates):
    """Centre every shell on its disk, file the small disks in cells and link all pairs,
    each disk reaching a_i + δ_i (a_i from ``neighbours.reach``, else its radius). Returns the
    disk whose list overflowed, or -1. ``hint_candidates``: see :func:`_find_new_neighbours`.
    Pair states are left as they are: the engine sets them (:mod:`sim.engine.pairs`)."""
    nb_start, nb_count, nb = neighbours.nb_start, neighbours.nb_count, neighbours.nb
    n = table.shape[0]
    neighbours.cell_head[:] = -1
    nb_count[:] = 0
    for i in range(n):
        table[i, CX] = table[i, X]
        table[i, CY] = table[i, Y]
        if is_big[i]:
            neighbours.cell_of[i] = -1
        else:
            c = cell_index(table[i, CX], table[i, CY], box.geometry, box.grid)
            _cell_insert(i, c, neighbours)
    for i in range(n):
        first = list_start(nb_start, i) + nb_count[i]
        reach_i = shell_reach(i, table, delta, neighbours.reach)
        found = _find_new_neighbours(
            (np.int64(i), table[i, CX], table[i, CY], reach_i, np.nan, np.nan, np.nan,
             np.int64(i + 1)), table, delta, neighbours, box, hint_candidates)
        if found < 0:
            return i
        full = _full_list(first, found, neighbours)
        if full >= 0:
            return full
        for k in range(first, first + found):
            j = nb[k]
            nb[list_start(nb_start, j) + nb_count[j]] = i
            nb_count[j] += 1
        nb_count[i] += found
    return -1


@njit(cache=True)
def copy_lists(order, new_id, nb_start, nb_count, nb, new_start, new_nb, pair_state, new_state):
    """Write into ``new_nb`` at ``new_start[k]`` the list of disk ``order[k]``, each entry j
    as ``new_id[j]``, and its pairs' states into ``new_state`` (both None when there are
    none): lists moved to a new layout (identity ``order`` and ``new_id``) or renumbered,
    without temporary arrays."""
    for k in range(order.shape[0]):
        i = order[k]
        for m in range(nb_count[i]):
            new_nb[new_start[k] + m] = new_id[nb[nb_start[i] + m]]
            set_optional_entry(new_state, new_start[k] + m,
                               optional_entry(pair_state, nb_start[i] + m, 0))


def list_starts(capacity):
    """Offsets int32[n] of the lists in ``nb`` for the capacities ``capacity``: each list
    starts where the one before it ends."""
    ends = np.cumsum(capacity, dtype=np.int64)
    if ends.size and ends[-1] > np.iinfo(np.int32).max:
        raise MemoryError(f"the neighbour lists need {ends[-1]} slots, more than int32 indexes; "
                          f"use fewer disks or a smaller neighbour shell")
    starts = np.zeros(capacity.size, dtype=np.int32)
    starts[1:] = ends[:-1]
    return starts


def grow_lists(nb_start, nb_count, nb, new_cap, pair_state):
    """Return the list starts, lists and pairs' states (``nb_start``, ``nb``, ``pair_state``,
    None when there is none) laid out anew for the capacities ``new_cap`` int32[n], each at
    least the old one; contents and counts are kept. A rare step, done between compiled
    calls."""
    new_start = list_starts(new_cap)
    slots = int(new_cap.sum(dtype=np.int64))
    new_nb = np.full(slots, -1, dtype=np.int32)
    new_state = None if pair_state is None else np.zeros(slots, dtype=np.int32)
    identity = np.arange(nb_start.size)
    copy_lists(identity, identity, nb_start, nb_count, nb, new_start, new_nb, pair_state,
               new_state)
    return new_start, new_nb, new_state
