"""Direct simulation Monte Carlo (DSMC) of the spatially homogeneous Boltzmann equation for
hard disks in 2D, with a constant Enskog factor χ: a reference for the event-driven engine
that shares none of its code.

The gas: species s with masses m_s, diameters σ_s and number fractions x_s at total number
density n (disks per unit area), I = q m a² (a = σ/2; :mod:`sim.effects.rotation`). The kernel
of a pair (i, j) with relative velocity g = v_i − v_j and unit contact normal n̂ (from j to
i) is

    B = σ_ij χ |g·n̂| Θ(−g·n̂),   σ_ij = (σ_i + σ_j)/2,

so that over n̂ a pair collides at 2σ_ij χ |g| and a disk of a Maxwellian gas at Enskog's
ν = 2nσχ√(πT/m) (:func:`sim.analysis.theory.enskog_collision_frequency`): times are in the
engine's units, and a DSMC time series lies over the engine's at the same n, σ and χ.

Scheme: Bird's no-time-counter (NTC) selection in one homogeneous cell (G. A. Bird,
*Molecular Gas Dynamics and the Direct Simulation of Gas Flows*, Oxford 1994). Each of
the N(N − 1)/2 pairs collides at λ_ij = n/(N − 1) · 2σ_ij χ |g_ij|; with the majorant
k_max = 4 σ_max χ U ≥ 2σ_ij χ |g_ij| (U = max_i |v_i − ū|, ū the mass-weighted mean
velocity, so |g_ij| ≤ 2U) candidates come at Λ = N n k_max/2, uniformly among the pairs, and a
candidate collides with probability σ_ij |g_ij|/(2 σ_max U). A step of Δt = f/(n k_max)
(f = ``step_fraction``) takes M = ⌊ΛΔt + u⌋ (u uniform; f N/2 on average) candidates at once,
drawn disjoint so that the step is one array update: that is Babovsky's symmetric pairing
(H. Babovsky, Math. Methods Appl. Sci. 8, 223 (1986)), with a fraction f of the disks paired.
A disk then collides at most once per step: the mean evolution departs from that of the
N-disk master equation by an error of first order in f (:data:`STEP_FRACTION`). The contact
normal is drawn with the kernel's weight |g·n̂| over the half circle g·n̂ < 0: with the impact
parameter b uniform in (−1, 1), n̂ = −√(1 − b²) ĝ + b ẑ × ĝ. Momentum and energy (elastic
rules) are kept to round-off.

A collision rule is a callable taking :class:`Pairs` (arrays of the pairs that collide) and
returning (v_i', v_j', ω_i', ω_j'): :class:`SmoothDisks`, :class:`RoughDisks`. A
``forcing(state, dt, rng) -> State`` (driving, shear: none yet) acts between collision steps.

Temperatures as the engine's rough checks define them (:mod:`sim.checks.rough`), k_B = 1:
T_tr per species = Σ_s m |v − ū|²/(2 Σ_s (1 − m/M)) (two degrees of freedom per disk,
:func:`sim.analysis.cells.granular_temperature` on one cell), T_rot = ⟨I ω²⟩ (one).

Command: ``python -m sim.checks.dsmc --help`` (the cooling state of rough disks, as JSON).
"""

import argparse
import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from sim.analysis.cells import granular_temperature
from sim.analysis.theory import (
    enskog_collision_frequency,
    rough_disk_cooling_rate,
    rough_disk_temperature_ratio,
)
from sim.checks.rows import block_means

#: Default fraction f of the disks that are candidates in one step. A step updates all its
#: pairs from the velocities at its start (an explicit Euler step in time), so rates in time
#: carry an error of first order in f: the Haff rate ζ/ν of rough disks (ξ = 0.9, β = 0.5,
#: q = 1/2) measured 0.18566, 0.18407, 0.18380, 0.18376 (± 0.00015) at f = 0.4, 0.1, 0.05,
#: 0.025, i.e. ζ(f) ≈ ζ(0) (1 + 0.028 f), about (3/4) ζΔt as for Euler's step on
#: dT/dt ∝ −T^{3/2}. T_rot/T_tr stayed within its error (0.1 %) up to f = 1 (β = 0.5 and 0).
STEP_FRACTION = 0.05


@dataclass(frozen=True)
class Gas:
    """Species s = 0 … S − 1 (tuples of S): masses m_s, diameters σ_s, number fractions x_s
    (normalised); ``density`` n, disks per unit area; ``chi`` the constant Enskog factor χ
    (1: dilute, Boltzmann); ``inertia_factor`` q of I = q m a²."""

    masses: tuple = (1.0,)
    diameters: tuple = (1.0,)
    fractions: tuple = (1.0,)
    density: float = 1.0
    chi: float = 1.0
    inertia_factor: float = 0.5

    def __post_init__(self):
        arrays = [np.asarray(a, dtype=float) for a in (self.masses, self.diameters,
                                                       self.fractions)]
        if len({a.shape for a in arrays}) != 1 or arrays[0].ndim != 1:
            raise ValueError("masses, diameters and fractions must be sequences of one length")
        if not all(np.all(a > 0.0) for a in arrays) or min(self.density, self.chi) <= 0.0:
            raise ValueError("masses, diameters, fractions, density and chi must be positive")
        if not 0.0 < self.inertia_factor <= 1.0:
            raise ValueError(f"q = I/(m a²) must lie in (0, 1], got {self.inertia_factor}")

    def per_disk(self, species):
        """(m, a, I) of each disk, float64[N] each, from ``species`` int[N]."""
        mass = np.asarray(self.masses, dtype=float)[species]
        radius = 0.5 * np.asarray(self.diameters, dtype=float)[species]
        return mass, radius, self.inertia_factor * mass * radius**2


class State(NamedTuple):
    """The disks: ``velocity`` float64[N, 2], ``spin`` ω float64[N] (counter-clockwise
    positive), ``species`` int[N]."""

    velocity: np.ndarray
    spin: np.ndarray
    species: np.ndarray


class Pairs(NamedTuple):
    """The K pairs that collide in a step: velocities float64[K, 2], spins, masses, moments
    of inertia and radii float64[K] of i and j, ``normal`` n̂ float64[K, 2] from j to i
    (g·n̂ < 0)."""

    velocity_i: np.ndarray
    velocity_j: np.ndarray
    spin_i: np.ndarray
    spin_j: np.ndarray
    mass_i: np.ndarray
    mass_j: np.ndarray
    inertia_i: np.ndarray
    inertia_j: np.ndarray
    radius_i: np.ndarray
    radius_j: np.ndarray
    normal: np.ndarray


def apply_impulse(pairs, p_n, p_t):
    """(v_i', v_j', ω_i', ω_j') after the impulse P = P_n n̂ + P_t t̂ on i's contact point
    and −P on j's, t̂ = ẑ × n̂ (docs/rough-disks.md, "The impulse"):

        v_i' = v_i + P/m_i,   v_j' = v_j − P/m_j,
        ω_i' = ω_i − a_i P_t/I_i,   ω_j' = ω_j − a_j P_t/I_j.

    ``p_n``, ``p_t`` float64[K]."""
    n = pairs.normal
    t = np.stack([-n[:, 1], n[:, 0]], axis=1)
    impulse = p_n[:, None] * n + p_t[:, None] * t
    return (pairs.velocity_i + impulse / pairs.mass_i[:, None],
            pairs.velocity_j - impulse / pairs.mass_j[:, None],
            pairs.spin_i - pairs.radius_i * p_t / pairs.inertia_i,
            pairs.spin_j - pairs.radius_j * p_t / pairs.inertia_j)


def normal_impulse(pairs, restitution):
    """P_n = −(1 + ξ) μ g_n, g_n = (v_i − v_j)·n̂ < 0, μ = m_i m_j/(m_i + m_j): g_n' = −ξ g_n
    (:func:`sim.engine.contact.collide_disks`). float64[K]."""
    g_n = np.einsum("ka,ka->k", pairs.velocity_i - pairs.velocity_j, pairs.normal)
    mu = pairs.mass_i * pairs.mass_j / (pairs.mass_i + pairs.mass_j)
    return -(1.0 + restitution) * mu * g_n


@dataclass(frozen=True)
class SmoothDisks:
    """Smooth disks with normal restitution ξ (1: elastic); spins untouched."""

    restitution: float = 1.0

    def __call__(self, pairs):
        p_n = normal_impulse(pairs, self.restitution)
        return apply_impulse(pairs, p_n, np.zeros_like(p_n))


@dataclass(frozen=True)
class RoughDisks:
    """Rough disks with normal restitution ξ and constant tangential restitution β ∈ [−1, 1]
    (Huthmann & Zippelius, Phys. Rev. E 56, R6275 (1997); Luding, Huthmann, McNamara &
    Zippelius, Phys. Rev. E 58, 3416 (1998)), the rule of
    :func:`sim.effects.rotation.rough_contact`: with g_t = (v_i − v_j)·t̂ − (a_i ω_i + a_j ω_j),

        P_t = −(1 + β) m_t g_t,   1/m_t = 1/m_i + 1/m_j + a_i²/I_i + a_j²/I_j,

    so g_t' = −β g_t (β = −1 smooth, β = 1 perfectly rough), after the normal impulse of
    :class:`SmoothDisks`."""

    restitution: float
    roughness: float

    def __post_init__(self):
        if not -1.0 <= self.roughness <= 1.0:
            raise ValueError(f"tangential restitution β must lie in [−1, 1], got "
                             f"{self.roughness}")

    def __call__(self, pairs):
        n = pairs.normal
        g = pairs.velocity_i - pairs.velocity_j
        g_t = (g[:, 1] * n[:, 0] - g[:, 0] * n[:, 1]
               - (pairs.radius_i * pairs.spin_i + pairs.radius_j * pairs.spin_j))
        m_t = 1.0 / (1.0 / pairs.mass_i + 1.0 / pairs.mass_j
                     + pairs.radius_i**2 / pairs.inertia_i
                     + pairs.radius_j**2 / pairs.inertia_j)
        p_t = -(1.0 + self.roughness) * m_t * g_t
        return apply_impulse(pairs, normal_impulse(pairs, self.restitution), p_t)


@dataclass(frozen=True)
class Series:
    """Read-outs at the K requested times: ``time`` float64[K]; ``collisions_per_particle``
    C/N float64[K] (collisions since the start over the number of disks; each disk takes part
    in 2C/N); ``translational`` T_tr and ``rotational`` T_rot = ⟨I ω²⟩ per species,
    float64[K, S]."""

    time: np.ndarray
    collisions_per_particle: np.ndarray
    translational: np.ndarray
    rotational: np.ndarray


def temperatures(gas, state):
    """(T_tr, T_rot) per species, float64[S] each (the module's definitions)."""
    mass, _, inertia = gas.per_disk(state.species)
    n_species = len(gas.masses)
    translational = granular_temperature(state.velocity, mass,
                                         np.zeros(len(mass), dtype=np.intp), 1,
                                         state.species, n_species)
    rotational = (np.bincount(state.species, weights=inertia * state.spin**2,
                              minlength=n_species)
                  / np.bincount(state.species, minlength=n_species))
    return translational, rotational


def initial_state(gas, n_particles, rng, temperature=1.0, rotational_temperature=0.0,
                  fixed_speed=False):
    """N = ``n_particles`` disks: species by their fractions (largest remainders), velocities
    Maxwellian at T_tr = ``temperature`` (scalar or float64[S]), or all of speed √(2T/m) in
    random directions (``fixed_speed``), less the mass-weighted mean velocity; spins
    Maxwellian at ``rotational_temperature`` = ⟨I ω²⟩. ``rng`` a numpy Generator."""
    n_species = len(gas.masses)
    share = np.asarray(gas.fractions, dtype=float) / np.sum(gas.fractions) * n_particles
    counts = np.floor(share).astype(int)
    counts[np.argsort(counts - share)[:n_particles - counts.sum()]] += 1
    species = np.repeat(np.arange(n_species), counts)
    mass, _, inertia = gas.per_disk(species)
    thermal = np.sqrt(np.broadcast_to(np.asarray(temperature, dtype=float),
                                      (n_species,))[species] / mass)
    if fixed_speed:
        angle = rng.uniform(0.0, 2.0 * math.pi, n_particles)
        velocity = math.sqrt(2.0) * thermal[:, None] * np.stack([np.cos(angle),
                                                                 np.sin(angle)], axis=1)
    else:
        velocity = thermal[:, None] * rng.standard_normal((n_particles, 2))
    velocity -= np.sum(mass[:, None] * velocity, axis=0) / mass.sum()
    spin = rng.standard_normal(n_particles) * np.sqrt(rotational_temperature / inertia)
    return State(velocity, spin, species)


def simulate(gas, rule, state, times, rng, forcing=None, step_fraction=STEP_FRACTION):
    """Run ``state`` with collision ``rule`` from t = 0, reading out at ``times`` (float64[K],
    non-decreasing, ≥ 0) and stopping at the last. ``rng`` a numpy Generator (the same
    generator state gives the same bits); ``forcing(state, dt, rng) -> State`` acts after each
    collision step of length dt. Returns (:class:`Series`, the final :class:`State`); the
    given state is not changed."""
    times = np.asarray(times, dtype=float)
    if times.ndim != 1 or np.any(times < 0.0) or np.any(np.diff(times) < 0.0):
        raise ValueError("times must be a non-decreasing sequence of times ≥ 0")
    if not 0.0 < step_fraction <= 1.0:
        raise ValueError(f"step_fraction must lie in (0, 1], got {step_fraction}")
    velocity, spin, species = state.velocity.copy(), state.spin.copy(), state.species
    mass, radius, inertia = gas.per_disk(species)
    n_disks = len(species)
    diameter = np.asarray(gas.diameters, dtype=float)
    sigma_ij = 0.5 * (diameter[:, None] + diameter[None, :])
    sigma_max = diameter.max()

    def mean_and_bound():
        """ū and U = max |v − ū|."""
        mean = np.sum(mass[:, None] * velocity, axis=0) / mass.sum()
        return mean, float(np.sqrt(np.max(np.sum((velocity - mean) ** 2, axis=1))))

    mean, bound = mean_and_bound()
    t, collisions, candidates_since_bound = 0.0, 0, 0
    translational, rotational, per_particle = [], [], []
    for t_out in times:
        while t < t_out:
            k_max = 4.0 * sigma_max * gas.chi * bound  # ≥ 2σ_ij χ |g_ij|
            dt = t_out - t if k_max == 0.0 else min(step_fraction / (gas.density * k_max),
                                                    t_out - t)
            t = t_out if dt == t_out - t else t + dt
            candidates = min(int(0.5 * n_disks * gas.density * k_max * dt + rng.random()),
                             n_disks // 2)
            chosen = rng.choice(n_disks, 2 * candidates, replace=False)
            i, j = chosen[:candidates], chosen[candidates:]
            g = velocity[i] - velocity[j]
            g_abs = np.sqrt(np.sum(g * g, axis=1))
            accepted = (rng.random(candidates) * (2.0 * sigma_max * bound)
                        < sigma_ij[species[i], species[j]] * g_abs)
            i, j, g, g_abs = i[accepted], j[accepted], g[accepted], g_abs[accepted]
            g_hat = g / g_abs[:, None]
            b = rng.uniform(-1.0, 1.0, len(i))
            normal = (-np.sqrt(1.0 - b * b)[:, None] * g_hat
                      + b[:, None] * np.stack([-g_hat[:, 1], g_hat[:, 0]], axis=1))
            velocity[i], velocity[j], spin[i], spin[j] = rule(Pairs(
                velocity[i], velocity[j], spin[i], spin[j], mass[i], mass[j], inertia[i],
                inertia[j], radius[i], radius[j], normal))
            collisions += len(i)
            candidates_since_bound += candidates
            if forcing is not None:
                velocity, spin, _ = forcing(State(velocity, spin, species), dt, rng)
            if forcing is not None or 2 * candidates_since_bound >= n_disks:
                mean, bound = mean_and_bound()  # anew: in a cooling gas U shrinks
                candidates_since_bound = 0
            elif len(i):
                moved = np.concatenate([i, j])
                bound = max(bound, float(np.sqrt(np.max(np.sum(
                    (velocity[moved] - mean) ** 2, axis=1)))))
        final = State(velocity, spin, species)
        tr, rot = temperatures(gas, final)
        translational.append(tr)
        rotational.append(rot)
        per_particle.append(collisions / n_disks)
    n_species = len(gas.masses)
    series = Series(times, np.array(per_particle), np.reshape(translational, (-1, n_species)),
                    np.reshape(rotational, (-1, n_species)))
    return series, State(velocity.copy(), spin.copy(), species)


def run(gas, rule, n_particles, times, seed, forcing=None, step_fraction=STEP_FRACTION,
        **initial):
    """:func:`simulate` from :func:`initial_state` (keywords ``initial``: temperature,
    rotational_temperature, fixed_speed), both drawn from ``np.random.default_rng(seed)``:
    the same seed gives the same bits. Returns (:class:`Series`, final :class:`State`)."""
    rng = np.random.default_rng(seed)
    state = initial_state(gas, n_particles, rng, **initial)
    return simulate(gas, rule, state, times, rng, forcing, step_fraction)


def at_collisions(gas, rule, n_particles, marks, seed, step=0.05, **initial):
    """(T_tr, T_rot) per species, float64[K, S] each, at each of the K collisions per particle
    C/N of ``marks`` (increasing, ≥ 0): a time series by the engine's clock of collisions, for
    a gas whose collision rate changes as it cools. Read out about every ``step`` C/N (each
    chunk of time from the collision rate of the one before) and interpolated linearly in C/N
    between the read-outs on either side of a mark (an error of order (k step)² for a gas
    whose temperatures change as exp(−k C/N)). The start as :func:`run`'s (``initial``,
    ``seed``)."""
    marks = np.asarray(marks, dtype=float)
    if marks.ndim != 1 or np.any(marks < 0.0) or np.any(np.diff(marks) < 0.0):
        raise ValueError("marks must be a non-decreasing sequence of C/N ≥ 0")
    rng = np.random.default_rng(seed)
    state = initial_state(gas, n_particles, rng, **initial)
    frequency = enskog_collision_frequency(gas.density, max(gas.diameters), gas.chi, 1.0,
                                           min(gas.masses))  # a first guess; then measured
    done, now = 0.0, np.array(temperatures(gas, state))
    read = []
    for mark in marks:
        while done < mark:
            dt = 2.0 * step / frequency
            series, state = simulate(gas, rule, state, [dt], rng)
            added = series.collisions_per_particle[0]
            # a chunk without a collision (a tiny gas) doubles the next one
            frequency = 2.0 * added / dt if added > 0.0 else 0.5 * frequency
            before, now = now, np.array(temperatures(gas, state))
            done += added
        if done > mark:  # between the last two read-outs
            read.append(before + (mark - done + added) / added * (now - before))
        else:
            read.append(now)
    return np.array([r[0] for r in read]), np.array([r[1] for r in read])


def cooled_in_haff_time(gas, rule, n_particles, cooling_rate, seed, **initial):
    """T_tr(t₀)/T_tr(0) of species 0 at Haff's time t₀ = 2/(ν₀ ζ/ν), ν₀ Enskog's collision
    frequency of species 0 at the start's T_tr(0) and ζ/ν = ``cooling_rate`` ((1 − ξ²)/2 for
    smooth disks), where Haff's law gives 1/4. The start as :func:`run`'s."""
    rng = np.random.default_rng(seed)
    state = initial_state(gas, n_particles, rng, **initial)
    start = temperatures(gas, state)[0][0]
    t0 = 2.0 / (cooling_rate * enskog_collision_frequency(
        gas.density, gas.diameters[0], gas.chi, start, gas.masses[0]))
    series, _ = simulate(gas, rule, state, [t0], rng)
    return series.translational[0, 0] / start


class CoolingState(NamedTuple):
    """The homogeneous cooling state: r = T_rot/T_tr and ζ/ν (ν Enskog's at T_tr), each
    with its standard error; ``collisions_per_particle`` C/N simulated over all seeds."""

    ratio: float
    ratio_error: float
    cooling_rate: float
    cooling_rate_error: float
    collisions_per_particle: float


def cooling_state(gas, rule, n_particles, seeds, burn_in=20.0, collisions_per_particle=60.0,
                  spacing=0.5, blocks=5, step_fraction=STEP_FRACTION):
    """T_rot/T_tr and ζ/ν of the homogeneous cooling state of one species, by segments: from
    T_tr = T_rot = 1 (Maxwellian), each segment of Δt = 2 ``spacing``/ν₀ (ν₀ Enskog's at
    T_tr = 1, about ``spacing`` collisions per disk) reads r = T_rot/T_tr and the Haff rate
    ζ/ν₀ = 2(√(T_tr(0)/T_tr(Δt)) − 1)/(ν₀ Δt) (exact in that state, where dT_tr/dt ∝ −T_tr^{3/2};
    :func:`sim.analysis.theory.rough_disk_haff_temperature`), then rescales v and ω by
    1/√T_tr. The homogeneous Boltzmann equation is invariant under that rescaling (with time
    by √T_tr), so the gas cools on without limit of float64.

    Each seed runs ``collisions_per_particle`` C/N; the segments after ``burn_in`` C/N are
    cut into ``blocks`` contiguous blocks, and the means and standard errors are those of all
    blocks of all seeds (:func:`sim.checks.rows.block_means`), nearly independent when a
    block spans many C/N. The approach to the cooling state is slower for smaller roughness:
    at ξ = 0.9, q = 1/2, averaged over C/N = 0 … 5, 5 … 10 and 10 … 15 of eight runs, r
    exceeds its final value by 5 %, 0.1 % and 0.3 ± 0.3 % for β = 0.5, by 34 %, 3 % and
    0.6 ± 0.3 % for β = 0; hence a burn-in of 20."""
    if len(gas.masses) != 1:
        raise ValueError("the cooling state is computed for one species")
    frequency = enskog_collision_frequency(gas.density, gas.diameters[0], gas.chi, 1.0,
                                           gas.masses[0])
    segment = 2.0 * spacing / frequency
    ratio_blocks, rate_blocks, total = [], [], 0.0
    for seed in seeds:
        rng = np.random.default_rng(seed)
        state = initial_state(gas, n_particles, rng, rotational_temperature=1.0)
        ratios, rates, done = [], [], 0.0
        while done < collisions_per_particle:
            scale = 1.0 / math.sqrt(temperatures(gas, state)[0][0])
            state = state._replace(velocity=scale * state.velocity, spin=scale * state.spin)
            series, state = simulate(gas, rule, state, [segment], rng,
                                     step_fraction=step_fraction)
            if done >= burn_in:
                ratios.append(series.rotational[0, 0] / series.translational[0, 0])
                rates.append(2.0 * (1.0 / math.sqrt(series.translational[0, 0]) - 1.0)
                             / (frequency * segment))
            done += series.collisions_per_particle[0]
        if len(ratios) < blocks:
            raise ValueError("too few segments after the burn-in for the blocks: raise "
                             "collisions_per_particle")
        ratio_blocks += [np.mean(b) for b in np.array_split(ratios, blocks)]
        rate_blocks += [np.mean(b) for b in np.array_split(rates, blocks)]
        total += float(done)
    return CoolingState(*block_means(ratio_blocks), *block_means(rate_blocks), total)


#: (ξ, β) of the cooling states the validation table compares with the engine
#: (:func:`sim.checks.rough.rough_cooling`)
STATES = ((0.9, 0.5), (0.9, 0.0), (0.8, -0.5), (0.7, 0.5))

#: the cooling states as ``make dsmc`` writes them, in the repository
RESULTS = Path(__file__).resolve().parents[3] / "docs" / "results" / "dsmc.json"


def stored_cooling_state(restitution, roughness, path=RESULTS):
    """The cooling state of (ξ, β) that ``make dsmc`` wrote to ``path``: a dict of the fields
    of :class:`CoolingState` and the theory's ratio and rate. A pair it does not hold is a
    KeyError naming it."""
    for result in json.loads(Path(path).read_text())["results"]:
        if (result["restitution"], result["roughness"]) == (restitution, roughness):
            return result
    raise KeyError(f"{path} holds no cooling state for ξ = {restitution}, β = {roughness}: "
                   f"make dsmc")


def _state(text):
    """``ξ:β`` of the command line as (ξ, β)."""
    xi, colon, beta = text.partition(":")
    try:
        state = (float(xi), float(beta))
    except ValueError:
        state = None
    if not colon or state is None or not (0.0 < state[0] <= 1.0 and -1.0 <= state[1] <= 1.0):
        raise argparse.ArgumentTypeError(f"{text!r}: ξ:β with ξ in (0, 1] and β in [−1, 1]")
    return state


def main(argv=None):
    """The cooling state of rough disks for each (ξ, β), against the two-temperature Maxwellian
    theory (:func:`sim.analysis.theory.rough_disk_temperature_ratio`,
    :func:`sim.analysis.theory.rough_disk_cooling_rate`), written as JSON to ``--out``."""
    parser = argparse.ArgumentParser(
        prog="python -m sim.checks.dsmc",
        description="DSMC of the homogeneous cooling state of rough disks (one species, "
                    "dilute): T_rot/T_tr and ζ/ν against the Maxwellian theory.")
    parser.add_argument("--states", type=_state, nargs="+", default=STATES,
                        metavar="ξ:β", help="restitution ξ in (0, 1] and roughness β in "
                        "[−1, 1] of each cooling state (default: those of the validation "
                        "table, " + " ".join(f"{xi}:{beta}" for xi, beta in STATES) + ")")
    parser.add_argument("--q", type=float, default=0.5, help="q of I = q m a² (default 0.5)")
    parser.add_argument("--particles", type=int, default=20000, help="N (default 20000)")
    parser.add_argument("--seeds", type=int, default=8, help="independent runs (default 8)")
    parser.add_argument("--collisions", type=float, default=100.0,
                        help="C/N per run (default 100)")
    parser.add_argument("--burn-in", type=float, default=20.0,
                        help="C/N left out at the start of each run (default 20)")
    parser.add_argument("--step-fraction", type=float, default=STEP_FRACTION,
                        help=f"f, candidates per step over N/2 (default {STEP_FRACTION})")
    parser.add_argument("--out", type=Path, default=Path("outputs/dsmc/cooling_state.json"),
                        help="JSON file (default outputs/dsmc/cooling_state.json)")
    args = parser.parse_args(argv)
    gas = Gas(inertia_factor=args.q)
    results = []
    for xi, beta in args.states:
        started = time.perf_counter()
        state = cooling_state(gas, RoughDisks(xi, beta), args.particles,
                              range(args.seeds), args.burn_in, args.collisions,
                              step_fraction=args.step_fraction)
        results.append({
            "restitution": xi, "roughness": beta, **state._asdict(),
            "theory_ratio": rough_disk_temperature_ratio(xi, beta, args.q),
            "theory_cooling_rate": rough_disk_cooling_rate(xi, beta, args.q),
            "seconds": time.perf_counter() - started})
        r = results[-1]
        print(f"ξ = {xi}, β = {beta}, q = {args.q}: T_rot/T_tr = "
              f"{r['ratio']:.5f} ± {r['ratio_error']:.5f} (theory {r['theory_ratio']:.5f}), "
              f"ζ/ν = {r['cooling_rate']:.5f} ± {r['cooling_rate_error']:.5f} (theory "
              f"{r['theory_cooling_rate']:.5f}), C/N = {r['collisions_per_particle']:.0f}, "
              f"{r['seconds']:.0f} s", flush=True)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    parameters = {k: (str(v) if isinstance(v, Path) else v) for k, v in vars(args).items()}
    args.out.write_text(json.dumps({"parameters": parameters, "results": results}, indent=2)
                        + "\n")


if __name__ == "__main__":
    main()
