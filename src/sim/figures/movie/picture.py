"""Drawing a frame: the disks to scale (box units) inside the box, walls as solid lines where
they are at that time (pistons and vibrating walls move; thermal walls red), periodic sides
dashed; the simulated time and the total kinetic energy Σ m v²/2 (mass × (box units / time)²)
in the top-left corner, the colour key to the right."""

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import EllipseCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from sim.effects.growth import scale
from sim.effects.walls import wall_motion, wall_state
from sim.engine.box import WALL_NAMES
from sim.figures.movie.layout import (
    DPI,
    HEADER_PIXELS,
    KEY_PIXELS,
    MARGIN_PIXELS,
    TEXT_PIXELS,
    points,
)

WALL, THERMAL_WALL, PERIODIC_SIDE = "black", "tab:red", "0.55"


class Walls:
    """The box's sides as drawn: two walls on each axis that has walls, at their place at any
    time (:mod:`sim.effects.walls`: pistons and vibrating walls move), thermal ones marked; periodic
    sides at 0 and L."""

    def __init__(self, config, box, periodic):
        self.box = box
        self.periodic = periodic
        specs = {k: (config.get("walls") or {}).get(name) or {}
                 for k, name in enumerate(WALL_NAMES)}
        self.motion = wall_motion({k: spec for k, spec in specs.items()
                                   if not periodic[k >> 1]})
        self.thermal = [specs[k].get("temperature") is not None for k in range(4)]

    def at(self, time):
        """Positions float64[4] of the walls (left, right, bottom, top) at ``time``."""
        if self.motion is None:
            return np.array([0.0, self.box[0], 0.0, self.box[1]])
        return np.array([wall_state(self.motion, k, time, self.box)[0] for k in range(4)])

    def view(self, times):
        """(x0, x1, y0, y1): the box and every place its walls reach at ``times``."""
        places = np.array([self.at(t) for t in times] if self.motion is not None
                          else [self.at(0.0)])
        return (min(0.0, places[:, 0].min()), max(self.box[0], places[:, 1].max()),
                min(0.0, places[:, 2].min()), max(self.box[1], places[:, 3].max()))


def periodic_images(position, radius, box, periodic):
    """Disk centres float64[m, 2] and the index in ``position`` of each: every disk, and a copy
    shifted by a box side for each periodic side it reaches over."""
    centres, index = [position], [np.arange(len(position))]
    for shift_x in (-1, 0, 1):
        for shift_y in (-1, 0, 1):
            shift = np.array([shift_x, shift_y], dtype=np.float64)
            if not shift.any() or any(s and not p for s, p in zip(shift, periodic, strict=True)):
                continue
            moved = position + shift * box
            reaches = np.all((moved > -radius[:, None]) & (moved < box + radius[:, None]), axis=1)
            centres.append(moved[reaches])
            index.append(np.flatnonzero(reaches))
    return np.concatenate(centres), np.concatenate(index)


class Picture:
    """One figure redrawn for each frame: the disks, the walls, the clock, the kinetic energy
    and the colour key; :meth:`render` gives a frame's pixels."""

    def __init__(self, layout, walls, colors, radius, mass, title, time_decimals,
                 growth_rate=0.0):
        self.walls, self.colors = walls, colors
        self.radius, self.mass = radius, mass
        self.growth_rate = growth_rate  # γ of growing disks (sim.effects.growth), else 0
        self.time_decimals = time_decimals
        self.figure = Figure(figsize=(layout.width / DPI, layout.height / DPI), dpi=DPI)
        self.canvas = FigureCanvasAgg(self.figure)
        self.axes = self.figure.add_axes(layout.figure_rect(layout.left, layout.top,
                                                            layout.box_width, layout.box_height))
        x0, x1, y0, y1 = layout.view
        self.axes.set(xlim=(x0, x1), ylim=(y0, y1))
        self.axes.set_axis_off()
        self.sides = self._add_sides()
        key_left = layout.left + layout.box_width + MARGIN_PIXELS
        text = {"fontsize": points(TEXT_PIXELS), "va": "center"}
        self.clock = self.figure.text(layout.left / layout.width,
                                      1.0 - 0.5 * HEADER_PIXELS / layout.height, "",
                                      linespacing=1.1,
                                      family="monospace", **text)
        self.figure.text(key_left / layout.width, 1.0 - 0.5 * HEADER_PIXELS / layout.height,
                         title, **text)
        colors.draw_key(self.figure, layout.figure_rect(key_left, layout.top,
                                                        KEY_PIXELS - MARGIN_PIXELS,
                                                        layout.box_height))
        self.caption = self.figure.text(key_left / layout.width,
                                        (layout.height - layout.top - layout.box_height)
                                        / layout.height, "", va="bottom",
                                        fontsize=points(TEXT_PIXELS - 2))
        self.disks = None

    def _add_sides(self):
        """Draw the periodic sides; the walls' lines, placed by :meth:`_draw_walls`, as
        (wall, line) pairs."""
        box, sides = self.walls.box, []
        for axis in (0, 1):
            for side in (0, 1):
                if self.walls.periodic[axis]:
                    along = (0.0, box[1 - axis])
                    place = (side * box[axis],) * 2
                    ends = (place, along) if axis == 0 else (along, place)
                    self.axes.add_line(Line2D(*ends, color=PERIODIC_SIDE, ls="--", lw=1.0,
                                              clip_on=False))
                else:
                    wall = 2 * axis + side
                    color = THERMAL_WALL if self.walls.thermal[wall] else WALL
                    sides.append((wall, self.axes.add_line(
                        Line2D([], [], color=color, lw=points(2), clip_on=False,
                               solid_capstyle="projecting"))))
        return sides

    def _draw_walls(self, time):
        place = self.walls.at(time)
        for wall, line in self.sides:
            axis, other = wall >> 1, 1 - (wall >> 1)
            across = ((0.0, self.walls.box[other]) if self.walls.periodic[other]
                      else (place[2 * other], place[2 * other + 1]))
            at = (place[wall], place[wall])
            line.set_data(*((at, across) if axis == 0 else (across, at)))

    def render(self, frame):
        """The pixels uint8[height, width, 3] of ``frame``."""
        if self.disks is not None:
            self.disks.remove()
        radius = self.radius * scale(self.growth_rate, frame.time)
        centres, index = periodic_images(frame.position, radius, self.walls.box,
                                         self.walls.periodic)
        diameter = 2.0 * radius[index]
        colors, caption = self.colors(frame)
        self.disks = self.axes.add_collection(EllipseCollection(
            diameter, diameter, np.zeros_like(diameter), units="xy", offsets=centres,
            offset_transform=self.axes.transData, facecolors=colors[index],
            linewidths=0))
        self._draw_walls(frame.time)
        energy = 0.5 * float(np.sum(self.mass * np.sum(frame.velocity**2, axis=1)))
        self.clock.set_text(f"t = {frame.time:.{self.time_decimals}f}\n"
                            f"kinetic energy {energy:.4g}")
        self.caption.set_text(caption)
        self.canvas.draw()
        return np.ascontiguousarray(np.asarray(self.canvas.buffer_rgba())[..., :3])
