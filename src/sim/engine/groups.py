"""The arguments of the compiled loop, in named groups.

:func:`sim.engine.loop.run_events` takes seven tuples: what it reads and writes of the disks,
the schedule of their events, the neighbour lists and cells, the box, the effects
(:class:`sim.effects.Effects`), the running tallies and the limits of one call; and, one by
one, the values of the parts a scene may replace (:class:`Parts`) and whether it looks
ahead (True, or None: a variant of the loop without the look-ahead's code). numba
passes a tuple's fields as separate arguments, so grouping costs nothing; fields are read by
name, and a field that is a number where it could be an array (a mass every disk shares, one
list capacity for all) compiles a variant that never loads the array
(:func:`sim.engine.parameters.per_disk`).
"""

from typing import NamedTuple

import numpy as np


class Disks(NamedTuple):
    """Per-disk state (engine order; :mod:`sim.engine.state`)."""
    table: np.ndarray  # float64[n, DISK_COLUMNS], columns in sim.engine.kinematics
    delta: object  # float64[n] shell radii, or the one every disk shares
    mass: object  # float64[n], or the one every disk shares
    species: object  # int32[n], or the one every disk shares
    stamp: np.ndarray  # int32[n] staleness stamps (sim.engine.stamps)
    counted: np.ndarray  # int32[n] the stamp at which contacts was last counted
    contacts: np.ndarray  # int64[n] contacts in full, updated at every rebase
    t_last: np.ndarray  # float64[n] time of the last contact (collapse watch, TC)
    streak: np.ndarray  # int32[n] consecutive fast dissipative contacts


class Schedule(NamedTuple):
    """Each disk's next event and the queue that orders them (:mod:`sim.engine.queue`), and
    the slot of the system event (:mod:`sim.engine.system`)."""
    event_time: np.ndarray  # float64[n], relative clock
    event_partner: np.ndarray  # int32[n]: a disk, or the code of a kind (sim.engine.codes)
    event_stamp: np.ndarray  # int32[n]: the partner's stamp at prediction
    heap: np.ndarray
    links: np.ndarray
    list_head: np.ndarray
    calendar: np.ndarray
    block_rate: np.ndarray
    system_time: np.ndarray  # float64[1] the next system event, relative clock
    pair_event: object  # int32[n] the pair event's name (sim.engine.pairs), or None


class Neighbours(NamedTuple):
    """Neighbour lists and cells (:mod:`sim.engine.neighbours`)."""
    nb_start: object  # int32[n] list starts, or the capacity every list shares
    nb_cap: object  # int32[n] list capacities, or the capacity every list shares
    nb_count: np.ndarray  # int32[n]
    nb: np.ndarray  # int32[Σ capacity]
    cell_head: np.ndarray
    cell_next: np.ndarray
    cell_prev: np.ndarray
    cell_of: np.ndarray
    big: np.ndarray  # int32[n_big] disks kept out of the cells
    reach: object  # float64[n] each disk's reach a_i, or None: the radii
    pair_state: object  # int32[Σ capacity] each entry's pair state, or None: no state


class Box(NamedTuple):
    """The box and its cells (:mod:`sim.engine.box`)."""
    geometry: np.ndarray  # float64[GEOMETRY_SIZE]
    grid: np.ndarray  # int64[GRID_SIZE]


class Parts(NamedTuple):
    """The parts of the dynamics a scene may replace, by kind, each None for none (or the
    default): a value of a kind registered with its module, whose rules numba picks by the
    value's type. A kind may be defined outside sim, so no cached function but the loop takes
    these values (:func:`sim.engine.compilation.cacheable`); the loop takes them one by one
    (:func:`sim.engine.loop.run_events`)."""
    pair: object  # the pair interaction (sim.engine.pairs); None: hard disks
    system: object  # the system event (sim.engine.system)


class Tallies(NamedTuple):
    """What the loop counts and sums, carried from one call to the next."""
    counters: np.ndarray  # int64[N_COUNTERS] (sim.engine.loop)
    accumulators: np.ndarray  # float64[N_ACCUMULATORS] (sim.engine.loop)
    pair_collisions: np.ndarray  # int64[s, s] collisions per species pair (upper triangle)
    wall_impulse: np.ndarray  # float64[4] momentum given to each wall
    stall_watch: np.ndarray  # float64[2] time of the last event popped, length of the run


class Limits(NamedTuple):
    """Where one call stops, and the guards of the loop (see run_events)."""
    max_events: int
    max_contacts: int
    max_collisions: int
    t_stop: float  # absolute time
    dissipation_limit: float
    stall_dt: float
    rebase_every: int
