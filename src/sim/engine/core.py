"""The engine as Python sees it: a state of arrays, and ``run`` with stop conditions.

Python builds the state, calls the compiled loop (:func:`sim.engine.loop.run_events`) in chunks
of events, checks the conditions that need Python (wall-clock budget, user predicates) between
chunks, and turns the loop's error codes into exceptions. No Python runs per event.

The per-disk state lives in :class:`sim.engine.state.DiskArrays`, in engine order: disks are
renumbered by grid cell so that neighbours in space are neighbours in memory, and renumbered
again every ``reorder_every`` events as they diffuse. Everything the user reads
(:meth:`Engine.positions`, :meth:`Engine.velocities`, ``radius``, ``mass``, ``species``, …) is
in the original order.
"""

import math

import numpy as np

from sim.effects import Effects, keyword_doc, loop_values
from sim.effects.walls import closing_time
from sim.engine import codes
from sim.engine.box import folded
from sim.engine.checkpoint import Checkpoints
from sim.engine.groups import Box, Disks, Neighbours
from sim.engine.inputs import (
    Boundary,
    box_size,
    check_disks,
    check_inside,
    check_scales,
    per_disk,
    periodic_pair,
    real_array,
    real_number,
    refused,
    species_input,
    whole_count,
)
from sim.engine.kinematics import DISK_COLUMNS, RADIUS, VX, VY, X, Y
from sim.engine.neighbours import build_all_neighbours, grow_lists, list_starts
from sim.engine.observables import Observables
from sim.engine.overlap import first_overlap
from sim.engine.pairs import RULES, initial_reaches, initial_states, keeps
from sim.engine.parameters import common_value
from sim.engine.queue import BLOCK_EVENTS, build_queue, empty_queue
from sim.engine.running import Running
from sim.engine.sizing import (
    BIG_RADIUS_RATIO,
    LIST_GROWTH,
    LOOKAHEAD_MIN_DISKS,
    MAX_BIG,
    REORDER_EVENTS_PER_DISK,
    REORDER_MIN_DISKS,
    STALL_RADII,
    cell_limit,
    first_event_time,
    grid_cells,
    packing_fraction_around_disks,
    periodic_room,
    shell_lead,
    shell_ratio,
    stall_interval,
)
from sim.engine.state import OPTIONAL_PER_DISK, DiskArrays
from sim.engine.system import HANDLERS


class Engine(Running, Observables, Checkpoints):
    """Event-driven hard disks in a rectangular box.

    Parameters
    ----------
    position, velocity : array (n, 2)
    radius, mass : array (n,) or scalar
    species : int array (n,), default all 0
    boundary : :class:`Boundary` (size two finite sides > 0; periodic a bool or a pair)
    shell : neighbour-shell diameter r_n/σ, finite, > 1 and at most 1 + L/R (L the longer
        box side, R the median radius: a shell reaching across the box; default from the
        packing fraction around the disks, :func:`packing_fraction_around_disks`)
    shell_lead : λ in [0, 1): a new shell is centred λ δ ahead of its disk along its
        velocity (:func:`sim.engine.neighbours.shell_centre`; default from the same packing
        fraction, :data:`LEAD_TABLE`); changes the cost, never the physics
    list_capacity : initial slots per neighbour list of an ordinary disk, whole from 1 to n
        (default from the expected number of neighbours); full lists grow on demand
    pair_interaction : a pair interaction (:mod:`sim.engine.pairs`): a value of a kind whose
        rules are registered (its events, and optionally their names, its reach and a state
        per pair); default None, hard disks
    system_event : a system event (:mod:`sim.engine.system`): a value of a kind whose
        handler is registered, applied to the whole system first at t = 0 and then at the
        times its handler returns; default None, none

    The effects' keywords (keyword-only; each effect's ``KEYWORDS``, :mod:`sim.effects`):

    """

    def __init__(self, position, velocity, radius, mass=1.0, species=None,
                 boundary=Boundary(), *, shell=None, list_capacity=None, shell_lead=None,
                 pair_interaction=None, system_event=None, **effects):
        position = real_array("Engine", "position", position)
        velocity = real_array("Engine", "velocity", velocity)
        n = position.shape[0] if position.ndim else 0
        if position.shape != (n, 2) or velocity.shape != (n, 2) or n == 0:
            raise ValueError(f"position and velocity must both be (n, 2) with n ≥ 1; got "
                             f"{position.shape} and {velocity.shape}")
        radius = per_disk("Engine", "radius", radius, n)
        mass = per_disk("Engine", "mass", mass, n)
        species = np.zeros(n, np.int32) if species is None else species_input(species, n)
        check_disks(position, velocity, radius, mass, species)
        box = box_size(boundary)
        periodic = np.array(periodic_pair("Boundary", "periodic", boundary.periodic))
        shell, shell_lead, list_capacity = _sizing_options(shell, shell_lead, list_capacity, n,
                                                          box, radius)
        self.boundary = boundary
        self.n = n
        self.n_species = int(species.max()) + 1
        self.box = box
        self.periodic = periodic
        given = position
        position = folded(position, box, periodic)
        check_inside(given, position, radius, box, periodic)

        with np.errstate(over="ignore"):  # inf for speeds that check_scales refuses below
            self.initial_energy = float(np.sum(0.5 * mass * np.sum(velocity**2, axis=1)))
        values, self.effect_keywords = loop_values(effects, {
            "n": n, "n_species": self.n_species, "box": box, "periodic": periodic,
            "radius": radius, "mass": mass, "initial_energy": self.initial_energy})
        disk_effects = {field: values.pop(field) for field in OPTIONAL_PER_DISK}
        effect_system = values.pop("system_event")
        effect_pair = values.pop("pair_interaction")
        for field, value in values.items():
            setattr(self, field, value)
        # the far edge of the disks, whose ulps bound those of their coordinates (a disk
        # crossing a periodic axis reappears near its far side)
        extent = max(float(box[axis]) if periodic[axis]
                     else float(np.max(position[:, axis] + radius)) for axis in range(2))
        check_scales(box, radius, mass, velocity, extent, self.gravity, self.wall_motion,
                      self.wall_temperature)
        overlap = first_overlap(position, radius, box, periodic)
        if overlap is not None:
            i, j, distance = overlap
            raise ValueError(f"disk {i} at {given[i].tolist()} overlaps disk {j} (distance "
                             f"{distance:.6g} < contact distance {radius[i] + radius[j]:.6g}): "
                             f"disks may touch but not overlap")
        self.closing_time = closing_time(self.wall_motion, box, periodic, float(radius.max()))

        for name, value, registry, register in (
                ("pair_interaction", pair_interaction, RULES, "sim.engine.pairs.rules"),
                ("system_event", system_event, HANDLERS, "sim.engine.system.handler")):
            if value is not None and type(value) not in registry:
                raise refused("Engine", name, value, f"None, or a value of a kind registered "
                              f"with {register} (a {type(value).__name__} is none)")
        if effect_system is not None:
            if system_event is not None:
                raise refused("Engine", "system_event", system_event, "None for growing disks, "
                              "whose rescaling of the velocities is the system event")
            system_event = effect_system
        if effect_pair is not None:
            if pair_interaction is not None:
                raise refused("Engine", "pair_interaction", pair_interaction, "None with a "
                              "stepped potential, which is the pair interaction")
            pair_interaction = effect_pair
        if self.growth is not None and pair_interaction is not None:
            raise refused("Engine", "pair_interaction", pair_interaction,
                          "None for growing disks: they grow hard cores")
        self.pair_interaction = pair_interaction
        self.system_event = system_event
        self.radius = radius
        self.mass = mass
        self.species = species
        self.counters = np.zeros(codes.N_COUNTERS, dtype=np.int64)
        self.accumulators = np.zeros(codes.N_ACCUMULATORS)
        self.pair_collisions = np.zeros((self.n_species, self.n_species), dtype=np.int64)
        self.wall_impulse = np.zeros(4)
        self._logged = []
        self.event_sink = None
        self.rebase_every = 16 * n + 1024
        self.reorder_every = (REORDER_EVENTS_PER_DISK * n if n >= REORDER_MIN_DISKS
                              else np.iinfo(np.int64).max)
        self.lookahead = n >= LOOKAHEAD_MIN_DISKS
        self.stall_dt = stall_interval(min(extent, STALL_RADII * float(radius.min())), box,
                                       self.initial_energy, mass, self.gravity,
                                       self.wall_motion, self.wall_temperature)
        self.stall_watch = np.array([-math.inf, 0.0])
        # the list layout and look-ahead whose loop variant compile_once made
        self._compiled_layout = None
        #: wall-clock seconds this engine spent compiling (or loading) its event loop
        self.compile_seconds = 0.0
        self._build(position, velocity, shell, shell_lead, list_capacity, disk_effects,
                    first_event_time(box, velocity, self.gravity, self.wall_motion))
        self.initial_energy += self.rotational_energy()

    def _build(self, position, velocity, shell, lead, list_capacity, disk_effects,
               first_event):
        """Size shells and cells, allocate the state, link neighbours, schedule events;
        ``disk_effects``: the fields of :data:`OPTIONAL_PER_DISK`, ``first_event``:
        :func:`first_event_time`."""
        n, radius, box, pair = self.n, self.radius, self.box, self.pair_interaction
        table = np.zeros((n, DISK_COLUMNS))
        table[:, X:Y + 1] = position
        table[:, VX:VY + 1] = velocity
        table[:, RADIUS] = radius
        # how far each disk's pair events reach (sim.engine.pairs): its radius for hard disks,
        # frozen at each rebuild for growing ones (sim.effects.growth)
        reaches = (self._initial_reaches(table) if keeps(pair, "reach")
                   else radius.copy() if self.growth is not None else None)
        a = radius if reaches is None else reaches
        median = float(np.median(radius))
        phi = float(np.pi * np.sum(radius**2) / np.prod(box))
        # growing disks: shells, cells and the periodic limit sized for the largest radii
        # the box holds, R_i(0) s_max (packing fraction 1, or the periodic limit)
        self.largest_scale = self._largest_scale(phi, a)
        a_sizing = a * self.largest_scale
        big = np.flatnonzero(radius > BIG_RADIUS_RATIO * median)
        if big.size > MAX_BIG:
            big = big[:0]
        is_big = np.zeros(n, dtype=bool)
        is_big[big] = True
        small_radius = radius[~is_big]
        # shells and lists concern the small disks, where they are
        phi_small = packing_fraction_around_disks(position[~is_big], small_radius, box)
        ratio = shell_ratio(phi_small) if shell is None else shell
        lead = shell_lead(phi_small) if lead is None else lead
        delta_small = 0.5 * (ratio - 1.0) * 2.0 * median
        max_small = float(a_sizing[~is_big].max())
        room, axis, r_1, r_2 = periodic_room(box, self.periodic, a_sizing)
        if room <= 0.0:
            what, a_sum = (("radii", "R_1 + R_2") if reaches is None
                           else ("pair events reaching", "a_1 + a_2"))
            raise ValueError(f"periodic box side {box[axis]} is too small for disks of "
                             f"{what} {r_1:g} and {r_2:g}: it must exceed "
                             f"2 ({a_sum}) = {2.0 * (r_1 + r_2):g}")
        delta_small = min(delta_small, room)
        delta = np.full(n, delta_small)
        reach = max_small + delta_small
        cells = grid_cells(box, 2.0 * reach, cell_limit(n))
        self.geometry = np.array([box[0], box[1], box[0] / cells[0], box[1] / cells[1], reach,
                                  lead])
        self.grid = np.array([cells[0], cells[1], int(self.periodic[0]), int(self.periodic[1])],
                             dtype=np.int64)
        self._box_group = Box(self.geometry, self.grid)  # as the compiled code takes them
        # list capacity: the expected number of overlapping shells, 4 φ (a/R + δ/R)² (a the
        # median reach, R the median radius), plus three standard deviations of its (at most
        # Poisson) fluctuations and a margin; the rare list that overflows grows on demand
        a_median = median if reaches is None else float(np.median(reaches))
        expected = 4.0 * phi_small * (a_median / median + delta_small / median) ** 2
        if list_capacity is None:
            list_capacity = int(4 * math.ceil((expected + 3.0 * math.sqrt(expected) + 4.0) / 4))
        cap = np.full(n, max(list_capacity, 1), dtype=np.int32)
        if big.size:
            density = max(phi_small, 0.6) / (np.pi * median**2)
            reach_big = a_sizing[big] + delta[big] + reach
            cap[big] = (2.0 * density * np.pi * reach_big**2 + 16).astype(np.int32)
        self.disks = self._initial_state(table, delta, is_big, big, cap,
                                         int(cells[0] * cells[1]), disk_effects, reaches)
        del table  # copied into the state's buffer
        d = self.disks
        # per-disk values every disk shares (None where they differ): the compiled code gets
        # the number, and never loads the array (sim.engine.parameters); delta, mass and species
        # never change, the list capacity only when the lists grow
        self._common = {name: common_value(getattr(d, name))
                        for name in ("delta", "mass", "species")}
        self._common_capacity = common_value(d.nb_cap)
        shell_radius = self._per_disk_parameters()[0]
        while True:
            full = build_all_neighbours(d.table, shell_radius, d.is_big, self._neighbours(),
                                        self._box_group, self.lookahead)
            if full < 0:
                break
            self._grow_lists(full)
        if d.pair_state is not None:
            initial_states(pair, self._disk_group(), self._neighbours(), self._box_group)
        # first predictions: every disk queued at t = 0 and predicted by the event loop itself
        # (with the argument types of every later call) in a call that may apply no event;
        # then the queue is sized for the predicted events. Until then its blocks are sized
        # for the scene's first events (:func:`first_event_time`): a width of one time unit
        # would put the earliest prediction of disks slow against their box beyond the int64
        # blocks the queue's years reach, and the queue would look for it for ever. A contact
        # due at once (τ = 0) ends the call early, at the head of the queue: the other disks
        # are then predicted in the first run, in this queue, until the clock's first rebase
        # sizes it anew.
        d.event_time[:] = 0.0
        d.event_partner[:] = codes.UNPREDICTED
        build_queue(*d.queue, d.event_time, 0.0)
        d.block_rate[0] = n / (BLOCK_EVENTS * first_event)
        self._run_chunk(0, 0, 0, 0.0, np.inf)
        if not np.any(d.event_partner == codes.UNPREDICTED):
            build_queue(*d.queue, d.event_time, 0.0)
        self.stall_watch[:] = (-math.inf, 0.0)  # the first predictions, all at t = 0, are no run
        if n >= REORDER_MIN_DISKS:
            self.reorder()

    def _largest_scale(self, phi, reach):
        """The largest factor s_max by which growing disks may grow (1 without growth): the
        radii at packing fraction 1, or within the periodic limit R_1 + R_2 < L/2 (with room
        for shells: s (R_1 + R_2) ≤ 0.45 L), whichever comes first."""
        if self.growth is None:
            return 1.0
        largest = 1.0 / math.sqrt(phi)
        if self.n > 1 and np.any(self.periodic):
            r_2, r_1 = np.sort(reach)[-2:]
            side = float(np.min(self.box[self.periodic]))
            largest = min(largest, 0.45 * side / float(r_1 + r_2))
        return largest

    def _initial_reaches(self, table):
        """Every disk's reach a_i float64[n] by the rule of the pair interaction
        (:func:`sim.engine.pairs.pair_reach`), at the construction: the rule sees the disk
        group before any event, the shells not yet sized (``delta`` NaN). A reach below the
        radius, or not finite, is refused."""
        n = self.n
        zeros = np.zeros(n, np.int32)
        disks = Disks(table, np.nan, self.mass, self.species, zeros, zeros.copy(),
                      np.zeros(n, np.int64), np.full(n, -np.inf), zeros.copy())
        reach = np.empty(n)
        initial_reaches(self.pair_interaction, disks, reach)
        short = np.flatnonzero(~(reach >= table[:, RADIUS]) | ~np.isfinite(reach))
        if short.size:
            raise refused("Engine", "pair_interaction", self.pair_interaction,
                          f"a kind whose reach is finite and at least the radius (disk "
                          f"{short[0]}: reach {reach[short[0]]:g}, radius "
                          f"{table[short[0], RADIUS]:g})")
        return reach

    def _initial_state(self, table, delta, is_big, big, cap, n_cells, disk_effects, reach):
        """The state arrays before any list is built or event predicted (:mod:`sim.engine.state`);
        its own function, so that the arrays it makes are freed once they are copied into
        the state's buffer. ``reach``: every disk's reach, None for the radii."""
        n = self.n
        pair = self.pair_interaction
        minus_one = np.full(n, -1, dtype=np.int32)
        heap, links, list_head, calendar, block_rate = empty_queue(n)
        return DiskArrays(
            table=table, delta=delta, mass=self.mass.copy(), species=self.species.copy(),
            is_big=is_big, stamp=np.zeros(n, np.int32), counted=np.zeros(n, np.int32),
            contacts=np.zeros(n, np.int64),
            t_last=np.full(n, -np.inf),
            streak=np.zeros(n, np.int32), event_time=np.empty(n),
            event_partner=np.empty(n, np.int32), event_stamp=np.zeros(n, np.int32),
            links=links, nb_start=list_starts(cap), nb_cap=cap, nb_count=np.zeros(n, np.int32),
            cell_next=minus_one.copy(), cell_prev=minus_one.copy(), cell_of=minus_one.copy(),
            order=np.arange(n, dtype=np.int32), nb=np.full(int(cap.sum()), -1, dtype=np.int32),
            heap=heap, list_head=list_head, calendar=calendar, block_rate=block_rate,
            big=big.astype(np.int32),
            cell_head=np.full(n_cells, -1, dtype=np.int32),
            system_time=np.array([np.inf if self.system_event is None else 0.0]),
            pair_event=np.zeros(n, np.int32) if keeps(pair, "apply") else None,
            reach=reach,
            pair_state=(np.zeros(int(cap.sum()), np.int32) if keeps(pair, "initial_state")
                        else None),
            **disk_effects)

    def _effects(self):
        """The scene's effects as the compiled loop takes them (:class:`sim.effects.Effects`):
        the fields of :data:`OPTIONAL_PER_DISK` from the disk state, the others from the engine."""
        return Effects(**{field: getattr(self.disks if field in OPTIONAL_PER_DISK else self, field)
                          for field in Effects._fields})

    def _per_disk_parameters(self):
        """Shell radius, mass and species as the compiled loop takes them: the number every
        disk shares, else the array (:func:`sim.engine.parameters.per_disk`)."""
        return tuple(getattr(self.disks, name) if value is None else value
                     for name, value in self._common.items())

    def _list_layout(self):
        """``nb_start, nb_cap`` as the compiled code takes them: the capacity every list
        shares, twice (a list then starts at i × capacity,
        :func:`sim.engine.neighbours.list_start`), else both arrays."""
        if self._common_capacity is None:
            return self.disks.nb_start, self.disks.nb_cap
        return self._common_capacity, self._common_capacity

    def _neighbours(self):
        """The neighbour lists and cells as the compiled code takes them
        (:class:`sim.engine.groups.Neighbours`, the lists' layout of :meth:`_list_layout`)."""
        d = self.disks
        return Neighbours(*self._list_layout(), d.nb_count, d.nb, d.cell_head, d.cell_next,
                          d.cell_prev, d.cell_of, d.big, d.reach, d.pair_state)

    def _grow_lists(self, full):
        """Enlarge the lists after ``full`` overflowed. Lists of one common capacity all grow
        by LIST_GROWTH entries, so that they stay alike (the loop's fast layout, see
        :func:`sim.engine.neighbours.list_start`); otherwise every full list doubles."""
        d = self.disks
        if self._common_capacity is None:
            new_cap = d.nb_cap.copy()
            new_cap[np.union1d([full], np.flatnonzero(d.nb_count >= d.nb_cap))] *= 2
        else:
            new_cap = d.nb_cap + np.int32(LIST_GROWTH)
        d.nb_start, d.nb, d.pair_state = grow_lists(d.nb_start, d.nb_count, d.nb, new_cap,
                                                    d.pair_state)
        d.nb_cap = new_cap
        d.pack()
        self._common_capacity = common_value(d.nb_cap)

    def reorder(self):
        """Renumber disks in row order of their grid cells (big disks last) for locality."""
        cell = self.disks.cell_of.astype(np.int64)
        cell[cell < 0] = self.disks.cell_head.size
        self.disks.permute(np.argsort(cell, kind="stable"))


Engine.__doc__ = Engine.__doc__.rstrip(" ") + keyword_doc()


def _sizing_options(shell, shell_lead, list_capacity, n, box, radius):
    """``shell`` (finite, > 1, at most 1 + L/R: L the longer box side, R the median radius),
    ``shell_lead`` (in [0, 1)) and ``list_capacity`` (whole, from 1 to n) of :class:`Engine`
    as float, float and int (None kept); a ValueError naming the first at fault."""
    if shell is not None:
        shell = real_number("Engine", "shell", shell, lambda s: 1.0 < s < math.inf,
                            "a finite shell diameter r_n/σ > 1")
        widest = 1.0 + float(np.max(box)) / float(np.median(radius))
        if shell > widest:
            raise refused("Engine", "shell", shell,
                          f"at most {widest:.6g} = 1 + L/R (L the longer box side, R the "
                          f"median radius), a shell reaching across the box")
    if shell_lead is not None:
        shell_lead = real_number("Engine", "shell_lead", shell_lead,
                                 lambda lead: 0.0 <= lead < 1.0, "a lead λ in [0, 1)")
    if list_capacity is not None:
        list_capacity = whole_count("Engine", "list_capacity", list_capacity, low=1, high=n)
    return shell, shell_lead, list_capacity
