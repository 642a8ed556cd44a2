"""Validation of rough disks (:mod:`sim.effects.rotation`): equipartition of an elastic,
perfectly rough gas, and the homogeneous cooling state of inelastic rough disks against the
DSMC solution of the Boltzmann equation (:mod:`sim.checks.dsmc`), the two-temperature
theory (:func:`sim.analysis.theory.rough_disk_temperature_ratio`) beside it.

Temperatures (k_B = 1): T_tr from the velocities in the frame of the local flow
(:func:`sim.analysis.datasets.granular_temperatures`, two degrees of freedom per disk),
T_rot = ⟨I ω²⟩ (one), I = q m a² with q = 1/2. Rows are
:class:`sim.checks.rows.Check`, studies are listed in
:data:`sim.checks.validation.STUDIES`.
"""

import math
import time

import numpy as np
from scipy import stats

from sim.analysis.datasets import granular_temperatures
from sim.analysis.theory import (
    enskog_collision_frequency,
    kolafa_rottner_z,
    rough_disk_temperature_ratio,
)
from sim.checks import dsmc
from sim.checks.gases import equilibrated_gas
from sim.checks.rows import Check, block_means
from sim.effects.rotation import moment_of_inertia
from sim.engine.core import Engine

#: q of the validation runs (uniform disks)
Q = 0.5


def _temperatures(engine, cells):
    """(T_tr in the frame of the local flow on ``cells`` × ``cells``, T_rot)."""
    n = engine.n
    translational = granular_temperatures(engine.positions()[None], engine.velocities()[None],
                                          engine.mass, np.zeros(n, int), engine.box,
                                          cells)[0, 0]
    inertia = moment_of_inertia(Q, engine.mass, engine.radius)
    return translational, float(np.mean(inertia * engine.angular_velocities() ** 2))


def _rough_gas(n, phi, seed, rotational_ratio, **effects):
    """The equilibrated elastic gas (:func:`sim.checks.gases.equilibrated_gas`, 10
    collisions per disk) continued as rough disks with spins Maxwellian at T_rot =
    ``rotational_ratio`` T_tr."""
    elastic, radius = equilibrated_gas(n, phi, 10, seed)
    temperature = elastic.kinetic_energy() / (n - 1)
    engine = Engine(elastic.positions(), elastic.velocities(), radius, elastic.mass,
                    boundary=elastic.boundary, inertia_factor=Q, seed=seed,
                    rotational_temperature=rotational_ratio * temperature, **effects)
    return engine, radius, temperature


def rough_equipartition(n=1000, phi=0.1, seed=61, runs=4, starts=(0.0, 4.0)):
    """Elastic, perfectly rough disks (ξ = 1, β = 1) reach equipartition, T_rot/T_tr = 1,
    from spins at rest and from spins four times hotter than the translation: the ratio
    averaged over C/N = 10 … 30 (every 2), mean of ``runs`` runs per start. Tolerance: four
    standard errors of the mean of the runs (T_tr and T_rot of N disks fluctuate by about
    √(2/N) and √(1/N)) plus 1 %. A last row tests the spins of every run and snapshot,
    ω √(I/T_rot), against the standard normal (KS p-value above 0.01).
    """
    started = time.perf_counter()
    rows, spins = [], []
    for start in starts:
        ratios = []
        for run in range(runs):
            engine, _, _ = _rough_gas(n, phi, seed + run, start, tangential_restitution=1.0)
            samples = []
            for c_per_n in range(10, 31, 2):
                engine.run(collisions=c_per_n * n)
                translational, rotational = _temperatures(engine, 1)
                samples.append(rotational / translational)
                inertia = moment_of_inertia(Q, engine.mass, engine.radius)
                spins.append(engine.angular_velocities() * np.sqrt(inertia / rotational))
            ratios.append(np.mean(samples))
        ratio, error = block_means(ratios)
        rows.append(Check(f"rough elastic gas (ξ = 1, β = 1) T_rot/T_tr from T_rot/T_tr = "
                          f"{start:g}, N = {n}, φ = {phi}, mean of {runs} runs", ratio, 1.0,
                          4.0 * error + 0.01, "equipartition", None))
    p_value = stats.kstest(np.concatenate(spins), stats.norm.cdf).pvalue
    rows.append(Check("KS p-value, spins ω √(I/T_rot) of the rough elastic gas", p_value, 1.0,
                      0.99, "Gaussian (Maxwellian)", None))
    rows[0] = Check(**{**rows[0].__dict__, "seconds": time.perf_counter() - started})
    return rows


def rough_cooling(restitution, roughness, n=2000, phi=0.005, seed=71, runs=32, window=(2, 6),
                  cells=4, dsmc_particles=10000, dsmc_runs=16):
    """The homogeneous cooling state of rough disks (ξ, β, q = 1/2) against the DSMC solution
    of the Boltzmann equation for the same gas (:mod:`sim.checks.dsmc`), each from the same
    start: velocities and spins Maxwellian at T_rot = r T_tr, r DSMC's cooling state of
    ``make dsmc``. Two rows: T_rot/T_tr averaged over C/N = ``window[0]`` … ``window[1]``
    (:func:`sim.checks.dsmc.at_collisions` for DSMC), and T_tr(t₀)/T₀ at t₀ = 2/(ν₀ ζ/ν₀),
    ζ/ν₀ the state's cooling rate and ν₀ Enskog's collision frequency at T₀ (χ from
    Kolafa–Rottner), where Haff's law gives 1/4; each the mean of ``runs`` runs against that of
    ``dsmc_runs`` DSMC runs of ``dsmc_particles``. The start is not quite the state (its
    distributions are Gaussian where the state's are not) and the ratio drifts a little over
    the window, in DSMC as in the engine, so the references are DSMC's from that start, not
    the state's values. The two-temperature Maxwellian theory (Huthmann & Zippelius 1997;
    Luding et al. 1998) is named beside it: its closure neglects the fourth cumulants and
    misses r by a few per cent.

    The gas is dilute, where the Boltzmann equation holds, and its box small against the
    clustering length (N φ = 10: 2.3 box sides for smooth disks at ξ = 0.9; the energy rough
    contacts lose to spin shortens it, and it stays above the box for these four states);
    T_tr is taken in the frame of the local flow on ``cells`` × ``cells`` cells. Tolerances:
    four standard errors of the difference (those of the mean of the runs and of DSMC, in
    quadrature).
    """
    started = time.perf_counter()
    state = dsmc.stored_cooling_state(restitution, roughness)
    start, rate = state["ratio"], state["cooling_rate"]
    theory = rough_disk_temperature_ratio(restitution, roughness, Q)
    chi = (kolafa_rottner_z(phi) - 1.0) / (2.0 * phi)
    marks = np.arange(window[0], window[1] + 1)
    ratios, decays = [], []
    for run in range(runs):
        engine, radius, _ = _rough_gas(n, phi, seed + run, start, restitution=restitution,
                                       tangential_restitution=roughness)
        t_zero = _temperatures(engine, cells)[0]
        t0 = 2.0 / (enskog_collision_frequency(n, 2.0 * radius, chi, t_zero) * rate)
        samples = []
        for c_per_n in marks:
            engine.run(collisions=int(c_per_n * n))
            translational, rotational = _temperatures(engine, cells)
            samples.append(rotational / translational)
        ratios.append(np.mean(samples))
        fresh, _, _ = _rough_gas(n, phi, seed + run, start, restitution=restitution,
                                 tangential_restitution=roughness)
        fresh.run(time=t0)
        decays.append(_temperatures(fresh, cells)[0] / t_zero)
    gas = dsmc.Gas(inertia_factor=Q)
    rule = dsmc.RoughDisks(restitution, roughness)
    exact_ratios, exact_decays = [], []
    for k in range(dsmc_runs):
        translational, rotational = dsmc.at_collisions(gas, rule, dsmc_particles, marks,
                                                       seed + k, rotational_temperature=start)
        exact_ratios.append(np.mean(rotational[:, 0] / translational[:, 0]))
        exact_decays.append(dsmc.cooled_in_haff_time(gas, rule, dsmc_particles, rate, seed + k,
                                                     rotational_temperature=start))
    (ratio, error), (decay, decay_error) = block_means(ratios), block_means(decays)
    (reference, reference_error), (exact_decay, exact_decay_error) = (
        block_means(exact_ratios), block_means(exact_decays))
    seconds = time.perf_counter() - started
    source = f"DSMC from the same start, {dsmc_runs} runs of {dsmc_particles}"
    return [
        Check(f"rough cooling T_rot/T_tr, ξ = {restitution}, β = {roughness}, q = {Q}, "
              f"N = {n}, φ = {phi}, C/N = {window[0]} … {window[1]}, mean of {runs} runs",
              ratio, reference, 4.0 * math.hypot(error, reference_error),
              f"{source}; its cooling state {start:.4f} (make dsmc); Maxwellian theory "
              f"{theory:.4f}", seconds),
        Check(f"rough cooling T_tr(t₀)/T₀, ξ = {restitution}, β = {roughness}", decay,
              exact_decay, 4.0 * math.hypot(decay_error, exact_decay_error),
              f"{source}; Haff's law at DSMC's ζ: 0.2500", None),
    ]
