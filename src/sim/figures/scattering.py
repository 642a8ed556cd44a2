"""Figure 3: a light small disk sent at a heavy large one at rest, over impact parameters.

The scattering angle θ of the projectile against the impact parameter b, for a target 10⁶
times heavier (the fixed-scatterer law b = a cos(θ/2), a the contact distance) and 3 times
heavier (the exact finite-mass curve: b = a cos(χ/2) for the centre-of-mass angle χ, and
tan θ = sin χ / (m₁/m₂ + cos χ); docs/physics.md, "Two-body collisions").
"""

import numpy as np

from sim.analysis.datasets import at_last_snapshot, open_sweep
from sim.figures.style import figure, save

NAME = "fig03_scattering"
TARGET_MASSES = (1.0e6, 3.0)


def sweeps(quick):
    step = 0.011 if quick else 0.0022
    return {"scattering": ["scenario=scattering",
                           f"scattering.impact_parameter=range(0,0.1099,{step})",
                           "scattering.target_mass=" + ",".join(map(str, TARGET_MASSES))]}


def lab_angle(b, a, mass_ratio):
    """Projectile lab angle for impact parameter b, contact distance a, m₁/m₂."""
    chi = 2.0 * np.arccos(np.clip(b / a, -1.0, 1.0))
    return np.arctan2(np.sin(chi), mass_ratio + np.cos(chi))


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["scattering"])
    velocity = at_last_snapshot(ds, "velocity").isel(disk=0)
    theta = np.degrees(np.arctan2(velocity.sel(axis="y"), velocity.sel(axis="x")))
    b = ds["scattering_impact_parameter"].values
    a = float(ds["radius"].isel(disk=0).max() + ds["radius"].isel(disk=1).max())
    m1 = float(ds["mass"].isel(disk=0).max())
    fig, (left, right) = figure()
    rows = []
    for k, m2 in enumerate(ds["scattering_target_mass"].values):
        measured = np.abs(theta.sel(scattering_target_mass=m2).values)
        exact = np.degrees(np.abs(lab_angle(b, a, m1 / m2)))
        label = f"m₂/m₁ = {m2 / m1:g}"
        left.plot(measured, b, "o", ms=3.5, color=f"C{k}", label=f"simulated, {label}")
        curve_b = np.linspace(0, a, 400)
        left.plot(np.degrees(np.abs(lab_angle(curve_b, a, m1 / m2))), curve_b, "-",
                  color=f"C{k}", lw=1, label=f"exact, {label}")
        right.semilogy(b, np.maximum(np.abs(measured - exact), 1e-16), "o-", ms=3,
                       color=f"C{k}", label=label)
        rows += [(m2, bi, mi, ei) for bi, mi, ei in zip(b, measured, exact, strict=True)]
    theta_law = np.linspace(0, 180, 200)
    left.plot(theta_law, a * np.cos(np.radians(theta_law) / 2), "k--", lw=1,
              label="s(θ) = a cos(θ/2)")
    left.set(xlabel="scattering angle θ (degrees)", ylabel="impact parameter b (box units)",
             title=f"b against θ, contact distance a = {a:g}")
    left.legend(fontsize=7)
    right.set(xlabel="impact parameter b (box units)",
              ylabel="|θ − θ_exact| (degrees; 0 drawn at 1e-16)",
              title="deviation from the exact two-body angle")
    right.legend(fontsize=8)
    np.savetxt(out_dir / f"{NAME}.csv", np.array(rows), delimiter=",",
               header="target_mass,impact_parameter,theta_deg,theta_exact_deg", comments="")
    return save(fig, out_dir, NAME)
