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

from sim.pipeline.config import ConfigError


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
    if s.at_rest is not None and at_rest(s.at_rest)(engine):
        return ("stop.at_rest", s.at_rest, "a fraction the run has not reached yet")
    return None


def _dissipates(engine, never_touch):
    """Whether any contact can lose energy: of two disks that can meet, or with a wall (the
    engine's energy fraction counts what contacts dissipate)."""
    return (engine.disk_contacts_dissipate and not never_touch) \
        or engine.wall_contacts_dissipate


def check_reachable(cfg, engine):
    """Refuse (:class:`ConfigError` on ``stop``, or on ``stop.time``) a scene none of whose
    stop conditions can ever hold for the initial state of ``engine``, or that reaches its
    ``stop.time`` only after more events than the engine counts; see the module
    docstring."""
    s = cfg.stop
    others = [s.collisions, s.contacts, s.wall_seconds]
    if not engine.conserves_kinetic_energy:  # an energy condition may end the run first
        others += [s.energy_fraction, s.at_rest]
    if s.time is not None and all(x is None for x in others):
        latest, reason = engine.latest_time()
        if float(s.time) > latest:
            raise ConfigError("stop.time", s.time, f"a time the run can reach: {reason}; or "
                              f"add stop.collisions or stop.wall_seconds")
    if s.time is not None or s.wall_seconds is not None:
        return
    if np.all(engine.velocities() == 0.0) and engine.gravity is None \
            and engine.wall_motion is None:
        return  # nothing moves: the run ends at once with no events left
    why = {}
    never_touch = engine.disks_never_touch()
    if s.collisions is not None and never_touch:
        why["stop.collisions"] = ("one disk has no other to collide with" if engine.n == 1
                                  else "these disks never touch one another")
    if s.contacts is not None and never_touch and np.all(engine.periodic):
        why["stop.contacts"] = "a periodic box has no walls and these disks never touch"
    if s.energy_fraction is not None and s.energy_fraction < 1.0 \
            and not _dissipates(engine, never_touch):
        why["stop.energy_fraction"] = "no contact dissipates energy (elastic disks and walls, " \
                                      "or inelastic disks that never meet)"
    if s.at_rest is not None and engine.conserves_kinetic_energy and engine.n_species == 1:
        why["stop.at_rest"] = "the kinetic energy never changes"
    given = [key for key in ("collisions", "contacts", "energy_fraction", "at_rest")
             if s[key] is not None]
    if given and len(why) == len(given):
        reasons = "; ".join(f"{key}: {text}" for key, text in why.items())
        raise ConfigError("stop", {key: s[key] for key in given},
                          f"a condition the scene can meet ({reasons}); add stop.time or "
                          f"stop.wall_seconds, or change the scene")
