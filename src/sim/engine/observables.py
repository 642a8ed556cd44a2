"""What an engine reports: times, counts, positions, velocities, energies and momenta, in the
user's numbering of the disks, and the contacts its event log kept (:class:`Observables`, a
part of :class:`sim.engine.core.Engine`)."""


import numpy as np

from sim.effects.event_log import LOG_COLUMNS, LOG_DISK, LOG_PARTNER
from sim.effects.gravity import potential_energy
from sim.effects.growth import scale
from sim.effects.rotation import moment_of_inertia, rotational_energy
from sim.effects.walls import wall_state
from sim.engine import codes, loop
from sim.engine.kinematics import T_OWN, VX, VY, X, Y
from sim.engine.pairs import pair_energy
from sim.engine.stamps import count_all_contacts


def virial_pressure(virial, kinetic, elapsed):
    """βP/ρ = 1 + X/(2 K Δt) from the collision virial X = Σ r_ij·Δp_i of a time Δt and the
    kinetic energy K (K = N kT in two dimensions; Alder & Wainwright, J. Chem. Phys. 33, 1439
    (1960)); numbers or arrays. With zero total momentum kT is K/(N − 1):
    :func:`sim.analysis.equation_of_state.pressure_area`."""
    return 1.0 + virial / (2.0 * kinetic * elapsed)


class Observables:
    """Read-outs of the engine's state (the engine's observing part)."""

    @property
    def time(self):
        """Absolute time of the last processed event."""
        return float(self.accumulators[codes.T_ORIGIN] + self.accumulators[codes.T_NOW])

    @property
    def collisions(self):
        """Disk–disk contacts so far."""
        return int(self.counters[codes.COLLISIONS])

    @property
    def wall_contacts(self):
        """Disk–wall contacts so far."""
        return int(self.counters[codes.WALL_CONTACTS])

    @property
    def contacts(self):
        """Disk–disk and disk–wall contacts so far."""
        return self.collisions + self.wall_contacts

    @property
    def events(self):
        """Events the engine applied so far: contacts, other events of a pair interaction
        and neighbour-shell exits (the words of :mod:`sim.engine.codes`)."""
        return int(self.counters[codes.EVENTS])

    @property
    def dissipated_energy(self):
        return float(self.accumulators[codes.DISSIPATED_DISKS]
                     + self.accumulators[codes.DISSIPATED_WALLS])

    @property
    def virial(self):
        """Σ r_ij·Δp_i over all disk–disk contacts so far."""
        return float(self.accumulators[codes.VIRIAL])

    def _user_order(self, values):
        out = np.empty_like(values)
        out[self.disks.order] = values
        return out

    def _relative_time(self, t):
        return (self.accumulators[codes.T_NOW] if t is None
                else float(t) - self.accumulators[codes.T_ORIGIN])

    def _state(self, t):
        return loop.state_at(self._relative_time(t), self.disks.table, self._box_group,
                             self.gravity)

    def scale(self, t=None):
        """R_i(t)/R_i(0) at absolute time ``t`` (default: the last event): 1 + γ t for
        growing disks (:mod:`sim.effects.growth`), else 1."""
        return scale(None if self.growth is None else self.growth.rate,
                     self.time if t is None else float(t))

    def radii(self, t=None):
        """Radii float64[n] at absolute time ``t`` (default: the last event): ``radius``,
        grown by :meth:`scale` for growing disks."""
        return self.radius * self.scale(t)

    def packing_fraction(self, t=None):
        """The packing fraction Σ π R_i(t)² / A at absolute time ``t`` (default: the last
        event)."""
        return float(np.pi * np.sum(self.radii(t) ** 2) / np.prod(self.box))

    def positions(self, t=None):
        """Positions float64[n, 2] of every disk at absolute time ``t`` (default: the time of
        the last event); ``t`` must not precede the last event."""
        return self._user_order(self._state(t)[0])

    def velocities(self, t=None):
        """Velocities float64[n, 2] at absolute time ``t`` (default: the last event); they
        change between events only under gravity."""
        return self._user_order(self._state(t)[1])

    def unwrapped_positions(self, t=None):
        """Positions float64[n, 2] at time ``t`` continued across periodic boundaries
        (r + windings · L), for mean squared displacements; needs ``unwrap=True``."""
        if self.disks.images is None:
            raise ValueError("unwrapped positions need an engine made with unwrap=True")
        d = self.disks
        dt = (self._relative_time(t) - d.table[:, T_OWN])[:, None]
        acceleration = 0.0 if self.gravity is None else self.gravity
        flown = (d.table[:, VX:VY + 1] + 0.5 * acceleration * dt) * dt
        return self._user_order(d.table[:, X:Y + 1] + d.images * self.box + flown)

    def wall_positions(self, t=None):
        """Positions float64[4] of the walls (left, right, bottom, top) at absolute time t."""
        t_abs = self.time if t is None else float(t)
        return np.array([wall_state(self.wall_motion, w, t_abs, self.geometry)[0]
                         for w in range(4)])

    def contacts_by_disk(self):
        """Contacts (disk and wall) of each disk so far: int64[n]."""
        count_all_contacts(self.disks.stamp, self.disks.counted, self.disks.contacts)
        return self._user_order(self.disks.contacts)

    def next_event_time(self):
        """Absolute time of the next scheduled event (possibly stale)."""
        d = self.disks
        return float(d.event_time.min() + self.accumulators[codes.T_ORIGIN])

    def kinetic_energy_by_species(self, t=None):
        """Σ m v²/2 per species at time t: float64[n_species]."""
        d = self.disks
        energy = 0.5 * d.mass * np.sum(self._state(t)[1] ** 2, axis=1)
        return np.bincount(d.species, weights=energy, minlength=self.n_species)

    def kinetic_energy(self, t=None):
        """Translational kinetic energy Σ m v²/2 at time t (default: the last event); the
        rotational part is :meth:`rotational_energy`."""
        d = self.disks
        return float(np.sum(0.5 * d.mass * np.sum(self._state(t)[1] ** 2, axis=1)))

    @property
    def spinning(self):
        """Whether disks turn (:mod:`sim.effects.rotation`): rough contacts, or spins given."""
        return self.disks.spin is not None

    def angular_velocities(self):
        """Spins ω float64[n] (counter-clockwise positive; constant between contacts), zero
        when no disk turns."""
        if not self.spinning:
            return np.zeros(self.n)
        return self._user_order(self.disks.spin)

    def moments_of_inertia(self):
        """I = q m a² float64[n] (q: ``inertia_factor``)."""
        return moment_of_inertia(self.effect_keywords["inertia_factor"], self.mass, self.radius)

    def rotational_energy(self):
        """Σ I ω²/2 (zero when no disk turns)."""
        if not self.spinning:
            return 0.0
        return rotational_energy(self.angular_velocities(), self.moments_of_inertia())

    def potential_energy(self, t=None):
        """Σ −m g·r at time t (zero without gravity), plus the potential energy of the
        pairs from their states (:func:`sim.engine.pairs.pair_energy`; zero for hard
        disks)."""
        return (potential_energy(self._state(t)[0], self.disks.mass, self.gravity)
                + pair_energy(self.pair_interaction, self.disks))

    @property
    def wall_work(self):
        """Work done on the disks by moving and thermal walls so far."""
        return float(self.accumulators[codes.WALL_WORK])

    def momentum(self, t=None):
        d = self.disks
        return (d.mass[:, None] * self._state(t)[1]).sum(axis=0)

    def drain_event_log(self):
        """Hand the rows of the compiled log to :attr:`event_sink` (else keep them for
        :meth:`take_event_log`), disks renamed to the user's numbering (the engine's own
        numbering changes when it reorders)."""
        if self.event_log is None or self.event_log[1][0] == 0:
            return
        log, fill = self.event_log
        rows = log[:fill[0]].copy()
        order = self.disks.order
        rows[:, LOG_DISK] = order[rows[:, LOG_DISK].astype(np.int64)]
        partner = rows[:, LOG_PARTNER].astype(np.int64)
        disk = partner >= 0
        rows[disk, LOG_PARTNER] = order[partner[disk]]
        fill[0] = 0
        if self.event_sink is None:
            self._logged.append(rows)
        else:
            self.event_sink(rows)

    def take_event_log(self):
        """The contacts logged since the last call: float64[k, 6], columns as in
        :mod:`sim.effects.event_log` (disks in the user's numbering)."""
        self.drain_event_log()
        rows = (np.concatenate(self._logged) if self._logged
                else np.zeros((0, LOG_COLUMNS)))
        self._logged = []
        return rows
