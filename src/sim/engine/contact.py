"""The impulse of a contact between two smooth hard disks.

With unit normal n = r_ij/|r_ij|, normal relative speed v_n = (v_i - v_j)·n < 0, reduced mass
μ = m_i m_j/(m_i + m_j) and normal restitution ξ (1 when elastic;
:mod:`sim.effects.restitution`), the impulse on i is Δp_i = -(1 + ξ) μ v_n n = -Δp_j
(Brilliantov & Pöschel, *Kinetic Theory of Granular Gases*, §1). Momentum is conserved and
the kinetic energy falls by exactly (1 - ξ²) μ v_n²/2. The collision virial
r_ij·Δp_i = -(1 + ξ) μ v_n |r_ij| enters the pressure. Growing disks
(:mod:`sim.effects.growth`), whose contact distance grows at ṡ, take v_n − ṡ for v_n: the
impulse is μ (1 + ξ)(ṡ − v_n) n on i, and they part at ṡ − ξ (v_n − ṡ) (Donev, Torquato &
Stillinger, J. Comput. Phys. 202, 737 (2005)). A wall contact is the rule of
:mod:`sim.effects.walls`.

:func:`collide_disks` returns ``(dissipated energy, virial term)`` and updates velocities in
place in the disk table ``disks`` (columns in :mod:`sim.engine.kinematics`); masses are passed
as values.
"""

import math

from numba import njit, types
from numba.extending import overload

from sim.engine.kinematics import VX, VY


def growth_frame(v_n, sigma_rate):
    """The normal speed v_n seen from a contact growing at ``sigma_rate``: v_n − ṡ, or v_n
    itself when the disks do not grow (``sigma_rate`` None, compiled away)."""
    return v_n if sigma_rate is None else v_n - sigma_rate


@overload(growth_frame, inline="always")
def _growth_frame(v_n, sigma_rate):
    if sigma_rate is types.none:
        return lambda v_n, sigma_rate: v_n
    return lambda v_n, sigma_rate: v_n - sigma_rate


@njit(cache=True, inline="always")
def collide_disks(i, j, rx, ry, xi, disks, m_i, m_j, sigma_rate):
    """Apply the impulse of a contact between disks i and j (masses m_i, m_j) at separation
    r = r_i - r_j, their contact distance growing at ``sigma_rate`` (None: not growing).

    Returns (energy dissipated, r·Δp_i); growing disks dissipate (1 − ξ²) μ (v_n − ṡ)²/2, and
    growth does the rest of the change of kinetic energy. Disks found separating (v_n ≥ 0,
    possible only by round-off; v_n ≥ ṡ when growing) are left alone. With M = m_i + m_j the
    velocity changes are Δv_i = -(1 + ξ) v_n (m_j/M) n and Δv_j = +(1 + ξ) v_n (m_i/M) n: two
    divisions in all.
    """
    r = math.sqrt(rx * rx + ry * ry)
    inverse_r = 1.0 / r
    nx = rx * inverse_r
    ny = ry * inverse_r
    v_n = growth_frame((disks[i, VX] - disks[j, VX]) * nx + (disks[i, VY] - disks[j, VY]) * ny,
                       sigma_rate)
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
