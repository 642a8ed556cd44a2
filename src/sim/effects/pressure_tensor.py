"""The collision part of the pressure tensor, accumulated when a scene observes it.

``virial_tensor`` float64[3] sums r_a Δp_b over disk contacts, as (xx, xy, yy); with the
kinetic tensor Σ m v_a v_b it gives the pressure tensor
P_ab = (⟨Σ m v_a v_b⟩ + Σ r_a Δp_b / t)/A (Allen & Tildesley, *Computer Simulation of
Liquids*, 2nd ed., §2.4 and §3.7), whose trace is twice the pressure. None when not observed
(``observe.pressure_tensor``), and then no code of it is compiled.
"""

import numpy as np

from sim.effects.rules import effect_rule
from sim.engine.inputs import refused

KEYWORDS = {"pressure_tensor": (False, "True or False: accumulate the collision virial tensor "
                                       "Σ r_a Δp_b (:attr:`virial_tensor`)")}


def check_config(cfg):
    """A boolean switch: its type is the schema's."""


def engine_arguments(cfg):
    """Whether the scene observes the pressure tensor."""
    return {"pressure_tensor": cfg.observe.pressure_tensor}


def loop_values(keywords, context):
    """The virial tensor float64[3] at zero, or None."""
    return {"virial_tensor": np.zeros(3) if observed(keywords["pressure_tensor"]) else None}


def observed(pressure_tensor):
    """The keyword ``pressure_tensor`` as a bool: True or False (numpy's too), a ValueError
    of ``Engine(pressure_tensor=…)`` otherwise."""
    if not isinstance(pressure_tensor, bool | np.bool_):
        raise refused("Engine", "pressure_tensor", pressure_tensor, "True or False")
    return bool(pressure_tensor)


def _not_observed(virial_tensor, rx, ry, virial):
    pass


@effect_rule(_not_observed)
def add_virial_tensor(virial_tensor, rx, ry, virial):
    """Add r_a Δp_b of one contact: Δp_i is along r = r_i − r_j, and r·Δp_i = ``virial``, so
    r_a Δp_b = virial r_a r_b / r²."""
    scale = virial / (rx * rx + ry * ry)
    virial_tensor[0] += scale * rx * rx
    virial_tensor[1] += scale * rx * ry
    virial_tensor[2] += scale * ry * ry
