"""Closed-form results the figures, the validation studies and the tests compare against, each
with its source.

Units: k_B = 1, temperature in 2D T = E_kin / N; speeds in box units per time unit; packing
fraction φ = Σ πR² / A; σ the disk diameter.
"""

import math

import numpy as np
from scipy.optimize import brentq

#: Kolafa & Rottner, Mol. Phys. 104, 3435 (2006), Eq. (7) with the fit up to ρσ² = 0.90
#: (φ ≤ 0.707): Z = Σ A_i x^i, x = φ/(1 − φ), as {i: A_i}. It passes within about one error bar
#: through their molecular dynamics data (relative errors 2e-6 … 1e-5) and expands to the exact
#: B₃ and the known B₄.
KOLAFA_ROTTNER = {0: 1.0, 1: 2.0, 2: 1.12801775, 3: 0.00181895291, 4: -0.0526134737,
                  5: 0.0504960168, 6: -0.0325537792, 7: 0.0134578632, 8: 0.00140888182,
                  9: -0.00834273601, 10: 0.00694127367, 11: -0.00262254723,
                  12: 0.000355746352, 22: -5.24672938e-9, 57: 5.88054639e-23}


def henderson_z(phi):
    """Compressibility factor Z = PA/(N T) of the hard-disk fluid at packing fraction φ,
    Henderson, Mol. Phys. 30, 971 (1975): Z = (1 + φ²/8)/(1 − φ)²."""
    return (1.0 + phi * phi / 8.0) / (1.0 - phi) ** 2


def kolafa_rottner_z(phi):
    """Compressibility factor Z = PA/(N T) of the hard-disk fluid at packing fraction φ, the
    fit of Kolafa & Rottner, Mol. Phys. 104, 3435 (2006) (:data:`KOLAFA_ROTTNER`)."""
    x = phi / (1.0 - phi)
    return sum(a * x**i for i, a in KOLAFA_ROTTNER.items())


def mixture_z(phi, diameters, fractions, pure=kolafa_rottner_z):
    """Compressibility factor of a mixture of hard disks of ``diameters`` in number
    ``fractions`` at total packing fraction φ, mapped onto the one-size fluid's Z_s = ``pure``
    (Santos, Yuste & López de Haro, Mol. Phys. 96, 1 (1999), arXiv:cond-mat/0204246, for
    d = 2): Z = 1/(1 − φ) + (⟨σ⟩²/⟨σ²⟩)[Z_s(φ) − 1/(1 − φ)], exact to second order in φ (its
    B₂ is the mixture's, (π/8)(⟨σ²⟩ + ⟨σ⟩²)). Santos, Yuste, López de Haro & Ogarko
    (arXiv:1703.03825) test it against event-driven MD of 26 polydisperse mixtures: the
    data collapse on it in the stable fluid and follow it less closely in the metastable
    one."""
    diameters, fractions = np.asarray(diameters, float), np.asarray(fractions, float)
    ratio = float(np.sum(fractions * diameters)) ** 2 / float(np.sum(fractions * diameters**2))
    free = 1.0 / (1.0 - np.asarray(phi))
    return free + ratio * (pure(phi) - free)


def free_volume_z(phi, phi_jamming):
    """βP/ρ ≈ d/(1 − φ/φ_J) of hard disks (d = 2) near their jamming density φ_J: the
    free-volume form, each disk rattling in a cage whose size vanishes as φ → φ_J
    (Salsburg & Wood, J. Chem. Phys. 37, 798 (1962); Donev, Torquato & Stillinger, PRE 71,
    011105 (2005))."""
    return 2.0 / (1.0 - np.asarray(phi) / phi_jamming)


def enskog_collision_frequency(n_density, sigma, chi, temperature, mass=1.0):
    """Collisions per disk per unit time in the hard-disk fluid, Enskog's ω = 2 n σ χ √(πT/m):
    a disk sweeps a strip of width 2σ at the mean relative speed √(πT/m) of two Maxwellian
    disks, and χ = g(σ⁺) = (Z − 1)/(2φ) raises the rate of contacts over the dilute gas's
    (Enskog's dense gas, Chapman & Cowling, *The Mathematical Theory of Non-uniform Gases*,
    in 2D). ``n_density`` disks per unit area, ``sigma`` the diameter; 1/time."""
    return 2.0 * n_density * sigma * chi * math.sqrt(math.pi * temperature / mass)


def maxwell_speed_pdf(v, mass, temperature):
    """2D Maxwell–Boltzmann speed density f(v) = (m v / T) exp(−m v² / 2T)."""
    return mass * v / temperature * np.exp(-mass * v**2 / (2.0 * temperature))


def maxwell_speed_cdf(v, mass, temperature):
    """Its distribution function 1 − exp(−m v² / 2T)."""
    return 1.0 - np.exp(-mass * np.asarray(v) ** 2 / (2.0 * temperature))


def garzo_dufty_cooling_rates(temperatures, masses, fractions, restitution):
    """Cooling rates ζ_i of a 2D binary mixture of equal-size disks, up to a common factor
    (Garzó & Dufty, Phys. Rev. E 60, 5706 (1999); docs/physics.md, "Binary mixtures"):
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


def garzo_dufty_haff_temperature(t, temperature0, masses, fractions, restitution, n_density,
                                 sigma, chi):
    """Haff's law of the mixture temperature T = Σ_s x_s T_s in the homogeneous cooling state
    of a binary mixture of equal-size disks: T(t) = T₀/(1 + ζ₀t/2)², ζ₀ the common cooling rate
    ζ₁ = ζ₂ of :func:`garzo_dufty_cooling_rates` at T₀ and the ratio of
    :func:`garzo_dufty_temperature_ratio`, made absolute by the factor 2√(2π) n σ χ (with it,
    one species gives ζ = (1 − ξ²) n σ χ √(πT/m) = (1 − ξ²) ω/2, ω Enskog's collision frequency
    :func:`enskog_collision_frequency`). Maxwellian velocity distributions; ``n_density``
    disks per unit area, ``sigma`` the diameter (in one length unit L), ``t`` in L√(m/T) with
    the masses' and temperatures' units."""
    x = np.asarray(fractions, dtype=float) / np.sum(fractions)
    ratio = garzo_dufty_temperature_ratio(masses, x, restitution)
    t1 = temperature0 / (x[0] + x[1] * ratio)
    rate = (2.0 * math.sqrt(2.0 * math.pi) * n_density * sigma * chi
            * garzo_dufty_cooling_rates([t1, ratio * t1], masses, x, restitution)[0])
    return temperature0 / (1.0 + 0.5 * rate * np.asarray(t)) ** 2


def rough_disk_cooling_coefficients(xi, beta, q):
    """(A, B, C) of the cooling of a dilute gas of equal rough disks (normal restitution ξ,
    tangential restitution β, I = q m a²; :mod:`sim.effects.rotation`) in the two-temperature
    Maxwellian approximation (Huthmann & Zippelius, Phys. Rev. E 56, R6275 (1997); Luding,
    Huthmann, McNamara & Zippelius, Phys. Rev. E 58, 3416 (1998); Santos, arXiv:1803.04290 for
    disks):

        dT_tr/dt = −ν (A T_tr − B T_rot),   dT_rot/dt = 2ν (B T_tr − C T_rot),

    A = (1 − ξ²)/2 + η(1 − η), B = η²/q, C = (η/q)(1 − η/q), η = q(1 + β)/(2(1 + q)), with
    ν = :func:`enskog_collision_frequency` at T_tr and T_tr = m⟨v²⟩/2, T_rot = I⟨ω²⟩. The
    Maxwellian average of the contact rule that gives them is derived in docs/rough-disks.md
    (in 2D the tangent is one-dimensional and there is one rotational degree of freedom
    against two translational ones: hence (1 − ξ²)/2 and the factor 2, where 3D has
    (1 − ξ²)/4 and equal prefactors)."""
    eta = q * (1.0 + beta) / (2.0 * (1.0 + q))
    return (0.5 * (1.0 - xi * xi) + eta * (1.0 - eta), eta * eta / q,
            eta / q * (1.0 - eta / q))


def rough_disk_temperature_ratio(xi, beta, q):
    """r = T_rot/T_tr of the homogeneous cooling state of rough disks, two-temperature
    Maxwellian approximation (:func:`rough_disk_cooling_coefficients`).

    Both temperatures decay at the same rate: 2(B/r − C) = −(A − B r), the positive root of
    B r² + (2C − A) r − 2B = 0 (the roots' product is −2). ξ = β = 1 gives r = 1
    (equipartition) for every q. β = −1 decouples spin (B = C = 0) and the equation leaves
    r = 0, the spinless state: with ξ < 1 it repels (T_tr decays, T_rot stays), and r → ∞ as
    β → −1 from above (r ≈ q(1 − ξ²)/(2η²)); at ξ = 1, r → 0 as β → −1 for q < 2.

    Accuracy: the Maxwellian closure ignores the cumulants of the velocity distribution.
    The Sonine corrections found by Santos and co-workers for disks and spheres change r
    little over most of the (ξ, β) plane, more as β → −1 (small roughness) where the
    distribution is far from Maxwellian; docs/rough-disks.md says what was checked here.
    """
    a, b, c = rough_disk_cooling_coefficients(xi, beta, q)
    if b == 0.0:
        return 0.0
    s = a - 2.0 * c
    root = math.sqrt(s * s + 8.0 * b * b)
    if s >= 0.0:
        return (s + root) / (2.0 * b)
    return 4.0 * b / (root - s)  # the same root, free of cancellation


def rough_disk_cooling_rate(xi, beta, q):
    """ζ/ν = A − B r: the decay rate of T_tr (and T_rot) in the homogeneous cooling state of
    rough disks, dT/dt = −ζ T, per collision frequency ν (:func:`rough_disk_temperature_ratio`);
    (1 − ξ²)/2 for smooth disks (β = −1, spins at rest)."""
    a, b, _ = rough_disk_cooling_coefficients(xi, beta, q)
    return a - b * rough_disk_temperature_ratio(xi, beta, q)


def rough_disk_haff_temperature(t, temperature0, collision_frequency0, xi, beta, q):
    """Haff's law for rough disks in the homogeneous cooling state: ν ∝ √T_tr and
    dT_tr/dt = −ν (A − B r) T_tr give T_tr(t) = T₀/(1 + t/t₀)², t₀ = 2/(ν₀ (A − B r)) with
    ν₀ the collision frequency at T₀ (t₀ = 4/((1 − ξ²) ν₀) for smooth disks); T_rot = r T_tr."""
    t0 = 2.0 / (collision_frequency0 * rough_disk_cooling_rate(xi, beta, q))
    return temperature0 / (1.0 + np.asarray(t) / t0) ** 2
