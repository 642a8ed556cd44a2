"""The box and its cell grid, as the compiled code takes them.

  geometry float64[6]: box sides (L_x, L_y) at ``SIDE + axis``, cell sides at
      ``CELL_SIDE + axis``, the reach R_max + δ of the ordinary disks at ``REACH`` (how far
      a shell reaches beyond its centre) and the shell lead λ at ``LEAD``
      (:func:`sim.engine.neighbours.shell_centre`);
  grid int64[4]: cells along each axis at ``CELLS + axis``, 1 for a periodic axis at
      ``PERIODIC + axis`` (0: walls).

Walls are numbered ``2 axis + side`` (0 x-low, 1 x-high, 2 y-low, 3 y-high).

The boundary: every compiled function that needs the separation of two points, the velocity
of an image or a position inside the box asks :func:`separation`, :func:`image_velocity` and
:func:`fold` with the loop's ``box`` group (:class:`sim.engine.groups.Box`), so that another
boundary (a sliding one) changes these three and nothing else; Python that measures positions
of a run (analysis, the audit, export, movies) asks :func:`nearest_images` and :func:`folded`.
"""

import numpy as np
from numba import njit

from sim.engine.kinematics import minimum_image, wrap

#: Wall names by number.
WALL_NAMES = ("left", "right", "bottom", "top")

SIDE = 0
CELL_SIDE = 2
REACH = 4
LEAD = 5
GEOMETRY_SIZE = 6

CELLS = 0
PERIODIC = 2
GRID_SIZE = 4


@njit(cache=True, inline="always")
def separation(box, dx, dy):
    """The separation (dx, dy) of two points through the boundary: the nearest periodic image
    on a periodic axis (:func:`sim.engine.kinematics.minimum_image`), as it is between
    walls."""
    return (minimum_image(dx, box.geometry[SIDE], box.grid[PERIODIC] != 0),
            minimum_image(dy, box.geometry[SIDE + 1], box.grid[PERIODIC + 1] != 0))


@njit(cache=True, inline="always")
def image_velocity(box, dy, ry):
    """The velocity (u_x, u_y) of the image through which a point at separation dy along y
    (before :func:`separation`, ``ry`` after) is seen, relative to the point itself: the
    relative velocity of a pair is v_i − v_j − u. Zero between walls and across periodic
    sides, whose images rest; a sliding (Lees–Edwards) boundary gives the images across its
    y sides the shear velocity, ±γ̇ L_y per side crossed ((dy − ry) / L_y of them)."""
    return 0.0, 0.0


@njit(cache=True, inline="always")
def fold(box, x, axis):
    """Coordinate ``axis`` of a point folded into the box on a periodic axis
    (:func:`sim.engine.kinematics.wrap`), as it is between walls."""
    return wrap(x, box.geometry[SIDE + axis], box.grid[PERIODIC + axis] != 0)


def nearest_images(r, box, periodic):
    """Separations ``r`` float64[..., 2] replaced by their nearest periodic images on the
    periodic axes (``box`` the sides, ``periodic`` a pair of bools): numpy's
    :func:`separation` for the positions a run file holds."""
    box = np.asarray(box, dtype=np.float64)
    return r - np.where(periodic, box * np.round(r / box), 0.0)


def folded(position, box, periodic):
    """Positions float64[..., 2] folded into the box on its periodic axes: numpy's
    :func:`fold`."""
    box = np.asarray(box, dtype=np.float64)
    return np.where(periodic, position % box, position)
