"""Walls: when a disk meets a box edge, and what the edge does to it.

Walls are numbered ``2 axis + side`` (0 x-low, 1 x-high, 2 y-low, 3 y-high); ``sign`` is +1 for
a low wall and −1 for a high one, so the gap of disk i (radius R) to wall w is
sign (x_i − w) − R. Every wall is hard, with restitution ξ_w (:mod:`sim.effects.restitution`). A
scene may also give walls

  motion float64[4, 3] — per wall (U, A, ω): the wall sits at w(t) = w_rest + U t + A sin(ω t)
      (w_rest = 0 or L; t absolute). U ≠ 0 is a piston; A ≠ 0 a vibrating wall. In the
      wall's frame, moving with u(t) = U + A ω cos(ω t), the disk's normal velocity reverses:
      v_n' − u = −ξ_w (v_n − u), so a wall does work on the disks.

or make them thermal (:mod:`sim.effects.thermal_walls`). ``motion`` is None when no wall of
the scene moves, and none of its code is compiled then (:mod:`sim.effects.rules`).
"""

import math

import numpy as np
from numba import njit, types
from numba.extending import overload

from sim.effects.gravity import acceleration, resting_lift
from sim.effects.rules import effect_rule
from sim.effects.thermal_walls import thermal_redraw
from sim.effects.values import ConfigError, positive, walled
from sim.engine.box import SIDE, WALL_NAMES
from sim.engine.inputs import WALLS, wall_keyword
from sim.engine.kinematics import (
    INF,
    VX,
    X,
    first_contact_accelerated,
    first_contact_oscillating,
    wall_contact_time,
)

#: A piston (a wall moving at constant speed) that has raised the kinetic energy this many
#: times above max(initial energy, N m U²) has jammed the disks against the opposite wall:
#: driven at constant speed, their collision rate and energy diverge at a finite time.
PISTON_ENERGY_LIMIT = 1e6

#: A disk within this fraction of the box side of a vibrating wall (a few units of round-off),
#: and closing, touches it.
CONTACT_TOLERANCE = 1e-15

KEYWORDS = {"walls": (None, '{"left" | "right" | "bottom" | "top": {"temperature": T_w, '
                            '"speed": U, "amplitude": A, "frequency": ω}} — thermal, moving and '
                            "vibrating walls (:mod:`sim.effects.walls`): T_w finite and > 0 (or "
                            "None), U finite, A and ω finite and ≥ 0 (ω > 0 with A > 0); absent "
                            "walls and keys keep the wall hard and still")}


def check_config(cfg):
    """Per wall: a finite speed, amplitude and frequency ≥ 0, a frequency for an amplitude,
    and no moving wall in a periodic box."""
    for name in WALLS:
        wall, key = cfg.walls[name], f"walls.{name}"
        positive(f"{key}.amplitude", wall.amplitude, allow_none=False, zero=True)
        positive(f"{key}.frequency", wall.frequency, allow_none=False, zero=True)
        if not math.isfinite(wall.speed):
            raise ConfigError(f"{key}.speed", wall.speed, "a finite speed")
        if wall.speed != 0.0 or wall.amplitude != 0.0:
            walled(cfg, name)
        if wall.amplitude > 0.0 and wall.frequency == 0.0:
            raise ConfigError(f"{key}.frequency", wall.frequency,
                              "an angular frequency > 0 for a wall with an amplitude")


def engine_arguments(cfg):
    """The walls that are not plain hard walls: thermal, moving or vibrating ones."""
    walls = {}
    for name in WALLS:
        wall = cfg.walls[name]
        if wall.temperature is not None or wall.speed or wall.amplitude:
            walls[name] = {key: wall[key] for key in wall}
    return {"walls": walls}


def loop_values(keywords, context):
    """(U, A, ω) per wall, None when no wall moves (``walls`` checked by
    :func:`sim.engine.inputs.wall_keyword`)."""
    return {"wall_motion": wall_motion(wall_keyword(keywords["walls"], context["periodic"]))}


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
            raise ValueError(f"{WALL_NAMES[wall]} wall: speed {speed}, amplitude {amplitude} and "
                             f"frequency {frequency} must be finite, amplitude and frequency ≥ 0")
    motion[motion[:, 2] == 0.0, 1] = 0.0  # no frequency, no oscillation
    return motion if np.any(motion[:, :2]) else None


def closing_time(motion, box, periodic, largest_radius):
    """The absolute time at which moving walls could come closer to the opposite wall than
    the largest disk diameter (inf when they never do): the gap along each walled axis is at
    least L + (U_high − U_low) t − A_low − A_high."""
    if motion is None:
        return math.inf
    closing = math.inf
    for axis in range(2):
        if periodic[axis]:
            continue
        low, high = motion[2 * axis], motion[2 * axis + 1]
        room = box[axis] - low[1] - high[1] - 2.0 * largest_radius
        if room <= 0.0:
            raise ValueError(f"the walls of axis {'xy'[axis]} oscillate with amplitudes "
                             f"{low[1]} and {high[1]} in a box {box[axis]} wide: they would "
                             f"crush disks of radius {largest_radius}")
        rate = low[0] - high[0]
        if rate > 0.0:
            closing = min(closing, room / rate)
    return closing


def piston_jam(motion, initial_energy, total_mass, kinetic_energy, time):
    """The message of a piston that has jammed the disks, or None: a wall moving at constant
    speed U that has raised the kinetic energy (``kinetic_energy()``, asked only when a wall
    moves so) above :data:`PISTON_ENERGY_LIMIT` times max(initial energy, N m U²)."""
    if motion is None or not np.any(motion[:, 0]):
        return None
    speed = float(np.abs(motion[:, 0]).max())
    scale = max(initial_energy, total_mass * speed**2)
    kinetic_energy = kinetic_energy()
    if kinetic_energy <= PISTON_ENERGY_LIMIT * scale:
        return None
    return (f"at t = {time:.6g} the piston has jammed the disks: their kinetic energy "
            f"{kinetic_energy:.3g} is {kinetic_energy / scale:.3g} times max(initial energy, "
            f"N m U²), and a wall driven at constant speed makes it diverge; stop the run "
            f"earlier (stop.time) or slow the piston")


def _still(motion, wall):
    return 0.0, 0.0, 0.0


@effect_rule(_still)
def wall_motion_of(motion, wall):
    """(U, A, ω) of ``wall``: zeros for a still wall, or when no wall moves."""
    return motion[wall, 0], motion[wall, 1], motion[wall, 2]


def _at_rest(motion, wall, t_abs, geometry):
    return geometry[SIDE + (wall >> 1)] * (wall & 1), 0.0


@effect_rule(_at_rest)
def wall_state(motion, wall, t_abs, geometry):
    """Position and velocity of ``wall`` at absolute time ``t_abs``:
    w_rest + U t + A sin(ω t) and U + A ω cos(ω t)."""
    rest = geometry[SIDE + (wall >> 1)] * (wall & 1)
    speed, amplitude, omega = wall_motion_of(motion, wall)
    return (rest + speed * t_abs + amplitude * math.sin(omega * t_abs),
            speed + amplitude * omega * math.cos(omega * t_abs))


def predict_wall_contact(gravity, motion, axis, t_abs, x, v, radius, edge, geometry, horizon):
    """Time until the disk at coordinate ``x`` with velocity ``v`` along ``axis`` (at absolute
    time ``t_abs``, radius ``radius`` then, its edge moving out at ``edge``: a growing disk's
    Ṙ, :mod:`sim.effects.growth`, else None) touches a wall of that axis. Returns (τ, side):
    side 0 or 1 for a contact, -1 for a time short of contact at which the disk must be
    predicted again (a search near a vibrating wall that has not converged yet), τ = inf
    when no wall is reached. A vibrating wall is not searched beyond ``horizon``, the time of
    an event known to come first. Still walls without gravity or growth: a straight line to
    the nearer wall (:func:`sim.engine.kinematics.wall_contact_time`)."""
    rule = (_straight_to_still if gravity is None and motion is None and edge is None
            else _first_wall_contact)
    return rule(gravity, motion, axis, t_abs, x, v, radius, edge, geometry, horizon)


@overload(predict_wall_contact, inline="always")
def _predict_wall_contact(gravity, motion, axis, t_abs, x, v, radius, edge, geometry, horizon):
    if gravity is types.none and motion is types.none and edge is types.none:
        return _straight_to_still
    return _first_wall_contact


def _straight_to_still(gravity, motion, axis, t_abs, x, v, radius, edge, geometry, horizon):
    return wall_contact_time(x, v, radius, geometry[SIDE + axis])


def _first_wall_contact(gravity, motion, axis, t_abs, x, v, radius, edge, geometry, horizon):
    a = acceleration(gravity, axis)
    best = INF
    best_side = -1
    for side in range(2):
        wall = 2 * axis + side
        sign = 1.0 - 2.0 * side
        rest = geometry[SIDE + axis] * side
        speed, amplitude, omega = wall_motion_of(motion, wall)
        h = sign * (x - rest - speed * t_abs) - radius
        closing = sign * (v - edge_velocity(speed, sign, edge))
        if amplitude == 0.0:
            tau = first_contact_accelerated(h, closing, sign * a)
            touching = True
        else:
            tau, touching = first_contact_oscillating(
                h, closing, sign * a, amplitude, omega,
                omega * t_abs + (0.0 if side == 0 else math.pi),
                CONTACT_TOLERANCE * geometry[SIDE + axis], min(horizon, best))
        if tau < best:
            best = tau
            best_side = side if touching else -1
    return best, best_side


def _no_work(motion, m, v_after, v_before, lost):
    return 0.0


@effect_rule(_no_work)
def moving_wall_work(motion, m, v_after, v_before, lost):
    """Work a moving wall does on a disk of mass m whose normal velocity went from
    ``v_before`` to ``v_after`` while ``lost`` was dissipated: ΔE_kin + lost."""
    return 0.5 * m * (v_after**2 - v_before * v_before) + lost


def edge_velocity(u, sign, edge):
    """The velocity of a wall at u seen by a disk whose edge moves out from its centre at
    ``edge`` (a growing disk, :mod:`sim.effects.growth`): u + sign Ṙ; u itself for a disk that
    does not grow (``edge`` None, compiled away)."""
    return u if edge is None else u + sign * edge


@overload(edge_velocity, inline="always")
def _edge_velocity(u, sign, edge):
    if edge is types.none:
        return lambda u, sign, edge: u
    return lambda u, sign, edge: u + sign * edge


@njit(cache=True, inline="always")
def hit_wall(i, wall, t_abs, xi_wall, disks, m, geometry, effects, key, radius, edge):
    """Disk i (mass m, radius ``radius``, at the time of contact) touches ``wall``: clamp it
    inside the wall against round-off, then reflect it, v_n' − u = −ξ_w (v_n − u) in the
    frame of the wall moving at u (hard wall; for a disk growing at Ṙ = ``edge`` the frame of
    its edge, u + sign Ṙ), or redraw its velocity (thermal wall). The walls' effects
    (``wall_motion``, ``wall_temperature``, ``gravity``, ``tc``) come from ``effects``.

    Returns (energy dissipated, momentum given to the wall along its axis, work done by the
    wall on the disk), so that E_kin changes by work − dissipated. A disk found receding
    from the wall (round-off) keeps its velocity, unless it rests on a floor under gravity
    and the TC model (:func:`sim.effects.gravity.resting_lift`); without that model such a
    disk stalls the clock (:class:`sim.engine.errors.StalledError`).
    """
    motion = effects.wall_motion
    axis = wall >> 1
    other = 1 - axis
    sign = 1.0 - 2.0 * (wall & 1)
    position, u = wall_state(motion, wall, t_abs, geometry)
    inside = position + sign * radius
    if sign * (disks[i, X + axis] - inside) < 0.0:
        disks[i, X + axis] = inside
    v_n = disks[i, VX + axis]
    v_t = disks[i, VX + other]
    redrawn, impulse, work = thermal_redraw(effects.wall_temperature, key, wall, u, sign, m,
                                            disks, i, v_n, v_t)
    if redrawn:
        return 0.0, impulse, work
    u = edge_velocity(u, sign, edge)
    w_n = v_n - u
    if sign * w_n >= 0.0:
        lifted, lift = resting_lift(effects.gravity, effects.tc, motion, disks, i, axis, sign)
        if lifted:
            return 0.0, -m * lift, 0.5 * m * lift * lift
        return 0.0, 0.0, 0.0
    disks[i, VX + axis] = u - xi_wall * w_n
    lost = 0.5 * (1.0 - xi_wall * xi_wall) * m * w_n * w_n
    work = moving_wall_work(motion, m, disks[i, VX + axis], v_n, lost)
    return lost, m * (v_n - disks[i, VX + axis]), work
