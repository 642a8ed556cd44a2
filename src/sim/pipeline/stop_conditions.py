"""Stop conditions that need more than a count: a scene at rest, conditions a resumed run has
met already, and conditions a scene can never meet.

A run ends at the first of its conditions that holds (``stop:`` in the config). A condition
on disk–disk collisions in a scene whose disks can never touch, on contacts in a periodic box
of disks that never meet, on the energy contacts dissipate where none can, or on a kinetic
energy that never changes would never hold;
when every condition of a scene is of that kind, :func:`check_reachable` refuses the scene
before any work. (A scene in which nothing moves at all ends by itself: the engine then has
no event left, stop reason ``no_events``.) So does it refuse a ``stop.time`` that the scene
reaches only after more events than the engine counts (:data:`sim.engine.inputs.MAX_COUNT`),
where that is bounded: a kinetic energy that never changes, or gravity
(:meth:`sim.engine.Engine.latest_time`).
"""

import numpy as np

from sim.pipeline.config import STOP_KEYS, ConfigError


def at_rest(fraction):
    """Stop predicate of ``stop.at_rest``: the translational kinetic energy of every species
    has fallen below ``fraction`` of the initial total (which counts the spins of rough
    disks: a bed whose disks still turn in place is at rest). Hard-disk dynamics has no
    energy scale (a run at
    speeds ×λ is the same run in time /λ, unless the TC model's fixed t_c intervenes), so it
    ends runs that differ only in their speeds at the same stage."""
    def predicate(engine):
        return bool(np.all(engine.kinetic_energy_by_species() < fraction * engine.initial_energy))
    return predicate


def already_met(engine, cfg):
    """The first stop condition of ``cfg`` that ``engine`` (restored from a checkpoint) meets
    already, as ``(key, value, explanation)`` for :class:`ConfigError`; None if none does."""
    s = cfg.stop
    if s.collisions is not None and engine.collisions >= s.collisions:
        return ("stop.collisions", s.collisions,
                f"more than the {engine.collisions} collisions the run has made already")
    if s.contacts is not None and engine.contacts >= s.contacts:
        return ("stop.contacts", s.contacts,
                f"more than the {engine.contacts} contacts the run has made already")
    if s.time is not None and engine.time >= s.time:
        return ("stop.time", s.time, f"later than t = {engine.time:.6g}, where the run is")
    if s.energy_fraction is not None and \
            engine.dissipated_energy >= engine.initial_energy * (1.0 - s.energy_fraction):
        left = 1.0 - engine.dissipated_energy / engine.initial_energy
        return ("stop.energy_fraction", s.energy_fraction,
                f"below the fraction {left:.6g} of the initial energy the run has left")
    if s.packing_fraction is not None and engine.packing_fraction() >= s.packing_fraction:
        return ("stop.packing_fraction", s.packing_fraction,
                f"above the packing fraction {engine.packing_fraction():.6g} the run has "
                f"reached already")
    if s.at_rest is not None and at_rest(s.at_rest)(engine):
        return ("stop.at_rest", s.at_rest, "a fraction the run has not reached yet")
    return None


def check_reachable(cfg, engine):
    """Refuse (:class:`ConfigError` on the ``stop`` key, or on ``stop`` for several) a scene
    none of whose stop conditions can ever hold for the state of ``engine``: the engine says
    why for each (:meth:`sim.engine.Engine.never_holds`, as for its own :meth:`run`), and
    ``stop.at_rest`` where the kinetic energy never changes; see the module docstring."""
    s = cfg.stop
    if engine.still:
        return  # nothing moves: the run ends at once with no events left
    given = {key: s[key] for key in STOP_KEYS if s[key] is not None}
    why = {}
    for key, value in given.items():
        if key != "at_rest":
            reason = engine.never_holds(key, value)
        elif engine.conserves_kinetic_energy and engine.n_species == 1:
            reason = "a condition of a scene whose kinetic energy changes (this one's never does)"
        else:
            reason = None
        if reason is None:
            return
        why[key] = reason
    if not why:
        return
    advice = ("add " + " or ".join(f"stop.{key}" for key in ("collisions", "time", "wall_seconds")
                                   if key not in given) + ", or change the scene")
    if len(why) == 1:
        (key, reason), = why.items()
        raise ConfigError(f"stop.{key}", given[key], f"{reason}; {advice}")
    raise ConfigError("stop", given, "a condition the scene can meet (" + "; ".join(
        f"stop.{key}: {reason}" for key, reason in why.items()) + f"); {advice}")
