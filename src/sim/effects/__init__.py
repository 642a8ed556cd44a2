"""Effects a scene switches on, one module each: the check and normalisation of its keys,
the compiled rules the event loop calls (:mod:`sim.effects.rules`), and what it records. An
effect a scene does not use reaches the loop as None in :class:`Effects`, and numba compiles
it away.

:data:`EFFECTS` is the one list of them: for each, its module, the fields of
:class:`Effects` it fills, the config keys it reads, the validation rows (studies of
:data:`sim.checks.validation.STUDIES`, or tests) that check it, and its rows in
``benchmarks/effects_cost.py``. ``tests/test_effect_registry.py`` fails when an effect is
missing from any of them, or its module lacks a part of the protocol.

The protocol: every effect module defines

``KEYWORDS``
    {keyword of :class:`sim.engine.core.Engine`: (default, meaning)} — the keywords it takes;
``check_config(cfg)``
    raise :class:`sim.effects.values.ConfigError` for a bad value of its config keys;
``engine_arguments(cfg)``
    its keywords from a validated config, {keyword: value};
``loop_values(keywords, context)``
    its fields of :class:`Effects`, {field: value, None when off or neutral}, from every
    effect's keywords and the ``context``: the scene (n, n_species, box, periodic, radius,
    mass, initial_energy) and the fields of the effects before it in :data:`EFFECTS`; for
    an effect that acts on the whole system at times (growth's rescaling), the key
    ``system_event``: its system event (:mod:`sim.engine.system`), or None; and for an
    effect that is the pairs' interaction (a stepped potential), the key
    ``pair_interaction``: its value (:mod:`sim.engine.pairs`), or None.

and may define

``check_scene(cfg, scene)``
    raise :class:`sim.effects.values.ConfigError` for a value of its config keys that the
    scene built from the config cannot take (:class:`sim.pipeline.scenes.Scene`: radii,
    species, box), before the engine is made.

The functions below run the protocol over every effect, in the order of :data:`EFFECTS`.
"""

import importlib
import textwrap
from collections import namedtuple
from dataclasses import dataclass


@dataclass(frozen=True)
class Effect:
    name: str  # its module is sim.effects.<name>
    fields: tuple  # fields of Effects it fills (None when off)
    config: tuple  # keys of conf/config.yaml it reads (check_config, engine_arguments)
    validation: tuple  # keys of sim.checks.validation.STUDIES, or tests as "file.py::name"
    cost: tuple  # rows of benchmarks/effects_cost.py (absent, neutral, on)

    @property
    def module(self):
        """sim.effects.<name>, imported on first use (the effects import the engine's
        compiled modules, which import this registry)."""
        return importlib.import_module(f"{__name__}.{self.name}")


WALL_SECTIONS = tuple(f"walls.{wall}" for wall in ("left", "right", "bottom", "top"))

EFFECTS = (
    Effect("rotation", ("roughness", "friction", "spin"),
           ("restitution.tangential", "restitution.wall_tangential", "friction.mu",
            "friction.wall_mu", "disks.inertia_factor", "disks.rotational_temperature",
            "box.boundary", "observe.pressure_tensor"),
           ("rough_equipartition", "rough_cooling_0.9_0.5", "rough_cooling_0.9_0.0",
            "rough_cooling_0.8_-0.5", "rough_cooling_0.7_0.5"),
           ("rotation", "friction")),
    Effect("restitution", ("restitution", "wall_restitution", "collapse"),
           ("restitution.disk", "restitution.wall"),
           ("haff_0.9", "haff_0.8", "mixture_0.8", "bouncing_ball"),
           ("restitution", "wall_restitution", "pair_restitution")),
    Effect("tc", ("tc",), ("tc.time",), ("tc_model",), ("tc",)),
    Effect("gravity", ("gravity",), ("gravity", "box.boundary"),
           ("bouncing_ball", "barometric"), ("gravity",)),
    Effect("walls", ("wall_motion",),
           ("box.boundary",) + tuple(f"{wall}.{key}" for wall in WALL_SECTIONS
                                     for key in ("temperature", "speed", "amplitude",
                                                 "frequency")),
           ("piston", "driven_steady_state"), ("moving_walls",)),
    Effect("thermal_walls", ("wall_temperature", "seed"),
           ("seed", "box.boundary") + tuple(f"{wall}.temperature" for wall in WALL_SECTIONS),
           ("thermal_walls",), ("thermal_walls",)),
    Effect("growth", ("growth",), ("growth.rate", "growth.rescale_every",
                                   "restitution.tangential", "friction.mu")
           + tuple(f"{wall}.{key}" for wall in WALL_SECTIONS
                   for key in ("temperature", "speed", "amplitude")),
           ("compression_eos", "jamming_density",
            "test_growth.py::test_growing_gas_never_overlaps"), ("growth",)),
    Effect("potential", (), ("potential.steps", "potential.energies", "growth.rate"),
           ("potential_energy", "potential_steps", "potential_b2",
            "test_potential.py::test_a_square_well_gas_keeps_its_energy_and_its_pair_states"),
           ("square_well",)),
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
#: images int32[n, 2], virial_tensor float64[3], event_log (float64[rows, 6], int64[1]),
#: roughness :class:`sim.effects.rotation.Roughness`, friction
#: :class:`sim.effects.rotation.Friction`, spin float64[n], growth
#: :class:`sim.effects.growth.Growth`. An effect's ``loop_values`` may also return the key
#: ``system_event``: the system event (:mod:`sim.engine.system`) the effect needs, which the
#: engine runs (growth's rescaling), and the key ``pair_interaction``: the pairs' interaction
#: the effect is (:mod:`sim.effects.potential`), which the loop takes as its own argument.
Effects = namedtuple("Effects", [field for effect in EFFECTS for field in effect.fields])


def engine_keywords():
    """{keyword: (default, meaning)} of every effect's Engine keywords."""
    return {keyword: entry for effect in EFFECTS
            for keyword, entry in effect.module.KEYWORDS.items()}


def keyword_doc(indent="    "):
    """The effects' Engine keywords as entries of a numpydoc Parameters section."""
    return "".join(textwrap.fill(f"{keyword} : {meaning}", 92, initial_indent=indent,
                                 subsequent_indent=2 * indent) + "\n"
                   for keyword, (_, meaning) in engine_keywords().items())


def check_config(cfg):
    """Every effect's check of its config keys (:class:`ConfigError` on the first bad one)."""
    for effect in EFFECTS:
        effect.module.check_config(cfg)


def check_scene(cfg, scene):
    """Every effect's check of its config keys against the scene built from the config (those
    effects that have one)."""
    for effect in EFFECTS:
        check = getattr(effect.module, "check_scene", None)
        if check is not None:
            check(cfg, scene)


def engine_arguments(cfg):
    """The Engine keywords of every effect from a validated config."""
    return {keyword: value for effect in EFFECTS
            for keyword, value in effect.module.engine_arguments(cfg).items()}


def loop_values(given, scene):
    """(every field of :class:`Effects`, every effect keyword) from the Engine keywords
    ``given`` (absent ones take their defaults; an unknown one is a TypeError) and the
    ``scene`` facts of the context."""
    keywords = engine_keywords()
    unknown = sorted(set(given) - set(keywords))
    if unknown:
        raise TypeError(f"Engine() got unexpected keyword arguments {unknown}; the effects "
                        f"take {', '.join(keywords)}")
    keywords = {keyword: given.get(keyword, default)
                for keyword, (default, _) in keywords.items()}
    context = dict(scene)
    values = {}
    for effect in EFFECTS:
        values.update(effect.module.loop_values(keywords, context))
        context.update(values)
    return values, keywords
