"""The compiled event loop: pop the earliest event, apply it, predict anew.

Each disk owns one scheduled event, the earliest of (Smallenburg, Eur. Phys. J. E 45, 22 (2022)):
  * a pair event with a disk of its neighbour list (``partner ≥ 0``): a contact, or another
    event of the scene's pair interaction (:mod:`sim.engine.pairs`, whose name for it is kept
    in ``Schedule.pair_event``), valid while the partner's staleness stamp
    (:mod:`sim.engine.stamps`) still equals the value recorded at prediction, and scheduled
    only when it comes no later than the partner's own next event (:func:`predict`);
  * a contact with a wall (``partner = WALL_X_LOW … WALL_Y_HIGH``);
  * its exit from its neighbour shell (``partner = SHELL_EXIT``), which rebuilds its list;
  * at construction, its first prediction (``partner = UNPREDICTED``, at the current time):
    every disk is predicted through the loop's one inlined copy of :func:`predict`, which
    spares the compiler a second copy.
The codes of these kinds are :data:`sim.engine.codes.KINDS`. A system event, something done to
the whole system at a time, is no disk's: it waits in the schedule's slot, and the loop
applies it before the disk event at the head of the queue when it comes no later
(:mod:`sim.engine.system`; compiled away when the scene has none).
Positions are advanced lazily: disk i is stored at ``table[i, X:Y+1]`` at its own time
``table[i, T_OWN]`` (disk table columns in :mod:`sim.engine.kinematics`). Every
``rebase_every`` events all disks are brought to the current time and the clock restarts from
zero (its origin kept in ``accumulators[T_ORIGIN]``), so long runs keep full float64
precision. Stale events are re-predicted, never applied. At large N the loop waits on memory:
it asks the CPU to prefetch the partner's data and that of the next disks in the queue, and for
states larger than the caches several events ahead (:func:`sim.engine.lookahead.prefetch_upcoming`,
:mod:`sim.engine.prefetch`).

Its codes — event partners, statuses, counters and accumulators — and the words for what it
counts are in :mod:`sim.engine.codes`.

The loop takes its arguments in named groups (:mod:`sim.engine.groups`); the effects a scene
uses arrive in :class:`sim.effects.Effects`, each None when off, and act through the rules of
their modules (:mod:`sim.effects.rules`): numba compiles one loop per combination and removes
the code of every effect that is off. It returns ``(status, disk)``; errors are codes, raised
as exceptions by the caller.
"""

import numpy as np
from numba import njit

from sim.effects.event_log import log_contact
from sim.effects.gravity import shell_exit
from sim.effects.growth import growing, grown, shell_room
from sim.effects.restitution import collapsing, wall_restitution_of
from sim.effects.rotation import rough_wall_contact
from sim.effects.tc import tc_restitution
from sim.effects.thermal_walls import contact_key
from sim.effects.walls import hit_wall, predict_wall_contact
from sim.engine.box import PERIODIC, fold, image_velocity, separation
from sim.engine.codes import (
    COLLISIONS,
    DISSIPATED_DISKS,
    DISSIPATED_WALLS,
    EVENTS,
    NO_EVENT,
    SHELL_EXIT,
    SHELL_EXITS,
    STALE_EVENTS,
    STATUS_COLLAPSE,
    STATUS_COLLISION_LIMIT,
    STATUS_CONTACT_LIMIT,
    STATUS_ENERGY_REACHED,
    STATUS_EVENT_LIMIT,
    STATUS_LIST_FULL,
    STATUS_LOG_FULL,
    STATUS_NO_EVENTS,
    STATUS_STALLED,
    STATUS_TIME_REACHED,
    SYSTEM,
    T_NOW,
    T_ORIGIN,
    UNPREDICTED,
    VIRIAL,
    WALL_CONTACTS,
    WALL_WORK,
    WALL_X_LOW,
)
from sim.engine.flight import flown, fly, position_at, velocity_of
from sim.engine.kinematics import (
    CX,
    CY,
    INF,
    RADIUS,
    T_OWN,
    VX,
    VY,
    X,
    Y,
)
from sim.engine.lookahead import prefetch_next, prefetch_upcoming
from sim.engine.neighbours import list_start, rebuild_neighbours
from sim.engine.pairs import (
    apply_pair_event,
    collide,
    pair_event_time,
    pair_reach,
)
from sim.engine.parameters import optional_entry, per_disk, set_optional_entry
from sim.engine.queue import (
    build_queue,
    earliest,
    prefetch_bucket,
    reschedule,
)
from sim.engine.stamps import count_contacts
from sim.engine.system import apply_system_event


@njit(cache=True, inline="always")
def predict(i, t, disks, schedule, neighbours, box, effects, pair, t_origin):
    """The earliest event of disk i, which must be at time t already (``t_origin``: the
    absolute time of the clock's zero, which moving walls need): its time, its partner (a
    disk, a wall code, ``SHELL_EXIT`` or ``NO_EVENT``), the partner's staleness stamp when
    the partner is a disk (else 0) and the pair interaction's name of the event (0 but for
    a pair event), for :func:`set_event`.

    A contact with j at time t_ij is left out when j's own next event comes first
    (``event_time[j] < t_ij``): j is predicted again at that event, whatever it is, and then
    finds the contact itself if it still comes. Of the two, the one predicted last before
    the contact sees the other's event no earlier and schedules it; a contact due now
    (τ = 0, round-off overlaps included) is never left out, as no event is due before now.
    Without the rule the contact would mostly go stale, as j's earlier event is mostly a
    collision: stale events per collision 0.20 → 0.08 at φ = 0.5 (0.17 → 0.05 at 0.1,
    0.32 → 0.14 at 0.7), and ``benchmarks/compare_builds.py`` 1.047 at N = 1e4, φ = 0.5,
    1.034 at 0.1, 1.032 at 0.7, 1.050 at N = 1e5.

    The same rule bounds the search: a pair's event is looked for only before
    min(τ, t_j − t) (never below 0: t_j may lie before t by round-off), τ the earliest event
    found so far and t_j j's next event, so that the filter of the pair's rule
    (:func:`sim.engine.kinematics.may_touch_before` for hard cores) spares the root of every
    contact that would be left out anyway. In a dense gas, where most neighbours are about
    to collide with a disk of their own, that is most of them: ``compare_builds.py`` 1.143
    at N = 16384, φ = 0.708.
    """
    table = disks.table
    geometry, grid = box
    gravity = effects.gravity
    x = table[i, X]
    y = table[i, Y]
    vx = table[i, VX]
    vy = table[i, VY]
    r_i = table[i, RADIUS]
    now = t_origin + t
    r_now, edge = growing(effects.growth, r_i, now)  # R_i(now), Ṙ_i (None: not growing)
    dx, dy = separation(box, x - table[i, CX], y - table[i, CY])
    tau = shell_exit(gravity, dx, dy, vx, vy,
                     shell_room(effects.growth, per_disk(disks.delta, i), r_i,
                                optional_entry(neighbours.reach, i, r_i), now), edge)
    partner = SHELL_EXIT
    for axis in range(2):
        if grid[PERIODIC + axis] == 0:
            tau_w, side = predict_wall_contact(gravity, effects.wall_motion, axis, now,
                                               table[i, X + axis], table[i, VX + axis],
                                               r_now, edge, geometry, tau)
            if tau_w < tau:
                tau = tau_w
                # a search near a vibrating wall that stopped short: predict again from there
                partner = WALL_X_LOW - 2 * axis - side if side >= 0 else SHELL_EXIT
    nb = neighbours.nb
    event_time = schedule.event_time
    event = 0
    start = list_start(neighbours.nb_start, i)
    for k in range(start, start + neighbours.nb_count[i]):
        j = nb[k]
        dt = t - table[j, T_OWN]
        vx_j = velocity_of(j, 0, dt, table, gravity)
        vy_j = velocity_of(j, 1, dt, table, gravity)
        dx = x - table[j, X] - flown(j, 0, dt, table, gravity)
        dy = y - table[j, Y] - flown(j, 1, dt, table, gravity)
        rx, ry = separation(box, dx, dy)
        ux, uy = image_velocity(box, dy, ry)
        vx_ij = vx - vx_j - ux
        vy_ij = vy - vy_j - uy
        sigma, sigma_rate = growing(effects.growth, r_i + table[j, RADIUS], now)
        tau_ij, event_ij = pair_event_time(pair, i, j, rx, ry, vx_ij, vy_ij, sigma, sigma_rate,
                                           max(min(tau, event_time[j] - t), 0.0),
                                           optional_entry(neighbours.pair_state, k, 0),
                                           disks)
        if tau_ij < tau and t + tau_ij <= event_time[j]:
            tau = tau_ij
            partner = j
            event = event_ij
    if tau == INF:
        partner = NO_EVENT
    return t + tau, partner, disks.stamp[partner] if partner >= 0 else np.int32(0), event


@njit(cache=True, inline="always")
def set_event(i, when, partner, partner_stamp, event, schedule):
    """Record the event :func:`predict` found for disk i; filing it in the queue
    (:func:`sim.engine.queue.reschedule`) comes after."""
    schedule.event_time[i] = when
    schedule.event_partner[i] = partner
    if partner >= 0:
        schedule.event_stamp[i] = partner_stamp
        set_optional_entry(schedule.pair_event, i, event)


@njit(cache=True, inline="always")
def touch_wall(i, wall, t, t_origin, disks, box, effects, tallies, wall_contacts, contact):
    """Disk i, flown to time t, touches ``wall`` as the run's ``wall_contacts``-th wall contact
    (counted from 0) and ``contact``-th contact: restitution (with the TC model), the wall's
    rule (:func:`sim.effects.walls.hit_wall`), the log, the collapse watch. Returns (energy
    dissipated, work done by the wall, log full, collapsing)."""
    t_last = disks.t_last
    xi_w = tc_restitution(effects.tc, wall_restitution_of(effects.wall_restitution), t,
                          t_last[i], t_last[i])
    key = contact_key(effects.wall_temperature, effects.seed, wall_contacts)
    m = per_disk(disks.mass, i)
    r_now, edge = growing(effects.growth, disks.table[i, RADIUS], t_origin + t)
    lost, impulse, work = hit_wall(i, wall, t_origin + t, xi_w, disks.table, m, box.geometry,
                                   effects, key, r_now, edge)
    lost += rough_wall_contact(effects.roughness, effects, i, wall, impulse, t, disks, m)
    tallies.wall_impulse[wall] += impulse
    disks.stamp[i] += 1
    log_full = log_contact(effects.event_log, t_origin + t, i, -1 - wall, abs(impulse), lost,
                           contact)
    return lost, work, log_full, collapsing(effects.collapse, t_last, disks.streak, i, xi_w, t)


@njit(cache=True, _nrt=False, error_model="numpy")
def rebase_clock(disks, schedule, box, effects, accumulators):
    """Bring every disk to the current time and restart the clock there (order-preserving);
    the event queue is rebuilt for the shifted times, and the contact counts are updated."""
    count_contacts(disks.stamp, disks.counted, disks.contacts)
    t0 = accumulators[T_NOW]
    table = disks.table
    for i in range(table.shape[0]):
        fly(i, t0, table, box, effects.gravity, effects.images)
        table[i, T_OWN] = 0.0
        disks.t_last[i] -= t0
        schedule.event_time[i] -= t0
    schedule.system_time[0] -= t0
    accumulators[T_ORIGIN] += t0
    accumulators[T_NOW] = 0.0
    build_queue(schedule.heap, schedule.links, schedule.list_head, schedule.calendar,
                schedule.block_rate, schedule.event_time, 0.0)


@njit(cache=True, inline="always")
def predict_and_file(i, j, t, disks, schedule, neighbours, box, effects, pair, t_origin):
    """Predict the next event of disk i and, when j ≥ 0, of disk j, and file both.

    One call site each for predict and reschedule: numba inlines them wherever they are
    called, and with one copy instead of five the loop compiles about four times faster.
    Both disks are predicted before either is filed, so that the bucket head a filing reads
    is on its way while the second prediction runs (no prediction reads the queue). The queue
    sees one event time change at a time, as a filing compares times: the event of j is
    recorded only once i is filed."""
    s = schedule
    moved_disks = 1 if j < 0 else 2
    when, whom, whose_stamp, event = INF, NO_EVENT, np.int32(0), 0
    for k in range(moved_disks):
        when, whom, whose_stamp, event = predict(i if k == 0 else j, t, disks, schedule,
                                                 neighbours, box, effects, pair, t_origin)
        prefetch_bucket(s.list_head, s.calendar, s.block_rate, when)
        if k == 0:
            set_event(i, when, whom, whose_stamp, event, schedule)
    for k in range(moved_disks):
        if k == 1:  # the prediction of j, the last one made
            set_event(j, when, whom, whose_stamp, event, schedule)
        reschedule(s.heap, s.links, s.list_head, s.calendar, s.block_rate, s.event_time,
                   i if k == 0 else j)


@njit(cache=True, inline="always")
def stop_status(limits, partner, t, t_stop, t_previous, stalled, stall_limit, events, collisions,
                wall_contacts, dissipated, log_full):
    """The status that ends the loop before the event of ``partner`` at time t (relative
    clock; ``t_stop`` on the same clock), or 0, and the length of the stall run.

    In this order: the limits of ``limits`` on the tallies (not for a first prediction, which
    is made whatever they are), the time limit, the end of all events, and a stall — more than
    ``stall_limit`` = 16 N + 1000 events in a row, each at most ``limits.stall_dt`` after the
    one before (a time of float64 resolution, :data:`sim.engine.sizing.STALL_RESOLUTION`),
    which ends the loop instead of hanging it."""
    if partner != UNPREDICTED:
        if events >= limits.max_events:
            return STATUS_EVENT_LIMIT, stalled
        if collisions >= limits.max_collisions:
            return STATUS_COLLISION_LIMIT, stalled
        if collisions + wall_contacts >= limits.max_contacts:
            return STATUS_CONTACT_LIMIT, stalled
        if dissipated >= limits.dissipation_limit:
            return STATUS_ENERGY_REACHED, stalled
        if log_full:
            return STATUS_LOG_FULL, stalled
    if t > t_stop:
        return STATUS_TIME_REACHED, stalled
    if t == INF:
        return STATUS_NO_EVENTS, stalled
    if t - t_previous > limits.stall_dt:
        return 0, np.int64(0)
    if stalled + 1 > stall_limit:
        return STATUS_STALLED, stalled + 1
    return 0, stalled + 1


@njit(cache=True, _nrt=False, error_model="numpy")
def run_events(disks, schedule, neighbours, box, effects, pair, system, lookahead, tallies,
               limits):
    """Process events in time order until :func:`stop_status` ends the loop; see the module
    docstring. Returns (status, the disk it concerns or −1).

    ``pair`` and ``system`` are the fields of :class:`sim.engine.groups.Parts`, passed one by
    one: numba prunes a branch ``if system is not None`` only for an argument of the function
    it compiles, so that a scene without a system event compiles none of its code (0.7 s of
    the first compilation, against the group). ``lookahead``: True to prefetch several events
    ahead, for states larger than the caches
    (:func:`sim.engine.lookahead.prefetch_upcoming`), else None, and the loop compiles none of
    it.

    ``tallies.stall_watch`` carries the time of the last event popped (relative clock) and
    the length of its stall run from one call to the next; counters and accumulators live in
    local variables (registers) during the loop and are written back when it stops.
    """
    counters, accumulators = tallies.counters, tallies.accumulators
    events = counters[EVENTS]
    collisions = counters[COLLISIONS]
    wall_contacts = counters[WALL_CONTACTS]
    shell_exits = counters[SHELL_EXITS]
    stale_events = counters[STALE_EVENTS]
    t_now = accumulators[T_NOW]
    dissipated_disks = accumulators[DISSIPATED_DISKS]
    dissipated_walls = accumulators[DISSIPATED_WALLS]
    virial_sum = accumulators[VIRIAL]
    wall_work = accumulators[WALL_WORK]
    log_full = False
    t_stop = limits.t_stop - accumulators[T_ORIGIN]
    events_to_rebase = limits.rebase_every - events % limits.rebase_every
    culprit = -1
    t_previous = tallies.stall_watch[0]
    stalled = np.int64(tallies.stall_watch[1])
    stall_limit = 16 * disks.table.shape[0] + 1000
    walker = -1  # the queue's look-ahead (prefetch_next_block)
    walker_block = -1
    s = schedule
    while True:
        i = earliest(s.heap, s.links, s.list_head, s.calendar, s.block_rate, s.event_time)
        partner = s.event_partner[i]
        t = s.event_time[i]
        if system is not None and s.system_time[0] <= t:
            partner = SYSTEM
            t = s.system_time[0]
        status, stalled = stop_status(limits, partner, t, t_stop, t_previous, stalled,
                                      stall_limit, events, collisions, wall_contacts,
                                      dissipated_disks + dissipated_walls, log_full)
        if status != 0:
            culprit = i if status == STATUS_STALLED and partner != SYSTEM else -1
            break
        t_previous = t
        if lookahead is None:
            prefetch_next(partner, 3, False, disks, schedule, neighbours)
        else:
            walker, walker_block = prefetch_upcoming(partner, walker, walker_block, disks,
                                                     schedule, neighbours, box)
        t_origin = accumulators[T_ORIGIN]
        fly(i, t, disks.table, box, effects.gravity, effects.images)
        j = NO_EVENT  # the second disk to re-predict, when it is a collision
        if partner >= 0 and disks.stamp[partner] != s.event_stamp[i]:
            stale_events += 1
        elif partner >= 0:
            j = partner
            fly(j, t, disks.table, box, effects.gravity, effects.images)
            events += 1
            if pair is not None:
                lost, virial, log_full, culprit, contact = apply_pair_event(
                    pair, optional_entry(s.pair_event, i, 0), i, j, t, t_origin, disks, neighbours,
                    box, effects, tallies, collisions + wall_contacts + 1)
                collisions += 1 if contact else 0
            else:
                collisions += 1
                lost, virial, log_full, culprit = collide(i, j, t, t_origin, disks, box, effects,
                                                          tallies, collisions + wall_contacts)
            dissipated_disks += lost
            virial_sum += virial
        elif partner == SHELL_EXIT:
            culprit = rebuild_neighbours(i, grown(effects.growth, pair_reach(pair, i, disks),
                                                  t_origin + t),
                                         disks.table, disks.delta, neighbours, box,
                                         lookahead is not None)
            if culprit >= 0:
                status = STATUS_LIST_FULL
                break
            shell_exits += 1
            events += 1
        elif system is not None and partner == SYSTEM:  # i (the queue's head) flown to t: harmless
            s.system_time[0] = apply_system_event(system, t, t_origin, disks, schedule,
                                                  neighbours, box, effects)
            t_now = t
            continue
        elif partner != UNPREDICTED:
            wall_contacts += 1
            events += 1
            lost, work, log_full, collapsed = touch_wall(
                i, WALL_X_LOW - partner, t, t_origin, disks, box, effects, tallies,
                wall_contacts - 1, collisions + wall_contacts)
            dissipated_walls += lost
            wall_work += work
            culprit = i if collapsed else -1
        if culprit >= 0:
            status = STATUS_COLLAPSE
            break
        predict_and_file(i, j, t, disks, schedule, neighbours, box, effects, pair, t_origin)
        if (partner >= 0 and j < 0) or partner == UNPREDICTED:
            continue  # a stale event or a first prediction is no event: the clock stays
        t_now = t
        events_to_rebase -= 1
        if events_to_rebase == 0:
            accumulators[T_NOW] = t_now
            rebase_clock(disks, schedule, box, effects, accumulators)
            t_now = 0.0
            t_previous = 0.0  # this event's time, on the restarted clock
            t_stop = limits.t_stop - accumulators[T_ORIGIN]
            events_to_rebase = limits.rebase_every
    counters[EVENTS] = events
    counters[COLLISIONS] = collisions
    counters[WALL_CONTACTS] = wall_contacts
    counters[SHELL_EXITS] = shell_exits
    counters[STALE_EVENTS] = stale_events
    accumulators[T_NOW] = t_now
    accumulators[DISSIPATED_DISKS] = dissipated_disks
    accumulators[DISSIPATED_WALLS] = dissipated_walls
    accumulators[VIRIAL] = virial_sum
    accumulators[WALL_WORK] = wall_work
    tallies.stall_watch[0] = t_previous
    tallies.stall_watch[1] = stalled
    return status, culprit


#: :func:`run_events` without numba's cache, for arguments of types defined outside sim (a
#: kind of system event written by a user, :func:`sim.engine.compilation.cacheable`)
run_events_uncached = njit(_nrt=False, error_model="numpy")(run_events.py_func)


@njit(cache=True)
def state_at(t, table, box, gravity):
    """Positions and velocities of all disks at time t (relative clock), without changing
    the state.

    Returns (position float64[n, 2] wrapped into the periodic box, velocity float64[n, 2]).
    """
    n = table.shape[0]
    position = np.empty((n, 2))
    velocity = np.empty((n, 2))
    for i in range(n):
        dt = t - table[i, T_OWN]
        for axis in range(2):
            position[i, axis] = fold(box, position_at(i, axis, dt, table, gravity), axis)
            velocity[i, axis] = velocity_of(i, axis, dt, table, gravity)
    return position, velocity
