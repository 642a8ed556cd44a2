"""The textbook algorithm, kept plain on purpose: a cross-check and a baseline, never a tool.

As in the seed study (TFY4235 exercise 1; Allen & Tildesley, *Computer Simulation of
Liquids*, §3.7): after every event the disks involved are
re-predicted against *every* other disk and every wall, and each future contact is pushed
onto one heap of all predicted events. Stale entries are recognised by per-disk collision
counters when popped. Cost O(N) per event, memory growing with the heap. Each disk keeps
its own clock and the contact roots use the same arithmetic as the engine, so the two agree
to round-off for as long as chaos lets round-off stay small.

Periodic axes are handled by testing the nine nearest images of each pair. That finds every
contact as long as the pair moves less than a box side relative to each other between its
last prediction and its contact, so on a periodic axis every disk is also re-predicted after
flying half the shortest periodic side (a horizon event, applied silently): then the contact
image is among the nine while the box side exceeds 2 (R_i + R_j).
"""

import heapq
import math

import numpy as np

WALL = -1
HORIZON = -10  # a re-prediction after half a periodic side of flight


class ReferenceEngine:
    """Plain event-driven hard disks; ``position``/``velocity`` float64[n, 2]."""

    def __init__(self, position, velocity, radius, mass=1.0, box=(1.0, 1.0),
                 periodic=(False, False), restitution=1.0, wall_restitution=1.0):
        self.position = np.array(position, dtype=np.float64)
        self.velocity = np.array(velocity, dtype=np.float64)
        n = self.position.shape[0]
        self.radius = np.array(np.broadcast_to(np.asarray(radius, np.float64), (n,)))
        self.mass = np.array(np.broadcast_to(np.asarray(mass, np.float64), (n,)))
        self.box = np.asarray(box, dtype=np.float64)
        self.periodic = tuple(bool(p) for p in periodic)
        self.xi = float(restitution)
        self.xi_wall = float(wall_restitution)
        self.time = 0.0
        self.t_disk = np.zeros(n)
        self.count = np.zeros(n, dtype=np.int64)
        self.collisions = 0
        self.wall_contacts = 0
        self.dissipated = 0.0
        self.heap = []
        self._sequence = 0
        images = [(0.0, 0.0)]
        if any(self.periodic):
            shifts = [(-1, 0, 1) if p else (0,) for p in self.periodic]
            images = [(a * self.box[0], b * self.box[1]) for a in shifts[0] for b in shifts[1]]
        self.images = np.array(images)
        periodic_sides = [side for side, p in zip(self.box, self.periodic, strict=True) if p]
        self.horizon = 0.5 * min(periodic_sides) if periodic_sides else math.inf
        for i in range(n):
            self._predict(i)

    def _push(self, t, i, j, count_j):
        self._sequence += 1
        heapq.heappush(self.heap, (t, self._sequence, i, j, self.count[i], count_j))

    def _predict(self, i):
        """Push every future contact of disk i (at the current time), with each other disk
        (nearest image and, on periodic axes, its neighbours) and each wall, and its horizon
        event."""
        others = np.flatnonzero(np.arange(self.position.shape[0]) != i)
        dt = self.time - self.t_disk[others]
        r = self.position[i] - self.position[others] - self.velocity[others] * dt[:, None]
        r -= np.where(self.periodic, self.box * np.round(r / self.box), 0.0)
        v = self.velocity[i] - self.velocity[others]
        sigma = self.radius[i] + self.radius[others]
        best = np.full(others.size, np.inf)
        for shift in self.images:
            rx, ry = r[:, 0] + shift[0], r[:, 1] + shift[1]
            b = rx * v[:, 0] + ry * v[:, 1]
            a = v[:, 0] * v[:, 0] + v[:, 1] * v[:, 1]
            cross = rx * v[:, 1] - ry * v[:, 0]
            disc = a * sigma * sigma - cross * cross
            c = rx * rx + ry * ry - sigma * sigma
            ok = (b < 0.0) & (disc > 0.0)
            tau = np.full(others.size, np.inf)
            tau[ok] = np.maximum(c[ok] / (-b[ok] + np.sqrt(disc[ok])), 0.0)
            best = np.minimum(best, tau)
        for k in np.flatnonzero(np.isfinite(best)):
            j = int(others[k])
            self._push(self.time + best[k], i, j, self.count[j])
        for axis in range(2):
            if self.periodic[axis]:
                continue
            x, u, rad = self.position[i, axis], self.velocity[i, axis], self.radius[i]
            if u < 0.0:
                self._push(self.time + max((x - rad) / -u, 0.0), i, WALL - 2 * axis, 0)
            elif u > 0.0:
                self._push(self.time + max((self.box[axis] - rad - x) / u, 0.0), i,
                           WALL - 2 * axis - 1, 0)
        speed = math.hypot(*self.velocity[i])
        if speed > 0.0 and math.isfinite(self.horizon):
            self._push(self.time + self.horizon / speed, i, HORIZON, 0)

    def _advance(self, i, t):
        """Bring disk i to time t along its straight path (each disk keeps its own clock)."""
        self.position[i] += self.velocity[i] * (t - self.t_disk[i])
        for axis in range(2):
            if self.periodic[axis]:
                self.position[i, axis] %= self.box[axis]
        self.t_disk[i] = t

    def positions(self, t):
        """Positions of all disks at time t, not before the last contact applied (horizon
        events move a disk's clock but not its path)."""
        p = self.position + self.velocity * (t - self.t_disk)[:, None]
        return np.where(self.periodic, p % self.box, p)

    def _settle(self):
        """Drop stale entries and apply due horizon events until a valid contact is on top."""
        while self.heap:
            t, _, i, j, count_i, count_j = self.heap[0]
            if count_i != self.count[i] or (j >= 0 and count_j != self.count[j]):
                heapq.heappop(self.heap)
            elif j == HORIZON:
                heapq.heappop(self.heap)
                self.time = t
                self._advance(i, t)
                self._predict(i)
            else:
                return

    def next_event_time(self):
        """Time of the next valid contact (inf if none)."""
        self._settle()
        return self.heap[0][0] if self.heap else math.inf

    def step(self):
        """Apply the next valid contact; returns (time, i, j) with j < 0 for walls
        (-1 left, -2 right, -3 bottom, -4 top)."""
        self._settle()
        t, _, i, j, _, _ = heapq.heappop(self.heap)
        self.time = t
        self._advance(i, t)
        if j >= 0:
            self._advance(j, t)
            rx, ry = self.position[i] - self.position[j]
            if self.periodic[0]:
                rx -= self.box[0] * round(rx / self.box[0])
            if self.periodic[1]:
                ry -= self.box[1] * round(ry / self.box[1])
            distance = math.sqrt(rx * rx + ry * ry)
            n = np.array([rx / distance, ry / distance])
            dv = self.velocity[i] - self.velocity[j]
            v_n = float(dv[0] * n[0] + dv[1] * n[1])
            mu = self.mass[i] * self.mass[j] / (self.mass[i] + self.mass[j])
            impulse = (1.0 + self.xi) * mu * v_n
            self.velocity[i] -= impulse / self.mass[i] * n
            self.velocity[j] += impulse / self.mass[j] * n
            self.dissipated += 0.5 * (1.0 - self.xi**2) * mu * v_n**2
            self.count[i] += 1
            self.count[j] += 1
            self.collisions += 1
            self._predict(i)
            self._predict(j)
        else:
            axis = (WALL - j) // 2
            u = self.velocity[i, axis]
            self.velocity[i, axis] = -self.xi_wall * u
            self.dissipated += 0.5 * (1.0 - self.xi_wall**2) * self.mass[i] * u**2
            self.count[i] += 1
            self.wall_contacts += 1
            self._predict(i)
        return t, i, j

    def run(self, events):
        """Apply ``events`` events; returns the list of (time, i, j)."""
        return [self.step() for _ in range(events)]

    def kinetic_energy(self):
        return float(np.sum(0.5 * self.mass * np.sum(self.velocity**2, axis=1)))
