"""Effects a scene switches on, one module each: the check and normalisation of its keys,
the compiled rules the event loop calls (:mod:`sim.effects.rules`), and what it records. An
effect a scene does not use reaches the loop as None in :class:`Effects`, and numba compiles
it away.

:data:`EFFECTS` is the one list of them: for each, its module, the fields of
:class:`Effects` it fills, the config keys that switch it on, the validation rows (studies of
:data:`sim.checks.validation.STUDIES`, or tests) that check it, and its rows in
``benchmarks/effects_cost.py``. ``tests/test_effect_registry.py`` fails when an effect is
missing from any of them.
"""

from collections import namedtuple
from dataclasses import dataclass


@dataclass(frozen=True)
class Effect:
    name: str  # its module is sim.effects.<name>
    fields: tuple  # fields of Effects it fills (None when off)
    config: tuple  # keys of conf/config.yaml that switch it on
    validation: tuple  # keys of sim.checks.validation.STUDIES, or tests as "file.py::name"
    cost: tuple  # rows of benchmarks/effects_cost.py (absent, neutral, on)


WALL_SECTIONS = tuple(f"walls.{wall}" for wall in ("left", "right", "bottom", "top"))

EFFECTS = (
    Effect("restitution", ("restitution", "wall_restitution", "collapse"),
           ("restitution.disk", "restitution.wall"),
           ("haff_0.9", "haff_0.8", "mixture_0.8", "bouncing_ball"),
           ("restitution", "wall_restitution", "pair_restitution")),
    Effect("tc", ("tc",), ("tc.time",), ("tc_model",), ("tc",)),
    Effect("gravity", ("gravity",), ("gravity",), ("bouncing_ball", "barometric"),
           ("gravity",)),
    Effect("walls", ("wall_motion",),
           tuple(f"{wall}.{key}" for wall in WALL_SECTIONS
                 for key in ("speed", "amplitude", "frequency")),
           ("piston", "driven_steady_state"), ("moving_walls",)),
    Effect("thermal_walls", ("wall_temperature", "seed"),
           tuple(f"{wall}.temperature" for wall in WALL_SECTIONS), ("thermal_walls",),
           ("thermal_walls",)),
    Effect("unwrap", ("images",), ("observe.mean_squared_displacement",),
           ("test_observers.py::test_unwrapped_positions_agree_with_unwrapping_frequent_snapshots",),
           ("unwrap",)),
    Effect("pressure_tensor", ("virial_tensor",), ("observe.pressure_tensor",),
           ("test_observers.py::test_pressure_tensor_is_isotropic_and_its_trace_is_the_pressure",),
           ("pressure_tensor",)),
    Effect("event_log", ("event_log",), ("observe.event_log",),
           ("test_observers.py::test_event_log_holds_every_contact",), ("event_log",)),
)

#: The effects of a scene as the compiled loop takes them, one field per entry of the
#: effects' ``fields``, None when off: restitution float64[s, s] (ξ per species pair),
#: wall_restitution float, collapse :class:`sim.effects.restitution.CollapseWatch`, tc float,
#: gravity float64[2], wall_motion float64[4, 3], wall_temperature float64[4], seed int,
#: images int32[n, 2], virial_tensor float64[3], event_log (float64[rows, 6], int64[1]).
Effects = namedtuple("Effects", [field for effect in EFFECTS for field in effect.fields])
