"""The compiled event loop: pop the earliest event, apply it, predict anew.

Each disk owns one scheduled event, the earliest of (Smallenburg, Eur. Phys. J. E 45, 22 (2022)):
  * a contact with a disk of its neighbour list (``partner ≥ 0``), valid while the partner's
    collision counter still equals the value recorded at prediction;
  * a contact with a wall (``partner = WALL_X_LOW … WALL_Y_HIGH``);
  * its exit from its neighbour shell (``partner = SHELL_EXIT``), which rebuilds its list.
Positions are advanced lazily: disk i is stored at ``position[i]`` at its own time
``t_disk[i]``. Every ``rebase_every`` events all disks are brought to the current time and the
clock restarts from zero (its origin kept in ``accumulators[T_ORIGIN]``), so long runs keep
full float64 precision. Stale events are re-predicted, never applied.

Optional effects arrive as arguments that are either ``None`` or a value; numba compiles one
loop per combination and removes the code of every effect that is ``None``:
``restitution`` float64[s, s] per species pair, ``wall_restitution`` float, ``tc`` float.

The loop returns ``(status, disk)``; errors are codes, raised as exceptions by the caller.
"""

import numpy as np
from numba import njit

from sim.collision_rules import collide_disks, reflect_from_wall
from sim.event_queue import reschedule
from sim.kinematics import (
    INF,
    minimum_image,
    pair_contact_time,
    shell_exit_time,
    wall_contact_time,
    wrap,
)
from sim.neighbours import rebuild_neighbours

# event partners other than a disk
NO_EVENT = -1
SHELL_EXIT = -2
WALL_X_LOW = -3  # wall codes: WALL_X_LOW - (2 * axis + side)
WALL_X_HIGH = -4
WALL_Y_LOW = -5
WALL_Y_HIGH = -6

# loop status
STATUS_EVENT_LIMIT = 1
STATUS_COLLISION_LIMIT = 2
STATUS_TIME_REACHED = 3
STATUS_ENERGY_REACHED = 4
STATUS_NO_EVENTS = 5
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
N_ACCUMULATORS = 5


@njit(cache=True, inline="always")
def advance(i, t, position, velocity, t_disk, geometry, grid):
    """Move disk i along its straight path to time t."""
    dt = t - t_disk[i]
    position[i, 0] = wrap(position[i, 0] + velocity[i, 0] * dt, geometry[0], grid[2] != 0)
    position[i, 1] = wrap(position[i, 1] + velocity[i, 1] * dt, geometry[1], grid[3] != 0)
    t_disk[i] = t


@njit(cache=True, inline="always")
def predict(i, t, position, velocity, t_disk, center, delta, radius, coll_count,
            event_time, event_partner, event_count, nb_start, nb_count, nb, geometry, grid):
    """Schedule the earliest event of disk i at time t (its position taken lazily)."""
    px = grid[2] != 0
    py = grid[3] != 0
    vx = velocity[i, 0]
    vy = velocity[i, 1]
    x = position[i, 0] + vx * (t - t_disk[i])
    y = position[i, 1] + vy * (t - t_disk[i])
    tau = shell_exit_time(minimum_image(x - center[i, 0], geometry[0], px),
                          minimum_image(y - center[i, 1], geometry[1], py), vx, vy, delta[i])
    partner = SHELL_EXIT
    if not px:
        tau_w, side = wall_contact_time(x, vx, radius[i], geometry[0])
        if tau_w < tau:
            tau = tau_w
            partner = WALL_X_LOW - side
    if not py:
        tau_w, side = wall_contact_time(y, vy, radius[i], geometry[1])
        if tau_w < tau:
            tau = tau_w
            partner = WALL_Y_LOW - side
    r_i = radius[i]
    start = nb_start[i]
    for k in range(start, start + nb_count[i]):
        j = nb[k]
        dt = t - t_disk[j]
        rx = minimum_image(x - position[j, 0] - velocity[j, 0] * dt, geometry[0], px)
        ry = minimum_image(y - position[j, 1] - velocity[j, 1] * dt, geometry[1], py)
        tau_ij = pair_contact_time(rx, ry, vx - velocity[j, 0], vy - velocity[j, 1],
                                   r_i + radius[j])
        if tau_ij < tau:
            tau = tau_ij
            partner = j
    if tau == INF:
        partner = NO_EVENT
    event_time[i] = t + tau
    event_partner[i] = partner
    if partner >= 0:
        event_count[i] = coll_count[partner]


@njit(cache=True, _nrt=False)
def rebase_clock(position, velocity, t_disk, t_last, event_time, geometry, grid, accumulators):
    """Bring every disk to the current time and restart the clock there (order-preserving)."""
    t0 = accumulators[T_NOW]
    for i in range(position.shape[0]):
        advance(i, t0, position, velocity, t_disk, geometry, grid)
        t_disk[i] = 0.0
        t_last[i] -= t0
        event_time[i] -= t0
    accumulators[T_ORIGIN] += t0
    accumulators[T_NOW] = 0.0


@njit(cache=True, _nrt=False)
def run_events(position, velocity, t_disk, center, delta, radius, mass, species,
               coll_count, t_last, streak, event_time, event_partner, event_count, heap, slot,
               nb_start, nb_cap, nb_count, nb, cell_head, cell_next, cell_prev, cell_of, big,
               geometry, grid, restitution, wall_restitution, tc,
               counters, accumulators, pair_collisions, wall_impulse,
               max_events, max_collisions, t_stop, dissipation_limit,
               collapse_dt, collapse_streak, rebase_every):
    """Process events in time order until a limit is met; see the module docstring.

    Limits: ``max_events`` and ``max_collisions`` are totals of ``counters``, ``t_stop`` is an
    absolute time (events after it stay scheduled), ``dissipation_limit`` the energy whose
    dissipation ends the run. Inelastic collapse: a disk with more than ``collapse_streak``
    consecutive dissipative contacts, each less than ``collapse_dt`` after its previous
    contact (contacts made elastic by the TC model break the streak). A stall — more than
    16 N + 1000 events in a row at one instant — ends the loop instead of hanging it.
    """
    dissipative = restitution is not None or wall_restitution is not None
    t_stop_rel = t_stop - accumulators[T_ORIGIN]
    t_previous = -INF
    stalled = 0
    stall_limit = 16 * position.shape[0] + 1000
    while True:
        if counters[EVENTS] >= max_events:
            return STATUS_EVENT_LIMIT, -1
        if counters[DISK_COLLISIONS] >= max_collisions:
            return STATUS_COLLISION_LIMIT, -1
        if accumulators[DISSIPATED_DISKS] + accumulators[DISSIPATED_WALLS] >= dissipation_limit:
            return STATUS_ENERGY_REACHED, -1
        i = heap[0]
        t = event_time[i]
        if t > t_stop_rel:
            return STATUS_TIME_REACHED, -1
        if t == INF:
            return STATUS_NO_EVENTS, -1
        if t == t_previous:
            stalled += 1
            if stalled > stall_limit:
                return STATUS_STALLED, i
        else:
            stalled = 0
            t_previous = t
        partner = event_partner[i]
        if partner >= 0:
            j = partner
            if coll_count[j] != event_count[i]:
                counters[STALE_EVENTS] += 1
                predict(i, t, position, velocity, t_disk, center, delta, radius, coll_count,
                        event_time, event_partner, event_count, nb_start, nb_count, nb,
                        geometry, grid)
                reschedule(heap, slot, event_time, i)
                continue
            advance(i, t, position, velocity, t_disk, geometry, grid)
            advance(j, t, position, velocity, t_disk, geometry, grid)
            rx = minimum_image(position[i, 0] - position[j, 0], geometry[0], grid[2] != 0)
            ry = minimum_image(position[i, 1] - position[j, 1], geometry[1], grid[3] != 0)
            xi = 1.0
            if restitution is not None:
                xi = restitution[species[i], species[j]]
                if tc is not None:
                    if t - t_last[i] < tc or t - t_last[j] < tc:
                        xi = 1.0
            lost, virial = collide_disks(i, j, rx, ry, xi, velocity, mass)
            accumulators[DISSIPATED_DISKS] += lost
            accumulators[VIRIAL] += virial
            s_i = species[i]
            s_j = species[j]
            if s_i <= s_j:
                pair_collisions[s_i, s_j] += 1
            else:
                pair_collisions[s_j, s_i] += 1
            coll_count[i] += 1
            coll_count[j] += 1
            counters[DISK_COLLISIONS] += 1
            counters[EVENTS] += 1
            if dissipative:
                for d in (i, j):
                    streak[d] = streak[d] + 1 if (xi < 1.0 and t - t_last[d] < collapse_dt) else 0
                    t_last[d] = t
                if streak[i] > collapse_streak:
                    return STATUS_COLLAPSE, i
                if streak[j] > collapse_streak:
                    return STATUS_COLLAPSE, j
            predict(i, t, position, velocity, t_disk, center, delta, radius, coll_count,
                    event_time, event_partner, event_count, nb_start, nb_count, nb,
                    geometry, grid)
            reschedule(heap, slot, event_time, i)
            predict(j, t, position, velocity, t_disk, center, delta, radius, coll_count,
                    event_time, event_partner, event_count, nb_start, nb_count, nb,
                    geometry, grid)
            reschedule(heap, slot, event_time, j)
        elif partner == SHELL_EXIT:
            advance(i, t, position, velocity, t_disk, geometry, grid)
            full = rebuild_neighbours(i, position, center, delta, radius, nb_start, nb_cap,
                                      nb_count, nb, cell_head, cell_next, cell_prev, cell_of,
                                      big, geometry, grid)
            if full >= 0:
                return STATUS_LIST_FULL, full
            counters[SHELL_EXITS] += 1
            counters[EVENTS] += 1
            predict(i, t, position, velocity, t_disk, center, delta, radius, coll_count,
                    event_time, event_partner, event_count, nb_start, nb_count, nb,
                    geometry, grid)
            reschedule(heap, slot, event_time, i)
        else:
            wall = WALL_X_LOW - partner
            axis = wall >> 1
            advance(i, t, position, velocity, t_disk, geometry, grid)
            lo = radius[i]
            hi = geometry[axis] - radius[i]
            if position[i, axis] < lo:
                position[i, axis] = lo
            elif position[i, axis] > hi:
                position[i, axis] = hi
            xi_w = 1.0
            if wall_restitution is not None:
                xi_w = wall_restitution
                if tc is not None:
                    if t - t_last[i] < tc:
                        xi_w = 1.0
            lost, impulse = reflect_from_wall(i, axis, xi_w, velocity, mass)
            accumulators[DISSIPATED_WALLS] += lost
            wall_impulse[wall] += impulse
            coll_count[i] += 1
            counters[WALL_COLLISIONS] += 1
            counters[EVENTS] += 1
            if dissipative:
                streak[i] = streak[i] + 1 if (xi_w < 1.0 and t - t_last[i] < collapse_dt) else 0
                t_last[i] = t
                if streak[i] > collapse_streak:
                    return STATUS_COLLAPSE, i
            predict(i, t, position, velocity, t_disk, center, delta, radius, coll_count,
                    event_time, event_partner, event_count, nb_start, nb_count, nb,
                    geometry, grid)
            reschedule(heap, slot, event_time, i)
        accumulators[T_NOW] = t
        if counters[EVENTS] % rebase_every == 0:
            rebase_clock(position, velocity, t_disk, t_last, event_time, geometry, grid,
                         accumulators)
            t_stop_rel = t_stop - accumulators[T_ORIGIN]


@njit(cache=True, _nrt=False)
def predict_all(t, position, velocity, t_disk, center, delta, radius, coll_count,
                event_time, event_partner, event_count, nb_start, nb_count, nb, geometry, grid):
    """Schedule the first event of every disk (all disks at time t)."""
    for i in range(position.shape[0]):
        predict(i, t, position, velocity, t_disk, center, delta, radius, coll_count,
                event_time, event_partner, event_count, nb_start, nb_count, nb, geometry, grid)


@njit(cache=True)
def positions_at(t, position, velocity, t_disk, geometry, grid):
    """Positions of all disks at time t (relative clock), without changing the state.

    Returns float64[n, 2] wrapped into the periodic box.
    """
    n = position.shape[0]
    out = np.empty((n, 2))
    for i in range(n):
        dt = t - t_disk[i]
        out[i, 0] = wrap(position[i, 0] + velocity[i, 0] * dt, geometry[0], grid[2] != 0)
        out[i, 1] = wrap(position[i, 1] + velocity[i, 1] * dt, geometry[1], grid[3] != 0)
    return out


@njit(cache=True)
def kinetic_energy_by_species(velocity, mass, species, n_species):
    """Σ m v²/2 per species: float64[n_species]."""
    energy = np.zeros(n_species)
    for i in range(velocity.shape[0]):
        energy[species[i]] += 0.5 * mass[i] * (velocity[i, 0] ** 2 + velocity[i, 1] ** 2)
    return energy
