"""Neighbour shells, their lists, and the cell grid used to build them.

Design after Smallenburg, Eur. Phys. J. E 45, 22 (2022): disk i owns a shell, the circle of
radius ``delta[i]`` around its centre c_i (its position when the list was last built). Until its
shell-exit event, disk i stays inside the shell, so i and j can only touch while
``|c_i - c_j| < R_i + R_j + δ_i + δ_j``. The neighbour lists hold exactly those pairs and are
kept symmetric: when i rebuilds, it leaves its old neighbours' lists and joins the new ones'.

The grid files disks by shell centre, so a disk changes cell only when it rebuilds. Cells are
sized for the ordinary ("small") disks. The few disks much larger than the rest ("big", e.g. a
crater projectile) are not filed in cells: every small disk checks them directly, and a big
disk scans as many cells as its reach needs. So one projectile never forces large cells on
everyone.

Arrays (n disks):
  disks float64[n, DISK_COLUMNS] — the disk table of :mod:`sim.kinematics`, whose columns
  CX, CY hold the shell centre; delta float64[n];
  nb_start int64[n], nb_cap int32[n], nb_count int32[n], nb int32[sum(nb_cap)] — list of disk i
  is ``nb[nb_start[i] : nb_start[i] + nb_count[i]]``;
  cell_head int32[ncx*ncy], cell_next int32[n], cell_prev int32[n], cell_of int32[n] (-1 big);
  big int32[n_big];
  geometry float64[5] = (Lx, Ly, cell width x, cell width y, largest small R + δ);
  grid int64[4] = (cells along x, cells along y, periodic x, periodic y).
"""

import math

import numpy as np
from numba import njit

from sim.kinematics import CX, CY, RADIUS, X, Y, minimum_image

#: Relative slack on the shell-overlap test, far above round-off and far below any physics.
SHELL_SLACK = 1e-9


@njit(cache=True, inline="always")
def cell_index(x, y, geometry, grid):
    """Cell holding the point (x, y); points on or beyond the box edge go to the edge cell."""
    ix = int(x / geometry[2])
    iy = int(y / geometry[3])
    ix = min(max(ix, 0), grid[0] - 1)
    iy = min(max(iy, 0), grid[1] - 1)
    return iy * grid[0] + ix


@njit(cache=True, inline="always")
def _cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of):
    head = cell_head[c]
    cell_next[i] = head
    cell_prev[i] = -1
    if head >= 0:
        cell_prev[head] = i
    cell_head[c] = i
    cell_of[i] = c


@njit(cache=True, inline="always")
def _cell_remove(i, cell_head, cell_next, cell_prev, cell_of):
    c = cell_of[i]
    nxt = cell_next[i]
    prv = cell_prev[i]
    if prv >= 0:
        cell_next[prv] = nxt
    else:
        cell_head[c] = nxt
    if nxt >= 0:
        cell_prev[nxt] = prv


@njit(cache=True, inline="always")
def _remove_from_list(owner, disk, nb_start, nb_count, nb):
    """Remove ``disk`` (which must be listed) from the list of ``owner``: the last entry
    takes its place. The whole short list is scanned with a select instead of stopping at
    the match, whose position the branch predictor cannot guess."""
    start = nb_start[owner]
    last = start + nb_count[owner] - 1
    found = last
    for k in range(start, last):
        found = k if nb[k] == disk else found
    nb[found] = nb[last]
    nb_count[owner] -= 1


@njit(cache=True, inline="always")
def _shells_overlap(i, j, disks, delta, geometry, grid):
    dx = minimum_image(disks[i, CX] - disks[j, CX], geometry[0], grid[2] != 0)
    dy = minimum_image(disks[i, CY] - disks[j, CY], geometry[1], grid[3] != 0)
    reach = (disks[i, RADIUS] + disks[j, RADIUS] + delta[i] + delta[j]) * (1.0 + SHELL_SLACK)
    return dx * dx + dy * dy < reach * reach


@njit(cache=True, inline="always")
def _axis_span(c, k, nc, periodic):
    if periodic:
        if 2 * k + 1 >= nc:
            return 0, nc
        return c - k, c + k + 1
    return max(0, c - k), min(nc, c + k + 1)


@njit(cache=True, _nrt=False, error_model="numpy")
def link_new_neighbours(i, only_higher, disks, delta, nb_start, nb_cap, nb_count, nb,
                        cell_head, cell_next, cell_of, big, geometry, grid):
    """Find every disk j whose shell overlaps the shell of i and link the pair.

    Small disks scan the 3×3 cells around their own and the big disks; a big disk scans the
    cells within its reach. With ``only_higher`` only j > i are linked (initial build).
    Returns the disk whose list overflowed, or -1; the lists stay symmetric either way.

    Two passes: the scan writes every candidate into the next free slot of i's list and
    advances the count only on overlap (no branch on the test, whose outcome the branch
    predictor cannot guess); then i joins the list of each new neighbour.
    """
    ncx = grid[0]
    ncy = grid[1]
    c = cell_index(disks[i, CX], disks[i, CY], geometry, grid)
    cx = c % ncx
    cy = c // ncx
    if cell_of[i] >= 0:
        kx = 1
        ky = 1
    else:
        reach = disks[i, RADIUS] + delta[i] + geometry[4]
        kx = int(math.ceil(reach / geometry[2]))
        ky = int(math.ceil(reach / geometry[3]))
    x_lo, x_hi = _axis_span(cx, kx, ncx, grid[2] != 0)
    y_lo, y_hi = _axis_span(cy, ky, ncy, grid[3] != 0)
    start = nb_start[i]
    cap = nb_cap[i]
    first_new = nb_count[i]
    count = first_new
    for ay in range(y_lo, y_hi):
        row = (ay % ncy) * ncx
        for ax in range(x_lo, x_hi):
            j = cell_head[row + ax % ncx]
            while j >= 0:
                new = ((j != i) & ((j > i) | (not only_higher))
                       & _shells_overlap(i, j, disks, delta, geometry, grid))
                if count < cap:
                    nb[start + count] = j
                elif new:
                    return i
                count += new
                j = cell_next[j]
    for b in range(big.shape[0]):
        j = big[b]
        new = ((j != i) & ((j > i) | (not only_higher))
               & _shells_overlap(i, j, disks, delta, geometry, grid))
        if count < cap:
            nb[start + count] = j
        elif new:
            return i
        count += new
    for k in range(start + first_new, start + count):
        j = nb[k]
        if nb_count[j] >= nb_cap[j]:
            return j
        nb[nb_start[j] + nb_count[j]] = i
        nb_count[j] += 1
        nb_count[i] += 1
    return -1


@njit(cache=True, _nrt=False, error_model="numpy")
def rebuild_neighbours(i, disks, delta, nb_start, nb_cap, nb_count, nb, cell_head, cell_next,
                       cell_prev, cell_of, big, geometry, grid):
    """New shell for disk i centred on its current position, and its new list.

    Idempotent: if a list overflows (returned disk id ≥ 0) the lists stay symmetric, and
    calling again after enlarging them completes the rebuild.
    """
    start = nb_start[i]
    for k in range(start, start + nb_count[i]):
        _remove_from_list(nb[k], i, nb_start, nb_count, nb)
    nb_count[i] = 0
    disks[i, CX] = disks[i, X]
    disks[i, CY] = disks[i, Y]
    if cell_of[i] >= 0:
        c = cell_index(disks[i, CX], disks[i, CY], geometry, grid)
        if c != cell_of[i]:
            _cell_remove(i, cell_head, cell_next, cell_prev, cell_of)
            _cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of)
    return link_new_neighbours(i, False, disks, delta, nb_start, nb_cap, nb_count, nb,
                               cell_head, cell_next, cell_of, big, geometry, grid)


@njit(cache=True, _nrt=False, error_model="numpy")
def build_all_neighbours(disks, delta, is_big, nb_start, nb_cap, nb_count, nb, cell_head,
                         cell_next, cell_prev, cell_of, big, geometry, grid):
    """Centre every shell on its disk, file the small disks in cells and link all pairs.
    Returns the disk whose list overflowed, or -1."""
    n = disks.shape[0]
    cell_head[:] = -1
    nb_count[:] = 0
    for i in range(n):
        disks[i, CX] = disks[i, X]
        disks[i, CY] = disks[i, Y]
        if is_big[i]:
            cell_of[i] = -1
        else:
            c = cell_index(disks[i, CX], disks[i, CY], geometry, grid)
            _cell_insert(i, c, cell_head, cell_next, cell_prev, cell_of)
    for i in range(n):
        full = link_new_neighbours(i, True, disks, delta, nb_start, nb_cap, nb_count, nb,
                                   cell_head, cell_next, cell_of, big, geometry, grid)
        if full >= 0:
            return full
    return -1


@njit(cache=True)
def _copy_lists(nb_start, nb_count, nb, new_start, new_nb):
    for i in range(nb_start.shape[0]):
        for k in range(nb_count[i]):
            new_nb[new_start[i] + k] = nb[nb_start[i] + k]


def grow_lists(nb_start, nb_cap, nb_count, nb, disks):
    """Return enlarged neighbour arrays: the lists of ``disks`` double their capacity.

    Contents and counts are kept; a rare step, done between compiled calls.
    """
    new_cap = nb_cap.copy()
    new_cap[disks] *= 2
    new_start = np.zeros_like(nb_start)
    new_start[1:] = np.cumsum(new_cap[:-1], dtype=np.int64)
    new_nb = np.full(int(new_start[-1] + new_cap[-1]), -1, dtype=np.int32)
    _copy_lists(nb_start, nb_count, nb, new_start, new_nb)
    return new_start, new_cap, nb_count, new_nb
