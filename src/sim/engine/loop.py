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
Positions are advanced lazily: disk i is stored at ``disks[i, X:Y+1]`` at its own time
``disks[i, T_OWN]`` (disk table columns in :mod:`sim.engine.kinematics`). Every ``rebase_every``
events all disks are brought to the current time and the clock restarts from zero (its
origin kept in ``accumulators[T_ORIGIN]``), so long runs keep full float64 precision. Stale
events are re-predicted, never applied. At large N the loop waits on memory: it asks the CPU
to prefetch the partner's data and that of the next disks in the queue, and for states larger
than the caches several events ahead (:func:`prefetch_upcoming`, :mod:`sim.engine.prefetch`).

Optional effects arrive as arguments that are either ``None`` or a value; numba compiles one
loop per combination and removes the code of every effect that is ``None``:
``restitution`` float64[s, s] per species pair, ``wall_restitution`` float, ``tc`` float;
``gravity`` float64[2] (:mod:`sim.effects.gravity`, :mod:`sim.engine.flight`); wall ``motion``
float64[4, 3] and wall ``temperature`` float64[4] (:mod:`sim.effects.walls`); winding counts
``images`` int32[n, 2] (:mod:`sim.engine.flight`); ``virial_tensor`` float64[3] and ``event_log``
float64[capacity, 6] with ``log_fill`` int64[1] (:mod:`sim.effects.recorders`).
Likewise ``mass``, ``species`` and ``delta`` are arrays only when the disks differ in them, and
otherwise one number (:func:`sim.engine.parameters.per_disk`).

The loop returns ``(status, disk)``; errors are codes, raised as exceptions by the caller.
"""

import math

import numpy as np
from numba import njit

from sim.effects.gravity import shell_exit
from sim.effects.recorders import add_virial_tensor, log_contact
from sim.effects.walls import contact_key, hit_wall, predict_wall_contact
from sim.engine.contact import collide_disks
from sim.engine.flight import displacement, fly, position_at, velocity_at
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
EVENTS = 0  # applied events: disk and wall contacts and shell exits
DISK_COLLISIONS = 1
WALL_COLLISIONS = 2
SHELL_EXITS = 3
STALE_EVENTS = 4
N_COUNTERS = 5

# accumulators: float64[N_ACCUMULATORS]
T_ORIGIN = 0  # absolute time of the clock's zero
T_NOW = 1  # time of the last event, relative to T_ORIGIN
DISSIPATED_DISKS = 2
DISSIPATED_WALLS = 3
VIRIAL = 4  # Σ r_ij·Δp_i over disk contacts
WALL_WORK = 5  # work done by moving and thermal walls on the disks
N_ACCUMULATORS = 6


@njit(cache=True, inline="always")
def predict(i, t, disks, delta, coll_count, event_time, nb_start, nb_count, nb, geometry, grid,
            gravity, motion, t_origin):
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
    px = grid[2] != 0
    py = grid[3] != 0
    x = disks[i, X]
    y = disks[i, Y]
    vx = disks[i, VX]
    vy = disks[i, VY]
    r_i = disks[i, RADIUS]
    tau = shell_exit(minimum_image(x - disks[i, CX], geometry[0], px),
                     minimum_image(y - disks[i, CY], geometry[1], py), vx, vy,
                     per_disk(delta, i), gravity)
    partner = SHELL_EXIT
    for axis in range(2):
        if grid[2 + axis] == 0:
            tau_w, side = predict_wall_contact(axis, t_origin + t, disks[i, X + axis],
                                               disks[i, VX + axis], r_i, geometry, gravity,
                                               motion, tau)
            if tau_w < tau:
                tau = tau_w
                # a search near a vibrating wall that stopped short: predict again from there
                partner = WALL_X_LOW - 2 * axis - side if side >= 0 else SHELL_EXIT
    start = list_start(nb_start, i)
    for k in range(start, start + nb_count[i]):
        j = nb[k]
        dt = t - disks[j, T_OWN]
        vx_j = velocity_at(j, 0, dt, disks, gravity)
        vy_j = velocity_at(j, 1, dt, disks, gravity)
        rx = minimum_image(x - disks[j, X] - displacement(j, 0, dt, disks, gravity),
                           geometry[0], px)
        ry = minimum_image(y - disks[j, Y] - displacement(j, 1, dt, disks, gravity),
                           geometry[1], py)
        vx_ij = vx - vx_j
        vy_ij = vy - vy_j
        sigma = r_i + disks[j, RADIUS]
        if may_touch_before(rx, ry, vx_ij, vy_ij, sigma, tau):
            tau_ij = pair_contact_time(rx, ry, vx_ij, vy_ij, sigma)
            if tau_ij < tau and t + tau_ij <= event_time[j]:
                tau = tau_ij
                partner = j
    if tau == INF:
        partner = NO_EVENT
    return t + tau, partner, coll_count[partner] if partner >= 0 else np.int32(0)


@njit(cache=True, inline="always")
def set_event(i, when, partner, partner_count, event_time, event_partner, event_count):
    """Record the event :func:`predict` found for disk i; filing it in the queue
    (:func:`sim.engine.queue.reschedule`) comes after."""
    event_time[i] = when
    event_partner[i] = partner
    if partner >= 0:
        event_count[i] = partner_count


@njit(cache=True, inline="always")
def prefetch_upcoming(partner, lookahead, walker, walker_block, disks, delta, coll_count,
                      event_time, event_partner, event_count, heap, links, list_head, calendar,
                      nb_start, nb_count, nb, cell_head, cell_next, cell_prev, cell_of, geometry,
                      grid):
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
    in cache (hence :data:`sim.engine.core.LOOKAHEAD_MIN_DISKS`). The hints for the walked disks'
    rows, partners and lists, with blocks of 8 mean event times instead of 4
    (:data:`sim.engine.queue.BLOCK_EVENTS`), against neither: 1.07, 1.12 and 1.11 at N = 1e5
    (quartiles of rounds 0.98–1.17, 1.04–1.22, 1.05–1.17), 1.05 at 1e6 (1.02–1.12). The
    hints for the neighbours' collision counts, the list lengths and a shell exit's cell links
    and edited lists, with the loop's :func:`sim.engine.queue.prefetch_bucket`, against none of
    them (on a day a miss took 200 ns): 1.135 at N = 1e5 (1.03–1.20), 1.26 at φ = 0.1, 1.20
    at 1e6 (1.13–1.33).
    """
    if partner >= 0:
        prefetch(disks, partner)
        prefetch(coll_count, partner)
        prefetch(links, partner)
        start = list_start(nb_start, partner)
        prefetch(nb, start)
        if lookahead:
            for k in range(start, start + nb_count[partner]):
                prefetch(disks, nb[k])
                prefetch(coll_count, nb[k])
    size = calendar[HEAP_SIZE]
    for slot in range(1, min(4 if lookahead else 3, size)):
        c = heap[slot]
        prefetch(disks, c)
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
            prefetch(disks, nb[k])
            prefetch(coll_count, nb[k])
            if partner_c == SHELL_EXIT:
                prefetch(nb, list_start(nb_start, nb[k]))
                prefetch(nb_count, nb[k])
        if partner_c >= 0:
            prefetch(disks, partner_c)
            prefetch(nb, list_start(nb_start, partner_c))
            prefetch(nb_count, partner_c)
            prefetch(coll_count, partner_c)
            prefetch(event_count, partner_c)
        elif partner_c == SHELL_EXIT:
            prefetch(cell_of, c)
            prefetch(cell_prev, c)
            cx, cy = shell_centre(c, disks, delta, geometry, grid)
            prefetch_cells(cx, cy, slot == 1, disks, cell_head, cell_next, geometry, grid)
    walker, walker_block = prefetch_next_block(walker, walker_block, links, list_head,
                                               calendar, event_time)
    if walker >= 0:
        prefetch(disks, walker)
        prefetch(event_partner, walker)
        prefetch(nb, list_start(nb_start, walker))
        prefetch(nb_count, walker)
    return walker, walker_block


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
def rebase_clock(disks, coll_count, contacts, t_last, event_time, heap, links, list_head,
                 calendar, block_rate, geometry, grid, gravity, images, accumulators):
    """Bring every disk to the current time and restart the clock there (order-preserving);
    the event queue is rebuilt for the shifted times, and the contact counts are updated."""
    count_contacts(coll_count, contacts)
    t0 = accumulators[T_NOW]
    for i in range(disks.shape[0]):
        fly(i, t0, disks, geometry, grid, gravity, images)
        disks[i, T_OWN] = 0.0
        t_last[i] -= t0
        event_time[i] -= t0
    accumulators[T_ORIGIN] += t0
    accumulators[T_NOW] = 0.0
    build_queue(heap, links, list_head, calendar, block_rate, event_time, 0.0)


@njit(cache=True, _nrt=False, error_model="numpy")
def run_events(disks, delta, mass, species, coll_count, contacts, t_last, streak, event_time,
               event_partner, event_count, heap, links, list_head, calendar, block_rate,
               nb_start, nb_cap, nb_count, nb, cell_head, cell_next, cell_prev, cell_of, big,
               geometry, grid, restitution, wall_restitution, tc, gravity, motion, temperature,
               seed, images, virial_tensor, event_log, log_fill,
               counters, accumulators, pair_collisions, wall_impulse,
               max_events, max_contacts, max_collisions, t_stop, dissipation_limit,
               collapse_dt, collapse_streak, stall_dt, stall_watch, rebase_every, lookahead):
    """Process events in time order until a limit is met; see the module docstring.

    Limits: ``max_events`` (applied events, shell exits included: the chunk size),
    ``max_contacts`` (disk and wall contacts) and ``max_collisions`` (disk contacts) are
    totals of ``counters``, ``t_stop`` is an
    absolute time (events after it stay scheduled), ``dissipation_limit`` the energy whose
    dissipation ends the run. Inelastic collapse: a disk with more than ``collapse_streak``
    consecutive dissipative contacts, each less than ``collapse_dt`` after its previous
    contact (contacts made elastic by the TC model break the streak). A stall — more than
    16 N + 1000 events in a row, each at most ``stall_dt`` after the one before (a time of
    float64 resolution, :data:`sim.engine.core.STALL_RESOLUTION`) — ends the loop instead of
    hanging it; ``stall_watch`` float64[2] holds the time of the last event popped (relative
    clock) and the length of that run, carried from one call to the next.

    ``lookahead``: prefetch several events ahead, and the candidates of a shell exit's cell
    scan, for states larger than the caches (:func:`prefetch_upcoming`,
    :func:`sim.engine.neighbours._prefetch_candidates`).

    Counters and accumulators live in local variables (registers) during the loop and are
    written back to ``counters`` and ``accumulators`` when it stops.
    """
    dissipative = restitution is not None or wall_restitution is not None
    events = counters[EVENTS]
    disk_collisions = counters[DISK_COLLISIONS]
    wall_collisions = counters[WALL_COLLISIONS]
    shell_exits = counters[SHELL_EXITS]
    stale_events = counters[STALE_EVENTS]
    t_now = accumulators[T_NOW]
    dissipated_disks = accumulators[DISSIPATED_DISKS]
    dissipated_walls = accumulators[DISSIPATED_WALLS]
    virial_sum = accumulators[VIRIAL]
    wall_work = accumulators[WALL_WORK]
    log_full = False
    t_stop_rel = t_stop - accumulators[T_ORIGIN]
    events_to_rebase = rebase_every - events % rebase_every
    status = 0
    culprit = -1
    t_previous = stall_watch[0]
    stalled = np.int64(stall_watch[1])
    stall_limit = 16 * disks.shape[0] + 1000
    walker = -1  # the queue's look-ahead (prefetch_next_block)
    walker_block = -1
    while True:
        i = earliest(heap, links, list_head, calendar, block_rate, event_time)
        partner = event_partner[i]
        if partner != UNPREDICTED:  # a first prediction is made whatever the limits
            if events >= max_events:
                status = STATUS_EVENT_LIMIT
                break
            if disk_collisions >= max_collisions:
                status = STATUS_COLLISION_LIMIT
                break
            if disk_collisions + wall_collisions >= max_contacts:
                status = STATUS_CONTACT_LIMIT
                break
            if dissipated_disks + dissipated_walls >= dissipation_limit:
                status = STATUS_ENERGY_REACHED
                break
            if log_full:
                status = STATUS_LOG_FULL
                break
        t = event_time[i]
        if t > t_stop_rel:
            status = STATUS_TIME_REACHED
            break
        if t == INF:
            status = STATUS_NO_EVENTS
            break
        if t - t_previous <= stall_dt:
            stalled += 1
            if stalled > stall_limit:
                status = STATUS_STALLED
                culprit = i
                break
        else:
            stalled = 0
        t_previous = t
        walker, walker_block = prefetch_upcoming(
            partner, lookahead, walker, walker_block, disks, delta, coll_count, event_time,
            event_partner, event_count, heap, links, list_head, calendar, nb_start, nb_count, nb,
            cell_head, cell_next, cell_prev, cell_of, geometry, grid)
        fly(i, t, disks, geometry, grid, gravity, images)
        j = partner  # the second disk to re-predict, when it is a disk contact
        if partner >= 0 and coll_count[j] != event_count[i]:
            stale_events += 1
            j = NO_EVENT
        elif partner >= 0:
            fly(j, t, disks, geometry, grid, gravity, images)
            rx = minimum_image(disks[i, X] - disks[j, X], geometry[0], grid[2] != 0)
            ry = minimum_image(disks[i, Y] - disks[j, Y], geometry[1], grid[3] != 0)
            xi = 1.0
            if restitution is not None:
                xi = restitution[per_disk(species, i), per_disk(species, j)]
                if tc is not None:
                    if t - t_last[i] < tc or t - t_last[j] < tc:
                        xi = 1.0
            lost, virial = collide_disks(i, j, rx, ry, xi, disks, per_disk(mass, i),
                                         per_disk(mass, j))
            dissipated_disks += lost
            virial_sum += virial
            if virial_tensor is not None:
                add_virial_tensor(virial_tensor, rx, ry, virial)
            s_i = per_disk(species, i)
            s_j = per_disk(species, j)
            if s_i <= s_j:
                pair_collisions[s_i, s_j] += 1
            else:
                pair_collisions[s_j, s_i] += 1
            coll_count[i] += 1
            coll_count[j] += 1
            disk_collisions += 1
            events += 1
            if event_log is not None:
                log_full = log_contact(event_log, log_fill, accumulators[T_ORIGIN] + t, i, j,
                                       virial / math.sqrt(rx * rx + ry * ry), lost,
                                       disk_collisions + wall_collisions)
            if dissipative:
                for d in (i, j):
                    streak[d] = streak[d] + 1 if (xi < 1.0 and t - t_last[d] < collapse_dt) else 0
                    t_last[d] = t
                if streak[i] > collapse_streak or streak[j] > collapse_streak:
                    status = STATUS_COLLAPSE
                    culprit = i if streak[i] > collapse_streak else j
                    break
        elif partner == UNPREDICTED:
            pass  # nothing happens: the disk is only predicted below
        elif partner == SHELL_EXIT:
            full = rebuild_neighbours(i, disks, delta, nb_start, nb_cap, nb_count, nb,
                                      cell_head, cell_next, cell_prev, cell_of, big, geometry,
                                      grid, lookahead)
            if full >= 0:
                status = STATUS_LIST_FULL
                culprit = full
                break
            shell_exits += 1
            events += 1
        else:
            wall = WALL_X_LOW - partner
            xi_w = 1.0
            if wall_restitution is not None:
                xi_w = wall_restitution
                if tc is not None:
                    if t - t_last[i] < tc:
                        xi_w = 1.0
            key = np.uint64(0)
            if temperature is not None:
                key = contact_key(seed, wall_collisions)
            lost, impulse, work = hit_wall(i, wall, accumulators[T_ORIGIN] + t, xi_w, disks,
                                           per_disk(mass, i), geometry, motion, temperature, key,
                                           gravity, tc)
            dissipated_walls += lost
            wall_work += work
            wall_impulse[wall] += impulse
            coll_count[i] += 1
            wall_collisions += 1
            events += 1
            if event_log is not None:
                log_full = log_contact(event_log, log_fill, accumulators[T_ORIGIN] + t, i,
                                       -1 - wall, abs(impulse), lost,
                                       disk_collisions + wall_collisions)
            if dissipative:
                streak[i] = streak[i] + 1 if (xi_w < 1.0 and t - t_last[i] < collapse_dt) else 0
                t_last[i] = t
                if streak[i] > collapse_streak:
                    status = STATUS_COLLAPSE
                    culprit = i
                    break
        # One call site each for predict and reschedule: numba inlines them wherever they are
        # called, and with one copy instead of five the loop compiles about four times faster.
        # Both disks are predicted before either is filed, so that the bucket head a filing
        # reads is on its way while the second prediction runs (no prediction reads the
        # queue). The queue sees one event time change at a time, as a filing compares times:
        # the event of j is recorded only once i is filed.
        moved_disks = 1 if j < 0 else 2
        when, whom, whose_count = INF, NO_EVENT, np.int32(0)
        for k in range(moved_disks):
            when, whom, whose_count = predict(i if k == 0 else j, t, disks, delta, coll_count,
                                              event_time, nb_start, nb_count, nb, geometry,
                                              grid, gravity, motion, accumulators[T_ORIGIN])
            prefetch_bucket(list_head, calendar, block_rate, when)
            if k == 0:
                set_event(i, when, whom, whose_count, event_time, event_partner, event_count)
        for k in range(moved_disks):
            if k == 1:  # the prediction of j, the last one made
                set_event(j, when, whom, whose_count, event_time, event_partner, event_count)
            reschedule(heap, links, list_head, calendar, block_rate, event_time,
                       i if k == 0 else j)
        if (partner >= 0 and j < 0) or partner == UNPREDICTED:
            continue  # a stale event or a first prediction is no event: the clock stays
        t_now = t
        events_to_rebase -= 1
        if events_to_rebase == 0:
            accumulators[T_NOW] = t_now
            rebase_clock(disks, coll_count, contacts, t_last, event_time, heap, links,
                         list_head, calendar, block_rate, geometry, grid, gravity, images,
                         accumulators)
            t_now = 0.0
            t_previous = 0.0  # this event's time, on the restarted clock
            t_stop_rel = t_stop - accumulators[T_ORIGIN]
            events_to_rebase = rebase_every
    counters[EVENTS] = events
    counters[DISK_COLLISIONS] = disk_collisions
    counters[WALL_COLLISIONS] = wall_collisions
    counters[SHELL_EXITS] = shell_exits
    counters[STALE_EVENTS] = stale_events
    accumulators[T_NOW] = t_now
    accumulators[DISSIPATED_DISKS] = dissipated_disks
    accumulators[DISSIPATED_WALLS] = dissipated_walls
    accumulators[VIRIAL] = virial_sum
    accumulators[WALL_WORK] = wall_work
    stall_watch[0] = t_previous
    stall_watch[1] = stalled
    return status, culprit


@njit(cache=True)
def state_at(t, disks, geometry, grid, gravity):
    """Positions and velocities of all disks at time t (relative clock), without changing
    the state.

    Returns (position float64[n, 2] wrapped into the periodic box, velocity float64[n, 2]).
    """
    n = disks.shape[0]
    position = np.empty((n, 2))
    velocity = np.empty((n, 2))
    for i in range(n):
        dt = t - disks[i, T_OWN]
        for axis in range(2):
            position[i, axis] = wrap(position_at(i, axis, dt, disks, gravity), geometry[axis],
                                     grid[2 + axis] != 0)
            velocity[i, axis] = velocity_at(i, axis, dt, disks, gravity)
    return position, velocity
