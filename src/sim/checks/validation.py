"""Validation against theory: each study runs the engine and returns rows of a table.

A row (:class:`Check`) holds the measured value, the reference and its source, the tolerance
the comparison allows and why, whether it passed, and the wall-clock seconds of its run.
``tests/test_validation.py`` runs every study as a slow test and writes the table to
``outputs/validation/`` (``make validate``). Each study's docstring gives its formula and source;
the closed forms it compares with (equations of state, Enskog's collision frequency, the
mixture's temperature ratio) are those of :mod:`sim.analysis.theory`.

Units: k_B = 1, unit masses unless stated, 2D temperature T = E_kin/(N − 1) when the total
momentum is zero (E_kin = (N − 1) T: two degrees of freedom per disk, two fixed by the
momentum), lengths in box units.
"""

import math
import time

import numpy as np
from scipy import stats
from scipy.optimize import brentq

from sim.analysis.datasets import granular_temperatures
from sim.analysis.theory import (
    enskog_collision_frequency,
    garzo_dufty_temperature_ratio,
    henderson_z,
    kolafa_rottner_z,
)
from sim.checks import dsmc
from sim.checks.gases import cooling_gas, equilibrated_gas
from sim.checks.jamming import compression_eos, jamming_density
from sim.checks.melting import small_n_pressure
from sim.checks.potential import energy_conservation, second_virial, step_jumps
from sim.checks.rough import rough_cooling, rough_equipartition
from sim.checks.rows import Check, block_means, ratio_of_means
from sim.engine.core import Engine
from sim.engine.inputs import Boundary
from sim.pipeline.initial import (
    fixed_speed,
    maxwellian,
    radius_for_packing,
    random_sequential,
    remove_drift,
)

# -- equilibrium hard-disk fluid --------------------------------------------------------------

def virial_blocks(engine, blocks, collisions_per_block):
    """Run an elastic engine on in ``blocks`` consecutive blocks of ``collisions_per_block``
    collisions per disk; returns, per block, Z = 1 + Σ r_ij·Δp_i/(2 N T t) from the collision
    virial and the collision frequency per disk ω = 2 C/(N t). T = E_kin/(N − 1)."""
    n = engine.n
    temperature = engine.kinetic_energy() / (n - 1)
    z, omega = [], []
    for _ in range(blocks):
        t0, v0, c0 = engine.time, engine.virial, engine.collisions
        engine.run(collisions=c0 + collisions_per_block * n)
        t = engine.time - t0
        z.append(1.0 + (engine.virial - v0) / (2.0 * n * temperature * t))
        omega.append(2.0 * (engine.collisions - c0) / (n * t))
    return np.array(z), np.array(omega)


def equation_of_state(phi, n=2000, warmup=200, blocks=20, collisions_per_block=200,
                      seed=1):
    """Z from the collision virial, Z = 1 + Σ r_ij·Δp_i/(2 N T t), in ``blocks`` blocks, and the
    collision frequency against Enskog's with the same run's χ = (Z − 1)/(2φ).

    Tolerances: four standard errors of the block means, plus 0.6 % for Henderson's formula
    at φ ≤ 0.5 (docs/physics.md: good to about 0.5 %) — compared only there — and 1/N relative for
    the finite box against the Kolafa–Rottner limit.
    """
    started = time.perf_counter()
    engine, radius = equilibrated_gas(n, phi, warmup, seed)
    temperature = engine.kinetic_energy() / (n - 1)
    z_blocks, omega_blocks = virial_blocks(engine, blocks, collisions_per_block)
    z, z_error = block_means(z_blocks)
    omega, omega_error = block_means(omega_blocks)
    seconds = time.perf_counter() - started
    chi = (z - 1.0) / (2.0 * phi)
    rows = [Check(f"Z at φ = {phi}, N = {n}", z, kolafa_rottner_z(phi),
                  4.0 * z_error + kolafa_rottner_z(phi) / n,
                  "Kolafa & Rottner 2006 fit", seconds)]
    if phi <= 0.5:
        rows.append(Check(f"Z at φ = {phi} (Henderson)", z, henderson_z(phi),
                          4.0 * z_error + 0.006 * henderson_z(phi), "Henderson 1975", None))
    omega_enskog = enskog_collision_frequency(n, 2.0 * radius, chi, temperature)
    rows.append(Check(f"collision frequency at φ = {phi}", omega, omega_enskog,
                      4.0 * omega_error + 4.0 * omega_enskog * z_error / (z - 1.0),
                      "Enskog, χ from the same run's Z", None))
    return rows


def maxwell_boltzmann(n=4000, phi=0.3, warmup=20, snapshots=5, apart=10, seed=3):
    """Speeds after equilibration from equal speeds, against the 2D Maxwell–Boltzmann law at
    the run's temperature: the KS p-value (pass above 0.01; for one mass the energies give the
    same statistic) and the kurtosis ⟨v⁴⟩/⟨v²⟩² = 2 (four standard errors)."""
    started = time.perf_counter()
    radius = radius_for_packing(n, phi)
    periodic = (True, True)
    position = random_sequential(np.full(n, radius), periodic=periodic, seed=seed)
    velocity = remove_drift(fixed_speed(n, 1.0, seed=seed + 1), np.ones(n))
    engine = Engine(position, velocity, radius, boundary=Boundary(periodic=periodic))
    engine.run(collisions=warmup * n)
    temperature = engine.kinetic_energy() / (n - 1)
    speeds = []
    for _ in range(snapshots):
        engine.run(collisions=engine.collisions + apart * n)
        speeds.append(np.linalg.norm(engine.velocities(), axis=1))
    v = np.concatenate(speeds)
    seconds = time.perf_counter() - started
    speed_p = stats.kstest(v, stats.rayleigh(scale=math.sqrt(temperature)).cdf).pvalue
    v2 = v**2
    kurtosis = float(np.mean(v2**2) / np.mean(v2) ** 2)
    # its standard error from the spread over snapshots, which are nearly independent
    per_snapshot = [np.mean(s**4) / np.mean(s**2) ** 2 for s in speeds]
    kurtosis_error = float(np.std(per_snapshot, ddof=1) / math.sqrt(len(per_snapshot)))
    return [
        Check(f"KS p-value, speeds (N = {n} × {snapshots})", speed_p, 1.0, 0.99,
              "2D Maxwell–Boltzmann at the run's T", seconds),
        Check("kurtosis ⟨v⁴⟩/⟨v²⟩²", kurtosis, 2.0, 4.0 * kurtosis_error, "2D Maxwellian", None),
    ]


# -- granular gases ---------------------------------------------------------------------------

def haff_cooling(restitution, n=2000, phi=0.005, seed=5, runs=32, cells=4,
                 dsmc_particles=10000, dsmc_runs=32):
    """Homogeneous cooling of smooth disks: T(C)/T₀ at C/N = 1/(1 − ξ²) and T(t₀)/T₀ at
    t₀ = 4/((1 − ξ²) ω₀) (ω₀ Enskog's collision frequency at T₀, χ from Kolafa–Rottner), each
    the mean of ``runs`` runs (seeds ``seed``, ``seed + 1``, …) from the equilibrated elastic
    gas, against DSMC of the same Boltzmann–Enskog equation from a Maxwellian start
    (:mod:`sim.checks.dsmc`, ``dsmc_runs`` runs of ``dsmc_particles``, t₀ from its own T₀).
    Haff's law, which takes the distribution as Maxwellian, is named beside them:
    T/T₀ = exp(−(1 − ξ²) C/N) = 1/e and T/T₀ = 1/(1 + t/t₀)² = 1/4 (the Sonine correction a₂
    is below 1 % for ξ ≥ 0.7).

    The box is below the length at which a cooling gas grows shear and clusters,
    2√π/(nσ√(1 − ξ²)) (N φ = 10: 2.3 box sides at ξ = 0.9, 1.7 at ξ = 0.8), so that the gas
    stays homogeneous; T is taken in the frame of the local flow on ``cells`` × ``cells``
    cells (:func:`sim.analysis.datasets.granular_temperatures`), as in DSMC's homogeneous gas.
    Tolerances: four standard errors of the difference (the runs' and DSMC's, in quadrature).
    """
    started = time.perf_counter()
    rate = 1.0 - restitution**2
    chi = (kolafa_rottner_z(phi) - 1.0) / (2.0 * phi)
    radius = radius_for_packing(n, phi)
    kind = np.zeros(n, dtype=int)

    def temperature(engine):
        return granular_temperatures(engine.positions()[None], engine.velocities()[None],
                                     engine.mass, kind, engine.box, cells)[0, 0]

    cooled_by_collisions, cooled_in_time = [], []
    for realization in range(runs):
        engine, _ = cooling_gas(n, phi, restitution, seed + realization)
        t_zero = temperature(engine)
        t0 = 4.0 / (rate * enskog_collision_frequency(n, 2.0 * radius, chi, t_zero))
        engine.run(collisions=round(n / rate))  # T/T₀ = 1/e comes before T/T₀ = 1/4
        cooled_by_collisions.append(temperature(engine) / t_zero)
        engine.run(time=t0)
        cooled_in_time.append(temperature(engine) / t_zero)
    gas = dsmc.Gas(diameters=(2.0 * radius,), density=float(n), chi=chi)
    rule = dsmc.SmoothDisks(restitution)
    exact_by_collisions, exact_in_time = [], []
    for k in range(dsmc_runs):
        translational, _ = dsmc.at_collisions(gas, rule, dsmc_particles, [0.0, 1.0 / rate],
                                              seed + k)
        exact_by_collisions.append(translational[1, 0] / translational[0, 0])
        exact_in_time.append(dsmc.cooled_in_haff_time(gas, rule, dsmc_particles, rate / 2.0,
                                                      seed + k))
    seconds = time.perf_counter() - started
    rows = []
    for name, measured, exact, haff, source in (
            (f"Haff T(C)/T₀ at C/N = {1 / rate:.2f}, ξ = {restitution}, N = {n}, φ = {phi}, "
             f"mean of {runs} runs", cooled_by_collisions, exact_by_collisions,
             math.exp(-1.0), "exp(−(1−ξ²)C/N)"),
            (f"Haff T(t₀)/T₀, ξ = {restitution}", cooled_in_time, exact_in_time, 0.25,
             "T₀/(1 + t/t₀)², Enskog ω₀")):
        value, error = block_means(measured)
        reference, reference_error = block_means(exact)
        rows.append(Check(name, value, reference, 4.0 * math.hypot(error, reference_error),
                          f"DSMC, {dsmc_runs} runs of {dsmc_particles} (± "
                          f"{reference_error:.2g}); Haff's law {source}: {haff:.4f}",
                          seconds if not rows else None))
    return rows


def mixture_temperature_ratio(restitution, n=800, phi=0.02, mass_ratio=4.0, seed=7, runs=32,
                              window=(5, 30), cells=4, dsmc_particles=10000, dsmc_runs=16):
    """T₂/T₁ of an equimolar mixture of equal-size disks with m₂/m₁ = ``mass_ratio``, against
    equipartition (ξ = 1, exact) or, at ξ < 1, the homogeneous cooling state of the Boltzmann–
    Enskog equation solved by DSMC (:func:`sim.checks.dsmc.at_collisions`, the same masses,
    fractions and Maxwellian start, read at the same collisions per disk), with the Maxwellian
    theory of Garzó & Dufty (1999) named beside it.

    The gas is that of figure 7: N φ = 16 puts the box below the length at which a cooling
    gas grows shear and clusters (1.31 box sides at ξ = 0.8), so it stays homogeneous. It
    still carries some flow, more of it in the heavier species, so the temperatures are taken
    in the frame of the local flow on ``cells`` × ``cells`` cells
    (:func:`sim.analysis.datasets.granular_temperatures`, which also counts the degrees of
    freedom the zero total momentum takes), as in DSMC's homogeneous gas. T₂/T₁ is the ratio of
    the species temperatures averaged over the runs, at the snapshots at C/N = ``window[0]`` …
    ``window[1]``, one per collision per disk, then over them, with its jackknife error over
    ``runs`` independent runs (seeds ``seed``, ``seed + 1``, …;
    :func:`sim.checks.rows.ratio_of_means`); DSMC's is the mean over its ``dsmc_runs`` runs.
    Tolerance: four standard errors of the difference (both in quadrature). At ξ = 1 a second
    row tests the energies m v²/2 of both species together against the exponential law with
    mean T (KS p-value above 0.01), which holds for any mass.
    """
    started = time.perf_counter()
    species = np.arange(n) % 2
    mass = np.where(species == 1, mass_ratio, 1.0)
    marks = np.arange(window[0], window[1] + 1)
    temperatures, energies = [], []
    for run in range(runs):
        engine, _ = cooling_gas(n, phi, None if restitution == 1.0 else restitution,
                                seed + run, mass=mass, species=species)
        positions, velocities = [], []
        for c_per_n in marks:
            engine.run(collisions=int(c_per_n * n))
            positions.append(engine.positions())
            velocities.append(engine.velocities())
        temperatures.append(granular_temperatures(np.array(positions), np.array(velocities),
                                                  mass, species, engine.box, cells))
        if restitution == 1.0:
            energies.append(0.5 * mass * np.sum(velocities[0] ** 2, axis=1))
    _, _, ratio, error = ratio_of_means(np.array(temperatures), np.ones(marks.size, bool))
    theory = garzo_dufty_temperature_ratio([1.0, mass_ratio], [0.5, 0.5], restitution)
    if restitution == 1.0:
        reference, reference_error, source = 1.0, 0.0, "equipartition"
    else:
        radius = radius_for_packing(n, phi)
        gas = dsmc.Gas(masses=(1.0, mass_ratio), diameters=(2.0 * radius,) * 2,
                       fractions=(0.5, 0.5), density=float(n),
                       chi=(kolafa_rottner_z(phi) - 1.0) / (2.0 * phi))
        exact = [dsmc.at_collisions(gas, dsmc.SmoothDisks(restitution), dsmc_particles, marks,
                                    seed + k)[0] for k in range(dsmc_runs)]
        reference, reference_error = block_means([np.mean(t[:, 1] / t[:, 0]) for t in exact])
        source = (f"DSMC, {dsmc_runs} runs of {dsmc_particles} (± {reference_error:.2g}); "
                  f"Garzó & Dufty 1999, Maxwellian: {theory:.4f}")
    seconds = time.perf_counter() - started
    rows = [Check(f"mixture T₂/T₁, m₂/m₁ = {mass_ratio:g}, ξ = {restitution}, N = {n}, "
                  f"φ = {phi}, C/N = {window[0]} … {window[1]}, mean of {runs} runs", ratio,
                  reference, 4.0 * math.hypot(error, reference_error), source, seconds)]
    if restitution == 1.0:
        energies = np.concatenate(energies)
        p_value = stats.kstest(energies, stats.expon(scale=energies.mean()).cdf).pvalue
        rows.append(Check("KS p-value, energies m v²/2 of both masses", p_value, 1.0, 0.99,
                          "exponential with mean T, any mass", None))
    return rows


def tc_model(restitution=0.8, n=4000, phi=0.1, seed=5, runs=8):
    """The TC model with t_c = 10⁻⁴ mean free times leaves the cooling unchanged: E(C)/E₀ at
    C/N = 1/(1 − ξ²) with it over E(C)/E₀ without it, run by run from the same start (seeds
    ``seed``, ``seed + 1``, …), is 1 within four standard errors of the mean of ``runs`` runs
    (the two runs of a pair part as their paths diverge, so their ratio scatters); and the
    energy the engine booked as dissipated equals the kinetic energy lost, to round-off (1e-12
    relative)."""
    started = time.perf_counter()
    rate = 1.0 - restitution**2
    chi = (kolafa_rottner_z(phi) - 1.0) / (2.0 * phi)
    mean_free_time = 1.0 / enskog_collision_frequency(n, 2.0 * radius_for_packing(n, phi), chi,
                                                      1.0)
    ratios, worst = [], 0.0
    for run in range(runs):
        plain, _ = cooling_gas(n, phi, restitution, seed + run)
        with_tc, _ = cooling_gas(n, phi, restitution, seed + run, tc=1e-4 * mean_free_time)
        cooled = []
        for engine in (plain, with_tc):
            e0 = engine.kinetic_energy()
            engine.run(collisions=round(n / rate))
            cooled.append(engine.kinetic_energy() / e0)
        ratios.append(cooled[1] / cooled[0])
        lost = e0 - with_tc.kinetic_energy()
        worst = max(worst, abs(with_tc.dissipated_energy / lost - 1.0))
    ratio, error = block_means(ratios)
    seconds = time.perf_counter() - started
    return [
        Check(f"TC (t_c = 1e-4 mean free times): E(C)/E₀ with / without, mean of {runs} runs",
              ratio, 1.0, 4.0 * error, "unchanged cooling (Luding & McNamara 1998)", seconds),
        Check("dissipated energy booked / kinetic energy lost − 1, worst of the runs", worst,
              0.0, 1e-12, "exact bookkeeping", None),
    ]


# -- exact two-body results -------------------------------------------------------------------

def two_body(cases=1000, seed=11):
    """Random binary collisions — masses log-uniform over 10⁻³ … 10³, impact parameter
    b/a ∈ [0, 0.99], ξ ∈ [0, 1] — against the closed forms (docs/physics.md): the recoil of the
    target (speed J/m₂ along the line of centres, J = (1 + ξ) μ v cos α), the energy lost
    (1 − ξ²) μ (v cos α)²/2 and, when elastic, the projectile's scattering angle
    tan θ₁ = sin χ/(m₁/m₂ + cos χ). The largest relative error of all must stay below 1e-12."""
    started = time.perf_counter()
    rng = np.random.default_rng(seed)
    worst = 0.0
    v, r1, r2 = 2.0, 0.01, 0.03
    a = r1 + r2
    for _ in range(cases):
        m1, m2 = 10.0 ** rng.uniform(-3.0, 3.0, 2)
        b_over_a = rng.uniform(0.0, 0.99)
        xi = 1.0 if rng.random() < 0.25 else rng.uniform(0.0, 1.0)
        engine = Engine([[0.3, 0.5 + b_over_a * a], [0.6, 0.5]], [[v, 0.0], [0.0, 0.0]],
                        [r1, r2], mass=[m1, m2], restitution=xi)
        engine.run(collisions=1)
        cos_alpha = math.sqrt(1.0 - b_over_a**2)
        mu = m1 * m2 / (m1 + m2)
        recoil = engine.velocities()[1]
        errors = [np.hypot(*recoil) / ((1.0 + xi) * mu * v * cos_alpha / m2) - 1.0]
        lost = 0.5 * (1.0 - xi**2) * mu * (v * cos_alpha) ** 2
        if lost > 0.0:
            errors.append(engine.dissipated_energy / lost - 1.0)
        if xi == 1.0:
            chi = 2.0 * math.acos(b_over_a)
            v1 = engine.velocities()[0]
            theta1 = math.atan2(math.sin(chi), m1 / m2 + math.cos(chi))
            errors.append(math.remainder(math.atan2(v1[1], v1[0]) - theta1, 2.0 * math.pi))
        worst = max(worst, *(abs(e) for e in errors))
    return [Check(f"two-body: worst relative error of {cases} random collisions", worst, 0.0,
                  1e-12, "closed forms (docs/physics.md)", time.perf_counter() - started)]


# -- gravity and walls ------------------------------------------------------------------------

def bouncing_ball(restitution=0.8, bounces=30, height=0.5, g=9.81):
    """A ball dropped from ``height`` above contact onto a floor with restitution ξ_w: the k-th
    bounce leaves at ξ_w^k √(2 g h₀) and peaks at ξ_w^(2k) h₀. The largest relative error of
    the bounce speeds and peak heights over ``bounces`` bounces must stay below 1e-11."""
    started = time.perf_counter()
    radius = 0.05
    engine = Engine([[0.5, radius + height]], [[0.0, 0.0]], radius,
                    wall_restitution=restitution, gravity=[0.0, -g])
    worst = 0.0
    for k in range(1, bounces + 1):
        engine.run(contacts=k)
        speed = restitution**k * math.sqrt(2.0 * g * height)
        peak = engine.positions(engine.time + speed / g)[0, 1] - radius
        worst = max(worst, abs(engine.velocities()[0, 1] / speed - 1.0),
                    abs(peak / (restitution ** (2 * k) * height) - 1.0))
    return [Check(f"bouncing ball, ξ_w = {restitution}: worst relative error of {bounces} "
                  f"bounce speeds and heights", worst, 0.0, 1e-11,
                  "v_k = ξ_w^k √(2 g h₀), h_k = ξ_w^(2k) h₀", time.perf_counter() - started)]


def barometric(n=400, phi=0.001, g=4.0, snapshots=2000, seed=13):
    """An elastic, very dilute gas under gravity in the unit box relaxes to the isothermal
    atmosphere: heights above the floor (y − R) follow the exponential law of scale height
    H = T/(m g), truncated at the ceiling, with T = E_kin/N; and the temperature is the same in
    the lower and the upper half. H is read from the mean height, ⟨y'⟩ = H − L'/(e^(L'/H) − 1)
    on [0, L'], L' = 1 − 2R; snapshots are 0.25 apart in time, about the time a disk takes
    to fall one scale height. At φ = 0.001 the non-ideal correction to the scale height
    (Z − 1 ≈ 2φ, so H grows by about 4φ at the floor, where φ is 4 times the mean) is below
    2 %."""
    started = time.perf_counter()
    radius = radius_for_packing(n, phi)
    position = random_sequential(np.full(n, radius), seed=seed)
    engine = Engine(position, maxwellian(np.ones(n), 1.0, seed=seed + 1), radius,
                    gravity=[0.0, -g])
    engine.run(collisions=50 * n)
    start = engine.time
    heights, low, high = [], [], []
    for k in range(1, snapshots + 1):
        t = start + 0.25 * k
        engine.run(time=t)
        y = engine.positions(t)[:, 1] - radius
        energy = 0.5 * np.sum(engine.velocities(t) ** 2, axis=1)
        heights.append(y)
        lower = y < np.median(y)
        low.append(energy[lower].mean())
        high.append(energy[~lower].mean())
    heights = np.concatenate(heights)
    temperature = 0.5 * (np.mean(low) + np.mean(high))
    span = 1.0 - 2.0 * radius
    mean_height = float(heights.mean())

    def mean_of_truncated(scale):
        return scale - span / math.expm1(span / scale)

    scale = brentq(lambda h: mean_of_truncated(h) - mean_height, 1e-2 * span, 1e2 * span)
    seconds = time.perf_counter() - started
    return [
        Check(f"barometric scale height / (T/mg), φ = {phi}", scale / (temperature / g), 1.0,
              0.02, "isothermal atmosphere n ∝ exp(−m g y/T)", seconds),
        Check("temperature of the upper half / lower half", np.mean(high) / np.mean(low), 1.0,
              0.02, "equilibrium: one temperature at every height", None),
    ]


def thermal_walls(n=1000, phi=0.02, temperature=2.0, samples=400, seed=3):
    """Elastic disks between four walls at T_w come to equilibrium at T_w: the time average of
    E_kin/N is T_w, and the energies m v²/2 are exponential with mean T_w (a KS test on
    thinned samples). The total energy fluctuates by about 1/√N and relaxes only through the
    walls, so the average runs over ``samples`` snapshots 0.1 apart in time; its error is that
    of the means of ten consecutive blocks of them, and the tolerance four of it."""
    started = time.perf_counter()
    radius = radius_for_packing(n, phi)
    walls = {name: {"temperature": temperature} for name in ("left", "right", "bottom", "top")}
    engine = Engine(random_sequential(np.full(n, radius), seed=seed),
                    fixed_speed(n, 1.0, seed=seed + 1), radius, walls=walls, seed=seed)
    engine.run(collisions=100 * n)
    start = engine.time
    energies = []
    for k in range(1, samples + 1):
        engine.run(time=start + 0.1 * k)
        energies.append(0.5 * np.sum(engine.velocities(start + 0.1 * k) ** 2, axis=1))
    mean, error = block_means([np.mean(block) / temperature
                               for block in np.array_split(np.array(energies), 10)])
    energies = np.concatenate(energies)
    seconds = time.perf_counter() - started
    return [
        Check(f"thermal walls: ⟨m v²/2⟩ / T_w, T_w = {temperature}", mean, 1.0, 4.0 * error,
              "equilibrium with the walls", seconds),
        Check("KS p-value of energies m v²/2 against exp(mean T_w)",
              stats.kstest(energies[np.arange(samples) * n + np.arange(samples) * 7919 % n],
                           "expon", args=(0.0, temperature)).pvalue, 1.0,
              0.99, "> 0.01 (Maxwell–Boltzmann at T_w)", None),
    ]


def driven_steady_state(n=1000, phi=0.1, restitution=0.9, seed=5):
    """ξ = 0.9 disks between walls at T_w = 1 reach a steady state in which the walls' work
    balances the dissipation (over 500 collisions per disk after 200 of transient), and the
    kinetic energy is E₀ + W − D at every moment, to round-off of the work W."""
    started = time.perf_counter()
    radius = radius_for_packing(n, phi)
    walls = {name: {"temperature": 1.0} for name in ("left", "right", "bottom", "top")}
    engine = Engine(random_sequential(np.full(n, radius), seed=seed),
                    fixed_speed(n, 1.0, seed=seed + 1), radius, restitution=restitution,
                    walls=walls, seed=seed)
    engine.run(collisions=200 * n)
    work, lost = engine.wall_work, engine.dissipated_energy
    engine.run(collisions=700 * n)
    balance = engine.initial_energy + engine.wall_work - engine.dissipated_energy
    seconds = time.perf_counter() - started
    return [
        Check(f"driven gas ξ = {restitution}: wall work / dissipation in the steady state",
              (engine.wall_work - work) / (engine.dissipated_energy - lost), 1.0, 0.005,
              "steady state: input = dissipation", seconds),
        Check("(E_kin − (E₀ + W − D)) / W", (engine.kinetic_energy() - balance)
              / engine.wall_work, 0.0, 1e-12, "exact bookkeeping", None),
    ]


def piston(n=200, phi=0.02, speed=-0.01, seeds=(7, 8, 9)):
    """A slow piston halves the box of a dilute elastic gas: the temperature follows the
    adiabat of hard disks, d ln T = −Z d ln A with Z = 1 + 2φ at low density, in the area open
    to disk centres: T₁/T₀ = (A₀'/A₁') exp(2(φ₁ − φ₀)); mean over ``seeds``."""
    started = time.perf_counter()
    radius = radius_for_packing(n, phi)
    ratios = []
    t_half = 0.5 / -speed
    for seed in seeds:
        engine = Engine(random_sequential(np.full(n, radius), seed=seed),
                        fixed_speed(n, 1.0, seed=seed + 1), radius,
                        walls={"top": {"speed": speed}})
        e0 = engine.kinetic_energy()
        engine.run(time=t_half)
        ratios.append(engine.kinetic_energy(t_half) / e0)
    adiabat = (1.0 - 2.0 * radius) / (0.5 - 2.0 * radius) * math.exp(2.0 * (2 * phi - phi))
    return [Check(f"piston at U = {speed}: T₁/T₀ when the area halves, / adiabat",
                  float(np.mean(ratios)) / adiabat, 1.0, 0.01,
                  "quasi-static adiabat of hard disks (Z = 1 + 2φ)",
                  time.perf_counter() - started)]


#: Every study of the table, by name: a callable returning rows.
STUDIES = {
    **{f"equation_of_state_{phi}": (lambda phi=phi: equation_of_state(phi))
       for phi in (0.2, 0.4, 0.5, 0.6, 0.65)},
    "maxwell_boltzmann": maxwell_boltzmann,
    "haff_0.9": lambda: haff_cooling(0.9),
    "haff_0.8": lambda: haff_cooling(0.8),
    "mixture_elastic": lambda: mixture_temperature_ratio(1.0),
    "mixture_0.8": lambda: mixture_temperature_ratio(0.8),
    "tc_model": tc_model,
    "two_body": two_body,
    "bouncing_ball": bouncing_ball,
    "barometric": barometric,
    "thermal_walls": thermal_walls,
    "driven_steady_state": driven_steady_state,
    "piston": piston,
    "rough_equipartition": rough_equipartition,
    **{f"rough_cooling_{xi}_{beta}": (lambda xi=xi, beta=beta: rough_cooling(xi, beta))
       for xi, beta in ((0.9, 0.5), (0.9, 0.0), (0.8, -0.5), (0.7, 0.5))},
    "compression_eos": compression_eos,
    "jamming_density": jamming_density,
    "melting_small_n": small_n_pressure,
    "potential_energy": energy_conservation,
    "potential_steps": step_jumps,
    "potential_b2": second_virial,
}
