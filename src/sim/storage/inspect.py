"""``python -m sim.storage.inspect PATH [--json]`` (also ``sim-inspect``): what a run file holds.

Scene, number of disks, snapshots, time span, energy drift (or dissipation), collisions, the
stop reason, and what is damaged: every chunk of every dataset is read and checked against
its checksum (:func:`find_damage`), and the damaged snapshots are named; the rest is computed
from the intact snapshots. ``--json`` prints the same as one JSON object for scripts. Exit
status 0 for an intact file, 1 when something is damaged, 2 (with one line on stderr) for a
file that is not a readable sim run file.
"""

import argparse
import errno
import json
import os
import re
import sys
from pathlib import Path

import h5py
import numpy as np
import yaml

from sim.storage.errors import RunFileError
from sim.storage.run_lock import writer_of  # the run's own lock: HDF5's may be off

#: what a read of a damaged run file raises: h5py's errors, and HDF5's for broken metadata
DAMAGE = (KeyError, OSError, RuntimeError, ValueError)


def _reason(error):
    """HDF5's reason for an error, in a few words (its messages carry times, addresses and
    line breaks)."""
    code = getattr(error, "errno", None)
    if code:
        return os.strerror(code)
    text = " ".join(str(error).split())
    inner = re.search(r"\(([^()]*)\)", text)
    return inner.group(1) if inner else text[:160]


def open_run_file(path):
    """The run file at ``path`` opened for reading (an :class:`h5py.File`), or
    :class:`RunFileError` saying why it is not one: held by a run still writing it, not HDF5
    (or truncated), another HDF5 file, or damaged."""
    if Path(path).is_dir():
        raise RunFileError(f"{path} is a folder, not a run file")
    if not Path(path).exists():
        raise RunFileError(f"{path}: no such file")
    if not Path(path).is_file():  # opening a named pipe would wait for a writer
        raise RunFileError(f"{path} is not a regular file (a device, pipe or socket), not a "
                           f"run file")
    try:
        f = h5py.File(path, "r")
    except (OSError, ValueError) as error:
        if (getattr(error, "errno", None) in (errno.EAGAIN, errno.EWOULDBLOCK)
                or "unable to lock file" in str(error)):
            raise RunFileError(f"{path} is open for writing in another process (a run still "
                               f"going?); read it when that run has ended") from error
        raise RunFileError(f"{path}: not a readable HDF5 file ({_reason(error)})") from error
    try:
        is_run_file = "h5md" in f and "particles/disks/position" in f
    except RuntimeError as error:  # HDF5 finds its own metadata damaged
        f.close()
        raise RunFileError(f"{path}: damaged run file ({_reason(error)})") from error
    if not is_run_file:
        f.close()
        raise RunFileError(f"{path}: an HDF5 file, but not an H5MD run file of sim "
                           f"(no /h5md or /particles/disks/position)")
    return f


def time_series(f):
    """The H5MD time-dependent elements of a run file: position, velocity, each observable."""
    return [f["particles/disks/position"], f["particles/disks/velocity"],
            *f["observables"].values()]


def _chunk_reads(dataset):
    """(selection, values) for every chunk of ``dataset``, values None where the chunk does
    not read (its checksum fails); a dataset without chunks is one."""
    if dataset.size == 0:
        return
    for selection in dataset.iter_chunks() if dataset.chunks else [Ellipsis]:
        try:
            yield selection, dataset[selection]
        except OSError:
            yield selection, None


def _frames(dataset, selection):
    """The indices along the first axis (the snapshots of a time series) of a selection."""
    if selection is Ellipsis:
        return range(dataset.shape[0] if dataset.ndim else 0)
    return range(*selection[0].indices(dataset.shape[0]))


def read_intact(dataset):
    """``dataset`` read whole, or chunk by chunk when that fails: its values, NaN in the chunks
    that do not read (integer data become float64 then), and the sorted indices along its
    first axis that they cover."""
    try:
        return dataset[()], []
    except OSError:
        pass
    values = np.empty(dataset.shape, dataset.dtype)
    damaged = []
    for selection, chunk in _chunk_reads(dataset):
        if chunk is None:
            if not damaged:
                values = values.astype(np.float64)
            values[selection] = np.nan
            damaged.extend(_frames(dataset, selection))
        else:
            values[selection] = chunk
    return values, sorted(set(damaged))


def damaged_frames(dataset):
    """The sorted indices along the first axis of ``dataset`` covered by chunks that do not
    read; only one chunk is in memory at a time."""
    return sorted({i for selection, chunk in _chunk_reads(dataset) if chunk is None
                   for i in _frames(dataset, selection)})


def snapshot_column(f, name):
    """``step`` or ``time`` of every snapshot as float64, from the first time series that
    reads there (they all hold the same); NaN where none does."""
    out = None
    for group in time_series(f):
        values, damaged = read_intact(group[name])
        values = values.astype(np.float64)
        out = values if out is None else np.where(np.isnan(out), values, out)
        if not damaged:
            break
    return out


def damage_reason(dataset):
    """Why a chunk of ``dataset`` that does not read is damaged, in words."""
    return "checksum mismatch" if dataset.fletcher32 else "unreadable"


def series_damage(dataset, frames, times):
    """The damage of a time series' dataset at snapshots ``frames``: named after the
    variable (``position``, an observable; ``position time`` for its times), with the
    snapshots' indices and times."""
    group, column = dataset.parent, dataset.name.rsplit("/", 1)[1]
    name = group.name.rsplit("/", 1)[1] + ("" if column == "value" else f" {column}")
    return {"name": name, "path": dataset.name.lstrip("/"),
            "snapshots": [int(i) for i in frames],
            "times": [float(times[i]) if i < len(times) else float("nan") for i in frames],
            "reason": damage_reason(dataset)}


def find_damage(f):
    """Every damaged place of the open run file ``f``, each chunk of each dataset read and
    checked: a list of dicts with ``name`` (what is damaged), ``path`` and ``reason``; time
    series add ``snapshots`` and ``times``, checkpoint slots ``slot``, ``snapshot``, ``time``
    and ``latest``."""
    times = snapshot_column(f, "time")
    found, series = [], set()
    for group in time_series(f):
        for column in ("value", "step", "time"):
            series.add(group[column].name)
            frames = damaged_frames(group[column])
            if frames:
                found.append(series_damage(group[column], frames, times))
    datasets = []
    f.visititems(lambda name, item: datasets.append(item)
                 if isinstance(item, h5py.Dataset) and item.name not in series else None)
    slots = {}
    for dataset in datasets:
        if not damaged_frames(dataset):
            continue
        parts = dataset.name.split("/")
        if parts[1] == "checkpoint":
            slots.setdefault(parts[2], dataset)
        else:
            path = dataset.name.lstrip("/")
            found.append({"name": path, "path": path, "reason": damage_reason(dataset)})
    for slot, dataset in slots.items():
        attrs = f["checkpoint"][slot].attrs
        entry = {"name": f"checkpoint slot {slot}", "path": f"checkpoint/{slot}", "slot": slot,
                 "latest": str(f["checkpoint"].attrs.get("latest", "")) == slot,
                 "reason": damage_reason(dataset)}
        if "snapshots" in attrs:
            entry.update(snapshot=int(attrs["snapshots"]) - 1, time=float(attrs["time"]))
        found.append(entry)
    return found


def _snapshots(frames, times):
    """``snapshots 12 (t = 0.6), 13 (t = 0.65)``; runs of three or more as ``0–40 (t = 0–2)``."""
    runs, start = [], 0
    for k in range(1, len(frames) + 1):
        if k == len(frames) or frames[k] != frames[k - 1] + 1:
            runs.append((start, k - 1))
            start = k
    parts = []
    for a, b in runs:
        if b - a >= 2:
            parts.append(f"{frames[a]}–{frames[b]} (t = {times[a]:.6g}–{times[b]:.6g})")
        else:
            parts.extend(f"{frames[k]} (t = {times[k]:.6g})" for k in range(a, b + 1))
    return ("snapshot " if len(frames) == 1 else "snapshots ") + ", ".join(parts)


def describe(entry):
    """One damaged place of :func:`find_damage` as text."""
    if "snapshots" in entry:
        where = f"{entry['name']} at {_snapshots(entry['snapshots'], entry['times'])}"
    elif "snapshot" in entry:
        where = (f"{entry['name']} ({'latest, ' if entry['latest'] else ''}checkpoint of "
                 f"snapshot {entry['snapshot']}, t = {entry['time']:.6g})")
    else:
        where = entry["name"]
    return f"{where}: {entry['reason']}"


def _checksums(f):
    """``all``, ``some`` or ``none``: which datasets of ``f`` carry a checksum."""
    filtered = []
    f.visititems(lambda name, item: filtered.append(item.fletcher32)
                 if isinstance(item, h5py.Dataset) else None)
    return "all" if all(filtered) else "some" if any(filtered) else "none"


def _at(values, index):
    """``values[index]`` as a Python number, or None when it is damaged (NaN) or missing."""
    if not values.size or np.isnan(values[index]):
        return None
    return values[index].item()


def summary(path, verify=True):
    """A dict describing the run file at ``path``; ``damaged`` lists :func:`find_damage`'s
    places (empty when intact; None when ``verify`` is false, which skips reading every
    chunk of the file), and what is computed from the snapshots uses the intact ones."""
    with open_run_file(path) as f:
        try:
            parameters = f["parameters"].attrs
            config = yaml.safe_load(parameters["config"])
            damaged = find_damage(f) if verify else None
            time = snapshot_column(f, "time")

            def observable(name):
                return (read_intact(f[f"observables/{name}/value"])[0] if name in f["observables"]
                        else np.zeros_like(time))

            energy = observable("kinetic_energy") + observable("rotational_energy")
            dissipated = observable("dissipated_energy")
            potential, work = observable("potential_energy"), observable("wall_work")
            collisions = observable("collisions")
            species = read_intact(f["particles/disks/species"])[0]
            creator = f["h5md/creator"].attrs
            result = {
                "path": str(path),
                "scene": config.get("scene"),
                "n": int(f["particles/disks/radius"].shape[0]),
                "species": None if np.isnan(species).any() else int(np.max(species) + 1),
                "boundary": _boundary(f["particles/disks/box"].attrs["boundary"]),
                "observables": sorted(f["observables"]),
                "snapshots": int(time.size),
                "time_span": [_at(time, 0), _at(time, -1)] if time.size else None,
                "collisions": _at(collisions, -1) if collisions.size else 0,
                "initial_energy": _at(energy, 0),
                "final_energy": _at(energy, -1),
                "dissipated_energy": _at(dissipated, -1) if dissipated.size else 0.0,
                "stop_reason": str(parameters["stop_reason"]),
                "seed": int(parameters["seed"]),
                "creator": f"{creator['name']} {creator['version']}",
            }
            result["walls"] = _walls(result["boundary"], config)
            checksums = _checksums(f)
        except (*DAMAGE, yaml.YAMLError) as error:
            raise RunFileError(f"{path}: damaged or incomplete run file ({error})") from error
    # energy balance: kinetic (translational and rotational) + potential + dissipated − work
    # of the walls stays constant;
    # the drift is measured, over the intact snapshots, against the largest energy seen
    balance = energy + potential + dissipated - work
    intact = ~np.isnan(balance)
    result["growth_rate"] = float((config.get("growth") or {}).get("rate", 0.0))
    if result["growth_rate"] > 0.0:
        result["energy_drift"] = None  # growing disks: growth pumps energy in, rescaling out
    elif intact.any():
        balance = balance[intact] - balance[intact][0]
        scale = max(np.max(energy[intact]), np.max(np.abs(work[intact])),
                    np.max(dissipated[intact]), np.finfo(float).tiny)
        result["energy_drift"] = float(np.max(np.abs(balance)) / scale)
    elif energy.size:
        result["energy_drift"] = None  # no snapshot has every energy intact
    result.update(checksums=checksums, damaged=damaged)
    return result


def _boundary(kinds):
    """``periodic`` or ``walls`` along x and y (H5MD writes a walled axis as ``none``)."""
    return ["periodic" if kind.decode() == "periodic" else "walls" for kind in kinds]


def _walls(boundary, config):
    """The walls that are not plain hard walls, in words, or ``hard`` (None without walls)."""
    if "walls" not in boundary:
        return None
    special = []
    for name, wall in (config.get("walls") or {}).items():
        if wall.get("temperature") is not None:
            special.append(f"{name} thermal at T = {wall['temperature']:g}")
        if wall.get("speed"):
            special.append(f"{name} moving at {wall['speed']:g}")
        if wall.get("amplitude") and wall.get("frequency"):
            special.append(f"{name} oscillating, amplitude {wall['amplitude']:g}, "
                           f"ω = {wall['frequency']:g}")
    return "; ".join(special) or "hard"


CHECKSUMS = {"all": "on every dataset (fletcher32)",
             "some": "on some datasets only (written before checksums, then resumed): damage "
                     "elsewhere goes unnoticed",
             "none": "none (written before checksums): damage goes unnoticed"}


def main(argv=None):
    parser = argparse.ArgumentParser(prog="sim-inspect", description=__doc__.splitlines()[0])
    parser.add_argument("path", help="run file (run.h5)")
    parser.add_argument("--json", action="store_true", help="one JSON object")
    args = parser.parse_args(argv)

    writer = writer_of(args.path)
    if writer is not None:
        print(f"sim-inspect: {args.path} is being written by {writer}, a run still going; "
              f"read it when that run has ended", file=sys.stderr)
        return 2
    try:
        info = summary(args.path)
    except RunFileError as error:
        print(f"sim-inspect: {' '.join(str(error).split())}", file=sys.stderr)
        return 2
    status = 1 if info["damaged"] else 0
    text = dict(info, checksums=CHECKSUMS[info["checksums"]],
                damaged="; ".join(describe(entry) for entry in info["damaged"]) or "nothing")
    width = max(len(k) for k in text)
    try:
        if args.json:
            print(json.dumps(info), flush=True)
        else:
            for key, value in text.items():
                print(f"{key:<{width}}  {value}", flush=True)
    except BrokenPipeError:  # a reader that stopped early (| head): the rest is not wanted
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return status


if __name__ == "__main__":
    sys.exit(main())
