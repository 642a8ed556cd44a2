"""Unwrapped positions: winding counts across periodic sides, for mean squared displacements.

On a periodic axis a position is folded back into the box. When a scene observes the mean
squared displacement (``observe.mean_squared_displacement``), the engine keeps
``images`` int32[n, 2], the times each disk has been folded (+1 for leaving through the high
side), so that r + images · L is the unwrapped position; otherwise ``images`` is None and the
loop holds no code for it.
"""

import numpy as np

from sim.effects.rules import effect_rule
from sim.engine.inputs import refused

KEYWORDS = {"unwrap": (False, "True or False: count periodic windings, for "
                              ":meth:`unwrapped_positions` (mean squared displacements)")}


def check_config(cfg):
    """A boolean switch: its type is the schema's."""


def engine_arguments(cfg):
    """Whether the scene observes mean squared displacements."""
    return {"unwrap": cfg.observe.mean_squared_displacement}


def loop_values(keywords, context):
    """Winding counts int32[n, 2] at zero, or None; ``unwrap`` a bool (numpy's too)."""
    unwrap = keywords["unwrap"]
    if not isinstance(unwrap, bool | np.bool_):
        raise refused("Engine", "unwrap", unwrap, "True or False")
    return {"images": np.zeros((context["n"], 2), dtype=np.int32) if unwrap else None}


def _not_counted(images, i, axis, x, folded):
    pass


@effect_rule(_not_counted)
def count_winding(images, i, axis, x, folded):
    """Count a fold of disk i along ``axis`` from x to ``folded``."""
    if x > folded:
        images[i, axis] += 1
    elif x < folded:
        images[i, axis] -= 1
