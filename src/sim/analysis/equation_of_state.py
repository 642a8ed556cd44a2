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

Blocks. A run's snapshots come every so many collisions, and the blocks between them last
unequal times: their pressures are averaged over the time they span, never block by block
(:func:`time_weighted`; the plain mean of the blocks' ratios X_b/t_b is biased upwards).

Errors. Successive blocks of a run are correlated; the blocking transformation of Flyvbjerg
& Petersen (J. Chem. Phys. 91, 461 (1989)) averages neighbours pairwise, level after level,
and the naive standard error of the blocked series grows until the blocks are independent,
then stays on a plateau. :func:`blocking` finds the first level of the plateau by Jonsson's
test of the remaining levels' lag-one correlations (or flags the series as too short).
"""

import math
from collections import namedtuple

import numpy as np
from scipy.stats import chi2

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
    """The standard error of the mean of a correlated ``series`` float64[m] by blocking, the
    level chosen by Jonsson's test (Phys. Rev. E 98, 043304 (2018)): (mean, standard error,
    converged, errors per level float64[levels]).

    Level k averages neighbours pairwise k times (Flyvbjerg & Petersen, J. Chem. Phys. 91,
    461 (1989)), n_k blocks of variance s_k² (about the series' mean) and lag-one
    autocovariance γ_k. While the blocks are correlated, M_k = Σ_{j ≥ k} n_j (γ_j / s_j²)²
    exceeds the 99 % quantile of χ² with as many degrees of freedom as levels from k on; the
    error is √(s_k²/n_k) of the first level below it. ``converged`` is False when no level
    of :data:`MIN_BLOCKS` blocks or more passes but the last of them (the error is then the
    largest of those levels'), and for a series shorter than :data:`MIN_BLOCKS` (at least
    two entries; its naive error)."""
    x = np.asarray(series, np.float64)
    mean = float(x.mean())
    if x.size < MIN_BLOCKS:  # too few to block: the naive error, flagged
        return mean, float(x.std(ddof=1) / math.sqrt(x.size)), False, np.array([])
    variance, autocovariance, counts = [], [], []
    while x.size >= 2:
        deviation = x - mean
        variance.append(float(np.mean(deviation * deviation)))
        autocovariance.append(float(np.mean(deviation[:-1] * deviation[1:])))
        counts.append(x.size)
        x = 0.5 * (x[: x.size // 2 * 2: 2] + x[1: x.size // 2 * 2: 2])
    variance, autocovariance, counts = (np.array(v) for v in (variance, autocovariance, counts))
    errors = np.sqrt(variance / counts)
    statistic = np.cumsum((counts * (autocovariance / variance) ** 2)[::-1])[::-1]
    quantile = chi2.ppf(0.99, np.arange(counts.size, 0, -1))
    usable = counts >= MIN_BLOCKS
    passed = np.flatnonzero((statistic < quantile) & usable)
    if passed.size:  # a plateau seen on one level only (the last usable) is not trusted
        return (mean, float(errors[passed[0]]), bool(passed[0] < usable.sum() - 1),
                errors[usable])
    return mean, float(errors[usable].max()), False, errors[usable]


def equilibration_cut(series):
    """The number of leading entries of ``series`` float64[m] to drop as equilibration: the
    marginal standard error rule (MSER; White, Simulation 69, 323 (1997)), the d ≤ m/2 that
    minimises Σ_{i ≥ d} (x_i − x̄_d)² / (m − d)², the squared standard error of the mean of
    what is kept were it uncorrelated. A drift at the start raises the sum more than
    dropping its entries costs; a stationary series keeps nearly all of its entries."""
    x = np.asarray(series, np.float64)
    m = x.size
    kept = m - np.arange(m // 2 + 1)
    tail = x[::-1] - x.mean()  # the sums about the mean: no cancellation
    mean = np.cumsum(tail)[kept - 1] / kept  # x̄_d over x[d:]
    squares = np.cumsum(tail * tail)[kept - 1]
    return int(np.argmin((squares - kept * mean * mean) / kept**2))


#: the largest relative change of the kinetic energy K of an elastic run: round-off moves K
#: by about 10⁻⁹ of itself in 10⁹ collisions, and a change δ K shifts βP d² (which takes
#: the K at the start) by at most δ βP d², far below its errors; a dissipative or
#: thermostatted run changes K by much more
ELASTIC = 1e-6


def block_pressures(run):
    """βP d² (:func:`reduced_pressure_d2`) of every interval between two snapshots of the
    run Dataset ``run`` (:func:`sim.analysis.datasets.open_run`) of equal elastic disks in a
    periodic box: float64[m], from the collision virial and time at the snapshots; the
    collisions at each interval's end int64[m]; its duration float64[m], over which
    :func:`time_weighted` averages the pressures. Intervals of the run's snapshot cadence
    only (the most common count of collisions between snapshots; a shorter last one is
    dropped). Raises ValueError for disks of several sizes or masses, a run with walls,
    kinetic energy that changes by more than :data:`ELASTIC` or a total momentum that is not
    zero at the start."""
    radius, mass = run["radius"].values, run["mass"].values
    if np.ptp(radius) or np.ptp(mass) or tuple(run.attrs["boundary"]) != ("periodic",) * 2:
        raise ValueError("the pressure of equal disks in a periodic box, not of this run")
    momentum = (mass[:, None] * run["velocity"].isel(time=0).values).sum(axis=0)
    kinetic = run["kinetic_energy"].values
    if np.hypot(*momentum) > 1e-9 * math.sqrt(2.0 * kinetic[0] * mass.sum()):
        raise ValueError(f"a total momentum of zero at the start, not {momentum}")
    if np.ptp(kinetic) > ELASTIC * kinetic[0]:
        raise ValueError(f"a constant kinetic energy (an elastic run), not one that changes "
                         f"by {np.ptp(kinetic) / kinetic[0]:.1e} of itself")
    collisions = run["collisions"].values
    steps = np.diff(collisions)
    lengths, counts = np.unique(steps, return_counts=True)
    whole = steps == (lengths[np.argmax(counts)] if steps.size else 0)
    area = float(np.prod(run.attrs["box"]))
    elapsed = np.diff(run["time"].values)[whole]
    pressure = reduced_pressure_d2(radius.size, kinetic[0],
                                   np.diff(run["collision_virial"].values)[whole], elapsed,
                                   area, 2.0 * radius[0])
    return pressure, collisions[1:][whole], elapsed


def time_weighted(pressure, elapsed):
    """The pressure of the whole time that blocks of pressures ``pressure`` float64[m] and
    durations ``elapsed`` float64[m] span, as a series whose plain mean it is:
    z_b = R + (P_b − R) t_b/t̄, with R = Σ P_b t_b / Σ t_b the ratio of the summed virials to
    the summed time (float64[m]). The blocking error of z is the error of R to first order
    (the delta method for a ratio estimator).

    Blocks of equal counts of collisions last unequal times, and P_b = X_b/t_b is a ratio:
    the plain mean of the P_b exceeds R by about the relative variance of t_b, times βP d².
    At N = 72 near melting, where t_b varies by 4–5 % over 1000 collisions per disk, that is
    +0.01 to +0.02 in βP d²: ten times the published errors of Li et al. (2022)."""
    p = np.asarray(pressure, np.float64)
    t = np.asarray(elapsed, np.float64)
    ratio = float(np.sum(p * t) / np.sum(t))
    return ratio + (p - ratio) * t / t.mean()


EquationOfStatePoint = namedtuple(
    "EquationOfStatePoint", "mean error converged cut blocks drift production_start")
EquationOfStatePoint.__doc__ = """βP d² of a run: the ``mean`` over the time of its
production blocks and its blocking ``error`` (``converged`` as :func:`blocking` says), the
``cut`` equilibration blocks dropped (:func:`equilibration_cut`), the ``blocks`` kept, the
``drift``: the difference of the means of the production's second and first halves over its
standard error (blocking errors of the halves), a few at most for a run whose averages no
longer drift; and the collisions at which the production starts (the snapshot that ends the
last block cut, or the first)."""


def run_pressure(run):
    """The :class:`EquationOfStatePoint` of the run Dataset ``run`` (:func:`block_pressures`):
    the equilibration cut from the blocks' pressures, the mean and errors of the production
    and of its halves over the time each spans (:func:`time_weighted`)."""
    pressure, ends, elapsed = block_pressures(run)
    if pressure.size < 2 * MIN_BLOCKS:
        raise ValueError(f"at least {2 * MIN_BLOCKS} blocks of pressure, not {pressure.size}")
    cut = equilibration_cut(pressure)
    production, spans = pressure[cut:], elapsed[cut:]
    mean, error, converged, _ = blocking(time_weighted(production, spans))
    half = production.size // 2
    first, second = (blocking(time_weighted(production[part], spans[part]))
                     for part in (slice(None, half), slice(half, None)))
    drift = (second[0] - first[0]) / math.hypot(first[1], second[1])
    start = int(ends[cut - 1]) if cut else int(run["collisions"].values[0])
    return EquationOfStatePoint(mean, error, converged, cut, production.size, float(drift),
                                start)
