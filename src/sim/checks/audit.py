"""Independent overlap audit: every pair closer than contact, found with a k-d tree.

Used by the tests after every dynamics run; it shares no code with the engine's cells and
neighbour lists, so it can catch their bugs.
"""

import numpy as np

from sim.engine.box import folded, nearest_images


def kd_tree(position, box, periodic):
    """A k-d tree of ``position`` float64[n, 2] that measures distances with the minimum image
    on periodic axes (scipy's periodicity is per axis: a huge side makes a walled axis
    non-periodic)."""
    from scipy.spatial import cKDTree  # here: every run's start would import it

    box = np.asarray(box, dtype=np.float64)
    if not any(periodic):
        return cKDTree(position)
    boxsize = np.where(periodic, box, 1e30 * max(box.max(), 1.0))
    return cKDTree(folded(position, box, periodic), boxsize=boxsize)


def overlapping_pairs(position, radius, box=(1.0, 1.0), periodic=(False, False),
                      tolerance=1e-9):
    """Pairs (i, j), i < j, with |r_i - r_j| < (R_i + R_j)(1 - tolerance).

    ``position`` float64[n, 2] (inside the box on periodic axes), ``radius`` float64[n].
    Returns int array (k, 2) and the relative overlaps float64[k].
    """
    position = np.asarray(position, dtype=np.float64)
    radius = np.broadcast_to(np.asarray(radius, dtype=np.float64), (position.shape[0],))
    box = np.asarray(box, dtype=np.float64)
    tree = kd_tree(position, box, periodic)
    pairs = tree.query_pairs(2.0 * float(radius.max()), output_type="ndarray")
    if pairs.size == 0:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0)
    r = nearest_images(position[pairs[:, 0]] - position[pairs[:, 1]], box, periodic)
    distance = np.hypot(r[:, 0], r[:, 1])
    sigma = radius[pairs[:, 0]] + radius[pairs[:, 1]]
    bad = distance < sigma * (1.0 - tolerance)
    return pairs[bad], 1.0 - distance[bad] / sigma[bad]


def outside_box(position, radius, box=(1.0, 1.0), periodic=(False, False), tolerance=1e-9,
                walls=None):
    """Indices of disks that poke through a wall by more than ``tolerance`` × radius. The
    walls sit at ``walls`` = (left, right, bottom, top) when they move
    (:meth:`sim.engine.core.Engine.wall_positions`), else at the box edges."""
    if walls is None:
        walls = (0.0, box[0], 0.0, box[1])
    position = np.asarray(position, dtype=np.float64)
    radius = np.broadcast_to(np.asarray(radius, dtype=np.float64), (position.shape[0],))
    bad = np.zeros(position.shape[0], dtype=bool)
    for axis in range(2):
        if not periodic[axis]:
            slack = tolerance * radius
            bad |= position[:, axis] - radius < walls[2 * axis] - slack
            bad |= position[:, axis] + radius > walls[2 * axis + 1] + slack
    return np.flatnonzero(bad)
