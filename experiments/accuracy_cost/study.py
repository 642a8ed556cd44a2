"""What accuracy costs: for each knob that trades accuracy for time, the error against an exact
or converged reference beside the wall-clock seconds it took.

Knobs (one function each, returning an xarray Dataset over the knob's settings with ``error``,
``error_bar`` where statistical, ``seconds`` and the reference in its attributes):
  n_disks            finite-size error of Z at φ = 0.5 (vs Kolafa–Rottner), KS distance of speeds
  collisions         statistical error of Z against collisions sampled (block error, 1/√C)
  sampling_interval  error of T₂/T₁ (elastic mixture, exact 1) against the snapshot interval
  equilibration      kurtosis of the velocities against 2, by collisions per disk from equal speeds
  tc_time            cooling against the gas without TC, and collapse, by t_c
  crater_dx          crater area against the finest grid
  crater_stop        crater area against the area at rest, by when the run stops
  snapshot_cadence   seconds per snapshot and file size against the snapshot interval

Settings run one after another in one process: their wall-clock seconds are the measurement,
so they must not share the two cores with each other, which is why the knobs are loops here
and not a parallel Hydra sweep. The crater and snapshot knobs run the Hydra-composed scenes.

Output in ``--out`` (default outputs/accuracy_cost): ``<knob>.nc``, ``<knob>.png``,
``pareto.png`` (every knob's error against seconds) and ``summary.md``.

    python experiments/accuracy_cost/study.py [--quick] [--knobs n_disks collisions …]
"""

import argparse
import math
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib import pyplot as plt
from matplotlib.ticker import NullFormatter
from scipy import stats

from sim.analysis.crater import CraterGeometry, crater_overrides
from sim.analysis.datasets import open_run
from sim.analysis.theory import enskog_collision_frequency, kolafa_rottner_z
from sim.checks.rows import block_means
from sim.checks.validation import equilibrated_gas, virial_blocks
from sim.engine import Boundary, Engine, InelasticCollapseError
from sim.pipeline.initial import (
    fixed_speed,
    hexagonal_lattice,
    maxwellian,
    radius_for_packing,
    random_sequential,
    remove_drift,
)
from sim.pipeline.run_cache import compose_config, ensure_run
from sim.pipeline.runner import run


def knob(name, setting, unit, reference, **variables):
    """A Dataset over the knob's settings; each variable a list, one entry per setting."""
    data = {k: ("setting", np.asarray(v, dtype=float)) for k, v in variables.items()}
    return xr.Dataset(data, coords={"setting": np.asarray(setting, dtype=float)},
                      attrs={"knob": name, "unit": unit, "reference": reference})


def n_disks(quick):
    """Z at φ = 0.5 for N disks: 50 collisions per disk of equilibration, 20 blocks of 20."""
    phi, reference = 0.5, kolafa_rottner_z(0.5)
    sizes = [64, 256, 1024] if quick else [64, 256, 1024, 4096, 16384]
    error, bar, seconds, ks = [], [], [], []
    for n in sizes:
        started = time.perf_counter()
        engine, _ = equilibrated_gas(n, phi, 50)
        z, z_error = block_means(virial_blocks(engine, 20, 20)[0])
        seconds.append(time.perf_counter() - started)
        error.append(abs(z / reference - 1.0))
        bar.append(2.0 * z_error / reference)
        speeds = np.linalg.norm(engine.velocities(), axis=1)
        temperature = engine.kinetic_energy() / (n - 1)
        ks.append(stats.kstest(speeds, stats.rayleigh(scale=math.sqrt(temperature)).cdf)
                  .statistic)
    return knob("n_disks", sizes, "disks", f"Z = {reference:.6f} (Kolafa & Rottner 2006)",
                error=error, error_bar=bar, seconds=seconds, ks_distance=ks)


def collisions(quick):
    """One run of N = 1000 at φ = 0.5; Z from its first C collisions (blocks of 10 per disk),
    error against Kolafa–Rottner and the block estimate of the statistical error, which
    falls as 1/√C once blocks are longer than the correlation time."""
    n, phi, reference = 1000, 0.5, kolafa_rottner_z(0.5)
    engine, _ = equilibrated_gas(n, phi, 50)
    lengths = [20, 50, 100, 300, 1000] if quick else [20, 50, 100, 300, 1000, 3000]
    blocks, error, bar, seconds = [], [], [], []
    started = time.perf_counter()
    for length in lengths:
        blocks.extend(virial_blocks(engine, length // 10 - len(blocks), 10)[0])
        z, z_error = block_means(blocks)
        seconds.append(time.perf_counter() - started)
        error.append(abs(z / reference - 1.0))
        bar.append(2.0 * z_error / reference)
    return knob("collisions", lengths, "collisions per disk sampled (N = 1000)",
                f"Z = {reference:.6f} (Kolafa & Rottner 2006)", error=error, error_bar=bar,
                seconds=seconds)


def sampling_interval(quick):
    """T₂/T₁ of an elastic mixture (m₂/m₁ = 4, N = 1000, φ = 0.3), exactly 1, from 100
    snapshots taken every Δ collisions per disk. Close snapshots are correlated: the naive
    error σ/√100 then underestimates the true one, which ``error_bar`` estimates from
    blocks of 10 snapshots."""
    n, count = 1000, 100
    mass = np.where(np.arange(n) % 2 == 1, 4.0, 1.0)
    intervals = [0.01, 0.1, 1.0] if quick else [0.01, 0.1, 1.0, 10.0]
    error, bar, naive, seconds = [], [], [], []
    for interval in intervals:
        engine, _ = equilibrated_gas(n, 0.3, 20, seed=3, mass=mass, species=np.arange(n) % 2)
        started = time.perf_counter()
        ratios = []
        for _ in range(count):
            engine.run(collisions=engine.collisions + max(1, round(interval * n)))
            energy = engine.kinetic_energy_by_species()
            ratios.append(energy[1] / energy[0])
        seconds.append(time.perf_counter() - started)
        ratios = np.array(ratios)
        error.append(abs(ratios.mean() - 1.0))
        naive.append(2.0 * ratios.std(ddof=1) / math.sqrt(count))
        bar.append(2.0 * block_means(ratios.reshape(10, -1).mean(axis=1))[1])
    return knob("sampling_interval", intervals, "collisions per disk between 100 snapshots",
                "T₂/T₁ = 1 (equipartition)", error=error, error_bar=bar, naive_error_bar=naive,
                seconds=seconds)


def equilibration(quick):
    """Relaxation from equal speeds (N = 4000, φ = 0.3): the kurtosis ⟨v⁴⟩/⟨v²⟩² after L
    collisions per disk against its Maxwellian value 2 (equal speeds give 1); the error bar
    is the spread over ten groups of disks."""
    n, phi = 4000, 0.3
    radius = radius_for_packing(n, phi)
    lengths = [0, 0.5, 1, 2, 4, 8] if quick else [0, 0.5, 1, 2, 4, 8, 16, 32]
    position = random_sequential(np.full(n, radius), periodic=(True, True), seed=9)
    error, bar, seconds = [], [], []
    for length in lengths:
        engine = Engine(position, fixed_speed(n, 1.0, seed=10), radius,
                        boundary=Boundary(periodic=(True, True)))
        started = time.perf_counter()
        engine.run(collisions=round(length * n))
        seconds.append(time.perf_counter() - started)
        v2 = np.sum(engine.velocities() ** 2, axis=1)
        error.append(abs(np.mean(v2**2) / np.mean(v2) ** 2 / 2.0 - 1.0))
        groups = [np.mean(g**2) / np.mean(g) ** 2 / 2.0 for g in v2.reshape(10, -1)]
        bar.append(2.0 * block_means(groups)[1])
    return knob("equilibration", lengths, "collisions per disk from equal speeds (N = 4000)",
                "kurtosis ⟨v⁴⟩/⟨v²⟩² = 2 (2D Maxwellian)", error=error, error_bar=bar,
                seconds=seconds)


def tc_time(quick):
    """A dense inelastic gas (N = 1000, φ = 0.6, ξ = ξ_w = 0.5, walls) with the TC time t_c
    from 10⁻⁹ to 1 mean free time (Enskog). ``error``: the energy left after 5 collisions
    per disk against the same gas without TC (exact inelastic dynamics up to there).
    ``collapsed``: whether the run collapses before 50 collisions per disk (without TC it
    does after about 8). Too short a t_c does not prevent the collapse; too long a one
    changes the cooling."""
    n, phi, xi = 1000, 0.6, 0.5
    radius = radius_for_packing(n, phi)
    chi = (kolafa_rottner_z(phi) - 1.0) / (2.0 * phi)
    mean_free_time = 1.0 / enskog_collision_frequency(n, 2.0 * radius, chi, 1.0)
    position = hexagonal_lattice(n, radius, seed=1)
    velocity = remove_drift(maxwellian(np.ones(n), 1.0, seed=2), np.ones(n))

    def energy_and_collapse(tc):
        engine = Engine(position, velocity, radius, restitution=xi, wall_restitution=xi,
                        tc=tc)
        e0 = engine.kinetic_energy()
        engine.run(collisions=5 * n)
        left = engine.kinetic_energy() / e0
        try:
            engine.run(collisions=50 * n)
        except InelasticCollapseError:
            return left, 1.0
        return left, 0.0

    reference, _ = energy_and_collapse(None)
    ratios = [1e-9, 1e-6, 1e-3, 1e-1, 1.0] if quick else [1e-9, 1e-7, 1e-5, 1e-3, 1e-2,
                                                            1e-1, 1.0]
    error, seconds, collapsed = [], [], []
    for ratio in ratios:
        started = time.perf_counter()
        left, collapse = energy_and_collapse(ratio * mean_free_time)
        seconds.append(time.perf_counter() - started)
        error.append(abs(left / reference - 1.0))
        collapsed.append(collapse)
    return knob("tc_time", ratios, "t_c in mean free times (φ = 0.6, ξ = 0.5)",
                f"E/E₀ = {reference:.5f} after 5 collisions per disk without TC",
                error=error, seconds=seconds, collapsed=collapsed)


def crater_run(quick, root, extra=()):
    return ensure_run("crater", [*crater_overrides(quick), *extra], root)


def crater_dx(quick, root):
    """Crater area at the end of the crater run on grids from 1/4 to 3 times the calibrated
    spacing, against the finest; seconds are those of the measure itself. Grids finer than
    the calibrated one count the gaps between resting disks as crater, so the finest grid
    is the converged value of the grid measure, not of the crater."""
    with open_run(crater_run(quick, root)) as ds:
        geometry = CraterGeometry.of_run(ds)
        end = ds["position"].isel(time=-1).values
    factors = [0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0]
    areas, seconds = [], []
    for factor in factors:
        started = time.perf_counter()
        areas.append(geometry.area(end, factor * geometry.dx))
        seconds.append(time.perf_counter() - started)
    areas = np.array(areas)
    return knob("crater_dx", factors, f"Δx / calibrated Δx ({geometry.dx:.5f})",
                f"area {areas[0]:.5f} on the finest grid", error=abs(areas / areas[0] - 1.0),
                seconds=seconds, area=areas)


def timed_run(overrides, folder, name):
    """Run the scene of ``overrides`` into ``folder/name``; returns (path, wall seconds)."""
    cfg = compose_config([*overrides, "output.progress=false", f"output.file={name}"])
    started = time.perf_counter()
    path = run(cfg, folder)
    return path, time.perf_counter() - started


def crater_stop(quick):
    """Crater area of runs stopped when a fraction f of the initial energy is left, against
    the run stopped at rest (every species below 2 % of it); seconds are each run's own."""
    fractions = [0.5, 0.3, 0.1, 0.05]
    stops = [[f"stop.energy_fraction={f}"] for f in fractions]
    stops.append(["stop.energy_fraction=null", "stop.at_rest=0.02"])
    areas, seconds = [], []
    with tempfile.TemporaryDirectory() as folder:
        for k, stop in enumerate(stops):
            path, wall = timed_run([*crater_overrides(quick), *stop, "stop.collisions=200000000",
                                    "output.every_collisions=100000000"], folder, f"run{k}.h5")
            with open_run(path) as ds:
                areas.append(CraterGeometry.of_run(ds).area(ds["position"].isel(time=-1).values))
            seconds.append(wall)
    areas = np.array(areas)
    return knob("crater_stop", [*fractions, 0.0], "energy left when the run stops (0: at rest)",
                f"area at rest {areas[-1]:.5f}", error=abs(areas / areas[-1] - 1.0),
                seconds=seconds, area=areas)


def snapshot_cadence(quick):
    """The gas scene (2000 disks, 400 000 collisions) with a snapshot every k collisions:
    wall seconds and file bytes; the cost of one snapshot is the slope of seconds (and of
    bytes) against the number of snapshots. There is no error here, only cost."""
    cadences = [1000, 10_000, 100_000] if quick else [200, 1000, 10_000, 100_000, 400_000]
    seconds, file_bytes, counts = [], [], []
    with tempfile.TemporaryDirectory() as folder:
        for k, every in enumerate(cadences):
            path, wall = timed_run([f"output.every_collisions={every}"], folder, f"run{k}.h5")
            seconds.append(wall)
            file_bytes.append(path.stat().st_size)
            counts.append(400_000 // every + 1)
    ds = knob("snapshot_cadence", cadences, "collisions between snapshots (gas scene)",
              "cost only", error=np.full(len(cadences), np.nan), seconds=seconds,
              file_bytes=file_bytes, snapshots=counts)
    ds.attrs["seconds_per_snapshot"] = float(np.polyfit(counts, seconds, 1)[0])
    ds.attrs["bytes_per_snapshot"] = float(np.polyfit(counts, file_bytes, 1)[0])
    return ds


KNOBS = {"n_disks": n_disks, "collisions": collisions, "sampling_interval": sampling_interval,
         "equilibration": equilibration, "tc_time": tc_time, "crater_dx": crater_dx,
         "crater_stop": crater_stop, "snapshot_cadence": snapshot_cadence}
CRATER_KNOBS = ("crater_dx",)


def plot(ds, out):
    """Error against seconds (log–log), each point labelled with its setting; for the
    snapshot cadence, seconds and file size against the number of snapshots."""
    fig, ax = plt.subplots(figsize=(5.5, 4), constrained_layout=True)
    if ds.attrs["knob"] == "snapshot_cadence":
        ax.plot(ds["snapshots"], ds["seconds"], "o-", label="wall seconds")
        ax.plot(ds["snapshots"], ds["file_bytes"] / 1e6, "s--", label="file MB")
        ax.set(xscale="log", yscale="log", xlabel="snapshots in 400 000 collisions",
               title=f"{ds.attrs['seconds_per_snapshot'] * 1e3:.2f} ms and "
                     f"{ds.attrs['bytes_per_snapshot'] / 1e3:.0f} kB per snapshot")
        ax.legend()
        fig.savefig(out / "snapshot_cadence.png", dpi=120)
        plt.close(fig)
        return
    error = ds["error"].values
    ax.errorbar(ds["seconds"].values, error, yerr=ds["error_bar"].values
                if "error_bar" in ds else None, fmt="o-", capsize=3)
    seconds = ds["seconds"].values
    if "error_bar" in ds:
        # the statistical error alone (2σ), and for the collisions knob the 1/√C law through
        # its longest run: correlated samples are inside the block estimate
        ax.plot(seconds, ds["error_bar"], "v:", color="C1", label="2σ from blocks")
        if ds.attrs["knob"] == "collisions":
            setting = ds["setting"].values
            ax.plot(seconds, ds["error_bar"].values[-1] * np.sqrt(setting[-1] / setting), "--",
                    color="0.5", label="∝ 1/√C")
    if "naive_error_bar" in ds:
        ax.plot(seconds, ds["naive_error_bar"], "^:", color="C2",
                label="2σ/√samples, as if independent")
    if "error_bar" in ds or "naive_error_bar" in ds:
        ax.legend(fontsize=7)
    for s, x, y in zip(ds["setting"].values, ds["seconds"].values, error, strict=True):
        if np.isfinite(y) and y > 0:
            ax.annotate(f"{s:g}", (x, y), textcoords="offset points", xytext=(4, 4),
                        fontsize=7)
    ax.set(xscale="log", yscale="log", xlabel="wall-clock seconds", ylabel="relative error")
    ax.set_title(f"{ds.attrs['knob']}\n{ds.attrs['unit']}", fontsize=9)
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.text(0.02, 0.02, f"reference: {ds.attrs['reference']}", transform=ax.transAxes,
            fontsize=7)
    fig.savefig(out / f"{ds.attrs['knob']}.png", dpi=120)
    plt.close(fig)


def pareto(datasets, out):
    fig, ax = plt.subplots(figsize=(7, 5), constrained_layout=True)
    for ds in datasets:
        if ds.attrs["knob"] != "snapshot_cadence":
            # what a measurement can claim: its error, or its 2σ bound when that is larger
            claim = ds["error"].values
            if "error_bar" in ds:
                claim = np.fmax(claim, ds["error_bar"].values)
            claim = np.where(claim > 0.0, claim, np.nan)  # a reference point has no error
            ax.plot(ds["seconds"].values, claim, "o-", label=ds.attrs["knob"])
    ax.set(xscale="log", yscale="log", xlabel="wall-clock seconds",
           ylabel="relative error (or its 2σ bound, if larger)",
           title="accuracy against cost, every knob")
    ax.legend(fontsize=8)
    fig.savefig(out / "pareto.png", dpi=120)
    plt.close(fig)


def summary(datasets):
    """The Markdown table of every knob's settings, errors and seconds, and the reference
    each knob's error is taken against."""
    lines = ["| knob | setting | error | ± (2σ) | seconds |", "| --- | --- | --- | --- | --- |"]
    references = []
    for ds in datasets:
        references.append(f"- `{ds.attrs['knob']}`: {ds.attrs['reference']}")
        if ds.attrs["knob"] == "snapshot_cadence":
            for k in range(ds.sizes["setting"]):
                lines.append(f"| snapshot_cadence (collisions between snapshots) | "
                             f"{ds['setting'].values[k]:g} | {ds['file_bytes'].values[k]:.3g} "
                             f"bytes | | {ds['seconds'].values[k]:.2f} |")
            continue
        for k in range(ds.sizes["setting"]):
            bar = ds["error_bar"].values[k] if "error_bar" in ds else math.nan
            collapsed = " (collapses)" if ds.get("collapsed", np.zeros(k + 1))[k] else ""
            lines.append(f"| {ds.attrs['knob']} ({ds.attrs['unit']}) | "
                         f"{ds['setting'].values[k]:g}{collapsed} | {ds['error'].values[k]:.3g} | "
                         f"{'' if math.isnan(bar) else f'{bar:.2g}'} | "
                         f"{ds['seconds'].values[k]:.2f} |")
    return "\n".join(lines + ["", "References:", "", *references]) + "\n"


def warm_up():
    """Load (or compile) the engine variants the knobs use, so that no knob's first setting
    pays for it: elastic, elastic with per-disk masses and species, and inelastic with walls
    and TC."""
    two = np.arange(64) % 2
    equilibrated_gas(64, 0.3, 1)
    equilibrated_gas(64, 0.3, 1, mass=np.where(two == 1, 4.0, 1.0), species=two)
    radius = radius_for_packing(64, 0.3)
    Engine(hexagonal_lattice(64, radius), fixed_speed(64, 1.0), radius, restitution=0.5,
           wall_restitution=0.5, tc=1e-9).run(collisions=100)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer and smaller settings")
    parser.add_argument("--knobs", nargs="+", default=list(KNOBS), choices=list(KNOBS))
    parser.add_argument("--out", type=Path, default=Path("outputs") / "accuracy_cost")
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    warm_up()
    datasets = []
    for name in args.knobs:
        started = time.perf_counter()
        if name in CRATER_KNOBS:
            ds = KNOBS[name](args.quick, args.out / "runs")
        else:
            ds = KNOBS[name](args.quick)
        ds.to_netcdf(args.out / f"{name}.nc")
        plot(ds, args.out)
        datasets.append(ds)
        print(f"{name}: {time.perf_counter() - started:.1f} s", flush=True)
    pareto(datasets, args.out)
    text = summary(datasets)
    for ds in datasets:
        if ds.attrs["knob"] == "snapshot_cadence":
            text += (f"\nOne snapshot costs {ds.attrs['seconds_per_snapshot'] * 1e3:.2f} ms and "
                     f"{ds.attrs['bytes_per_snapshot'] / 1e3:.0f} kB (gas scene, 2000 disks).\n")
    (args.out / "summary.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
