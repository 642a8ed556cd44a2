"""Figure 10 (beyond the study): crater area against impact speed v₀.

Hard disks have no energy scale: multiplying every velocity by λ gives the same trajectories
in time t/λ. A crater made at speed v₀ is the crater made at speed 1 seen at time t·v₀, and a
stop criterion measured against the impact energy (the study's 10 % left, or
``stop.at_rest``: every species below 2 % of the impact energy, which here means the
projectile has stopped near the floor and the bed has lost nearly all its kinetic energy)
ends every run at the same stage. Only the TC model's fixed time t_c = 1e-8 breaks the
scaling: at higher speed more contacts fall within t_c and are elastic, and the runs differ
(v₀ = 2.5 needs about three times the collisions of v₀ = 40 to come to rest), yet the area
barely moves. The study, stopping at 10 %, saw the area barely change with speed and
suspected its criterion; without the TC model the area could not change at all, whatever
the criterion, as long as it is free of a speed.

Left: area against t·v₀ (how far the projectile would have flown undisturbed), one curve
per speed; they lie on one another. Without gravity the loosened bed keeps flowing into the
empty upper half after the projectile stops, so the area has no final value to converge to
in time; it is read at the speed-free stop. Middle: the area at both criteria against v₀.
Right: the same on coarser grids, Δx/Δx_calibrated ≈ 1, 1.5, 2, each spacing rounded so that
the bed's top stays a grid line (sensitivity to Δx; finer grids count the gaps between
resting disks).
"""

import numpy as np

from sim.analysis.crater import CraterGeometry, crater_overrides, preparation_of
from sim.analysis.datasets import open_sweep
from sim.figures.style import figure, save

NAME = "fig10_crater_speed"
AT_REST = 0.02
STUDY_FRACTION = 0.1
SPACING_FACTORS = (1.0, 1.5, 2.0)


def speeds(quick):
    return (5.0, 10.0, 20.0) if quick else (2.5, 5.0, 10.0, 20.0, 40.0)


def sweeps(quick):
    every = 20_000 if quick else 100_000
    return {"speed": [*crater_overrides(quick), f"output.every_collisions={every}",
                      "stop.energy_fraction=null", f"stop.at_rest={AT_REST}",
                      "stop.collisions=400000000",
                      "projectile.speed=" + ",".join(map(str, speeds(quick)))]}


def aligned(dx, factor, height):
    """The spacing nearest ``factor`` × ``dx`` that divides ``height``."""
    return height / max(round(height / (factor * dx)), 1)


def draw(runs, sweeps, out_dir):
    ds = open_sweep(sweeps["speed"])
    v0 = ds["projectile_speed"].values
    fig, (left, middle, right) = figure(ncols=3, width=14, height=4.4)
    fig.suptitle(preparation_of(ds), fontsize=9)
    rows = []
    for k, speed in enumerate(v0):
        one = ds.isel(projectile_speed=k)
        valid = np.flatnonzero(one["time"].notnull().values)
        one = one.isel(snapshot=valid)
        geometry = CraterGeometry.of_run(one)
        if one["stop_reason"].item() != "at_rest":
            raise ValueError(f"the run at v0 = {speed} stopped by {one['stop_reason'].item()}, "
                             f"not at rest: raise its stop.collisions")
        position = one["position"].values
        area = np.array([geometry.area(p) for p in position])
        energy = one["kinetic_energy"].values
        study = np.flatnonzero(energy <= STUDY_FRACTION * energy[0])[0]
        scaled_time = one["time"].values * speed
        left.plot(scaled_time, area, color=f"C{k}", label=f"v₀ = {speed:g}")
        left.plot(scaled_time[-1], area[-1], "o", color=f"C{k}")
        left.plot(scaled_time[study], area[study], "s", mfc="none", color=f"C{k}")
        spacings = [aligned(geometry.dx, f, geometry.height) for f in SPACING_FACTORS]
        at_rest = [geometry.area(position[-1], dx) for dx in spacings]
        at_study = [geometry.area(position[study], dx) for dx in spacings]
        rows.append((speed, geometry.dx, *at_rest, *at_study, scaled_time[-1],
                     int(one["collisions"].values[-1])))
    table = np.array(rows)
    n = len(SPACING_FACTORS)
    left.set(xlabel="t·v₀ (box units: the projectile's undisturbed flight)",
             ylabel="crater area (box units²)",
             title="area against scaled time\n(○ at rest, □ 10 % energy left)")
    left.legend(fontsize=8)
    middle.semilogx(v0, table[:, 2], "o-", label=f"at rest (every species < {AT_REST:.0%})")
    middle.semilogx(v0, table[:, 2 + n], "s--", label="10 % energy left (study)")
    middle.set(xlabel="impact speed v₀ (box units / time)", ylabel="crater area (box units²)",
               ylim=(0, 1.2 * table[:, 2:2 + 2 * n].max()),
               title=f"area against speed, Δx = {table[0, 1]:.3g}")
    middle.legend(fontsize=8)
    for j, factor in enumerate(SPACING_FACTORS):
        right.semilogx(v0, table[:, 2 + j], "o-", color=f"C{j}", label=f"Δx × {factor:g}")
        right.semilogx(v0, table[:, 2 + n + j], "s--", color=f"C{j}")
    right.set(xlabel="impact speed v₀ (box units / time)", ylabel="crater area (box units²)",
              ylim=(0, 1.2 * table[:, 2:2 + 2 * n].max()),
              title="sensitivity to Δx (○ at rest, □ 10 %)")
    right.legend(fontsize=8)
    for ax in (middle, right):
        ax.set_xticks(v0, labels=[f"{v:g}" for v in v0])
        ax.minorticks_off()
    header = ",".join(["speed", "dx", *(f"area_at_rest_dx_x{f:g}" for f in SPACING_FACTORS),
                       *(f"area_10pct_dx_x{f:g}" for f in SPACING_FACTORS),
                       "scaled_time_at_rest", "collisions"])
    np.savetxt(out_dir / f"{NAME}.csv", table, delimiter=",", fmt="%.6g", header=header,
               comments="")
    return save(fig, out_dir, NAME)
