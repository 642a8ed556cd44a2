"""Walls: when a disk meets a box edge, and what the edge does to it.

Walls are numbered ``2 axis + side`` (0 x-low, 1 x-high, 2 y-low, 3 y-high); ``sign`` is +1 for
a low wall and −1 for a high one, so the gap of disk i (radius R) to wall w is
sign (x_i − w) − R. Every wall is hard, with restitution ξ_w (:mod:`sim.engine.contact`). A
scene may also give walls

  motion float64[4, 3] — per wall (U, A, ω): the wall sits at w(t) = w_rest + U t + A sin(ω t)
      (w_rest = 0 or L; t absolute). U ≠ 0 is a piston; A ≠ 0 a vibrating wall. In the
      wall's frame, moving with u(t) = U + A ω cos(ω t), the disk's normal velocity reverses:
      v_n' − u = −ξ_w (v_n − u), so a wall does work on the disks.
  temperature float64[4] — per wall T_w, NaN for a wall that is not thermal. A disk leaving a
      thermal wall forgets its velocity (Tehver, Toigo, Koplik & Banavar, Phys. Rev. E 57,
      R17 (1998)): its normal speed has the flux density (m v/T_w) exp(−m v²/(2T_w)) and its
      tangential velocity is Gaussian with variance T_w/m, in the wall's frame.

Each is None when no wall of the scene needs it, and none of its code is compiled then.
Thermal draws come from a counter-based generator (SplitMix64, Steele, Lea & Flood, OOPSLA
2014) keyed by the run's seed and the number of wall contacts so far, so a resumed run draws the
same numbers as one never interrupted.
"""

import math

import numpy as np
from numba import njit

from sim.engine.kinematics import (
    INF,
    RADIUS,
    VX,
    X,
    first_contact_accelerated,
    first_contact_oscillating,
    wall_contact_time,
)

#: A disk within this fraction of the box side of a vibrating wall (a few units of round-off),
#: and closing, touches it.
CONTACT_TOLERANCE = 1e-15

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_MIX_1 = np.uint64(0xBF58476D1CE4E5B9)
_MIX_2 = np.uint64(0x94D049BB133111EB)


#: Wall names by number.
NAMES = ("left", "right", "bottom", "top")


def wall_motion(walls):
    """float64[4, 3] of (U, A, ω) per wall for the compiled loop, or None when no wall moves.

    ``walls`` maps wall numbers to dicts with the keys speed, amplitude, frequency (angular):
    all finite, amplitude and frequency ≥ 0.
    """
    motion = np.zeros((4, 3))
    for wall, spec in walls.items():
        motion[wall] = (spec.get("speed", 0.0), spec.get("amplitude", 0.0),
                        spec.get("frequency", 0.0))
        speed, amplitude, frequency = motion[wall]
        if not (math.isfinite(speed) and 0.0 <= amplitude < INF and 0.0 <= frequency < INF):
            raise ValueError(f"{NAMES[wall]} wall: speed {speed}, amplitude {amplitude} and "
                             f"frequency {frequency} must be finite, amplitude and frequency ≥ 0")
    motion[motion[:, 2] == 0.0, 1] = 0.0  # no frequency, no oscillation
    return motion if np.any(motion[:, :2]) else None


def wall_temperature(walls):
    """float64[4] of wall temperatures (NaN: not thermal), or None when no wall is thermal.
    ``walls`` maps wall numbers to dicts whose key temperature, when given, is finite and > 0."""
    temperature = np.full(4, np.nan)
    for wall, spec in walls.items():
        if spec.get("temperature") is not None:
            t_wall = float(spec["temperature"])
            if not 0.0 < t_wall < INF:
                raise ValueError(f"{NAMES[wall]} wall: temperature {t_wall} must be finite and "
                                 f"> 0")
            temperature[wall] = t_wall
    return temperature if not np.all(np.isnan(temperature)) else None


@njit(cache=True, inline="always")
def wall_motion_of(wall, motion):
    """(U, A, ω) of ``wall``: zeros for a still wall, or when no wall moves."""
    if motion is None:
        return 0.0, 0.0, 0.0
    return motion[wall, 0], motion[wall, 1], motion[wall, 2]


@njit(cache=True, inline="always")
def wall_state(wall, t_abs, geometry, motion):
    """Position and velocity of ``wall`` at absolute time ``t_abs``."""
    rest = geometry[wall >> 1] * (wall & 1)
    if motion is None:
        return rest, 0.0
    speed, amplitude, omega = wall_motion_of(wall, motion)
    return (rest + speed * t_abs + amplitude * math.sin(omega * t_abs),
            speed + amplitude * omega * math.cos(omega * t_abs))


@njit(cache=True, inline="always")
def predict_wall_contact(axis, t_abs, x, v, radius, geometry, gravity, motion, horizon):
    """Time until the disk at coordinate ``x`` with velocity ``v`` along ``axis`` (at absolute
    time ``t_abs``) touches a wall of that axis. Returns (τ, side): side 0 or 1 for a contact,
    -1 for a time short of contact at which the disk must be predicted again (a search near a
    vibrating wall that has not converged yet), τ = inf when no wall is reached. A vibrating
    wall is not searched beyond ``horizon``, the time of an event known to come first."""
    if gravity is None and motion is None:
        return wall_contact_time(x, v, radius, geometry[axis])
    a = 0.0 if gravity is None else gravity[axis]
    best = INF
    best_side = -1
    for side in range(2):
        wall = 2 * axis + side
        sign = 1.0 - 2.0 * side
        rest = geometry[axis] * side
        speed, amplitude, omega = wall_motion_of(wall, motion)
        h = sign * (x - rest - speed * t_abs) - radius
        if amplitude == 0.0:
            tau = first_contact_accelerated(h, sign * (v - speed), sign * a)
            touching = True
        else:
            tau, touching = first_contact_oscillating(
                h, sign * (v - speed), sign * a, amplitude, omega,
                omega * t_abs + (0.0 if side == 0 else math.pi),
                CONTACT_TOLERANCE * geometry[axis], min(horizon, best))
        if tau < best:
            best = tau
            best_side = side if touching else -1
    return best, best_side


@njit(cache=True, inline="always")
def _splitmix64(z):
    z = z + _GOLDEN
    z = (z ^ (z >> np.uint64(30))) * _MIX_1
    z = (z ^ (z >> np.uint64(27))) * _MIX_2
    return z ^ (z >> np.uint64(31))


@njit(cache=True, inline="always")
def uniform(key, k):
    """The k-th uniform number in (0, 1] of the stream ``key`` (uint64)."""
    z = _splitmix64(key + np.uint64(k) * _GOLDEN)
    return (np.float64(z >> np.uint64(11)) + 1.0) * (1.0 / 9007199254740992.0)


@njit(cache=True, inline="always")
def contact_key(seed, contact):
    """Stream key of the ``contact``-th wall contact of the run seeded ``seed``."""
    return _splitmix64(np.uint64(seed) ^ _splitmix64(np.uint64(contact)))


@njit(cache=True, inline="always")
def hit_wall(i, wall, t_abs, xi_wall, disks, m, geometry, motion, temperature, key, gravity,
             tc):
    """Disk i (mass m, at the time of contact) touches ``wall``: clamp it inside the wall
    against round-off, then reflect it (hard wall) or redraw its velocity (thermal wall).

    Returns (energy dissipated, momentum given to the wall along its axis, work done by the
    wall on the disk), so that E_kin changes by work − dissipated. A disk found receding
    from the wall (round-off) keeps its velocity. A disk resting on a still wall that gravity
    presses it against (placed there at rest) would touch it again at once, for ever; under
    the TC model it leaves with the speed g t_c/2 of a bounce lasting t_c (the bounces the
    model settles resting disks into), the wall doing that work, and without it the clock
    stalls (:class:`sim.engine.core.StalledError`).
    """
    axis = wall >> 1
    other = 1 - axis
    sign = 1.0 - 2.0 * (wall & 1)
    position, u = wall_state(wall, t_abs, geometry, motion)
    inside = position + sign * disks[i, RADIUS]
    if sign * (disks[i, X + axis] - inside) < 0.0:
        disks[i, X + axis] = inside
    v_n = disks[i, VX + axis]
    v_t = disks[i, VX + other]
    if temperature is not None:
        t_wall = temperature[wall]
        if t_wall == t_wall:  # thermal wall
            scale = math.sqrt(t_wall / m)
            normal = scale * math.sqrt(-2.0 * math.log(uniform(key, 0)))
            tangential = (scale * math.sqrt(-2.0 * math.log(uniform(key, 1)))
                          * math.cos(2.0 * math.pi * uniform(key, 2)))
            disks[i, VX + axis] = u + sign * normal
            disks[i, VX + other] = tangential
            work = 0.5 * m * (disks[i, VX + axis] ** 2 + tangential**2 - v_n * v_n - v_t * v_t)
            return 0.0, m * (v_n - disks[i, VX + axis]), work
    w_n = v_n - u
    if sign * w_n >= 0.0:
        if gravity is not None and tc is not None and motion is None:
            if w_n == 0.0 and sign * gravity[axis] < 0.0:
                disks[i, VX + axis] = sign * 0.5 * abs(gravity[axis]) * tc
                lift = disks[i, VX + axis]
                return 0.0, -m * lift, 0.5 * m * lift * lift
        return 0.0, 0.0, 0.0
    disks[i, VX + axis] = u - xi_wall * w_n
    lost = 0.5 * (1.0 - xi_wall * xi_wall) * m * w_n * w_n
    work = 0.0 if motion is None else 0.5 * m * (disks[i, VX + axis] ** 2 - v_n * v_n) + lost
    return lost, m * (v_n - disks[i, VX + axis]), work
