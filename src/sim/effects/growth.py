"""Growth: every disk grows at a rate proportional to its size, the Lubachevsky–Stillinger
compression (Lubachevsky & Stillinger, J. Stat. Phys. 60, 561 (1990); Donev, Torquato &
Stillinger, J. Comput. Phys. 202, 737 and 765 (2005)).

Radii grow as R_i(T) = R_i(0)(1 + γ T) in absolute time T, so a polydisperse packing keeps its
size ratios; masses stay fixed. The engine's table keeps R_i(0); every compiled place that
needs a size asks :func:`grown` for it at the time of the question, and the contact distance
of a pair grows at ṡ = γ (R_i(0) + R_j(0)) (:func:`growing`). Then

  * a pair touches at the first root of |r + v τ| = σ + ṡ τ
    (:func:`sim.engine.kinematics.growing_contact_time`, through
    :func:`sim.engine.pairs.pair_event_time`), which growing disks reach even while
    receding;
  * at contact, with n̂ = r̂_ij and u = (v_i − v_j)·n̂, the impulse on i is
    μ (1 + ξ)(ṡ − u) n̂ (:func:`sim.engine.contact.collide_disks`), so that
    u′ − ṡ = −ξ (u − ṡ): the disks part faster than their contact grows;
  * a wall is met when the gap closes at the normal speed plus Ṙ_i = γ R_i(0), and reflects
    the disk in the frame of its growing edge (:func:`sim.effects.walls.predict_wall_contact`,
    :func:`sim.effects.walls.hit_wall`, given Ṙ_i as ``edge``);
  * a disk's neighbour shell reaches its radius at its last rebuild, a_i, plus δ_i; the disk
    leaves it when |r_i − c_i| + (R_i(t) − a_i) reaches δ_i, a shell shrinking at Ṙ_i
    (:func:`shell_room`, :func:`sim.effects.gravity.shell_exit`). Two disks outside each
    other's lists, each within its shrunk shell, are then at least R_i(t) + R_j(t) apart.
    The cells are sized at construction for the largest radii the box can hold (packing
    fraction 1; :meth:`sim.engine.core.Engine`). Shells sized for the growth ahead instead
    (a reach of R_i(now) + δ_i/2 at each rebuild: fewer rebuilds, longer lists) were slower:
    the compress scene of 2000 disks at γ = 0.3 to βP/ρ = 10⁶ took 6.7–7.5 s against
    5.4–6.1 s (two seeds, two rounds each).

Growth pumps kinetic energy in at every contact; a system event (:class:`Rescale`,
:mod:`sim.engine.system`) brings the kinetic energy back to its initial value, every
``rescale_every`` collisions per disk, by multiplying every velocity by one factor. Between two
rescalings the dynamics are exact: disks fly straight, every contact is the root of its
equation, and the rescaling is an instant at which every prediction is made anew
(:func:`sim.engine.system.predict_all`). Its times come from the disks' contact counts, not
from the chunks a run is called in, so the same config and seed give the same bits however
the run is cut.

With γ = 0 (or None) the effect is off: None in :class:`sim.effects.Effects`, no system event,
and the loop is that of disks that do not grow, to the bit.
"""

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from sim.effects.rules import effect_rule
from sim.effects.values import ConfigError, positive
from sim.engine.inputs import real_number, refused
from sim.engine.kinematics import VX, VY
from sim.engine.parameters import per_disk
from sim.engine.stamps import count_contacts
from sim.engine.system import advance_all, handler, predict_all

#: collisions per disk between two rescalings of the velocities, when not given
RESCALE_EVERY = 1.0

KEYWORDS = {
    "growth_rate": (None, "γ: every radius grows as R_i(0)(1 + γ t) (:mod:`sim.effects.growth`); "
                          "finite and ≥ 0, None or 0 = off"),
    "rescale_every": (RESCALE_EVERY, "collisions per disk between two rescalings of the "
                                     "velocities to the initial kinetic energy while the "
                                     "disks grow; finite and > 0"),
}


class Growth(NamedTuple):
    """The growth the compiled loop takes: γ, per unit of absolute time."""
    rate: float


class Rescale(NamedTuple):
    """The system event that brings the kinetic energy back to ``energy`` every ``every``
    collisions (of all disks) while the disks grow. ``state`` float64[3]: the absolute time
    of the last rescaling, the disks' contact count then (each collision counted twice) and
    the interval to the next (checkpointed with the engine)."""
    energy: float
    every: float
    state: np.ndarray


def check_config(cfg):
    """growth.rate finite and ≥ 0, growth.rescale_every finite and > 0; growth only with
    still, hard walls and smooth disks."""
    g = cfg.growth
    positive("growth.rate", g.rate, allow_none=False, zero=True)
    positive("growth.rescale_every", g.rescale_every, allow_none=False)
    walls = {name: (cfg.walls[name].speed, cfg.walls[name].amplitude,
                    cfg.walls[name].temperature) for name in ("left", "right", "bottom", "top")}
    moving = [name for name, (speed, amplitude, temperature) in walls.items()
              if speed or amplitude or temperature is not None]
    rough = (cfg.restitution.tangential, cfg.friction.mu) != (-1.0, None)
    if g.rate > 0.0 and moving:
        raise ConfigError("growth.rate", g.rate, f"0 with a moving or thermal wall "
                          f"(walls.{moving[0]}): disks grow between still, hard walls only")
    if g.rate > 0.0 and rough:
        raise ConfigError("growth.rate", g.rate, "0 with rough disks (restitution.tangential "
                          "≠ −1 or friction.mu): growing disks are smooth")


def engine_arguments(cfg):
    """γ and the rescaling interval of the config."""
    return {"growth_rate": float(cfg.growth.rate),
            "rescale_every": float(cfg.growth.rescale_every)}


def loop_values(keywords, context):
    """:class:`Growth` (None when γ is 0 or None) and its system event :class:`Rescale`;
    refused with moving or thermal walls and with rough disks (the effects before it)."""
    rate = keywords["growth_rate"]
    every = real_number("Engine", "rescale_every", keywords["rescale_every"],
                        lambda k: 0.0 < k < math.inf, "a finite number of collisions per "
                        "disk > 0")
    if rate is not None:
        rate = real_number("Engine", "growth_rate", rate, lambda g: 0.0 <= g < math.inf,
                           "a finite rate ≥ 0, or None")
    if not rate:
        return {"growth": None, "system_event": None}
    for field, what in (("wall_motion", "moving walls"), ("wall_temperature", "thermal walls"),
                        ("roughness", "rough disks")):
        if context[field] is not None:
            raise refused("Engine", "growth_rate", rate, f"None or 0 with {what}: disks grow "
                          f"between still, hard walls only, and are smooth")
    n, energy = context["n"], context["initial_energy"]
    if not 0.0 < energy < math.inf:
        raise refused("Engine", "growth_rate", rate, "None or 0 for disks at rest: growing "
                      "disks are held at their initial kinetic energy, which must be > 0")
    return {"growth": Growth(rate),
            "system_event": Rescale(energy, every * n, np.array(
                [0.0, 0.0, first_interval(every, context)]))}


def first_interval(every, context):
    """The time in which each disk makes ``every`` collisions at the start, 2 k / ω_E, from
    Enskog's collision frequency ω_E = 2 σ n g(σ) √(π T/m) of a two-dimensional gas (σ the
    mean diameter, n the number density, T = E/N, m the mean mass, g(σ) Henderson's
    (1 − 7φ/16)/(1 − φ)²); later intervals follow the measured rate."""
    n, radius, box = context["n"], context["radius"], context["box"]
    area = float(np.prod(box))
    phi = min(float(np.pi * np.sum(radius**2)) / area, 0.9)
    sigma = 2.0 * float(np.mean(radius))
    temperature = context["initial_energy"] / n
    mass = float(np.mean(context["mass"]))
    contact_value = (1.0 - 7.0 * phi / 16.0) / (1.0 - phi) ** 2
    frequency = 2.0 * sigma * (n / area) * contact_value * math.sqrt(math.pi * temperature / mass)
    return 2.0 * every / frequency


def growth_rate(relative, radius, temperature_per_mass):
    """γ at which contacts of the mean diameter ⟨σ⟩ = 2⟨R⟩ of ``radius`` (at time 0) grow at
    ``relative`` times the thermal speed √(T/m): Γ √(T/m)/⟨σ⟩. Γ = ṡ √(m/T)/⟨σ⟩ is the rate
    that compares compressions of any size and temperature."""
    return relative * math.sqrt(temperature_per_mass) / (2.0 * float(np.mean(radius)))


def scale(rate, time):
    """R(t)/R(0) = 1 + γ t at absolute time t (1 without growth)."""
    return 1.0 if not rate else 1.0 + rate * time


def time_of_scale(rate, s):
    """The absolute time at which the radii are s times their initial size."""
    return (s - 1.0) / rate


def _kept(growth, length, now):
    return length


@effect_rule(_kept)
def grown(growth, length, now):
    """A length of the disks at time 0 (a radius, a contact distance, a reach) grown to the
    absolute time ``now``: length (1 + γ now)."""
    return length * (1.0 + growth.rate * now)


def _fixed_size(growth, length, now):
    return length, None


@effect_rule(_fixed_size)
def growing(growth, length, now):
    """A length of the disks at time 0 at the absolute time ``now`` (:func:`grown`) and the
    speed γ length it grows at: a contact distance's ṡ, a radius's Ṙ (an edge moving out from
    its centre). Without growth (length, None): the compiled code takes None as another type
    and compiles away what it would do (the contact of disks that do not grow,
    :func:`sim.engine.pairs.pair_event_time`, :func:`sim.engine.contact.growth_frame`,
    :func:`sim.effects.walls.edge_velocity`)."""
    return grown(growth, length, now), growth.rate * length


def _whole_shell(growth, delta, radius, reach, now):
    return delta


@effect_rule(_whole_shell)
def shell_room(growth, delta, radius, reach, now):
    """The part of its shell's thickness δ a disk of initial radius ``radius`` may still
    cross: δ less what it has grown beyond its reach a_i since its list was rebuilt,
    δ − (R_i(now) − a_i); from then on it shrinks at Ṙ_i
    (:func:`sim.effects.gravity.shell_exit` with the speed of :func:`growing`)."""
    return delta - (grown(growth, radius, now) - reach)


@handler(Rescale)
@njit(cache=True)
def rescale(system, t, t_origin, disks, schedule, neighbours, box, effects):
    """Bring every disk to t, multiply every velocity by √(E/K) (K the kinetic energy, E the
    initial one) and predict every event anew. The next rescaling comes when the disks are
    expected to have made ``every`` more collisions at the rate they made them since the last
    one (contact counts, :mod:`sim.engine.stamps`; a wall contact counts half), at most twice
    the last interval later."""
    advance_all(t, disks, box, effects)
    table = disks.table
    n = table.shape[0]
    kinetic = 0.0
    for i in range(n):
        kinetic += 0.5 * per_disk(disks.mass, i) * (table[i, VX] ** 2 + table[i, VY] ** 2)
    if kinetic > 0.0:
        factor = math.sqrt(system.energy / kinetic)
        for i in range(n):
            table[i, VX] *= factor
            table[i, VY] *= factor
    predict_all(t, schedule)
    count_contacts(disks.stamp, disks.counted, disks.contacts)
    contacts = float(np.sum(disks.contacts))
    state = system.state
    now = t_origin + t
    collisions = 0.5 * (contacts - state[1])
    interval = state[2]
    if collisions > 0.0 and now > state[0]:
        interval = min((now - state[0]) * system.every / collisions, 2.0 * interval)
    state[0] = now
    state[1] = contacts
    state[2] = interval
    return t + interval
