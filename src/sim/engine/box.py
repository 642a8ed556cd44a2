"""The box and its cell grid, as the compiled code takes them.

  geometry float64[6]: box sides (L_x, L_y) at ``SIDE + axis``, cell sides at
      ``CELL_SIDE + axis``, the reach R_max + δ of the ordinary disks at ``REACH`` (how far
      a shell reaches beyond its centre) and the shell lead λ at ``LEAD``
      (:func:`sim.engine.neighbours.shell_centre`);
  grid int64[4]: cells along each axis at ``CELLS + axis``, 1 for a periodic axis at
      ``PERIODIC + axis`` (0: walls).

Walls are numbered ``2 axis + side`` (0 x-low, 1 x-high, 2 y-low, 3 y-high).
"""

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
