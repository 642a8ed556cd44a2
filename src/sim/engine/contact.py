"""The impulse of a contact between two smooth hard disks.

With unit normal n = r_ij/|r_ij|, normal relative speed v_n = (v_i - v_j)·n < 0, reduced mass
μ = m_i m_j/(m_i + m_j) and normal restitution ξ (1 when elastic;
:mod:`sim.effects.restitution`), the impulse on i is Δp_i = -(1 + ξ) μ v_n n = -Δp_j
(Brilliantov & Pöschel, *Kinetic Theory of Granular Gases*, §1). Momentum is conserved and
the kinetic energy falls by exactly (1 - ξ²) μ v_n²/2. The collision virial
r_ij·Δp_i = -(1 + ξ) μ v_n |r_ij| enters the pressure. A wall contact is the rule of
:mod:`sim.effects.walls`.

:func:`collide_disks` returns ``(dissipated energy, virial term)`` and updates velocities in
place in the disk table ``disks`` (columns in :mod:`sim.engine.kinematics`); masses are passed
as values.
"""

import math

from numba import njit

from sim.engine.kinematics import VX, VY


@njit(cache=True, inline="always")
def collide_disks(i, j, rx, ry, xi, disks, m_i, m_j):
    """Apply the impulse of a contact between disks i and j (masses m_i, m_j) at separation
    r = r_i - r_j.

    Returns (energy dissipated, r·Δp_i). Disks found separating (v_n ≥ 0, possible only by
    round-off) are left alone. With M = m_i + m_j the velocity changes are
    Δv_i = -(1 + ξ) v_n (m_j/M) n and Δv_j = +(1 + ξ) v_n (m_i/M) n: two divisions in all.
    """
    r = math.sqrt(rx * rx + ry * ry)
    inverse_r = 1.0 / r
    nx = rx * inverse_r
    ny = ry * inverse_r
    v_n = (disks[i, VX] - disks[j, VX]) * nx + (disks[i, VY] - disks[j, VY]) * ny
    if v_n >= 0.0:
        return 0.0, 0.0
    inverse_total = 1.0 / (m_i + m_j)
    mu = m_i * m_j * inverse_total
    dv = (1.0 + xi) * v_n * inverse_total
    dv_i = dv * m_j
    dv_j = dv * m_i
    disks[i, VX] -= dv_i * nx
    disks[i, VY] -= dv_i * ny
    disks[j, VX] += dv_j * nx
    disks[j, VY] += dv_j * ny
    return 0.5 * (1.0 - xi * xi) * mu * v_n * v_n, -(1.0 + xi) * mu * v_n * r
