"""Unwrapped positions: winding counts across periodic sides, for mean squared displacements.

On a periodic axis a position is folded back into the box. When a scene observes the mean
squared displacement (``observe.mean_squared_displacement``), the engine keeps
``images`` int32[n, 2], the times each disk has been folded (+1 for leaving through the high
side), so that r + images · L is the unwrapped position; otherwise ``images`` is None and the
loop holds no code for it.
"""

from sim.effects.rules import effect_rule


def _not_counted(images, i, axis, x, folded):
    pass


@effect_rule(_not_counted)
def count_winding(images, i, axis, x, folded):
    """Count a fold of disk i along ``axis`` from x to ``folded``."""
    if x > folded:
        images[i, axis] += 1
    elif x < folded:
        images[i, axis] -= 1
