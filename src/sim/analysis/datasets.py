"""Run files as labelled arrays: :func:`open_run` and :func:`open_sweep` return xarray
Datasets that the figure stages read; nothing here simulates.

``open_run(path)``: dims ``time`` (one entry per snapshot, coordinate the snapshot time),
``disk``, ``axis`` (x, y) and ``species``; variables ``position`` and ``velocity``
(time, disk, axis), and ``angular_velocity`` (time, disk) when the disks turn — read lazily
from the HDF5 file, so only what is indexed is loaded —
and the observables (``kinetic_energy``, ``kinetic_energy_by_species``, ``collisions``,
``wall_contacts``, ``dissipated_energy``, ``collision_virial``, and those of the scene's
observers, e.g. ``radial_distribution`` over ``r``, ``clusters`` over ``disk``,
``local_fields`` over ``field`` (``packing_fraction``, ``temperature``), ``y``, ``x``, the
tensors over ``a``, ``b`` (each ``x``, ``y``)); per-disk coordinates
``radius``, ``mass``, ``species_id``; attributes: scene, seed, the resolved config (YAML), how
the initial state was made (``preparation``), stop reason, box edges and boundary.

``open_sweep(multirun_dir)``: the runs of a Hydra sweep in one Dataset with each swept
parameter as a dimension (``projectile.radius`` → ``projectile_radius``); runs are aligned by
snapshot number (dim ``snapshot``), their snapshot times kept as a coordinate; a run with
fewer snapshots than another is padded with NaN, and its integer counters (``collisions``,
``wall_contacts``) with −1, so that they stay integers; each run's resolved config (YAML),
stop reason and preparation are the variables ``config``, ``stop_reason`` and
``preparation``.
"""

import warnings
from pathlib import Path

import h5py
import numpy as np
import xarray as xr
import yaml
from xarray.backends import BackendArray
from xarray.core import indexing

from sim.analysis.cells import cell_index, granular_temperature, grid
from sim.storage.errors import RunFileError
from sim.storage.h5md import (
    GROWTH_OBSERVABLES,
    OBSERVABLES,
    PARTICLE_SERIES,
    SPIN_OBSERVABLES,
)
from sim.storage.inspect import (
    DAMAGE,
    damage_reason,
    describe,
    open_run_file,
    read_intact,
    series_damage,
    snapshot_column,
)


class _H5Array(BackendArray):
    """A time series' h5py dataset (``position``, ``velocity``) as a lazily indexed xarray
    backend array: a read that meets damaged frames reads frame by frame, gives NaN for the
    damaged ones and says which in one RuntimeWarning."""

    def __init__(self, dataset, times, path):
        self.dataset = dataset
        self.times = times
        self.path = path
        self.shape = dataset.shape
        self.dtype = dataset.dtype

    def __getitem__(self, key):
        return indexing.explicit_indexing_adapter(key, self.shape, indexing.IndexingSupport.BASIC,
                                                  self._read)

    def _read(self, key):
        try:
            return self.dataset[key]
        except OSError:  # a frame fails its checksum
            pass
        out = np.full(np.broadcast_to(np.empty((), self.dtype), self.shape)[key].shape, np.nan)
        frames = range(self.shape[0])[key[0]]
        single = isinstance(frames, int)
        damaged = []
        for k, i in enumerate([frames] if single else frames):
            try:
                frame = self.dataset[(i, *key[1:])]
            except OSError:
                damaged.append(i)
                continue
            out[() if single else k] = frame
        if damaged:
            warnings.warn(f"{self.path}: "
                          f"{describe(series_damage(self.dataset, damaged, self.times))}; read "
                          f"as NaN", RuntimeWarning, stacklevel=2)
        return out


def _needed(path, dataset):
    """``dataset``, which the run cannot be read without, or :class:`RunFileError`."""
    try:
        return dataset[()]
    except OSError as error:
        raise RunFileError(f"{path}: {dataset.name.lstrip('/')} is damaged "
                           f"({damage_reason(dataset)}); the run file cannot be read without "
                           f"it") from error


def _coordinate(values):
    """An observer's coordinate as stored: numbers, or names (bytes in HDF5) as str."""
    return values.astype(str) if values.dtype.kind == "S" else values


def open_run(path):
    """The run file at ``path`` as an :class:`xarray.Dataset` (see the module docstring).
    Close it with ``ds.close()`` (or use it in a ``with`` block) to release the file.

    Damaged snapshots are NaN: those of the observables, checked at opening, are listed in
    ``ds.attrs["damaged"]`` and one RuntimeWarning; those of ``position`` and ``velocity``
    in a RuntimeWarning of the read that meets them. A damaged dataset that the run cannot be
    read without (``radius``, ``mass``, ``species``, box edges, an observer's coordinates)
    or ``/parameters`` is :class:`RunFileError`."""
    f = open_run_file(path)
    try:
        disks = f["particles/disks"]
        time = snapshot_column(f, "time")
        step = snapshot_column(f, "step")
        n_species = f["observables/kinetic_energy_by_species/value"].shape[1]
        data = {name: xr.Variable(("time", "disk", "axis")[:disks[f"{name}/value"].ndim],
                                  indexing.LazilyIndexedArray(
                                      _H5Array(disks[f"{name}/value"], time, path)))
                for name in PARTICLE_SERIES if name in disks}
        axes, damaged = {}, []
        for name, group in f["observables"].items():
            if name.endswith("by_species"):
                dims = ("time", "species")
            elif name in OBSERVABLES or name in SPIN_OBSERVABLES or name in GROWTH_OBSERVABLES:
                dims = ("time",)
            else:  # an observer's: its dims as an attribute, coordinates beside its value
                dims = ("time", *(str(d) for d in group.attrs["dims"]))
                axes.update({k: _coordinate(_needed(path, group[k])) for k in group
                             if k not in ("step", "time", "value")})
            values, frames = read_intact(group["value"])
            if frames:
                damaged.append(describe(series_damage(group["value"], frames, time)))
            data[name] = xr.Variable(dims, values,
                                     attrs={"unit": group["value"].attrs.get("unit", ""),
                                            "description": group.attrs.get("description", "")})
        try:
            parameters = f["parameters"].attrs
            config = yaml.safe_load(parameters["config"])
            attrs = {"scene": config.get("scene", ""), "seed": int(parameters["seed"]),
                     "config": str(parameters["config"]),
                     "preparation": str(parameters.get("preparation", "")),
                     "stop_reason": str(parameters["stop_reason"])}
        except (*DAMAGE, yaml.YAMLError, AttributeError) as error:
            raise RunFileError(f"{path}: /parameters is damaged ({' '.join(str(error).split())})"
                               f"; the run file cannot be read without it") from error
        box = disks["box"]
        ds = xr.Dataset(
            data,
            coords={"time": time,
                    "step": ("time", step if np.isnan(step).any() else step.astype(np.int64)),
                    "axis": ["x", "y"], "species": np.arange(n_species),
                    "radius": ("disk", _needed(path, disks["radius"])),
                    "mass": ("disk", _needed(path, disks["mass"])),
                    "species_id": ("disk", _needed(path, disks["species"])), **axes},
            attrs={**attrs, "box": _needed(path, box["edges"]).tolist(),
                   "boundary": [b.decode() for b in box.attrs["boundary"]],
                   "path": str(path), "damaged": damaged})
    except RunFileError:
        f.close()
        raise
    except DAMAGE as error:
        f.close()
        raise RunFileError(f"{path}: damaged or incomplete run file ({error})") from error
    except Exception:
        f.close()
        raise
    if damaged:
        warnings.warn(f"{path}: damaged, read as NaN: {'; '.join(damaged)}", RuntimeWarning,
                      stacklevel=2)
    ds.set_close(f.close)
    return ds


def _labels(path):
    """{key: value} of the overrides a run file records (``/parameters`` attribute
    ``overrides``), each value the one its resolved config holds under that key (the text
    of the override for keys outside the config, such as ``scenario``)."""
    with open_run_file(path) as f:
        attrs = f["parameters"].attrs
        overrides = yaml.safe_load(str(attrs.get("overrides", "[]"))) or []
        config = yaml.safe_load(str(attrs["config"]))
    labels = {}
    for item in overrides:
        key, _, text = item.partition("=")
        key = key.lstrip("+~")
        if key.startswith("hydra"):
            continue
        node = config
        for part in key.split("."):
            node = node.get(part, _MISSING) if isinstance(node, dict) else _MISSING
        labels[key] = _parsed(text) if node is _MISSING else node
    return labels


def _parsed(text):
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError:
        return text


_MISSING = object()

#: an integer counter of a snapshot that a run of a sweep does not have
NOT_REACHED = -1


def open_sweep(multirun_dir):
    """The runs of a sweep directory in one Dataset, one dimension per swept parameter: the
    overrides that differ between runs, labelled with what each run file records."""
    runs = sorted(Path(multirun_dir).glob("*/run.h5"))
    if not runs:
        raise FileNotFoundError(f"no */run.h5 under {multirun_dir}")
    overrides = [_labels(run) for run in runs]
    keys = sorted({k for o in overrides for k in o})
    swept = [k for k in keys if len({repr(o.get(k)) for o in overrides}) > 1]
    datasets, configs, reasons, preparations = [], [], [], []
    for run, override in zip(runs, overrides, strict=True):
        ds = open_run(run).load()
        ds.close()
        ds = ds.rename({"time": "snapshot"}).assign_coords(
            snapshot=np.arange(ds.sizes["time"]), time=("snapshot", ds["time"].values))
        configs.append(ds.attrs.pop("config"))
        reasons.append(ds.attrs.pop("stop_reason"))
        preparations.append(ds.attrs.pop("preparation"))
        datasets.append(ds.expand_dims({k.replace(".", "_"): [override[k]]
                                        for k in swept}))
    fill = {name: NOT_REACHED for ds in datasets for name, variable in ds.data_vars.items()
            if variable.dtype.kind in "iu"}
    if not swept:
        combined = xr.concat(datasets, dim="run", join="outer", data_vars="all",
                             coords="different", compat="equals", fill_value=fill)
        for name, texts in (("config", configs), ("stop_reason", reasons),
                            ("preparation", preparations)):
            combined[name] = ("run", np.array(texts, dtype=object))
        return combined
    combined = xr.combine_by_coords(datasets, join="outer", combine_attrs="drop_conflicts",
                                    data_vars="all", coords="different", compat="no_conflicts",
                                    fill_value=fill)
    dims = [k.replace(".", "_") for k in swept]
    for name, texts in (("config", configs), ("stop_reason", reasons),
                        ("preparation", preparations)):
        per_run = xr.DataArray(np.empty([combined.sizes[d] for d in dims], dtype=object),
                               dims=dims, coords={d: combined[d] for d in dims})
        for override, text in zip(overrides, texts, strict=True):
            per_run.loc[{k.replace(".", "_"): override[k] for k in swept}] = text
        combined[name] = per_run
    for name in (k.replace(".", "_") for k in swept):
        combined = combined.sortby(name)
    combined.attrs["swept"] = [k.replace(".", "_") for k in swept]
    combined.attrs["sweep_dir"] = str(multirun_dir)
    return combined


def granular_temperatures(position, velocity, mass, species, box, cells=8):
    """Temperature of each species in the frame of the local flow: the disks' velocities less
    the mass-weighted mean velocity of their cell on the grid of :func:`sim.analysis.cells.grid`
    (``cells`` along x), pooled by species (:func:`sim.analysis.cells.granular_temperature`:
    T_s = Σ_s m |v − u|² / (2 Σ_s (1 − m/M)), 2D, k_B = 1).

    ``position``, ``velocity``: float64[T, N, 2]; ``mass``, ``species``: [N].
    Returns float64[T, n_species].
    """
    position, velocity = np.asarray(position), np.asarray(velocity)
    mass, species = np.asarray(mass, dtype=np.float64), np.asarray(species)
    n_species = int(species.max()) + 1
    shape = grid(box, cells)
    cell = cell_index(position, box, shape)
    out = np.empty((position.shape[0], n_species))
    for t in range(position.shape[0]):
        out[t] = granular_temperature(velocity[t], mass, cell[t], shape[0] * shape[1], species,
                                      n_species)
    return out


def at_last_snapshot(sweep, name):
    """``sweep[name]`` at each run's own last snapshot (runs of a sweep differ in length; the
    shorter ones are padded with NaN, which ``time`` is not when the runs share their snapshot
    times)."""
    last = sweep["kinetic_energy"].notnull().sum("snapshot") - 1
    return sweep[name].isel(snapshot=last)


def pressure_tensor(run):
    """Pressure tensor between consecutive snapshots of a run that observed it
    (``observe.pressure_tensor=true``): P_ab = (K̄_ab + ΔW_ab/Δt)/A, with K_ab = Σ m v_a v_b
    averaged over the two ends of each interval and W_ab = Σ r_a Δp_b the cumulative collision
    virial tensor (Allen & Tildesley, *Computer Simulation of Liquids*, 2nd ed., §2.4). In a
    periodic box the pressure is (P_xx + P_yy)/2. Returns a DataArray (time, a, b), time the
    end of each interval."""
    area = float(np.prod(run.attrs["box"]))
    kinetic = 0.5 * (run["kinetic_tensor"] + run["kinetic_tensor"].shift(time=-1))
    rate = run["collision_virial_tensor"].diff("time", label="upper") / run["time"].diff(
        "time", label="upper")
    tensor = (kinetic.isel(time=slice(None, -1)).values + rate.values) / area
    return xr.DataArray(tensor, dims=("time", "a", "b"),
                        coords={"time": rate["time"].values, "a": ["x", "y"],
                                "b": ["x", "y"]},
                        attrs={"unit": "energy/area"})


def global_bond_order(run):
    """|Ψ₆| = |⟨ψ₆⟩| over the disks at every snapshot of a run that observed ψ₆
    (``observe.bond_order=true``, :class:`sim.analysis.observers.BondOrder`): a DataArray
    over time."""
    psi = run["bond_order"].isel(part=0) + 1j * run["bond_order"].isel(part=1)  # (re, im)
    return abs(psi.mean("disk")).rename("global_bond_order")


def velocity_autocorrelation(run, max_lag):
    """⟨v(t₀ + τ)·v(t₀)⟩ per species, averaged over every snapshot as time origin t₀, for lags
    of 0 … ``max_lag`` snapshots. Snapshots must be evenly spaced in time (``output.every_time``).
    Returns a DataArray (lag, species) with coordinate ``lag_time``."""
    time = run["time"].values
    steps = np.diff(time)
    if steps.size and not np.allclose(steps, steps[0], rtol=1e-9, atol=0.0):
        raise ValueError("velocity_autocorrelation needs snapshots evenly spaced in time "
                         "(output.every_time)")
    velocity = run["velocity"].values
    species = run["species_id"].values
    n_species = run.sizes["species"]
    count = np.bincount(species, minlength=n_species)
    lags = np.arange(min(max_lag, time.size - 1) + 1)
    out = np.empty((lags.size, n_species))
    for k, lag in enumerate(lags):
        products = np.sum(velocity[lag:] * velocity[:time.size - lag], axis=2).mean(axis=0)
        out[k] = np.bincount(species, weights=products, minlength=n_species) / count
    return xr.DataArray(out, dims=("lag", "species"),
                        coords={"lag": lags, "lag_time": ("lag", lags * (steps[0] if steps.size
                                                                         else 0.0)),
                                "species": np.arange(n_species)},
                        attrs={"unit": "length²/time²"})


def contacts(path):
    """The event log of a run (``observe.event_log=true``) as a Dataset over ``contact``:
    time, disk, partner (−1 − wall for wall contacts), impulse, dissipated."""
    with h5py.File(path, "r") as f:
        if "events/contacts" not in f:
            raise KeyError(f"{path} has no event log: run the scene with observe.event_log=true")
        rows = f["events/contacts"][()]
    return xr.Dataset({"time": ("contact", rows[:, 0]),
                       "disk": ("contact", rows[:, 1].astype(np.int64)),
                       "partner": ("contact", rows[:, 2].astype(np.int64)),
                       "impulse": ("contact", rows[:, 3]),
                       "dissipated": ("contact", rows[:, 4])},
                      coords={"contact": rows[:, 5].astype(np.int64)})


__all__ = ["at_last_snapshot", "contacts", "global_bond_order", "granular_temperatures",
           "open_run", "open_sweep", "pressure_tensor", "velocity_autocorrelation"]
