"""Pair interactions: when two neighbouring disks next have an event, and what it does.

The loop asks every neighbour pair of a disk it predicts for the time of their next pair event
and applies the earliest. By default (``Parts.pair`` None, :mod:`sim.engine.groups`) the pair
is two hard disks: their contact at σ_ij = R_i + R_j (:func:`hard_core_time`, the filter and
the root of :mod:`sim.engine.kinematics`) and the impulse of :func:`collide` (restitution,
the TC model, rough disks, the recorders); otherwise the rules of the pair's kind
(:func:`pair_event_time`, and :func:`apply_pair_event` when :func:`own_apply`).

A kind of pair interaction is a NamedTuple class (its value: the constants of the rule) with
compiled rules registered for it by :func:`rules`; numba picks them by the value's type while
it compiles the loop, so the registry is fixed at import. The rules are

``event_time(value, i, j, rx, ry, vx, vy, sigma, tau, disks)``
    the time until disks i and j (separation r = r_i − r_j through the boundary, relative
    velocity v = v_i − v_j, hard-core distance σ = R_i + R_j, the loop's disk group) next have
    an event, ``math.inf`` for none; it may return any time ≥ τ, the earliest event found so
    far, when the pair has none before τ; never a negative time;
``apply`` (optional; default :func:`collide`, the hard-core contact)
    ``apply(value, i, j, t, t_origin, disks, box, effects, tallies, contact)`` with both disks
    flown to t, as the run's ``contact``-th contact: change their motion and bump both
    staleness stamps (:mod:`sim.engine.stamps`); returns (energy dissipated, r·Δp_i, event
    log full, the disk found collapsing or −1), as :func:`collide`.

Every pair event counts as a collision. Neighbour shells reach the hard core σ: a rule may not
give an event beyond it.
"""

import math

from numba import njit, types
from numba.core.errors import TypingError
from numba.extending import overload

from sim.effects.event_log import log_contact
from sim.effects.pressure_tensor import add_virial_tensor
from sim.effects.restitution import collapsing, disk_restitution
from sim.effects.rotation import rough_collision
from sim.effects.tc import tc_restitution
from sim.engine.box import separation
from sim.engine.contact import collide_disks
from sim.engine.kinematics import INF, X, Y, may_touch_before, pair_contact_time
from sim.engine.parameters import per_disk

#: the rules of each kind of pair interaction: NamedTuple class → (event_time, apply or None)
RULES = {}


def rules(kind, event_time, apply=None):
    """Register the compiled rules of the pair interaction ``kind`` (a NamedTuple class)."""
    RULES[kind] = (event_time, apply)


def _rules_of(value):
    kind = getattr(value, "instance_class", None)
    if kind not in RULES:
        raise TypingError(f"no pair-interaction rules are registered for {value} "
                          f"(sim.engine.pairs.rules)")
    return RULES[kind]


def own_apply(pair):
    """Whether the pair interaction ``pair`` (not None) applies its events by a rule of its
    own kind, else :func:`collide`. A constant while numba compiles the loop, which calls
    :func:`collide` directly when it is False or ``pair`` None: the contact is then compiled
    as it was before the seam existed (through an overload it took 3 s more of the first
    compilation)."""
    return RULES[type(pair)][1] is not None


@overload(own_apply, inline="always")
def _own_apply(pair):
    own = _rules_of(pair)[1] is not None
    return lambda pair: own


@njit(cache=True, inline="always")
def hard_core_time(rx, ry, vx, vy, sigma, tau):
    """The hard core's event time: the contact at σ
    (:func:`sim.engine.kinematics.pair_contact_time`), or ∞ when the filter
    (:func:`sim.engine.kinematics.may_touch_before`) shows that it comes no sooner than τ."""
    if may_touch_before(rx, ry, vx, vy, sigma, tau):
        return pair_contact_time(rx, ry, vx, vy, sigma)
    return INF


def pair_event_time(pair, i, j, rx, ry, vx, vy, sigma, tau, disks):
    """The time until disks i and j next have a pair event: the rule of ``pair``'s kind (see
    the module docstring), or :func:`hard_core_time`."""
    if pair is None:
        return hard_core_time(rx, ry, vx, vy, sigma, tau)
    return RULES[type(pair)][0](pair, i, j, rx, ry, vx, vy, sigma, tau, disks)


@overload(pair_event_time, inline="always")
def _pair_event_time(pair, i, j, rx, ry, vx, vy, sigma, tau, disks):
    if pair is types.none:
        return lambda pair, i, j, rx, ry, vx, vy, sigma, tau, disks: hard_core_time(
            rx, ry, vx, vy, sigma, tau)
    event_time = _rules_of(pair)[0]
    return lambda pair, i, j, rx, ry, vx, vy, sigma, tau, disks: event_time(
        pair, i, j, rx, ry, vx, vy, sigma, tau, disks)


def apply_pair_event(pair, i, j, t, t_origin, disks, box, effects, tallies, contact):
    """Apply the pair event of disks i and j at time t, the run's ``contact``-th contact, by
    the rule of ``pair``'s kind; the loop calls it when :func:`own_apply`. Returns what
    :func:`collide` returns."""
    return RULES[type(pair)][1](pair, i, j, t, t_origin, disks, box, effects, tallies, contact)


@overload(apply_pair_event, inline="always")
def _apply_pair_event(pair, i, j, t, t_origin, disks, box, effects, tallies, contact):
    apply = None if pair is types.none else _rules_of(pair)[1]
    if apply is None:  # typed for a kind without an apply rule of its own, never called
        return lambda pair, i, j, t, t_origin, disks, box, effects, tallies, contact: (
            0.0, 0.0, False, -1)
    return lambda pair, i, j, t, t_origin, disks, box, effects, tallies, contact: apply(
        pair, i, j, t, t_origin, disks, box, effects, tallies, contact)


@njit(cache=True, inline="always")
def collide(i, j, t, t_origin, disks, box, effects, tallies, contact):
    """The collision of disks i and j, both already flown to time t, as the ``contact``-th
    contact of the run: restitution (with the TC model), the impulse
    (:func:`sim.engine.contact.collide_disks`), what the recorders keep, the collapse watch.
    Returns (energy dissipated, r·Δp_i, log full, the disk found collapsing or −1)."""
    table, t_last = disks.table, disks.t_last
    rx, ry = separation(box, table[i, X] - table[j, X], table[i, Y] - table[j, Y])
    xi = tc_restitution(effects.tc, disk_restitution(effects.restitution, disks.species, i, j),
                        t, t_last[i], t_last[j])
    m_i = per_disk(disks.mass, i)
    m_j = per_disk(disks.mass, j)
    lost, virial = collide_disks(i, j, rx, ry, xi, table, m_i, m_j)
    add_virial_tensor(effects.virial_tensor, rx, ry, virial)
    lost += rough_collision(effects.roughness, effects, i, j, rx, ry, virial, t, disks, m_i,
                            m_j)
    s_i = per_disk(disks.species, i)
    s_j = per_disk(disks.species, j)
    tallies.pair_collisions[min(s_i, s_j), max(s_i, s_j)] += 1
    disks.stamp[i] += 1
    disks.stamp[j] += 1
    log_full = log_contact(effects.event_log, t_origin + t, i, j,
                           virial / math.sqrt(rx * rx + ry * ry), lost, contact)
    collapsing_i = collapsing(effects.collapse, t_last, disks.streak, i, xi, t)
    collapsing_j = collapsing(effects.collapse, t_last, disks.streak, j, xi, t)
    culprit = i if collapsing_i else (j if collapsing_j else -1)
    return lost, virial, log_full, culprit
