"""Rough disks: spin, tangential restitution and Coulomb friction at a contact.

Disk i has mass m_i, radius a_i, spin ω_i (a scalar: the angular velocity about ẑ,
counter-clockwise positive) and moment of inertia I_i = q m_i a_i² (q = 1/2 for a uniform
disk, 1 for a ring). At a contact n is the unit vector from the centre of j to the centre of i
and t = ẑ × n = (−n_y, n_x). The touching points move apart at

    g = v_i − v_j − (a_i ω_i + a_j ω_j) t

(the point of i sits at −a_i n from its centre, that of j at +a_j n from its). Spin does not
enter g·n, so the normal impulse is the smooth rule of :func:`sim.engine.contact.collide_disks`
or :func:`sim.effects.walls.hit_wall`; the functions here add the tangential impulse P_t t on
i (−P_t t on j) after it:

    Δv_i = P_t t/m_i,  Δv_j = −P_t t/m_j,  Δω_i = −a_i P_t/I_i,  Δω_j = −a_j P_t/I_j,

so that Δ(g·t) = P_t/m_t with 1/m_t = 1/m_i + 1/m_j + a_i²/I_i + a_j²/I_j = (1 + 1/q)/μ
(μ the reduced mass; a_i²/I_i = 1/(q m_i)). Two rules for P_t:

  constant tangential restitution β ∈ [−1, 1] (Huthmann & Zippelius, Phys. Rev. E 56, R6275
      (1997); Luding, Huthmann, McNamara & Zippelius, Phys. Rev. E 58, 3416 (1998)):
      g_t' = −β g_t, P_t = −(1 + β) m_t g_t. β = −1 is smooth (no impulse), β = 1 perfectly
      rough (elastic, g_t reversed); the contact loses (1 − β²) m_t g_t²/2 on top of the
      normal (1 − ξ²) μ g_n²/2.
  Walton's Coulomb friction μ_f ≥ 0 (Walton, Mech. Mater. 16, 239 (1993)): the contact
      sticks with β₀ unless that needs more than the friction cone allows,
      (1 + β₀) m_t |g_t| > μ_f P_n; then it slides, P_t = −sign(g_t) μ_f P_n. In one line
      P_t = −sign(g_t) min((1 + β₀) m_t |g_t|, μ_f P_n): the branches meet continuously, and
      the effective β = −1 + μ_f (1 + ξ)(1 + 1/q) |g_n|/|g_t| depends on the impact angle.

P_n ≥ 0 is the magnitude of the normal impulse just applied: (1 + ξ) μ |g_n| between disks,
the virial of :func:`sim.engine.contact.collide_disks` divided by |r_ij| = a_i + a_j;
(1 + ξ_w) m |v_n − u| at a wall, the absolute momentum :func:`sim.effects.walls.hit_wall`
gives the wall. Call these functions only after a normal impulse was applied (v_n < 0).

As an effect of a scene (:mod:`sim.effects`): ``roughness`` = :class:`Roughness` (q, β per
species pair, β_w per wall), or None for smooth disks, and then no code of rotation is
compiled; ``friction`` = :class:`Friction` (μ_f per species pair and per wall, inf where a
contact has no friction limit), or None; ``spin`` float64[n] in the disk state, or None when
no disk turns. Thermal walls (:mod:`sim.effects.thermal_walls`) redraw the velocity of a
leaving disk and leave its spin alone.

In the contact functions, ``friction`` is μ_f, or None without friction; then no code of it
is compiled (:mod:`sim.effects.rules`). ``spin`` is float64[n], updated in place like the disk table
(columns in :mod:`sim.engine.kinematics`). The derivation of the signs, the wall case and the
theory of cooling rough disks (:mod:`sim.analysis.theory`) are in docs/rough-disks.md.
"""

import math
import sys
from typing import NamedTuple

import numpy as np
from numba import njit

from sim.effects.pressure_tensor import observed
from sim.effects.rules import effect_rule
from sim.effects.thermal_walls import is_thermal, seed_value
from sim.effects.values import ConfigError, positive, select, within
from sim.engine.inputs import real_number, refused, shaped_reals
from sim.engine.kinematics import RADIUS, VX, VY
from sim.engine.parameters import per_disk

#: The tangential restitution of a smooth contact: no tangential impulse.
SMOOTH = -1.0

#: Seed offset of the initial spins' generator (apart from every other draw of the seed)
SPIN_STREAM = 0x5EED5

KEYWORDS = {
    "tangential_restitution": (None, "scalar or (s, s) symmetric tangential restitution β per "
                               "species pair in [−1, 1] (β₀ of Walton's model with friction): "
                               "−1 = smooth, 1 = perfectly rough"),
    "wall_tangential_restitution": (None, "β_w in [−1, 1], one for every wall or [4] (left, "
                                    "right, bottom, top); −1 = smooth"),
    "friction": (None, "scalar or (s, s) symmetric Coulomb friction coefficient μ_f per species "
                 "pair, finite and ≥ 0 (Walton's model; needs β₀ > −1); None = constant β"),
    "wall_friction": (None, "μ_f of the walls, finite and ≥ 0, one or [4]; None = constant β_w"),
    "inertia_factor": (0.5, "q of the moment of inertia I = q m a², in (0, 1] (1/2 uniform "
                            "disk, 1 ring)"),
    "spin": (None, "initial angular velocities ω float64[n] or one for all, finite "
                   "(counter-clockwise positive); default all 0"),
    "rotational_temperature": (0.0, "initial spins drawn from the Maxwellian at this T_rot = "
                               "⟨I ω²⟩, finite and ≥ 0 (keyed by ``seed``), instead of "
                               "``spin``"),
}


class Roughness(NamedTuple):
    """Rough contacts as the compiled loop takes them."""
    q: float  # I = q m a²
    beta: np.ndarray  # float64[s, s], β (β₀ with friction) per species pair
    beta_wall: np.ndarray  # float64[4], per wall


class Friction(NamedTuple):
    """Walton's friction as the compiled loop takes it; inf: no limit (constant β)."""
    mu: np.ndarray  # float64[s, s]
    mu_wall: np.ndarray  # float64[4]


def check_config(cfg):
    """β and β_w in [−1, 1], μ_f ≥ 0 or null, with a β₀ that can stick; q in (0, 1];
    T_rot ≥ 0."""
    r, f = cfg.restitution, cfg.friction
    allowed = "between −1 (smooth) and 1 (perfectly rough)"
    within("restitution.tangential", r.tangential, -1.0, 1.0, allowed)
    within("restitution.wall_tangential", r.wall_tangential, -1.0, 1.0, allowed)
    positive("friction.mu", f.mu, zero=True)
    positive("friction.wall_mu", f.wall_mu, zero=True)
    for mu, beta, key in ((f.mu, r.tangential, "restitution.tangential"),
                          (f.wall_mu, r.wall_tangential, "restitution.wall_tangential")):
        if mu is not None and beta == SMOOTH:
            raise ConfigError(key, beta, "β₀ > −1 with friction (β₀ = −1 never sticks: "
                                         "the contact stays smooth whatever μ_f)")
    rough = r.tangential > SMOOTH or r.wall_tangential > SMOOTH
    if cfg.box.boundary == "periodic":
        for key in ("restitution.wall_tangential", "friction.wall_mu"):
            default = SMOOTH if key.startswith("restitution") else None
            if select(cfg, key) != default:
                raise ConfigError(key, select(cfg, key),
                                  f"{default} in a periodic box, which has no walls")
    if rough and cfg.observe.pressure_tensor:
        raise ConfigError("observe.pressure_tensor", True, "false with rough disks (the "
                          "tangential impulses make the collision stress asymmetric; it is "
                          "not computed)")
    q = cfg.disks.inertia_factor
    if not 0.0 < q <= 1.0:
        raise ConfigError("disks.inertia_factor", q, "q = I/(m a²) in (0, 1] (1/2 uniform "
                                                     "disk, 1 ring)")
    within("disks.rotational_temperature", cfg.disks.rotational_temperature, 0.0,
           sys.float_info.max, "a finite temperature ≥ 0 (0: spins at rest)")


def engine_arguments(cfg):
    """β, β_w, μ_f, the walls' μ_f, q and the initial T_rot of the config."""
    r, f = cfg.restitution, cfg.friction
    return {"tangential_restitution": float(r.tangential),
            "wall_tangential_restitution": float(r.wall_tangential),
            "friction": f.mu, "wall_friction": f.wall_mu,
            "inertia_factor": float(cfg.disks.inertia_factor),
            "rotational_temperature": float(cfg.disks.rotational_temperature)}


#: what β and μ_f may be: (accept elementwise, the words)
BETA = (lambda x: (x >= -1.0) & (x <= 1.0), "values in [−1, 1] (−1 smooth, 1 perfectly rough)")
MU = (lambda x: (x >= 0.0) & (x < math.inf), "finite values ≥ 0")


def _pairs(value, n_species, default, name, values):
    """The keyword ``name``: None (every pair ``default``), one number or a symmetric
    (s, s) matrix of ``values`` (:data:`BETA`, :data:`MU`), as float64[s, s]."""
    s = n_species
    if value is None:
        return np.full((s, s), default)
    accept, words = values
    matrix = np.array(np.broadcast_to(shaped_reals(
        "Engine", name, value, ((), (s, s)), accept,
        f"one number or a symmetric {s} × {s} matrix (a row and a column per species) of "
        f"{words}, or None"), (s, s)))
    if not np.array_equal(matrix, matrix.T):
        raise refused("Engine", name, value, f"a symmetric {s} × {s} matrix: the value of "
                                             f"the pair (a, b) is that of (b, a)",
                      show=matrix.size <= 4)
    return matrix


def _walls(value, default, name, values):
    """The keyword ``name``: None (every wall ``default``), one number or four (left, right,
    bottom, top) of ``values``, as float64[4]."""
    if value is None:
        return np.full(4, default)
    accept, words = values
    return np.array(np.broadcast_to(shaped_reals(
        "Engine", name, value, ((), (4,)), accept,
        f"one number for every wall or four (left, right, bottom, top) of {words}, or None"),
        (4,)))


def loop_values(keywords, context):
    """Roughness, friction and the spins (None when every contact is smooth and no disk
    turns); the initial spins from ``spin`` or drawn at ``rotational_temperature``. Each
    keyword is checked as :data:`KEYWORDS` says, naming it; friction on smooth contacts (β₀ =
    −1 never sticks), wall values in a box without walls and the pressure tensor of rough
    contacts (their impulses make it asymmetric) are refused."""
    s = context["n_species"]
    beta = _pairs(keywords["tangential_restitution"], s, SMOOTH, "tangential_restitution",
                  BETA)
    beta_wall = _walls(keywords["wall_tangential_restitution"], SMOOTH,
                       "wall_tangential_restitution", BETA)
    mu = _pairs(keywords["friction"], s, math.inf, "friction", MU)
    mu_wall = _walls(keywords["wall_friction"], math.inf, "wall_friction", MU)
    q = real_number("Engine", "inertia_factor", keywords["inertia_factor"],
                    lambda x: 0.0 < x <= 1.0,
                    "q = I/(m a²) in (0, 1] (1/2 uniform disk, 1 ring)")
    if np.all(context["periodic"]):
        for name, given in (("wall_friction", keywords["wall_friction"] is not None),
                            ("wall_tangential_restitution", np.any(beta_wall > SMOOTH))):
            if given:
                raise refused("Engine", name, keywords[name], "None: a periodic box has no "
                                                              "walls", show=True)
    for b, m in zip((*beta.ravel(), *beta_wall), (*mu.ravel(), *mu_wall), strict=True):
        rough_parameters(b, None if m == math.inf else m, q)
    for given, sticking, name in ((keywords["friction"], beta, "friction"),
                                  (keywords["wall_friction"], beta_wall, "wall_friction")):
        if given is not None and np.all(sticking == SMOOTH):
            raise refused("Engine", name, given, "None with smooth contacts: friction needs a "
                                                 "sticking tangential restitution β₀ > −1 (β₀ = "
                                                 "−1 never sticks: the contact stays smooth "
                                                 "whatever μ_f)", show=True)
    rough = bool(np.any(beta > SMOOTH) or np.any(beta_wall > SMOOTH))
    if rough and observed(keywords["pressure_tensor"]):
        raise refused("Engine", "pressure_tensor", keywords["pressure_tensor"],
                      "False with rough disks: the pressure tensor of rough disks is not "
                      "computed (the tangential impulses make the collision stress asymmetric)")
    spin = initial_spins(keywords, context, q)
    if not rough and not np.any(spin):
        return {"roughness": None, "friction": None, "spin": None}
    limited = np.isfinite([*mu.ravel(), *mu_wall]).any()
    return {"roughness": Roughness(q, beta, beta_wall) if rough else None,
            "friction": Friction(mu, mu_wall) if limited else None,
            "spin": spin}


def dissipates(roughness, friction):
    """Whether rough contacts lose energy (|β| < 1 somewhere, or friction)."""
    return roughness is not None and (
        friction is not None or bool(np.any(np.abs(roughness.beta) < 1.0))
        or bool(np.any(np.abs(roughness.beta_wall) < 1.0)))


def initial_spins(keywords, context, q):
    """float64[n]: ``spin`` as given (one finite number or n), or Maxwellian at
    ``rotational_temperature`` (finite and ≥ 0; keyed by ``seed``; zero at T = 0); each
    checked, naming it."""
    n = context["n"]
    temperature = real_number("Engine", "rotational_temperature",
                              keywords["rotational_temperature"],
                              lambda t: 0.0 <= t < math.inf,
                              "a finite temperature ≥ 0 (0: spins at rest or as ``spin``)")
    if keywords["spin"] is not None:
        spin = shaped_reals("Engine", "spin", keywords["spin"], ((), (n,)), np.isfinite,
                            f"one finite number or n = {n} of them (each spin must be a finite "
                            f"angular velocity), or None")
        if temperature:
            raise refused("Engine", "rotational_temperature", keywords["rotational_temperature"],
                          "0 when ``spin`` is given: give the initial spins or a rotational "
                          "temperature, not both")
        return np.array(np.broadcast_to(spin, (n,)))
    if not temperature:
        return np.zeros(n)
    inertia = moment_of_inertia(q, context["mass"], context["radius"])
    rng = np.random.default_rng([seed_value(keywords["seed"]), SPIN_STREAM])
    return maxwellian_spins(rng, temperature, inertia)


def _no_friction(friction, s_i, s_j):
    return None


@effect_rule(_no_friction)
def friction_of(friction, s_i, s_j):
    """μ_f of a contact between species s_i and s_j."""
    return friction.mu[s_i, s_j]


def _no_wall_friction(friction, wall):
    return None


@effect_rule(_no_wall_friction)
def wall_friction_of(friction, wall):
    """μ_f of a contact with ``wall``."""
    return friction.mu_wall[wall]


def _constant_beta(friction, beta, m_t, g_t, normal_impulse):
    return -(1.0 + beta) * m_t * g_t


@effect_rule(_constant_beta)
def tangential_impulse(friction, beta, m_t, g_t, normal_impulse):
    """P_t of a contact with tangential mass m_t and tangential relative velocity g_t:
    −(1 + β) m_t g_t without friction (``friction`` None), else Walton's
    −sign(g_t) min((1 + β₀) m_t |g_t|, μ_f P_n), P_n = ``normal_impulse`` ≥ 0."""
    sticking = (1.0 + beta) * m_t * abs(g_t)
    sliding = friction * normal_impulse
    return -math.copysign(min(sticking, sliding), g_t)


@njit(cache=True, inline="always")
def rough_contact(i, j, nx, ny, normal_impulse, disks, spin, m_i, m_j, q, beta, friction):
    """Apply the tangential impulse of a contact between disks i and j (masses m_i, m_j,
    radii from the disk table, moments of inertia q m a²) with unit normal n = (nx, ny) from
    j to i, after a normal impulse of magnitude P_n = ``normal_impulse``.

    g_t = (v_i − v_j)·t − a_i ω_i − a_j ω_j, m_t = q μ/(1 + q), P_t from
    :func:`tangential_impulse`; updates ``disks`` velocities and ``spin`` in place. Returns
    the energy lost, −P_t (g_t + g_t')/2 = (1 − β²) m_t g_t²/2 for constant β.
    """
    a_i = disks[i, RADIUS]
    a_j = disks[j, RADIUS]
    tx = -ny
    ty = nx
    g_t = ((disks[i, VX] - disks[j, VX]) * tx + (disks[i, VY] - disks[j, VY]) * ty
           - (a_i * spin[i] + a_j * spin[j]))
    m_t = q * m_i * m_j / ((1.0 + q) * (m_i + m_j))
    p_t = tangential_impulse(friction, beta, m_t, g_t, normal_impulse)
    dv_i = p_t / m_i
    dv_j = p_t / m_j
    disks[i, VX] += dv_i * tx
    disks[i, VY] += dv_i * ty
    disks[j, VX] -= dv_j * tx
    disks[j, VY] -= dv_j * ty
    spin[i] -= dv_i / (q * a_i)  # −a_i P_t/I_i
    spin[j] -= dv_j / (q * a_j)
    return -p_t * (g_t + 0.5 * p_t / m_t)


@njit(cache=True, inline="always")
def rough_wall(i, wall, normal_impulse, disks, spin, m, q, beta, friction):
    """Apply the tangential impulse of disk i (mass m, moment of inertia q m a²) touching
    ``wall`` (numbered as in :mod:`sim.effects.walls`), after a normal impulse of magnitude
    P_n = ``normal_impulse``.

    The wall is a partner j of infinite mass and inertia whose surface does not move along
    itself: n = sign e_axis points from the wall into the box, t = ẑ × n has the component
    sign (1 − 2 axis) along the other axis, g_t = v_i·t − a ω_i and m_t = q m/(1 + q).
    Updates the disk's tangential velocity and spin in place; returns the energy lost.
    """
    axis = wall >> 1
    other = 1 - axis
    t_other = (1.0 - 2.0 * (wall & 1)) * (1.0 - 2.0 * axis)
    a = disks[i, RADIUS]
    g_t = t_other * disks[i, VX + other] - a * spin[i]
    m_t = q * m / (1.0 + q)
    p_t = tangential_impulse(friction, beta, m_t, g_t, normal_impulse)
    dv = p_t / m
    disks[i, VX + other] += dv * t_other
    spin[i] -= dv / (q * a)
    return -p_t * (g_t + 0.5 * p_t / m_t)


def _no_tc(tc, beta, t, t_last_i, t_last_j):
    return beta


@effect_rule(_no_tc)
def tc_roughness(tc, beta, t, t_last_i, t_last_j):
    """The tangential restitution of a contact at time t whose partners last touched anything
    at ``t_last_i`` and ``t_last_j`` under the TC model (:mod:`sim.effects.tc`): smooth
    (β = −1, no tangential impulse, with or without friction) within t_c, else β.

    The TC model makes a contact within t_c of the one before elastic, so that lasting
    contacts do not dissipate. Of the two tangential rules that conserve energy, β = 1 would
    still exchange spin and sliding velocity at every one of the many contacts of a cluster
    or a disk resting on a floor, driving rotation from contacts that stand for one lasting
    touch; β = −1 leaves spins and tangential velocities alone, so the contact is the
    elastic smooth contact of the TC model for smooth disks, and a disk resting on a floor
    keeps its rolling or sliding state. Normal and tangential rules then agree: within t_c
    nothing is dissipated and nothing is exchanged.
    """
    if t - t_last_i < tc or t - t_last_j < tc:
        return SMOOTH
    return beta


def rough_parameters(beta, friction, q):
    """(β, μ_f or None, q) as floats for the compiled loop, checked: β ∈ [−1, 1], μ_f finite
    and ≥ 0 (μ_f = 0 makes every contact smooth), q ∈ (0, 1] (no disk has mass beyond its
    rim)."""
    if not -1.0 <= beta <= 1.0:
        raise ValueError(f"tangential restitution β must lie in [−1, 1], got {beta}")
    if friction is not None and not 0.0 <= friction < math.inf:
        raise ValueError(f"friction coefficient must be finite and ≥ 0, or None; got {friction}")
    if not 0.0 < q <= 1.0:
        raise ValueError(f"q = I/(m a²) must lie in (0, 1], got {q}")
    return float(beta), None if friction is None else float(friction), float(q)


def moment_of_inertia(q, m, a):
    """I = q m a² (q = 1/2 uniform disk, 1 ring); arrays broadcast."""
    return q * np.asarray(m) * np.asarray(a) ** 2


def rotational_energy(spin, inertia):
    """Σ I ω²/2 over the disks."""
    return 0.5 * float(np.sum(np.asarray(inertia) * np.asarray(spin) ** 2))


def translational_temperature(velocities, masses):
    """T_tr = ⟨m v²⟩/2 over two degrees of freedom (E_kin,tr/N, no mean flow subtracted);
    ``velocities`` float64[n, 2], ``masses`` float or float64[n]."""
    v = np.asarray(velocities)
    return 0.5 * float(np.mean(np.asarray(masses) * np.sum(v * v, axis=1)))


def rotational_temperature(spin, inertia):
    """T_rot = ⟨I ω²⟩ over the one rotational degree of freedom (2 E_rot/N)."""
    return float(np.mean(np.asarray(inertia) * np.asarray(spin) ** 2))


def maxwellian_spins(rng, temperature, inertia):
    """Spins drawn from the Maxwellian at rotational temperature T: ω ~ N(0, T/I) per disk,
    so that ⟨I ω²⟩ = T. ``rng`` a numpy Generator, ``inertia`` float64[n]."""
    inertia = np.asarray(inertia, dtype=float)
    return rng.normal(0.0, 1.0, inertia.shape) * np.sqrt(temperature / inertia)


def _smooth_disks(roughness, effects, i, j, rx, ry, virial, t, disks, m_i, m_j):
    return 0.0


@effect_rule(_smooth_disks)
def rough_collision(roughness, effects, i, j, rx, ry, virial, t, disks, m_i, m_j):
    """The tangential part of the collision of disks i and j (masses m_i, m_j; the loop's
    groups ``effects`` and ``disks``, :mod:`sim.engine.groups`) at time t, at separation
    r = r_i − r_j, after the normal impulse whose virial r·Δp_i = P_n |r| the smooth rule
    returned (zero: no contact, nothing to do), with friction and the TC model's choice
    (:func:`tc_roughness`) when the scene has them. Returns the energy lost."""
    if virial <= 0.0:
        return 0.0
    t_last = disks.t_last
    s_i = per_disk(disks.species, i)
    s_j = per_disk(disks.species, j)
    beta = tc_roughness(effects.tc, roughness.beta[s_i, s_j], t, t_last[i], t_last[j])
    inverse_r = 1.0 / math.sqrt(rx * rx + ry * ry)
    return rough_contact(i, j, rx * inverse_r, ry * inverse_r, virial * inverse_r, disks.table,
                         effects.spin, m_i, m_j, roughness.q, beta,
                         friction_of(effects.friction, s_i, s_j))


def _smooth_wall(roughness, effects, i, wall, impulse, t, disks, m):
    return 0.0


@effect_rule(_smooth_wall)
def rough_wall_contact(roughness, effects, i, wall, impulse, t, disks, m):
    """The tangential part of disk i's contact with ``wall`` at time t, after the wall gave
    it the momentum ``impulse`` along its axis (zero: no contact); a thermal wall
    (``effects.wall_temperature``) redraws the velocity and keeps the spin. Returns the
    energy lost."""
    if impulse == 0.0 or is_thermal(effects.wall_temperature, wall):
        return 0.0
    t_last = disks.t_last
    beta = tc_roughness(effects.tc, roughness.beta_wall[wall], t, t_last[i], t_last[i])
    return rough_wall(i, wall, abs(impulse), disks.table, effects.spin, m, roughness.q, beta,
                      wall_friction_of(effects.friction, wall))
