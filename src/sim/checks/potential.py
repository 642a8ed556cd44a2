"""Validation of stepped pair potentials (:mod:`sim.effects.potential`): the energy a gas of
square-well disks keeps over 10⁷ events, the jumps of g(r) at the steps, which equilibrium
fixes, and the pressure at low density against the exact second virial coefficient.

Across a step at λσ the cavity function y(r) = g(r) e^{βu(r)} is continuous, so
g(λσ⁺)/g(λσ⁻) = e^{−β(u_out − u_in)} (Hansen & McDonald, Theory of Simple Liquids, 4th ed.
(2013), §4.2; for square wells e.g. Largo, Solana, Yuste & Santos, J. Chem. Phys. 122,
084510 (2005)). g is histogrammed in bins whose edges sit on the steps, a line is fitted to
the bins on each side and each line is taken to the step; β comes from the run's kinetic
energy, kT = ⟨K⟩/(N − 1) with zero total momentum, K = Σ m v²/2 in two dimensions.
"""

import math
import time
from typing import NamedTuple

import numpy as np

from sim.analysis.observers import RadialDistribution
from sim.checks.gases import equilibrated_gas
from sim.checks.rows import Check, block_means
from sim.engine.core import Engine
from sim.engine.overlap import first_overlap

#: kT = ⟨K⟩/(N − 1) of a run is brought this close to the asked temperature before it counts
THERMALISED = 0.01


def stepped_gas(n, phi, temperature, steps, energies, seed=0):
    """Equal disks (mass 1) at packing fraction ``phi`` ≤ 0.3 in the periodic unit box with
    the stepped potential ``steps``, ``energies``, randomly placed, Maxwellian at
    ``temperature`` with zero total momentum (:func:`sim.checks.gases.equilibrated_gas`, not
    run). Returns (engine, radius)."""
    return equilibrated_gas(n, phi, 0, seed, temperature=temperature,
                            potential_steps=list(steps), potential_energies=list(energies))


def energy_conservation(n=1000, phi=0.3, temperatures=(0.5, 1.0, 5.0), events=10_000_000,
                        chunks=20, seed=0):
    """Kinetic plus potential energy of a square-well gas (λ = 1.5, ε = 1) over ``events``
    events at each of ``temperatures`` (kT/ε): the largest |E(t) − E(0)| over the run, at the
    end of each of ``chunks`` chunks, relative to the kinetic energy, within 1e-11; and no
    two cores overlapping (the audit) at any chunk's end."""
    rows = []
    for temperature in temperatures:
        started = time.perf_counter()
        engine, radius = stepped_gas(n, phi, temperature, [1.5], [-1.0], seed)
        energy = engine.kinetic_energy() + engine.potential_energy()
        worst, overlaps = 0.0, 0
        for k in range(1, chunks + 1):
            engine.run(events=events * k // chunks)
            worst = max(worst, abs(engine.kinetic_energy() + engine.potential_energy() - energy)
                        / engine.kinetic_energy())
            overlaps += first_overlap(engine.positions(), engine.radius, engine.box,
                                      engine.periodic) is not None
        rows.append(Check(
            f"square well λ = 1.5 started at kT/ε = {temperature:g}, φ = {phi}, N = {n}: "
            f"|ΔE|/K over "
            f"{events:.0e} events ({engine.collisions:.2g} collisions); overlaps {overlaps}",
            worst + overlaps, 0.0, 1e-11, "energy conservation; no overlap",
            time.perf_counter() - started))
    return rows


def step_jumps(n=1000, phi=0.2, temperature=1.0, steps=(1.3, 1.6), energies=(-1.0, 0.5),
               snapshots=4000, blocks=8, width=0.01, fitted=6, seed=0):
    """g(λσ⁺)/g(λσ⁻) at every step of a two-step potential (a well inside a shoulder) against
    e^{−β(u_out − u_in)}: g (:class:`sim.analysis.observers.RadialDistribution`) of
    ``snapshots`` snapshots one collision per disk apart, in
    ``blocks`` blocks (the error: the standard error of the blocks' ratios), bins of
    ``width`` σ with edges on the steps, a line through the ``fitted`` bins on each side."""
    started = time.perf_counter()
    engine, _ = stepped_gas(n, phi, temperature, steps, energies, seed)
    engine.run(collisions=50 * n)
    reach = max(steps) + fitted * width
    g_of = RadialDistribution(int(round(reach / width)), reach, engine)
    g = np.zeros((blocks, g_of.shape[0]))
    kinetic = []
    per_block = snapshots // blocks
    for s in range(per_block * blocks):
        engine.run(collisions=engine.collisions + n)
        g[s // per_block] += g_of(engine, engine.time, engine.positions(), None) / per_block
        kinetic.append(engine.kinetic_energy())
    kt = float(np.mean(kinetic)) / (n - 1)
    u = np.concatenate([[0.0], energies, [0.0]])
    rows = []
    for k, (step, mean, error, expected) in enumerate(
            step_ratios(g_of.coords["r"], g, steps, energies, kt, fitted)):
        rows.append(Check(
            f"g(λσ⁺)/g(λσ⁻) at λ = {step} (u {u[k + 1]:g} → {u[k + 2]:g}), kT/ε = "
            f"{kt:.3f}, φ = {phi}, N = {n}, {snapshots} snapshots", mean, expected,
            4.0 * error, "continuity of the cavity function: e^{−β(u_out − u_in)}",
            time.perf_counter() - started if not rows else None))
    return rows


def step_ratios(r, blocks, steps, energies, kt, fitted):
    """g(λσ⁺)/g(λσ⁻) at every step ``steps`` (units of σ) with its standard error over
    ``blocks`` (float64[blocks, bins], g in bins centred at ``r``, σ units, whose edges sit
    on the steps), each side a line through its ``fitted`` bins taken to the step; and
    e^{−(u_out − u_in)/kT} of the potential's ``energies``. A list of (λ, ratio, error,
    expected)."""
    width = r[1] - r[0]
    u = np.concatenate([[0.0], energies, [0.0]])
    found = []
    for k, step in enumerate(steps):
        at = int(round(step / width))  # the bin edge on the step
        inside, outside = slice(at - fitted, at), slice(at, at + fitted)
        ratios = [np.polyval(np.polyfit(r[outside], g[outside], 1), step)
                  / np.polyval(np.polyfit(r[inside], g[inside], 1), step) for g in blocks]
        mean, error = block_means(ratios)
        found.append((step, mean, error, math.exp(-(u[k + 2] - u[k + 1]) / kt)))
    return found


def second_virial_coefficient(temperature, steps, energies):
    """B₂/σ² = (π/2)[1 + Σ_k (λ_k² − λ_{k−1}²)(1 − e^{−ε_k/kT})] of a stepped potential in two
    dimensions (λ_0 = 1; derived in docs/stepped-potentials.md)."""
    edges = np.concatenate([[1.0], steps])
    shells = np.diff(edges**2)
    return 0.5 * math.pi * (1.0 + float(np.sum(shells * (1.0 - np.exp(
        -np.asarray(energies) / temperature)))))


def thermalised_gas(n, phi, temperature, steps, energies, seed=0, collisions_per_disk=20,
                    samples=16):
    """:func:`stepped_gas` run ``collisions_per_disk`` at a time and its velocities scaled
    by √(T/kT) until the mean kT = K/(N − 1) (zero momentum) of ``samples`` equal times of
    such a run is within ``THERMALISED`` of ``temperature``: the energy the pairs take or
    give as they settle into their shells comes out of the motion. Returns (engine,
    radius)."""
    engine, radius = stepped_gas(n, phi, temperature, steps, energies, seed)
    for _ in range(20):
        t0, c0 = engine.time, engine.collisions
        engine.run(collisions=c0 + collisions_per_disk * n)
        span, t0 = engine.time - t0, engine.time
        kinetic = []
        for k in range(1, samples + 1):
            engine.run(time=t0 + k * span / samples)
            kinetic.append(engine.kinetic_energy())
        kt = float(np.mean(kinetic)) / (n - 1)
        if abs(kt / temperature - 1.0) < THERMALISED:
            return engine, radius
        engine = Engine(engine.positions(), engine.velocities() * math.sqrt(temperature / kt),
                        radius, engine.mass, boundary=engine.boundary,
                        potential_steps=list(steps), potential_energies=list(energies))
    raise RuntimeError(f"kT did not settle at {temperature} within twenty rescalings")


def second_virial(n=1000, phis=(0.01, 0.02, 0.03, 0.04), temperatures=(1.0, 3.0),
                  steps=(1.5,), energies=(-1.0,), replicas=8, collisions=400_000, samples=64,
                  seed=0):
    """(βP/ρ − 1)/ρ of a square-well gas at each of ``phis`` extrapolated to ρ → 0 by a
    weighted line in ρσ², against the exact B₂/σ² (:func:`second_virial_coefficient`) at
    the runs' mean kT, at temperatures on both sides of the Boyle temperature (kT_B/ε = 1.70
    for λ = 1.5). At each φ, ``replicas`` independent runs (:func:`thermalised_gas`, seeds
    from ``seed``) of about ``collisions`` collisions each: βPA = N + (N − 1) X/⟨K⟩, X the
    collision virial (steps included) over twice the run's time, ⟨K⟩ the mean of
    ``samples`` kinetic energies at equal times; the error of a φ's mean is the standard
    error over its replicas, that of the intercept the line's. The replicas' kT differ by up
    to ``THERMALISED``: each one's ratio is moved to the mean kT by the difference of B₂
    between the two (B₂ of a well changes by 5σ² per unit of kT/ε at kT = ε)."""
    rows = []
    for temperature in temperatures:
        started = time.perf_counter()
        runs = []  # (ρσ², ratio, kT) of every replica
        for phi in phis:
            for replica in range(replicas):
                engine, radius = thermalised_gas(n, phi, temperature, steps, energies,
                                                 seed + 1000 * replica)
                t0, c0, virial = engine.time, engine.collisions, engine.virial
                engine.run(collisions=c0 + collisions // 8)
                span = 8.0 * (engine.time - t0)  # about ``collisions`` collisions
                t0, virial = engine.time, engine.virial
                kinetic = []
                for k in range(1, samples + 1):
                    engine.run(time=t0 + k * span / samples)
                    kinetic.append(engine.kinetic_energy())
                x = (engine.virial - virial) / (2.0 * span)
                rho = n * (2.0 * radius) ** 2  # ρσ² in the unit box
                kt = float(np.mean(kinetic)) / (n - 1)
                runs.append((rho, (n - 1) * x / (n * float(np.mean(kinetic))) / rho, kt))
        found = extrapolated_b2(runs, steps, energies)
        rows.append(Check(
            f"B₂/σ² of a square well λ = {steps[0]}, ε = {-energies[0]:g}, from βP/ρ at "
            f"φ = {', '.join(f'{p:g}' for p in phis)} ({replicas} runs each) to ρ → 0, "
            f"kT/ε = {found.kt:.3f}, N = {n}", found.b2, found.exact, 4.0 * found.b2_error,
            "B₂ = (πσ²/2)[1 + (λ² − 1)(1 − e^{βε})], exact", time.perf_counter() - started))
    return rows


class Virial(NamedTuple):
    """B₂ from runs at one temperature (:func:`extrapolated_b2`)."""
    kt: float  # the runs' mean kT
    density: np.ndarray  # ρσ² of each packing fraction
    mean: np.ndarray  # (βP/ρ − 1)/ρσ² at each, over its runs
    error: np.ndarray  # its standard error
    b2: float  # B₂/σ², the weighted line's intercept
    b2_error: float
    slope: float
    exact: float  # B₂/σ² at kT (:func:`second_virial_coefficient`)
    runs: int


def extrapolated_b2(runs, steps, energies):
    """The :class:`Virial` of ``runs``, (ρσ², (βP/ρ − 1)/ρσ², kT) of each: every run's
    value moved to the runs' mean kT by the difference of the exact B₂ between the two, the
    mean and standard error of each density's runs, and a line weighted by them taken to
    ρ → 0."""
    rho, ratio, kts = (np.array(column) for column in zip(*runs, strict=True))
    kt = float(np.mean(kts))
    exact = second_virial_coefficient(kt, steps, energies)
    ratio = ratio - np.array([second_virial_coefficient(t, steps, energies) for t in kts]) \
        + exact
    densities = np.unique(rho)
    means, errors = (np.array(c) for c in zip(*(block_means(ratio[rho == d])
                                                 for d in densities), strict=True))
    (slope, intercept), cov = np.polyfit(densities, means, 1, w=1.0 / errors, cov="unscaled")
    return Virial(kt, densities, means, errors, float(intercept), math.sqrt(cov[1, 1]),
                  float(slope), exact, rho.size)
