"""Pair interactions: when two neighbouring disks next have an event, and what it does.

The loop asks every neighbour pair of a disk it predicts for the time of their next pair event
and applies the earliest. By default (``Parts.pair`` None, :mod:`sim.engine.groups`) the pair
is two hard disks: their contact at σ_ij = R_i + R_j (:func:`hard_core_time`, the filter and
the root of :mod:`sim.engine.kinematics`) and the impulse of :func:`collide` (restitution,
the TC model, rough disks, the recorders); otherwise the rules of the pair's kind
(:func:`pair_event_time`, :func:`apply_pair_event`).

A kind of pair interaction is a NamedTuple class (its value: the constants of the rule) with
compiled rules registered for it by :func:`rules`; numba picks them by the value's type while
it compiles the loop, so the registry is fixed at import. The rules are

``event_time(value, i, j, rx, ry, vx, vy, sigma, tau, state, disks)``
    the next event of disks i and j (separation r = r_i − r_j through the boundary, relative
    velocity v = v_i − v_j, hard-core distance σ = R_i + R_j, the pair's ``state``, the loop's
    disk group) as (time until it, event): ``event`` a whole number ≥ 0 that names the kind's
    own event (a core contact, a step crossed …), kept with the prediction and given to
    ``apply``; a time ``math.inf`` for none. It may return any time ≥ τ when the pair has
    none before τ ≥ 0, the time before which an event can matter (the earliest event of
    disk i found so far, or the next event of j if that comes sooner; 0 when j's event is
    now); never a negative time.
``apply`` (optional; default :func:`collide`, the hard-core contact)
    ``apply(value, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies,
    contact)`` with both disks flown to t, where ``contact`` is the run's count of contacts
    should the event be one: change their motion and their pair's state
    (:func:`set_pair_state`); bump both staleness stamps (:mod:`sim.engine.stamps`) for a
    contact, or :func:`sim.engine.stamps.invalidate` each disk whose motion changed by an
    event that is no contact. Returns (energy dissipated, r·Δp_i, event log full, the disk
    found collapsing or −1, whether the event was a contact); a contact is counted as a
    collision, any pair event as an event.
``reach`` (optional; default the radius)
    ``reach(value, i, disks)``: a length a_i such that disks i and j have no event while they
    are more than a_i + a_j apart. The neighbour shells reach it
    (:mod:`sim.engine.neighbours`), frozen per disk at each rebuild of its list. It may
    change from one rebuild to the next, but never beyond the largest reach at the engine's
    construction, by which the cells and the periodic limit are sized.
``initial_state`` (optional; a kind that has it keeps a state per pair, and only such a kind
may call :func:`pair_state` and :func:`set_pair_state`)
    ``initial_state(value, i, j, rx, ry, sigma, disks)``: the state (an int32) of a pair at
    the engine's construction, from its separation (asked once per pair, for i < j). From
    then on the events alone change it (:func:`set_pair_state`); a pair that joins the
    neighbour lists later was farther apart than its reach and starts at state 0. The state is
    kept beside the pair's two entries of the lists (``Neighbours.pair_state``), through
    rebuilds, renumbering and checkpoints.
``energy`` (optional, Python; for a kind with a potential energy)
    ``energy(value, disks)``: the potential energy of every pair from their states (a
    float), which :meth:`sim.engine.Engine.potential_energy` adds to that of gravity.

A kind without its own ``apply`` keeps no event of its own: its ``event`` is taken as a
contact. A scene pays for what its kind has and nothing else: the event names, the reach
and the state arrays are None for a kind without them (and for hard disks), and numba
compiles them away.
"""

import math
from typing import NamedTuple

from numba import njit, types
from numba.core.errors import TypingError
from numba.extending import overload

from sim.effects.event_log import log_contact
from sim.effects.growth import growing
from sim.effects.pressure_tensor import add_virial_tensor
from sim.effects.restitution import collapsing, disk_restitution
from sim.effects.rotation import rough_collision
from sim.effects.tc import tc_restitution
from sim.engine.box import separation
from sim.engine.contact import collide_disks
from sim.engine.kinematics import (
    INF,
    RADIUS,
    X,
    Y,
    growing_contact_time,
    may_touch_before,
    pair_contact_time,
)
from sim.engine.neighbours import list_start
from sim.engine.parameters import per_disk


class Rules(NamedTuple):
    """The compiled rules of a kind of pair interaction (see the module docstring)."""
    event_time: object
    apply: object = None
    reach: object = None
    initial_state: object = None
    energy: object = None


#: the rules of each kind of pair interaction: NamedTuple class → :class:`Rules`
RULES = {}


def rules(kind, event_time, apply=None, *, reach=None, initial_state=None, energy=None):
    """Register the compiled rules of the pair interaction ``kind`` (a NamedTuple class)."""
    RULES[kind] = Rules(event_time, apply, reach, initial_state, energy)


def _rules_of(value):
    kind = getattr(value, "instance_class", None)
    if kind not in RULES:
        raise TypingError(f"no pair-interaction rules are registered for {value} "
                          f"(sim.engine.pairs.rules)")
    return RULES[kind]


def keeps(pair, rule):
    """Whether the kind of ``pair`` (None: hard disks) has the optional rule ``rule``
    (``"apply"``, ``"reach"``, ``"initial_state"``, ``"energy"``): the engine then
    allocates its arrays."""
    return pair is not None and getattr(RULES[type(pair)], rule) is not None


def pair_energy(pair, disks):
    """The potential energy of the pairs (the kind's ``energy`` rule), 0 without one."""
    return float(RULES[type(pair)].energy(pair, disks)) if keeps(pair, "energy") else 0.0


@njit(cache=True, inline="always")
def hard_core_time(rx, ry, vx, vy, sigma, tau):
    """The hard core's event time: the contact at σ
    (:func:`sim.engine.kinematics.pair_contact_time`), or ∞ when the filter
    (:func:`sim.engine.kinematics.may_touch_before`) shows that it comes no sooner than τ."""
    if may_touch_before(rx, ry, vx, vy, sigma, tau):
        return pair_contact_time(rx, ry, vx, vy, sigma)
    return INF


def pair_event_time(pair, i, j, rx, ry, vx, vy, sigma, sigma_rate, tau, state, disks):
    """The next pair event of disks i and j as (time until it, event): the rule of ``pair``'s
    kind (see the module docstring), or the hard core's contact and event 0: at σ
    (:func:`hard_core_time`) for disks that do not grow (``sigma_rate`` None), else at a
    contact distance σ growing at ``sigma_rate``
    (:func:`sim.engine.kinematics.growing_contact_time`, :mod:`sim.effects.growth`)."""
    if pair is None:
        if sigma_rate is None:
            return hard_core_time(rx, ry, vx, vy, sigma, tau), 0
        return growing_contact_time(rx, ry, vx, vy, sigma, sigma_rate, tau), 0
    return RULES[type(pair)].event_time(pair, i, j, rx, ry, vx, vy, sigma, tau, state, disks)


@overload(pair_event_time, inline="always")
def _pair_event_time(pair, i, j, rx, ry, vx, vy, sigma, sigma_rate, tau, state, disks):
    if pair is types.none and sigma_rate is types.none:
        return lambda pair, i, j, rx, ry, vx, vy, sigma, sigma_rate, tau, state, disks: (
            hard_core_time(rx, ry, vx, vy, sigma, tau), 0)
    if pair is types.none:
        return lambda pair, i, j, rx, ry, vx, vy, sigma, sigma_rate, tau, state, disks: (
            growing_contact_time(rx, ry, vx, vy, sigma, sigma_rate, tau), 0)
    event_time = _rules_of(pair).event_time
    return lambda pair, i, j, rx, ry, vx, vy, sigma, sigma_rate, tau, state, disks: event_time(
        pair, i, j, rx, ry, vx, vy, sigma, tau, state, disks)


def apply_pair_event(pair, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies,
                     contact):
    """Apply the pair event ``event`` of disks i and j at time t by the ``apply`` rule of
    ``pair``'s kind, or as a contact (:func:`collide`) for a kind without one. Returns what
    :func:`collide` returns and whether the event was a contact. The loop calls it for every
    pair event of a scene with a pair interaction, and :func:`collide` directly for hard
    disks, so that one copy of the contact is compiled into the loop, not a second one beside
    the stepped potential's that is never taken (which made the square-well loop's first
    compilation a quarter slower, ``docs/performance-history.md``)."""
    rule = RULES[type(pair)].apply
    if rule is None:
        return (*collide(i, j, t, t_origin, disks, box, effects, tallies, contact), True)
    return rule(pair, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies,
                contact)


@overload(apply_pair_event, inline="always")
def _apply_pair_event(pair, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies,
                      contact):
    apply = _rules_of(pair).apply
    if apply is None:
        def as_contact(pair, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies,
                       contact):
            lost, virial, log_full, culprit = collide(i, j, t, t_origin, disks, box, effects,
                                                      tallies, contact)
            return lost, virial, log_full, culprit, True
        return as_contact
    return lambda pair, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies, \
        contact: apply(pair, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies,
                       contact)


def pair_reach(pair, i, disks):
    """The reach a_i of disk i (see the module docstring): the rule of ``pair``'s kind, else
    the radius R_i."""
    if keeps(pair, "reach"):
        return RULES[type(pair)].reach(pair, i, disks)
    return disks.table[i, RADIUS]


@overload(pair_reach, inline="always")
def _pair_reach(pair, i, disks):
    reach = None if pair is types.none else _rules_of(pair).reach
    if reach is None:
        return lambda pair, i, disks: disks.table[i, RADIUS]
    return lambda pair, i, disks: reach(pair, i, disks)


@njit(cache=True)
def pair_entry(neighbours, i, j):
    """Where disk j stands in the neighbour list of disk i (an index into ``nb``); they must
    be neighbours."""
    k = list_start(neighbours.nb_start, i)
    while neighbours.nb[k] != j:
        k += 1
    return k


@njit(cache=True)
def pair_state(neighbours, i, j):
    """The state of the neighbour pair (i, j) (``Neighbours.pair_state``)."""
    return neighbours.pair_state[pair_entry(neighbours, i, j)]


@njit(cache=True)
def set_pair_state(neighbours, i, j, state):
    """Set the state of the neighbour pair (i, j): both its entries, in the lists of i and
    of j. (A compiled function that the rules call, not inlined into them by numba, whose
    inlining of a conditional expression given as ``state`` can drop its value.)"""
    neighbours.pair_state[pair_entry(neighbours, i, j)] = state
    neighbours.pair_state[pair_entry(neighbours, j, i)] = state


def initial_pair_state(pair, i, j, rx, ry, sigma, disks):
    """The state of the pair (i, j) at the engine's construction: the kind's
    ``initial_state`` rule."""
    return RULES[type(pair)].initial_state(pair, i, j, rx, ry, sigma, disks)


@overload(initial_pair_state)
def _initial_pair_state(pair, i, j, rx, ry, sigma, disks):
    initial_state = _rules_of(pair).initial_state
    return lambda pair, i, j, rx, ry, sigma, disks: initial_state(pair, i, j, rx, ry, sigma,
                                                                  disks)


@njit
def initial_reaches(pair, disks, reach):
    """Fill ``reach`` float64[n] with every disk's reach (:func:`pair_reach`), at the
    engine's construction. Not cached: the kind may be defined outside sim
    (:func:`sim.engine.compilation.cacheable`)."""
    for i in range(reach.shape[0]):
        reach[i] = pair_reach(pair, i, disks)


@njit
def initial_states(pair, disks, neighbours, box):
    """Set the state of every neighbour pair (i < j, both its entries) by the kind's
    ``initial_state`` rule, every disk at its own time 0 (the engine's construction). Not
    cached, as :func:`initial_reaches`."""
    table = disks.table
    for i in range(table.shape[0]):
        start = list_start(neighbours.nb_start, i)
        for k in range(start, start + neighbours.nb_count[i]):
            j = neighbours.nb[k]
            if j > i:
                rx, ry = separation(box, table[i, X] - table[j, X], table[i, Y] - table[j, Y])
                set_pair_state(neighbours, i, j, initial_pair_state(
                    pair, i, j, rx, ry, table[i, RADIUS] + table[j, RADIUS], disks))


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
    sigma_rate = growing(effects.growth, table[i, RADIUS] + table[j, RADIUS], t_origin + t)[1]
    lost, virial = collide_disks(i, j, rx, ry, xi, table, m_i, m_j, sigma_rate)
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
