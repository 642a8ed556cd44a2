"""Running the engine: the compiled loop called in chunks until a stop condition holds, the
conditions that need Python checked between chunks, and the loop's codes turned into
exceptions (:class:`Running`, a part of :class:`sim.engine.core.Engine`)."""

import math
import time as wallclock

import numpy as np

from sim.effects.growth import time_of_scale
from sim.effects.rotation import dissipates
from sim.effects.walls import piston_jam
from sim.engine import codes, loop
from sim.engine.compilation import cacheable, compile_once
from sim.engine.errors import (
    ClosedBoxError,
    GrowthLimitError,
    InelasticCollapseError,
    StalledError,
)
from sim.engine.groups import Disks, Limits, Parts, Schedule, Tallies
from sim.engine.inputs import MAX_COUNT, STOP_NAMES, check_reachable, check_stop, refused
from sim.engine.kinematics import TINY_SPEED_SQUARED, VX, VY, X, Y
from sim.engine.observables import virial_pressure
from sim.engine.pairs import keeps

#: With a wall-clock budget (``Engine.run(wall_seconds=...)``) chunks of events are sized to
#: take about this many seconds, from the rate of the chunk before, so that the budget is kept
#: to about that; the first chunk has TIMED_FIRST_CHUNK events, none fewer than
#: TIMED_MIN_CHUNK.
TIMED_CHUNK_SECONDS = 0.15
TIMED_FIRST_CHUNK = 20_000
TIMED_MIN_CHUNK = 1_000


#: The coldest a gas driven by thermal walls is taken to be, as a fraction of the walls'
#: temperature, in :meth:`Running.latest_time` (an estimate with a wide margin).
COLDEST_DRIVEN = 1e-6

#: The reduced pressure βP/ρ at which a run stopped by a packing fraction takes growing disks
#: for jammed (LS compressions stop at βP/ρ ≈ 10⁶ to 10¹²: Donev, Torquato & Stillinger,
#: J. Comput. Phys. 202, 765 (2005)).
JAMMING_PRESSURE = 1e6

#: The jamming watch measures the reduced pressure over this many events per disk (and at
#: most ``chunk_events``): near jamming the collision rate diverges, and the watch must see
#: it before the clock reaches float64 resolution.
JAMMING_WATCH_EVENTS = 20

#: π/√12, the packing fraction of the hexagonal packing of disks of one size, the densest
CLOSE_PACKING = math.pi / math.sqrt(12.0)

#: Above this many disks :meth:`Running.disks_never_touch` tests no pairs (O(N²) in memory);
#: scenes of disks that provably never meet are small hand-made ones.
PAIRWISE_LIMIT = 2000


class Running:
    """Advance the engine's state in time (the engine's running part)."""

    def _disk_group(self):
        """The disks as the compiled code takes them (:class:`sim.engine.groups.Disks`)."""
        d = self.disks
        return Disks(d.table, *self._per_disk_parameters(), d.stamp, d.counted, d.contacts,
                     d.t_last, d.streak)

    def _run_chunk(self, max_events, max_contacts, max_collisions, t_stop, dissipation_limit):
        while True:
            d = self.disks
            every = self.reorder_every
            reorder_at = (self.counters[codes.EVENTS] // every + 1) * every
            parts = Parts(self.pair_interaction, self.system_event)
            arguments = (
                self._disk_group(),
                Schedule(d.event_time, d.event_partner, d.event_stamp, *d.queue, d.system_time,
                         d.pair_event),
                self._neighbours(),
                self._box_group,
                self._effects(),
                *parts,
                True if self.lookahead else None,
                Tallies(self.counters, self.accumulators, self.pair_collisions,
                        self.wall_impulse, self.stall_watch),
                Limits(min(max_events, reorder_at), max_contacts, max_collisions, t_stop,
                       dissipation_limit, self.stall_dt, self.rebase_every))
            # the loop's variant is the engine's but for the lists' layout, which may change
            # (and the look-ahead, which a test may switch)
            layout = (self._common_capacity is None, self.lookahead)
            run_events = loop.run_events if cacheable(*parts) else loop.run_events_uncached
            if self._compiled_layout != layout:
                self.compile_seconds += compile_once(run_events, arguments)
                self._compiled_layout = layout
            status, disk = run_events(*arguments)
            self.drain_event_log()
            if status == codes.STATUS_LOG_FULL:
                continue
            if status == codes.STATUS_EVENT_LIMIT and self.counters[codes.EVENTS] == reorder_at:
                self.reorder()
                if reorder_at < max_events:
                    continue
            if status == codes.STATUS_LIST_FULL:
                self._grow_lists(disk)
                continue
            if status == codes.STATUS_STALLED and self.growth is not None:
                return status  # growing disks jam: their collision rate diverges (run: jamming)
            if status == codes.STATUS_STALLED:
                self._check_piston()  # a jammed piston stalls the clock too: say so
                last = (f"a {codes.kind(codes.SYSTEM)}" if disk < 0 else
                        f"disk {d.order[disk]}'s {codes.kind(int(d.event_partner[disk]))} at "
                        f"position {d.table[disk, X:Y + 1].tolist()} with velocity "
                        f"{d.table[disk, VX:VY + 1].tolist()}")
                raise StalledError(
                    f"the clock has stalled at t = {self.time:.17g}: more than 16 N + 1000 "
                    f"events in a row, each within {self.stall_dt:.3g} (float64 resolution) of "
                    f"the one before, the last of them {last}; the state is beyond float64 "
                    f"resolution: for inelastic disks, and for disks resting on a wall under "
                    f"gravity, switch on the TC model (tc.time); a chain of disks touching all "
                    f"round a periodic box needs room between its disks")
            if status == codes.STATUS_COLLAPSE:
                cluster = set(np.flatnonzero(d.streak >= 2).tolist()) | {int(disk)}
                raise InelasticCollapseError(sorted(int(d.order[k]) for k in cluster),
                                             self.time, self.collisions)
            return status

    def run(self, *, contacts=None, collisions=None, events=None, time=None,
            energy_fraction=None, packing_fraction=None, jamming=None, wall_seconds=None,
            until=None, chunk_events=200_000):
        """Advance until the first stop condition holds; returns its name.

        contacts : disk–disk and disk–wall contacts since the start of the engine
        collisions : disk–disk contacts since the start of the engine
        events : events (contacts and neighbour-shell exits) since the start of the engine
        time : absolute simulated time; the run stops at the last event not after it
        energy_fraction : stop once the kinetic energy is this fraction of the initial one
        packing_fraction : growing disks (:mod:`sim.effects.growth`): stop at the time their
            packing fraction is this one, to round-off (:meth:`packing_fraction_time`; the
            state is then read at that time: ``positions(t)``, ``radii(t)``); refused above
            π/√12 for disks of one size. Watches for jamming too (at :data:`JAMMING_PRESSURE`
            unless ``jamming`` is given): a mixture may jam first
        jamming : stop once the reduced pressure βP/ρ = 1 + X/(2 K Δt) (X the collision
            virial Σ r_ij·Δp_i over the last :data:`JAMMING_WATCH_EVENTS` events per disk
            or ``chunk_events``, whichever is fewer, Δt their time, K the kinetic energy)
            exceeds this. Growing disks whose collisions come closer in time than float64
            resolves (a stalled clock, :class:`StalledError` for others) have jammed too:
            their run stops with the reason ``jamming`` whatever its conditions
        wall_seconds : wall-clock budget of this call (compiling the loop not counted:
            :attr:`compile_seconds`), checked between chunks, which are then
            sized to take about :data:`TIMED_CHUNK_SECONDS` each (from the rate of the chunk
            before; the first has :data:`TIMED_FIRST_CHUNK` events)
        until : predicate ``until(engine) -> bool`` asked every ``chunk_events`` events from
            the start of the call, whatever the chunks a wall budget makes: the same inputs
            stop at the same event
        chunk_events : events per compiled call (the most, with ``wall_seconds``)

        Counts are whole numbers from 0 to 2^62, ``time`` finite and ≥ 0, ``energy_fraction``
        in [0, 1], ``wall_seconds`` finite and ≥ 0, ``chunk_events`` whole and ≥ 1: anything
        else is a ValueError naming the argument, before any event
        (:func:`sim.engine.inputs.check_stop`). A run given no condition but ``time`` and
        ``energy_fraction``, none of which can ever hold, is refused too, as the command line
        refuses such a ``stop`` (:func:`sim.engine.inputs.check_reachable`):
        ``energy_fraction`` < 1 where no contact dissipates energy, a ``time`` beyond what the
        2^62 events a run may count reach where that is bounded (:meth:`latest_time`). The
        piston-jam guard (:meth:`_check_piston`) runs after every chunk, whatever ended it.
        Chunk sizes change no result: the same inputs give the same bits.
        """
        given = {name: value for name, value in zip(STOP_NAMES, (
            contacts, collisions, events, time, energy_fraction, packing_fraction, jamming,
            wall_seconds, until), strict=True) if value is not None}  # as written
        (contacts, collisions, events, time, energy_fraction, packing_fraction, jamming,
         wall_seconds, until, chunk_events) = check_stop(
            contacts, collisions, events, time, energy_fraction, packing_fraction, jamming,
            wall_seconds, until, chunk_events)
        self._refuse_unreachable(given, dict(zip(STOP_NAMES, (
            contacts, collisions, events, time, energy_fraction, packing_fraction, jamming,
            wall_seconds, until), strict=True)))
        big = np.iinfo(np.int64).max
        max_contacts = big if contacts is None else contacts
        max_events = big if events is None else events
        max_collisions = big if collisions is None else collisions
        t_stop = math.inf if time is None else time
        closing = t_stop > self.closing_time
        t_stop = min(t_stop, self.closing_time)
        t_packed = math.inf
        if packing_fraction is not None:
            t_packed = self.packing_fraction_time(packing_fraction)
            jamming = JAMMING_PRESSURE if jamming is None else jamming
            if t_packed <= self.time:
                return "packing_fraction"
        grown_out = self.growth is not None and self.growth_end < min(t_stop, t_packed)
        packs = t_packed <= t_stop and t_packed <= self.growth_end
        t_stop = min(t_stop, t_packed, self.growth_end)
        pressure_from = (self.time, self.virial)
        dissipation_limit = (math.inf if energy_fraction is None
                             else self.initial_energy * (1.0 - energy_fraction))
        started, compiled_before = wallclock.perf_counter(), self.compile_seconds
        reasons = {codes.STATUS_COLLISION_LIMIT: "collisions",
                   codes.STATUS_CONTACT_LIMIT: "contacts", codes.STATUS_TIME_REACHED: "time",
                   codes.STATUS_ENERGY_REACHED: "energy_fraction",
                   codes.STATUS_NO_EVENTS: "no_events", codes.STATUS_STALLED: "jamming"}
        chunk = chunk_events if wall_seconds is None else min(chunk_events, TIMED_FIRST_CHUNK)
        # where ``until`` (and the jamming watch, every JAMMING_WATCH_EVENTS per disk) is
        # asked next
        ask_every = (chunk_events if jamming is None
                     else min(chunk_events, JAMMING_WATCH_EVENTS * self.n))
        ask_at = self.events + ask_every
        while True:
            chunk_started = wallclock.perf_counter()
            done = self.events
            status = self._run_chunk(min(done + chunk, ask_at, max_events), max_contacts,
                                     max_collisions, t_stop, dissipation_limit)
            self._check_piston()
            if status == codes.STATUS_EVENT_LIMIT and self.events >= max_events:
                return "events"
            if status != codes.STATUS_EVENT_LIMIT:
                if packs and status == codes.STATUS_TIME_REACHED:
                    return "packing_fraction"
                if grown_out and status == codes.STATUS_TIME_REACHED:
                    raise GrowthLimitError(
                        f"at t = {self.growth_end:.6g} the growing disks reach the largest "
                        f"radii their box holds ({self.largest_scale:.6g} times the initial "
                        f"ones, packing fraction {self.packing_fraction(self.growth_end):.6g}) "
                        f"without jamming: use a larger box (more disks) or stop earlier")
                if closing and status == codes.STATUS_TIME_REACHED:
                    raise ClosedBoxError(
                        f"at t = {self.closing_time:.6g} the moving walls come within the "
                        f"largest disk diameter ({2 * self.radius.max():.6g}) of the opposite "
                        f"wall: stop the run earlier (stop.time) or slow the piston")
                return reasons[status]
            if wall_seconds is not None:
                now = wallclock.perf_counter()
                if now - started - (self.compile_seconds - compiled_before) >= wall_seconds:
                    return "wall_seconds"
                rate = (self.events - done) / max(now - chunk_started, 1e-6)
                chunk = int(np.clip(rate * TIMED_CHUNK_SECONDS, TIMED_MIN_CHUNK, chunk_events))
            if self.events >= ask_at:
                ask_at += ask_every
                if jamming is not None:
                    pressure = self.reduced_pressure(*pressure_from)
                    pressure_from = (self.time, self.virial)
                    if pressure > jamming:
                        return "jamming"
                if until is not None and until(self):
                    return "predicate"

    @property
    def growth_end(self):
        """The absolute time at which growing disks reach the largest radii their box holds
        (``largest_scale``); inf for disks that do not grow."""
        return (math.inf if self.growth is None
                else time_of_scale(self.growth.rate, self.largest_scale))

    def packing_fraction_time(self, target):
        """The absolute time at which growing disks fill the packing fraction ``target``:
        φ(t) = φ(0)(1 + γ t)². A ValueError for disks that do not grow, and for a target
        above π/√12 (the densest packing) when all disks have one size."""
        if len(set(self.radius.tolist())) == 1 and target > CLOSE_PACKING:
            raise refused("run", "packing_fraction", target, f"at most π/√12 = "
                          f"{CLOSE_PACKING:.6g}, the densest packing of disks of one size")
        if self.growth is None:
            raise refused("run", "packing_fraction", target, f"{self.packing_fraction():.6g} "
                          f"(the disks' own) or below: these disks do not grow (growth_rate)")
        return time_of_scale(self.growth.rate, math.sqrt(target / self.packing_fraction(0.0)))

    def reduced_pressure(self, since_time, since_virial):
        """βP/ρ (:func:`sim.engine.observables.virial_pressure`) from the collision virial
        since the absolute time ``since_time`` (when it was ``since_virial``) and the kinetic
        energy now (growth's rescaling keeps it at its initial value); inf when no time has
        passed."""
        elapsed = self.time - since_time
        kinetic = self.kinetic_energy()
        if elapsed <= 0.0 or kinetic <= 0.0:
            return math.inf
        return virial_pressure(self.virial - since_virial, kinetic, elapsed)

    def _refuse_unreachable(self, given, checked):
        """:func:`check_reachable` for the stop conditions ``given`` to :meth:`run` (name →
        value as given), ``checked`` (name → value) as :func:`check_stop` made them: refused
        only when none may hold (:meth:`never_holds`), asked until one may."""
        if self.still:
            return  # the run ends at once: no event is left
        never = {}
        for name in given:
            reason = self.never_holds(name, checked[name])
            if reason is None:
                return
            never[name] = reason
        check_reachable(given, never)

    @property
    def still(self):
        """Whether nothing moves, nor ever will: no disk moving, no gravity, no moving wall,
        no growth (a run ends at once, stop reason ``no_events``)."""
        return (self.gravity is None and self.wall_motion is None and self.growth is None
                and not np.any(self.velocities() != 0.0))

    def never_holds(self, name, value):
        """Why the stop condition ``name`` = ``value`` of :meth:`run` (as :func:`check_stop`
        makes it) can never hold from this state, as what is allowed instead; None when it
        may. The command line asks the same of its ``stop``
        (:func:`sim.pipeline.stop_conditions.check_reachable`)."""
        if name == "time":
            latest, reason = self.latest_time()
            return f"a time this engine can reach: {reason}" if value > latest else None
        if name in ("collisions", "contacts"):
            done = self.collisions if name == "collisions" else self.contacts
            walls = name == "contacts" and not bool(np.all(self.periodic))
            if value <= done or walls or not self.disks_never_touch():
                return None
            if name == "contacts":
                return ("a count these disks reach: a periodic box has no walls and they never "
                        "touch one another")
            return ("a count these disks reach: "
                    + ("one disk has no other to collide with" if self.n == 1
                       else "they never touch one another"))
        if name == "energy_fraction":
            if value >= 1.0 or self.wall_contacts_dissipate \
                    or self.dissipated_energy >= self.initial_energy * (1.0 - value) \
                    or (self.disk_contacts_dissipate and not self.disks_never_touch()):
                return None
            return ("a fraction this engine can reach: no contact of it dissipates energy "
                    "(elastic disks and walls, smooth or elastic rough contacts, or inelastic "
                    "disks that never touch)")
        return None  # events, wall_seconds and until hold in the end (until: its caller's say)

    def disks_never_touch(self):
        """Whether no two disks can ever touch: no force acts between contacts (no gravity,
        every wall still and not thermal), the disks do not grow, and every pair either moves
        with one velocity in a periodic box, or keeps an axis fixed on which the two are
        further apart than contact (a disk with v_x = 0 keeps its x until its first contact,
        also when it bounces off the walls along y). Above :data:`PAIRWISE_LIMIT` disks only
        the first holds."""
        if self.n < 2:
            return True
        if self.gravity is not None or self.wall_motion is not None \
                or self.wall_temperature is not None or self.growth is not None:
            return False
        velocity = self.velocities()
        periodic = bool(np.all(self.periodic))
        if periodic and np.all(velocity == velocity[0]):
            return True
        if self.n > PAIRWISE_LIMIT or np.any(np.all(velocity != 0.0, axis=1)):
            return False  # a disk moving along no axis may meet any other: no pairs to test
        position = self.positions()
        pairs = np.triu_indices(self.n, 1)
        sigma = self.radius[pairs[0]] + self.radius[pairs[1]]
        never = np.zeros(sigma.size, dtype=bool)
        if periodic:
            never |= np.all(velocity[pairs[0]] == velocity[pairs[1]], axis=1)
        for axis in range(2):
            fixed = velocity[:, axis] == 0.0
            gap = np.abs(position[pairs[0], axis] - position[pairs[1], axis])
            if self.periodic[axis]:
                gap = np.minimum(gap, self.box[axis] - gap)
            never |= fixed[pairs[0]] & fixed[pairs[1]] & (gap >= sigma)
        return bool(np.all(never))

    @property
    def disk_contacts_dissipate(self):
        """Whether a contact of two disks can lose energy: inelastic, or rough with a loss."""
        return self.restitution is not None or dissipates(self.roughness, self.friction)

    @property
    def wall_contacts_dissipate(self):
        """Whether a contact with a wall can lose energy: inelastic walls in a box that has
        walls."""
        return self.wall_restitution is not None and not bool(np.all(self.periodic))

    @property
    def conserves_kinetic_energy(self):
        """Whether the kinetic energy never changes: elastic smooth disks, elastic walls or
        none, no gravity, still walls that are not thermal, no pair interaction that applies
        events of its own (a step of a potential) and no system event."""
        return not (self.restitution is not None or self.wall_contacts_dissipate
                    or self.roughness is not None or self.gravity is not None
                    or self.wall_motion is not None or self.wall_temperature is not None
                    or keeps(self.pair_interaction, "apply")
                    or self.system_event is not None)

    def latest_time(self):
        """The latest time the engine can reach in the events left to it (2^62 in all), inf
        where no bound is known, with the reason in words. Some event comes at least every

        - 2 δ √(M / 2E) where the kinetic energy E never changes
          (:attr:`conserves_kinetic_energy`; M the total mass): the fastest disk, at least
          as fast as √(2E/M), flies straight across at most its shell's diameter 2 δ before
          its next event;
        - (2 + 2√2) √(δ/g) under gravity g, whatever the energy does: on a parabola the
          displacement vt − gt²/2 along g leaves [−2δ, 2δ] by then from any speed v (the
          slowest start, v just under 2√(gδ) upward, rises almost 2δ and takes that long
          to fall to 2δ below);
        - 2 δ / √(2 ε T_w/m) with thermal walls at T_w (the coldest, m the largest mass),
          ε = :data:`COLDEST_DRIVEN`: an estimate, not a bound, with a wide margin: the walls
          keep the gas warm, and a driven gas in its steady state is not a million times
          colder than its walls.

        Returns (that time, the reason in words)."""
        delta = float(np.max(self.disks.delta))
        gaps = []  # (gap, why, "at least" for a bound or "about" for an estimate)
        if self.gravity is not None:
            g = float(np.hypot(*self.gravity))
            gaps.append(((2.0 + 2.0 * math.sqrt(2.0)) * math.sqrt(delta / g), "under gravity",
                         "at least"))
        if self.conserves_kinetic_energy:
            speed_squared = 2.0 * self.kinetic_energy() / float(self.mass.sum())
            if speed_squared > TINY_SPEED_SQUARED:
                gaps.append((2.0 * delta / math.sqrt(speed_squared),
                             "the kinetic energy never changes", "at least"))
        if self.wall_temperature is not None:
            t_wall = float(np.nanmin(self.wall_temperature))
            speed = math.sqrt(2.0 * COLDEST_DRIVEN * t_wall / float(self.mass.max()))
            gaps.append((2.0 * delta / speed, f"its thermal walls keep the gas warmer than "
                         f"{COLDEST_DRIVEN:g} of their temperature (an estimate with a wide "
                         f"margin)", "about"))
        if not gaps:
            return math.inf, ""
        gap, why, how = min(gaps)
        latest = self.time + (MAX_COUNT - self.events) * gap
        return latest, (f"{why}, so some event (a contact or a shell exit) comes {how} every "
                        f"{gap:.3g} time units, and the 2^62 events a run may count reach "
                        f"t = {latest:.3g} at most")

    def _check_piston(self):
        """Raise :class:`ClosedBoxError` when a piston has jammed the disks
        (:func:`sim.effects.walls.piston_jam`); checked after every chunk, so within one chunk
        of the jam."""
        jam = piston_jam(self.wall_motion, self.initial_energy, float(self.mass.sum()),
                         self.kinetic_energy, self.time)
        if jam is not None:
            raise ClosedBoxError(jam)
