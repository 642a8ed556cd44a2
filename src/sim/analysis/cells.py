"""A grid of cells over the box, and the granular temperature of the disks on it.

Cells are numbered row by row, iy · nx + ix: as an array of shape (ny, nx), row index = y cell,
column index = x cell, cell (iy, ix) being [ix w_x, (ix + 1) w_x] × [iy w_y, (iy + 1) w_y].
A disk counts in the cell of its centre.
"""

import numpy as np


def grid(box, cells):
    """Shape (ny, nx) of the grid of ``cells`` cells along x and, along y, as many as keep them
    nearest to square (at least one)."""
    return max(1, round(cells * float(box[1]) / float(box[0]))), int(cells)


def cell_index(position, box, shape):
    """The cell iy · nx + ix of each centre ``position`` float64[..., 2] on the grid ``shape``
    = (ny, nx) over ``box``; a centre on the far edge counts in the last cell."""
    ny, nx = shape
    ix = np.clip((position[..., 0] / (float(box[0]) / nx)).astype(int), 0, nx - 1)
    iy = np.clip((position[..., 1] / (float(box[1]) / ny)).astype(int), 0, ny - 1)
    return iy * nx + ix


def granular_temperature(velocity, mass, cell, n_cells, group=None, n_groups=0):
    """Granular temperature (2D, k_B = 1; energy units, mass × length²/time²) of the disks of
    each cell, or with ``group`` (int[N], e.g. the species) of each group over all cells:

        T = Σ m |v − u|² / (2 Σ (1 − m/M)),

    sums over the disks of the cell or group, u the mass-weighted mean (flow) velocity of a
    disk's cell and M the cell's mass. That is the kinetic energy in the frame of the local
    flow per degree of freedom left: subtracting u takes 2 of a cell's 2 N_c degrees of
    freedom, disk i the share m_i/M of them (at equilibrium ⟨m |v − u|²⟩ = 2 T (1 − m/M)), so
    a cell's denominator is 2 (N_c − 1) and T is unbiased; dividing by 2 N_c instead puts the
    T₂/T₁ of masses 1 and 4 (4000 disks, 8 × 8 cells) 2 % low. The flow of a cooling gas
    (shear, clusters) is not heat.

    ``velocity`` float64[N, 2], ``mass`` float64[N], ``cell`` int[N] (:func:`cell_index`).
    Returns float64[n_cells] (float64[n_groups] with ``group``); NaN where no degree of
    freedom is left (a cell of fewer than two disks).
    """
    held = np.bincount(cell, weights=mass, minlength=n_cells)
    momentum = np.stack([np.bincount(cell, weights=mass * velocity[:, a], minlength=n_cells)
                         for a in range(2)], axis=1)
    flow = momentum / np.where(held > 0.0, held, 1.0)[:, None]
    alone = np.bincount(cell, minlength=n_cells)[cell] == 1
    energy = np.where(alone, 0.0, mass * np.sum((velocity - flow[cell]) ** 2, axis=1))
    freedom = np.where(alone, 0.0, 2.0 * (1.0 - mass / held[cell]))
    label, size = (cell, n_cells) if group is None else (group, n_groups)
    with np.errstate(invalid="ignore"):
        return (np.bincount(label, weights=energy, minlength=size)
                / np.bincount(label, weights=freedom, minlength=size))
