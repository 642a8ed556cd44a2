"""Closed-form results the figures and tests compare against (sources in physics.md).

Units: k_B = 1, temperature in 2D T = E_kin / N; speeds in box units per time unit.
"""

import numpy as np
from scipy.optimize import brentq


def maxwell_speed_pdf(v, mass, temperature):
    """2D Maxwell–Boltzmann speed density f(v) = (m v / T) exp(−m v² / 2T)."""
    return mass * v / temperature * np.exp(-mass * v**2 / (2.0 * temperature))


def maxwell_speed_cdf(v, mass, temperature):
    """Its distribution function 1 − exp(−m v² / 2T)."""
    return 1.0 - np.exp(-mass * np.asarray(v) ** 2 / (2.0 * temperature))


def garzo_dufty_cooling_rates(temperatures, masses, fractions, restitution):
    """Cooling rates ζ_i of a 2D binary mixture of equal-size disks, up to a common factor
    (Garzó & Dufty, Phys. Rev. E 60, 5706 (1999); physics.md, "Binary mixture"):
    ζ_i ∝ Σ_j x_j μ_ji (1 + ξ) √(T_i/m_i + T_j/m_j) [1 − ½ μ_ji (1 + ξ)(1 + m_i T_j/(m_j T_i))]
    with μ_ji = m_j / (m_i + m_j)."""
    T, m, x, xi = (np.asarray(a, dtype=float) for a in (temperatures, masses, fractions,
                                                        restitution))
    rates = np.zeros(T.size)
    for i in range(T.size):
        for j in range(T.size):
            mu_ji = m[j] / (m[i] + m[j])
            rates[i] += (x[j] * mu_ji * (1 + xi) * np.sqrt(T[i] / m[i] + T[j] / m[j])
                         * (1 - 0.5 * mu_ji * (1 + xi) * (1 + m[i] * T[j] / (m[j] * T[i]))))
    return rates


def garzo_dufty_temperature_ratio(masses, fractions, restitution):
    """T₂/T₁ of the homogeneous cooling state: the root of ζ₁ = ζ₂ (1 at ξ = 1)."""
    if restitution == 1.0:
        return 1.0

    def difference(ratio):
        z = garzo_dufty_cooling_rates([1.0, ratio], masses, fractions, restitution)
        return z[0] - z[1]

    return brentq(difference, 1e-3, 1e3, xtol=1e-14)
