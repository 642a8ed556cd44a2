"""The pixels of a frame: the box drawn to scale (box units), the header above it with the
clock, the colour key to its right; sides multiples of 16 for H.264."""

import math
from dataclasses import dataclass

import numpy as np

#: pixels of the longer side of the drawn box; text height; margins; the colour key's strip
VIEW_PIXELS, TEXT_PIXELS, MARGIN_PIXELS, HEADER_PIXELS, KEY_PIXELS = 640, 15, 16, 48, 240
#: dots per inch: a power of two, so that a frame's pixel size is exact in float64
DPI = 64


def points(pixels):
    """Typographic points of ``pixels`` at :data:`DPI`."""
    return pixels * 72.0 / DPI


def _multiple_of_16(pixels):
    return 16 * math.ceil(pixels / 16)


@dataclass(frozen=True)
class Layout:
    """Pixels of a frame: ``width`` × ``height`` (multiples of 16), the view (x0, x1, y0, y1)
    in box units drawn in the rectangle of ``box_width`` × ``box_height`` pixels whose top-left
    corner is ``left`` pixels from the frame's left and ``top`` from its top; the header above
    it, the colour key to its right."""

    view: tuple
    width: int
    height: int
    left: int
    top: int
    box_width: int
    box_height: int

    @classmethod
    def of_view(cls, view):
        x0, x1, y0, y1 = view
        scale = VIEW_PIXELS / max(x1 - x0, y1 - y0)
        box_width = max(16, round((x1 - x0) * scale))
        box_height = max(16, round((y1 - y0) * scale))
        width = _multiple_of_16(2 * MARGIN_PIXELS + box_width + KEY_PIXELS)
        height = _multiple_of_16(HEADER_PIXELS + box_height + MARGIN_PIXELS)
        return cls(tuple(view), width, height, MARGIN_PIXELS, HEADER_PIXELS, box_width,
                   box_height)

    def pixel(self, position):
        """(column, row) float64[..., 2] of box points ``position`` [..., 2], in pixels from
        the frame's top-left corner (pixel (i, j) covers [i, i + 1) × [j, j + 1))."""
        x0, x1, y0, y1 = self.view
        position = np.asarray(position, dtype=np.float64)
        column = self.left + (position[..., 0] - x0) / (x1 - x0) * self.box_width
        row = self.top + (y1 - position[..., 1]) / (y1 - y0) * self.box_height
        return np.stack([column, row], axis=-1)

    def figure_rect(self, left, top, width, height):
        """[left, bottom, width, height] in figure fractions of a pixel rectangle."""
        return [left / self.width, 1.0 - (top + height) / self.height, width / self.width,
                height / self.height]
