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

``friction`` is μ_f, or None without friction; then no code of it is compiled
(:mod:`sim.effects.rules`). ``spin`` is float64[n], updated in place like the disk table
(columns in :mod:`sim.engine.kinematics`). The derivation of the signs, the wall case and the
theory of cooling rough disks (:mod:`sim.analysis.theory`) are in docs/rough-disks.md.
"""

import math

import numpy as np
from numba import njit

from sim.effects.rules import effect_rule
from sim.engine.kinematics import RADIUS, VX, VY

#: The tangential restitution of a smooth contact: no tangential impulse.
SMOOTH = -1.0


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
