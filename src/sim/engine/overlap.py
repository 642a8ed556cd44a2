"""The overlap check of initial states: the first disk that overlaps another, in O(N) on
grids of cells per radius level."""

import math

import numpy as np
from numba import njit

from sim.engine.kinematics import minimum_image
from sim.engine.neighbours import axis_span
from sim.engine.sizing import cell_limit, grid_cells


@njit(cache=True)
def _first_overlap(position, radius, level, reach, cells, box, periodic, tolerance):
    """The first disk, in the given order, that overlaps a disk before it:
    (i, j, distance) with j the earliest disk it overlaps, or (-1, -1, 0.0) when none does.
    Overlap: |r_i − r_j| < (R_i + R_j)(1 − tolerance), minimum image on periodic axes.

    Each disk is checked against the disks filed before it, then filed itself, in a grid per
    radius level (``level`` int64[n], 0 … K−1; level k has radii up to ``reach[k]`` and
    ``cells[k]`` (``cells`` int64[K, 2]) cells, each at least 2 ``reach[k]`` wide, no more
    than :func:`cell_limit` of its number of disks). The disks filed never overlap, so a cell
    holds a few of them when the disks spread over the box, and the cost is O(N K) for K
    levels, also when most disks overlap (the check stops at the first); disks crowded into a
    corner of a box far larger than they crowd the cells, as they do the engine's own.

    position float64[n, 2] (inside the box, or wrapped into it on periodic axes), radius
    float64[n], box float64[2], periodic bool[2].
    """
    n = position.shape[0]
    n_levels = reach.shape[0]
    first_cell = np.zeros(n_levels + 1, dtype=np.int64)
    for k in range(n_levels):
        first_cell[k + 1] = first_cell[k] + cells[k, 0] * cells[k, 1]
    head = np.full(first_cell[n_levels], -1, dtype=np.int64)
    following = np.full(n, -1, dtype=np.int64)
    for i in range(n):
        x = position[i, 0]
        y = position[i, 1]
        found = -1
        found_distance = 0.0
        for k in range(n_levels):
            nx = cells[k, 0]
            ny = cells[k, 1]
            width_x = box[0] / nx
            width_y = box[1] / ny
            cx = min(int(x / width_x), nx - 1)
            cy = min(int(y / width_y), ny - 1)
            kx = int(math.ceil((radius[i] + reach[k]) / width_x))
            ky = int(math.ceil((radius[i] + reach[k]) / width_y))
            x_lo, x_hi = axis_span(cx, kx, nx, periodic[0])
            y_lo, y_hi = axis_span(cy, ky, ny, periodic[1])
            for ay in range(y_lo, y_hi):
                row = first_cell[k] + (ay % ny) * nx
                for ax in range(x_lo, x_hi):
                    j = head[row + ax % nx]
                    while j >= 0:
                        dx = minimum_image(x - position[j, 0], box[0], periodic[0])
                        dy = minimum_image(y - position[j, 1], box[1], periodic[1])
                        distance = math.sqrt(dx * dx + dy * dy)
                        if (distance < (radius[i] + radius[j]) * (1.0 - tolerance)
                                and (found < 0 or j < found)):
                            found = j
                            found_distance = distance
                        j = following[j]
        if found >= 0:
            return i, found, found_distance
        k = level[i]
        nx = cells[k, 0]
        c = (first_cell[k] + min(int(y / (box[1] / cells[k, 1])), cells[k, 1] - 1) * nx
             + min(int(x / (box[0] / nx)), nx - 1))
        following[i] = head[c]
        head[c] = i
    return -1, -1, 0.0


def first_overlap(position, radius, box, periodic, tolerance=1e-9):
    """(i, j, distance) of the first disk i, in the given order, that overlaps a disk j before
    it (the earliest such j), or None; see :func:`_first_overlap`. Radii are grouped in
    levels a factor 2 apart, so that small disks are not filed in cells sized for large ones.
    """
    octave = np.floor(np.log2(radius / radius.min())).astype(np.int64)
    present = np.flatnonzero(np.bincount(octave))
    number = np.zeros(present[-1] + 1, dtype=np.int64)
    number[present] = np.arange(present.size)
    level = number[octave]
    reach = np.zeros(present.size)
    np.maximum.at(reach, level, radius)
    count = np.bincount(level)
    cells = np.array([grid_cells(box, 2.0 * reach[k], cell_limit(int(count[k])))
                      for k in range(present.size)])
    i, j, distance = _first_overlap(position, radius, level, reach, cells,
                                    np.asarray(box, dtype=np.float64),
                                    np.asarray(periodic, dtype=np.bool_), float(tolerance))
    return None if i < 0 else (int(i), int(j), float(distance))
