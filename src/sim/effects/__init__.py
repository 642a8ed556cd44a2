"""Effects a scene switches on: each module holds everything one effect is — the check and
normalisation of its keys, the compiled rules the event loop calls (:mod:`sim.effects.rules`),
and its observables. An effect a scene does not use reaches the loop as None in
:class:`Effects`, and numba compiles it away.
"""

from typing import NamedTuple


class Effects(NamedTuple):
    """The effects of a scene as the compiled loop takes them; None = off."""
    restitution: object  # float64[s, s] ξ per species pair (sim.effects.restitution)
    wall_restitution: object  # float ξ_w (sim.effects.restitution)
    collapse: object  # CollapseWatch, whenever a contact may dissipate (sim.effects.restitution)
    tc: object  # float t_c (sim.effects.tc)
    gravity: object  # float64[2] g (sim.effects.gravity)
    wall_motion: object  # float64[4, 3] (U, A, ω) per wall (sim.effects.walls)
    wall_temperature: object  # float64[4] T_w per wall (sim.effects.thermal_walls)
    seed: int  # keys the thermal walls' draws (sim.effects.thermal_walls)
    images: object  # int32[n, 2] windings (sim.effects.unwrap)
    virial_tensor: object  # float64[3] (sim.effects.pressure_tensor)
    event_log: object  # (float64[rows, 6], int64[1]) (sim.effects.event_log)
