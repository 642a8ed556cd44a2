"""The compiled event loop: pop the earliest event, apply it, predict anew.

Each disk owns one scheduled event, the earliest of (Smallenburg, Eur. Phys. J. E 45, 22 (2022)):
  * a contact with a disk of its neighbour list (``partner ≥ 0``), valid while the partner's
    collision counter still equals the value recorded at prediction, and scheduled only when
    it comes no later than the partner's own next event (:func:`predict`);
  * a contact with a wall (``partner = WALL_X_LOW … WALL_Y_HIGH``);
  * its exit from its neighbour shell (``partner = SHELL_EXIT``), which rebuilds its list;
  * at construction, its first prediction (``partner = UNPREDICTED``, at the current time):
    every disk is predicted through the loop's one inlined copy of :func:`predict`, which
    spares the compiler a second copy.
Positions are advanced lazily: disk i is stored at ``table[i, X:Y+1]`` at its own time
``table[i, T_OWN]`` (disk table columns in :mod:`sim.engine.kinematics`). Every
``rebase_every`` events all disks are brought to the current time and the clock restarts from
zero (its origin kept in ``accumulators[T_ORIGIN]``), so long runs keep full float64
precision. Stale events are re-predicted, never applied. At large N the loop waits on memory:
it asks the CPU to prefetch the partner's data and that of the next disks in the queue, and for
states larger than the caches several events ahead (:func:`prefetch_upcoming`,
:mod:`sim.engine.prefetch`).

Words: a *contact* is a disk touching a disk (a *collision*) or a wall (a *wall contact*); an
*event* is what the loop applies: a contact or a shell exit. Stale events and first
predictions are popped from the queue but are no events.

The loop takes its arguments in named groups (:mod:`sim.engine.groups`); the effects a scene
uses arrive in :class:`sim.effects.Effects`, each None when off, and act through the rules of
their modules (:mod:`sim.effects.rules`): numba compiles one loop per combination and removes
the code of every effect that is off. It returns ``(status, disk)``; errors are codes, raised
as exceptions by the caller.
"""

import math

import numpy as np
from numba import njit

from sim.effects.event_log import log_contact
from sim.effects.gravity import shell_exit
from sim.effects.pressure_tensor import add_virial_tensor
from sim.effects.restitution import collapsing, disk_restitution, wall_restitution_of
from sim.effects.tc import tc_restitution
from sim.effects.thermal_walls import contact_key
from sim.effects.walls import hit_wall, predict_wall_contact
from sim.engine.box import PERIODIC, SIDE
from sim.engine.contact import collide_disks
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
    may_touch_before,
    minimum_image,
    pair_contact_time,
    wrap,
)
from sim.engine.neighbours import list_start, prefetch_cells, rebuild_neighbours, shell_centre
from sim.engine.parameters import per_disk
from sim.engine.prefetch import prefetch
from sim.engine.queue import (
    HEAP_SIZE,
    build_queue,
    earliest,
    prefetch_bucket,
    prefetch_next_block,
    reschedule,
)

# event partners other than a disk
NO_EVENT = -1
SHELL_EXIT = -2
WALL_X_LOW = -3  # wall codes: WALL_X_LOW - (2 * axis + side)
WALL_X_HIGH = -4
WALL_Y_LOW = -5
WALL_Y_HIGH = -6
UNPREDICTED = -7  # a disk awaiting its first prediction, queued at the current time

# loop status
STATUS_EVENT_LIMIT = 1
STATUS_COLLISION_LIMIT = 2
STATUS_TIME_REACHED = 3
STATUS_ENERGY_REACHED = 4
STATUS_NO_EVENTS = 5
STATUS_CONTACT_LIMIT = 6
STATUS_LOG_FULL = 7
STATUS_COLLAPSE = -1
STATUS_LIST_FULL = -2
STATUS_STALLED = -3

# counters: int64[N_COUNTERS]
EVENTS = 0  # applied events: contacts and shell exits
COLLISIONS = 1  # disk–disk contacts
WALL_CONTACTS = 2
SHELL_EXITS = 3
STALE_EVENTS = 4  # popped, found stale, dropped
N_COUNTERS = 5

# accumulators: float64[N_ACCUMULATORS]
T_ORIGIN = 0  # absolute time of the clock's zero
T_NOW = 1  # time of the last event, relative to T_ORIGIN
DISSIPATED_DISKS = 2
DISSIPATED_WALLS = 3
VIRIAL = 4  # Σ r_ij·Δp_i over collisions
WALL_WORK = 5  # work done by moving and thermal walls on the disks
N_ACCUMULATORS = 6


@njit(cache=True, inline="always")
def predict(i, t, disks, schedule, neighbours, box, effects, t_origin):
    """The earliest event of disk i, which must be at time t already (``t_origin``: the
    absolute time of the clock's zero, which moving walls need): its time, its partner (a
    disk, a wall code, ``SHELL_EXIT`` or ``NO_EVENT``) and the partner's collision count when
    the partner is a disk (else 0), for :func:`set_event`.

    A contact with j at time t_ij is left out when j's own next event comes first
    (``event_time[j] < t_ij``): j is predicted again at that event, whatever it is, and then
    finds the contact itself if it still comes. Of the two, the one predicted last before
    the contact sees the other's event no earlier and schedules it; a contact due now
    (τ = 0, round-off overlaps included) is never left out, as no event is due before now.
    Without the rule the contact would mostly go stale, as j's earlier event is mostly a
    collision: stale events per collision 0.20 → 0.08 at φ = 0.5 (0.17 → 0.05 at 0.1,
    0.32 → 0.14 at 0.7), and ``benchmarks/compare_builds.py`` 1.047 at N = 1e4, φ = 0.5,
    1.034 at 0.1, 1.032 at 0.7, 1.050 at N = 1e5.
    """
    table = disks.table
    geometry, grid = box
    gravity = effects.gravity
    px = grid[PERIODIC] != 0
    py = grid[PERIODIC + 1] != 0
    x = table[i, X]
    y = table[i, Y]
    vx = table[i, VX]
    vy = table[i, VY]
    r_i = table[i, RADIUS]
    tau = shell_exit(gravity, minimum_image(x - table[i, CX], geometry[SIDE], px),
                     minimum_image(y - table[i, CY], geometry[SIDE + 1], py), vx, vy,
                     per_disk(disks.delta, i))
    partner = SHELL_EXIT
    for axis in range(2):
        if grid[PERIODIC + axis] == 0:
            tau_w, side = predict_wall_contact(gravity, effects.wall_motion, axis, t_origin + t,
                                               table[i, X + axis], table[i, VX + axis], r_i,
                                               geometry, tau)
            if tau_w < tau:
                tau = tau_w
                # a search near a vibrating wall that stopped short: predict again from there
                partner = WALL_X_LOW - 2 * axis - side if side >= 0 else SHELL_EXIT
    nb = neighbours.nb
    event_time = schedule.event_time
    start = list_start(neighbours.nb_start, i)
    for k in range(start, start + neighbours.nb_count[i]):
        j = nb[k]
        dt = t - table[j, T_OWN]
        vx_j = velocity_of(j, 0, dt, table, gravity)
        vy_j = velocity_of(j, 1, dt, table, gravity)
        rx = minimum_image(x - table[j, X] - flown(j, 0, dt, table, gravity), geometry[SIDE], px)
        ry = minimum_image(y - table[j, Y] - flown(j, 1, dt, table, gravity), geometry[SIDE + 1],
                           py)
        vx_ij = vx - vx_j
        vy_ij = vy - vy_j
        sigma = r_i + table[j, RADIUS]
        if may_touch_before(rx, ry, vx_ij, vy_ij, sigma, tau):
            tau_ij = pair_contact_time(rx, ry, vx_ij, vy_ij, sigma)
            if tau_ij < tau and t + tau_ij <= event_time[j]:
                tau = tau_ij
                partner = j
    if tau == INF:
        partner = NO_EVENT
    return t + tau, partner, disks.coll_count[partner] if partner >= 0 else np.int32(0)


@njit(cache=True, inline="always")
def set_event(i, when, partner, partner_count, schedule):
    """Record the event :func:`predict` found for disk i; filing it in the queue
    (:func:`sim.engine.queue.reschedule`) comes after."""
    schedule.event_time[i] = when
    schedule.event_partner[i] = partner
    if partner >= 0:
        schedule.event_count[i] = partner_count


@njit(cache=True, inline="always")
def prefetch_upcoming(partner, lookahead, walker, walker_block, disks, schedule, neighbours,
                      box):
    """Ask the CPU to start loading what the next events will read while this one is worked on
    (hints only: no result changes). A disk's data is hinted in stages, one event apart, each
    stage reading what the one before brought in: the partner of this event and the disks of
    the next two in the heap (heap slots 1, 2); with ``lookahead``, also the third, and for the
    next two the rows their predictions read (their neighbours' rows and collision counts),
    their partners' data, or, for a shell exit, the cells it scans, its own cell links and the
    lists and counts of its neighbours, which its rebuild edits; and the bucket that becomes
    the heap next
    (:func:`sim.engine.queue.prefetch_next_block`: one of its disks per event, whose row,
    partner and list are hinted too, for the first events of the next block would otherwise
    reach the heap top with nothing fetched). Returns the bucket walk's state.

    Against the hints without ``lookahead`` (``benchmarks/compare_builds.py``, φ = 0.5): 1.49
    at N = 1e5, 1.39 at 1e6, 1.11 at 5e4, but 0.94 at 3e4, where the state still sits mostly
    in cache (hence :data:`sim.engine.sizing.LOOKAHEAD_MIN_DISKS`). The hints for the walked disks'
    rows, partners and lists, with blocks of 8 mean event times instead of 4
    (:data:`sim.engine.queue.BLOCK_EVENTS`), against neither: 1.07, 1.12 and 1.11 at N = 1e5
    (quartiles of rounds 0.98–1.17, 1.04–1.22, 1.05–1.17), 1.05 at 1e6 (1.02–1.12). The
    hints for the neighbours' collision counts, the list lengths and a shell exit's cell links
    and edited lists, with the loop's :func:`sim.engine.queue.prefetch_bucket`, against none of
    them (on a day a miss took 200 ns): 1.135 at N = 1e5 (1.03–1.20), 1.26 at φ = 0.1, 1.20
    at 1e6 (1.13–1.33).
    """
    table, coll_count = disks.table, disks.coll_count
    event_partner, event_count, heap, links = (schedule.event_partner, schedule.event_count,
                                               schedule.heap, schedule.links)
    nb_start, nb_count, nb = neighbours.nb_start, neighbours.nb_count, neighbours.nb
    if partner >= 0:
        prefetch(table, partner)
        prefetch(coll_count, partner)
        prefetch(links, partner)
        start = list_start(nb_start, partner)
        prefetch(nb, start)
        if lookahead:
            for k in range(start, start + nb_count[partner]):
                prefetch(table, nb[k])
                prefetch(coll_count, nb[k])
    size = schedule.calendar[HEAP_SIZE]
    for slot in range(1, min(4 if lookahead else 3, size)):
        c = heap[slot]
        prefetch(table, c)
        prefetch(event_partner, c)
        prefetch(nb, list_start(nb_start, c))
        if lookahead:
            prefetch(event_count, c)
            prefetch(coll_count, c)
            prefetch(links, c)
            prefetch(nb_count, c)
    if not lookahead:
        return walker, walker_block
    for slot in range(1, min(3, size)):
        c = heap[slot]
        partner_c = event_partner[c]
        start = list_start(nb_start, c)
        for k in range(start, start + nb_count[c]):
            prefetch(table, nb[k])
            prefetch(coll_count, nb[k])
            if partner_c == SHELL_EXIT:
                prefetch(nb, list_start(nb_start, nb[k]))
                prefetch(nb_count, nb[k])
        if partner_c >= 0:
            prefetch(table, partner_c)
            prefetch(nb, list_start(nb_start, partner_c))
            prefetch(nb_count, partner_c)
            prefetch(coll_count, partner_c)
            prefetch(event_count, partner_c)
        elif partner_c == SHELL_EXIT:
            prefetch(neighbours.cell_of, c)
            prefetch(neighbours.cell_prev, c)
            cx, cy = shell_centre(c, table, disks.delta, box.geometry, box.grid)
            prefetch_cells(cx, cy, slot == 1, table, neighbours.cell_head, neighbours.cell_next,
                           box.geometry, box.grid)
    walker, walker_block = prefetch_next_block(walker, walker_block, links, schedule.list_head,
                                               schedule.calendar, schedule.event_time)
    if walker >= 0:
        prefetch(table, walker)
        prefetch(event_partner, walker)
        prefetch(nb, list_start(nb_start, walker))
        prefetch(nb_count, walker)
    return walker, walker_block


@njit(cache=True, inline="always")
def collide(i, j, t, t_origin, disks, box, effects, tallies, contact):
    """The collision of disks i and j, both already flown to time t, as the ``contact``-th
    contact of the run: restitution (with the TC model), the impulse
    (:func:`sim.engine.contact.collide_disks`), what the recorders keep, the collapse watch.
    Returns (energy dissipated, r·Δp_i, log full, the disk found collapsing or −1)."""
    table, t_last = disks.table, disks.t_last
    geometry, grid = box
    rx = minimum_image(table[i, X] - table[j, X], geometry[SIDE], grid[PERIODIC] != 0)
    ry = minimum_image(table[i, Y] - table[j, Y], geometry[SIDE + 1], grid[PERIODIC + 1] != 0)
    xi = tc_restitution(effects.tc, disk_restitution(effects.restitution, disks.species, i, j),
                        t, t_last[i], t_last[j])
    lost, virial = collide_disks(i, j, rx, ry, xi, table, per_disk(disks.mass, i),
                                 per_disk(disks.mass, j))
    add_virial_tensor(effects.virial_tensor, rx, ry, virial)
    s_i = per_disk(disks.species, i)
    s_j = per_disk(disks.species, j)
    tallies.pair_collisions[min(s_i, s_j), max(s_i, s_j)] += 1
    disks.coll_count[i] += 1
    disks.coll_count[j] += 1
    log_full = log_contact(effects.event_log, t_origin + t, i, j,
                           virial / math.sqrt(rx * rx + ry * ry), lost, contact)
    collapsing_i = collapsing(effects.collapse, t_last, disks.streak, i, xi, t)
    collapsing_j = collapsing(effects.collapse, t_last, disks.streak, j, xi, t)
    culprit = i if collapsing_i else (j if collapsing_j else -1)
    return lost, virial, log_full, culprit


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
    lost, impulse, work = hit_wall(i, wall, t_origin + t, xi_w, disks.table,
                                   per_disk(disks.mass, i), box.geometry, effects.wall_motion,
                                   effects.wall_temperature, key, effects.gravity, effects.tc)
    tallies.wall_impulse[wall] += impulse
    disks.coll_count[i] += 1
    log_full = log_contact(effects.event_log, t_origin + t, i, -1 - wall, abs(impulse), lost,
                           contact)
    return lost, work, log_full, collapsing(effects.collapse, t_last, disks.streak, i, xi_w, t)


@njit(cache=True, inline="always")
def count_contacts(coll_count, contacts):
    """Bring the full contact counts ``contacts`` int64[n] up to date with the counters
    ``coll_count`` int32[n], which wrap at 2³²: correct while no disk makes 2³² contacts
    between two calls, and it is called at every clock rebase."""
    for i in range(coll_count.shape[0]):
        contacts[i] += (np.int64(coll_count[i]) - contacts[i]) & 0xFFFFFFFF


@njit(cache=True, _nrt=False, error_model="numpy")
def count_all_contacts(coll_count, contacts):
    """:func:`count_contacts`, called from Python."""
    count_contacts(coll_count, contacts)


@njit(cache=True, _nrt=False, error_model="numpy")
def rebase_clock(disks, schedule, box, effects, accumulators):
    """Bring every disk to the current time and restart the clock there (order-preserving);
    the event queue is rebuilt for the shifted times, and the contact counts are updated."""
    count_contacts(disks.coll_count, disks.contacts)
    t0 = accumulators[T_NOW]
    table = disks.table
    for i in range(table.shape[0]):
        fly(i, t0, table, box.geometry, box.grid, effects.gravity, effects.images)
        table[i, T_OWN] = 0.0
        disks.t_last[i] -= t0
        schedule.event_time[i] -= t0
    accumulators[T_ORIGIN] += t0
    accumulators[T_NOW] = 0.0
    build_queue(schedule.heap, schedule.links, schedule.list_head, schedule.calendar,
                schedule.block_rate, schedule.event_time, 0.0)


@njit(cache=True, inline="always")
def predict_and_file(i, j, t, disks, schedule, neighbours, box, effects, t_origin):
    """Predict the next event of disk i and, when j ≥ 0, of disk j, and file both.

    One call site each for predict and reschedule: numba inlines them wherever they are
    called, and with one copy instead of five the loop compiles about four times faster.
    Both disks are predicted before either is filed, so that the bucket head a filing reads
    is on its way while the second prediction runs (no prediction reads the queue). The queue
    sees one event time change at a time, as a filing compares times: the event of j is
    recorded only once i is filed."""
    s = schedule
    moved_disks = 1 if j < 0 else 2
    when, whom, whose_count = INF, NO_EVENT, np.int32(0)
    for k in range(moved_disks):
        when, whom, whose_count = predict(i if k == 0 else j, t, disks, schedule, neighbours,
                                          box, effects, t_origin)
        prefetch_bucket(s.list_head, s.calendar, s.block_rate, when)
        if k == 0:
            set_event(i, when, whom, whose_count, schedule)
    for k in range(moved_disks):
        if k == 1:  # the prediction of j, the last one made
            set_event(j, when, whom, whose_count, schedule)
        reschedule(s.heap, s.links, s.list_head, s.calendar, s.block_rate, s.event_time,
                   i if k == 0 else j)


@njit(cache=True, inline="always")
def limit_reached(limits, events, collisions, wall_contacts, dissipated, log_full):
    """The status of the first limit of ``limits`` the tallies have reached, else 0."""
    if events >= limits.max_events:
        return STATUS_EVENT_LIMIT
    if collisions >= limits.max_collisions:
        return STATUS_COLLISION_LIMIT
    if collisions + wall_contacts >= limits.max_contacts:
        return STATUS_CONTACT_LIMIT
    if dissipated >= limits.dissipation_limit:
        return STATUS_ENERGY_REACHED
    if log_full:
        return STATUS_LOG_FULL
    return 0


@njit(cache=True, _nrt=False, error_model="numpy")
def run_events(disks, schedule, neighbours, box, effects, tallies, limits):
    """Process events in time order until a limit is met; see the module docstring.

    Limits (:class:`sim.engine.groups.Limits`): ``max_events`` (events: the chunk size),
    ``max_contacts`` and ``max_collisions`` are totals of ``tallies.counters``; ``t_stop`` is
    an absolute time (events after it stay scheduled); ``dissipation_limit`` the energy whose
    dissipation ends the run. A stall — more than 16 N + 1000 events in a row, each at most
    ``stall_dt`` after the one before (a time of float64 resolution,
    :data:`sim.engine.sizing.STALL_RESOLUTION`) — ends the loop instead of hanging it;
    ``tallies.stall_watch`` holds the time of the last event popped (relative clock) and the
    length of that run, carried from one call to the next. ``lookahead``: prefetch several
    events ahead, and the candidates of a shell exit's cell scan, for states larger than the
    caches (:func:`prefetch_upcoming`, :func:`sim.engine.neighbours._prefetch_candidates`).

    Counters and accumulators live in local variables (registers) during the loop and are
    written back to ``tallies`` when it stops.
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
    status = 0
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
        if partner != UNPREDICTED:  # a first prediction is made whatever the limits
            status = limit_reached(limits, events, collisions, wall_contacts,
                                   dissipated_disks + dissipated_walls, log_full)
            if status != 0:
                break
        t = s.event_time[i]
        if t > t_stop:
            status = STATUS_TIME_REACHED
            break
        if t == INF:
            status = STATUS_NO_EVENTS
            break
        stalled = stalled + 1 if t - t_previous <= limits.stall_dt else 0
        if stalled > stall_limit:
            status = STATUS_STALLED
            culprit = i
            break
        t_previous = t
        walker, walker_block = prefetch_upcoming(partner, limits.lookahead, walker, walker_block,
                                                 disks, schedule, neighbours, box)
        t_origin = accumulators[T_ORIGIN]
        fly(i, t, disks.table, box.geometry, box.grid, effects.gravity, effects.images)
        j = NO_EVENT  # the second disk to re-predict, when it is a collision
        if partner >= 0 and disks.coll_count[partner] != s.event_count[i]:
            stale_events += 1
        elif partner >= 0:
            j = partner
            fly(j, t, disks.table, box.geometry, box.grid, effects.gravity, effects.images)
            collisions += 1
            events += 1
            lost, virial, log_full, culprit = collide(i, j, t, t_origin, disks, box, effects,
                                                      tallies, collisions + wall_contacts)
            dissipated_disks += lost
            virial_sum += virial
        elif partner == SHELL_EXIT:
            nbs = neighbours
            culprit = rebuild_neighbours(i, disks.table, disks.delta, nbs.nb_start, nbs.nb_cap,
                                         nbs.nb_count, nbs.nb, nbs.cell_head, nbs.cell_next,
                                         nbs.cell_prev, nbs.cell_of, nbs.big, box.geometry,
                                         box.grid, limits.lookahead)
            if culprit >= 0:
                status = STATUS_LIST_FULL
                break
            shell_exits += 1
            events += 1
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
        predict_and_file(i, j, t, disks, schedule, neighbours, box, effects, t_origin)
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


@njit(cache=True)
def state_at(t, table, geometry, grid, gravity):
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
            position[i, axis] = wrap(position_at(i, axis, dt, table, gravity),
                                     geometry[SIDE + axis], grid[PERIODIC + axis] != 0)
            velocity[i, axis] = velocity_of(i, axis, dt, table, gravity)
    return position, velocity
