"""The pressure of elastic hard disks with honest errors: the virial pressure of a run with
zero total momentum, and the standard error of a correlated series by blocking.

Pressure. In an elastic run with zero total momentum the kinetic energy K is constant and
the configurations are distributed as in Monte Carlo at the temperature of the N − 1
independent momenta, kT = K/(N − 1); the ideal term of the pressure stays N kT per area
(the virial theorem counts every disk's momentum flux). With X = (1/2t) Σ r_ij·Δp_i over
the collisions of a time t (Alder & Wainwright, J. Chem. Phys. 33, 1439 (1960)),

    βPA = N + (N − 1) X / K,     βP d² = βPA d²/A,

d the disk diameter. The forms that take kT = K/N (βPA = N + N X/K) or P A = K + X with
kT = K/(N − 1) (βPA = (N − 1)(1 + X/K)) differ by about 1/N and 1/(βPA) of it: at N = 72
near melting, 1.2 % and 0.15 %, far beyond the published errors of small-N pressures
(Li, Nishikawa, Höllmer, Carillo, Maggs & Krauth, J. Chem. Phys. 157, 234111 (2022)).

Errors. Successive blocks of a run are correlated; the blocking transformation of Flyvbjerg
& Petersen (J. Chem. Phys. 91, 461 (1989)) averages neighbours pairwise, level after level,
and the naive standard error of the blocked series grows until the blocks are independent,
then stays on a plateau within its own error. :func:`blocking` returns every level and the
first level whose error agrees with the next within the error of its error (or the last
with at least :data:`MIN_BLOCKS` blocks, flagged as not converged).
"""

import math

import numpy as np

#: the fewest blocks a level of :func:`blocking` may keep
MIN_BLOCKS = 8


def pressure_area(n, kinetic, virial, elapsed):
    """βPA = N + (N − 1) X/K of ``n`` disks of constant kinetic energy ``kinetic`` and zero
    total momentum, X = ``virial``/(2 ``elapsed``) from the collision virial Σ r_ij·Δp_i of
    the time ``elapsed`` (arrays broadcast)."""
    x = np.asarray(virial, np.float64) / (2.0 * np.asarray(elapsed, np.float64))
    return n + (n - 1) * x / np.asarray(kinetic, np.float64)


def reduced_pressure_d2(n, kinetic, virial, elapsed, area, diameter):
    """βP d² = βPA d²/A (:func:`pressure_area`), the pressure of the published hard-disk
    data (βP(2σ)² with σ the radius)."""
    return pressure_area(n, kinetic, virial, elapsed) * diameter**2 / area


def blocking(series):
    """Flyvbjerg–Petersen blocking of a correlated ``series`` float64[m]: (mean, standard
    error, converged, errors per level float64[levels]). The error is that of the first
    level beyond which no level's error exceeds it by more than twice that level's own
    error (a standard error from b blocks is uncertain by about 1/√(2(b − 1)) of itself),
    else the largest of all levels of at least :data:`MIN_BLOCKS` blocks, with ``converged``
    False."""
    x = np.asarray(series, np.float64)
    mean = float(x.mean())
    errors, counts = [], []
    while x.size >= MIN_BLOCKS:
        errors.append(float(x.std(ddof=1) / math.sqrt(x.size)))
        counts.append(x.size)
        x = 0.5 * (x[: x.size // 2 * 2: 2] + x[1: x.size // 2 * 2: 2])
    errors, counts = np.array(errors), np.array(counts)
    uncertain = errors / np.sqrt(2.0 * (counts - 1))
    for level in range(len(errors) - 1):
        later = slice(level + 1, None)
        if np.all(errors[later] - errors[level] <= 2.0 * uncertain[later]):
            return mean, float(errors[level]), True, errors
    return mean, float(errors.max(initial=math.nan)), False, errors
