"""Validation of growing disks (:mod:`sim.effects.growth`): a slow Lubachevsky–Stillinger
compression of the 50:50 mixture of radius ratio 1.4 follows the fluid's equation of state,
and compressed on to jamming it stops at the published jamming density with an isostatic
backbone. Rows of :data:`sim.checks.validation.STUDIES`.

The mixture starts at φ = 0.3 from random sequential addition, Maxwellian at T = 1 (unit
masses, zero momentum) in a periodic box, and grows at the dimensionless rate
Γ = ṡ √(m/T)/⟨σ⟩ (contacts of mean diameter ⟨σ⟩ at the start grow at Γ times the thermal
speed), its velocities rescaled to the initial kinetic energy every collision per disk.
"""

import math
import time

import numpy as np

from sim.analysis.packing import compression_pressure, contact_number
from sim.analysis.theory import mixture_z
from sim.checks.rows import Check, block_means
from sim.effects.growth import growth_rate
from sim.engine import Boundary, Engine
from sim.pipeline.initial import maxwellian, random_sequential, remove_drift, two_sizes

#: the mixture: radius ratio and number fraction of the large disks
RADIUS_RATIO, LARGE_FRACTION = 1.4, 0.5
#: where the compressions start
START = 0.3
#: the slowest rate, at which halving it changes the pressure by less than its error up to
#: φ = 0.7 (rows ``compression_eos``)
SLOW_RATE = 1e-3
#: a contact: a gap below this fraction of ⟨σ⟩ in a packing at βP/ρ = JAMMED_PRESSURE, on the
#: plateau of the contact count (:func:`sim.analysis.packing.contact_numbers`)
CONTACT_TOLERANCE = 1e-5
JAMMED_PRESSURE = 1e9
#: published jamming densities of the 50:50, 1:1.4 disk mixture: 0.84 for fast quenches
#: (O'Hern, Silbert, Liu & Nagel, PRE 68, 011306 (2003)), 0.84 to 0.853 by protocol (Schreck,
#: O'Hern & Silbert, PRE 84, 011305 (2011)); both by energy minimisation of soft disks
PUBLISHED_JAMMING = (0.84, 0.853)


def mixture(n, seed, rate, start=START):
    """An engine of the mixture (module docstring) growing at the dimensionless rate
    ``rate``; seeds ``seed`` (placement, sizes) and ``seed + 1`` (velocities)."""
    radius, species = two_sizes(n, start, RADIUS_RATIO, LARGE_FRACTION, seed=seed)
    periodic = (True, True)
    position = random_sequential(radius, periodic=periodic, seed=seed)
    mass = np.ones(n)
    velocity = remove_drift(maxwellian(mass, 1.0, seed=seed + 1), mass)
    temperature = 0.5 * float(np.sum(mass[:, None] * velocity**2)) / n  # 2D: K = N T
    return Engine(position, velocity, radius, mass, species, Boundary(periodic=periodic),
                  growth_rate=growth_rate(rate, radius, temperature / float(np.mean(mass))))


def pressure_along(engine, packing_fractions):
    """Compress ``engine`` through ``packing_fractions`` (increasing), returning (φ, βP/ρ)
    over the intervals between them (:func:`sim.analysis.packing.compression_pressure`)."""
    rows = []
    for phi in packing_fractions:
        engine.run(packing_fraction=phi)
        rows.append((engine.time, engine.virial, engine.kinetic_energy(),
                     engine.packing_fraction()))
    return compression_pressure(*np.array(rows).T)


#: the relative accuracy taken for the mixture's equation of state (Santos, Yuste & López de
#: Haro's mapping of the one-size fluid; its authors find it collapses event-driven data of
#: mixtures in the stable fluid, without a stated bound)
EOS_ACCURACY = 0.01


def compression_eos(n=1000, rate=SLOW_RATE, seeds=4, windows=(0.4, 0.5, 0.6, 0.65, 0.7),
                    compared_to=0.65, width=0.01):
    """βP/ρ of the mixture compressed at Γ = ``rate`` and at half of it, averaged over
    [φ − ``width``, φ + ``width``] at each φ of ``windows``, mean and standard error over
    ``seeds`` runs: the change that halving the rate makes, at every φ (four standard errors
    in quadrature), and up to φ = ``compared_to`` the pressure at the slower rate against the
    mixture's fluid equation of state (:func:`sim.analysis.theory.mixture_z` on Kolafa &
    Rottner's one-size fluid; four standard errors and :data:`EOS_ACCURACY`). Beyond, near
    φ = 0.70, the one-size fluid's pressure bends towards its melting (hexatic order), which
    the mixture, which does not order, does not follow: the mapping no longer applies."""
    started = time.perf_counter()
    grid = np.arange(START + 0.005, max(windows) + width + 1e-9, 0.0025)
    measured = {}
    for r in (rate, 0.5 * rate):
        runs = []
        for seed in range(seeds):
            phi, pressure = pressure_along(mixture(n, 100 + seed, r), grid)
            runs.append([pressure[np.abs(phi - w) <= width].mean() for w in windows])
        measured[r] = np.array(runs)
    seconds = time.perf_counter() - started
    diameters, fractions = (2.0, 2.0 * RADIUS_RATIO), (1.0 - LARGE_FRACTION, LARGE_FRACTION)
    rows = []
    for k, w in enumerate(windows):
        z, error = block_means(measured[rate][:, k])
        z_half, error_half = block_means(measured[0.5 * rate][:, k])
        reference = float(mixture_z(w, diameters, fractions))
        if w <= compared_to:
            rows.append(Check(f"mixture 1:{RADIUS_RATIO} compressed at Γ = {0.5 * rate:g}: "
                              f"βP/ρ at φ = {w}", z_half, reference,
                              4.0 * error_half + EOS_ACCURACY * reference,
                              "Santos–Yuste–López de Haro on Kolafa–Rottner",
                              seconds if k == 0 else None))
        rows.append(Check(f"… halving Γ = {rate:g} changes βP/ρ at φ = {w} by", z_half - z,
                          0.0, 4.0 * math.hypot(error, error_half), "slow enough: no change",
                          None))
    return rows


def jamming_density(n=1000, rate=SLOW_RATE, seeds=5):
    """The mixture compressed at Γ = ``rate`` until βP/ρ = :data:`JAMMED_PRESSURE`, over
    ``seeds`` runs: the packing fraction it jams at against the published range
    (:data:`PUBLISHED_JAMMING`, the middle within half its width and two standard
    deviations of the seeds: LS growth is another protocol than energy minimisation, and
    it stops at a pressure, not at the onset of overlaps), and the mean contact number of
    the backbone (gaps below :data:`CONTACT_TOLERANCE` ⟨σ⟩, rattlers removed) against the
    isostatic z = 4 of frictionless disks (within 0.1: the finite-size 2/N_b and the
    packing's weakest contacts)."""
    started = time.perf_counter()
    phis, zs, rattlers = [], [], []
    for seed in range(seeds):
        engine = mixture(n, 200 + seed, rate)
        engine.run(jamming=JAMMED_PRESSURE)
        phis.append(engine.packing_fraction())
        z, loose, _ = contact_number(engine.positions(), engine.radii(), engine.box,
                                     engine.periodic, CONTACT_TOLERANCE)
        zs.append(z)
        rattlers.append(loose)
    seconds = time.perf_counter() - started
    low, high = PUBLISHED_JAMMING
    spread = float(np.std(phis, ddof=1))
    z, z_error = block_means(zs)
    return [
        Check(f"mixture 1:{RADIUS_RATIO} jams (Γ = {rate:g}, βP/ρ = {JAMMED_PRESSURE:g}, "
              f"{seeds} seeds, N = {n}) at φ_J", float(np.mean(phis)), 0.5 * (low + high),
              0.5 * (high - low) + 2.0 * spread,
              "O'Hern et al. 2003; Schreck, O'Hern & Silbert 2011", seconds),
        Check(f"… z of the backbone ({100 * np.mean(rattlers):.1f} % rattlers)", z, 4.0,
              0.1, "isostatic frictionless disks, 2d", None),
    ]
