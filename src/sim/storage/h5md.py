"""The run file: H5MD 1.1 (de Buyl, Colberg & Höfling, Comput. Phys. Commun. 185, 1546 (2014)).

Layout written by :class:`RunWriter`:
  /h5md                       version [1, 1]; author, creator (sim and its version)
  /particles/disks/box        dimension 2, boundary ["none"|"periodic"]×2, edges [Lx, Ly]
  /particles/disks/position   step int64[T], time float64[T], value float64[T, N, 2]
  /particles/disks/velocity   the same layout
  /particles/disks/angular_velocity   when the disks turn (:mod:`sim.effects.rotation`):
                              spins ω, value float64[T, N]
  /particles/disks/radius, mass, species   time-independent, [N]; growing disks
                              (:mod:`sim.effects.growth`): their radii at time 0, and
                              /observables/radius_scale R_i(t)/R_i(0)
  /observables/<name>         step, time, value — kinetic_energy, kinetic_energy_by_species
                              [T, S], collisions, wall_contacts, dissipated_energy,
                              collision_virial, rotational_energy (when the disks turn);
                              and one per observer the scene asks for
                              (:mod:`sim.analysis.observers`): attribute ``dims``, coordinates
                              beside ``value``
  /events/contacts            when the scene logs events (``observe.event_log``): one row per
                              contact, columns time, disk, partner, impulse, dissipated,
                              contact (:mod:`sim.effects.event_log`), written at every flush
  /parameters                 config (resolved YAML), overrides (YAML list), seed, preparation
                              (how the initial state was made, in words), versions,
                              git commit, stop reason; stop_message (a breakdown's), resumes
                              (YAML: each resume that changed something, from which snapshot)
  /checkpoint/{a,b}           the engine's full state at the last two snapshots, ``latest``
                              naming the complete one (for resume); a slot being rewritten
                              lacks its ``time`` and ``snapshots`` attributes; single values
                              are 1-element datasets with attribute ``scalar``
Datasets are chunked per snapshot and compressed, each with HDF5's fletcher32 checksum
(:func:`sim.storage.inspect.find_damage` names what fails it). Snapshots are buffered in memory and
written together, then flushed, at least every ``flush_seconds`` of wall time (1 s), whenever the
buffer holds ``buffer_bytes`` (64 MiB), with every checkpoint and at the end: a killed run
leaves a file readable up to its last flush, and a run with frequent small snapshots does not
spend its time in HDF5 calls. ``step`` counts contacts (disk–disk and disk–wall).
"""

import errno
import math
import os
import re
import resource
import shutil
import time as wallclock
import warnings

import h5py
import numpy as np
import yaml

import sim
from sim.effects.event_log import LOG_COLUMNS, LOG_CONTACT
from sim.storage.errors import RunFileError
from sim.storage.inspect import DAMAGE

OBSERVABLES = {
    "kinetic_energy": ("energy", "Σ m v²/2 over all disks"),
    "kinetic_energy_by_species": ("energy", "Σ m v²/2 per species, [species]"),
    "collisions": ("1", "cumulative disk–disk contacts"),
    "wall_contacts": ("1", "cumulative disk–wall contacts"),
    "dissipated_energy": ("energy", "cumulative kinetic energy lost in contacts"),
    "collision_virial": ("length × momentum", "cumulative Σ r_ij·Δp_i over disk contacts"),
    "potential_energy": ("energy", "Σ −m g·r (zero without gravity)"),
    "wall_work": ("energy", "cumulative work of moving and thermal walls on the disks"),
}

#: time series of /particles/disks (angular_velocity: when the disks turn)
PARTICLE_SERIES = ("position", "velocity", "angular_velocity")

#: observables of a run whose disks grow (:mod:`sim.effects.growth`)
GROWTH_OBSERVABLES = {"radius_scale": ("1", "R_i(t)/R_i(0) = 1 + γ t of growing disks, whose "
                                            "radii at time 0 are /particles/disks/radius")}

#: observables that count (int64)
COUNTS = ("collisions", "wall_contacts")

#: observables of a run whose disks turn (:mod:`sim.effects.rotation`)
SPIN_OBSERVABLES = {"rotational_energy": ("energy", "Σ I ω²/2 over all disks")}


def _time_series(group, shape, dtype, unit, description):
    """An H5MD time-dependent element: extensible step, time and value datasets. Every
    dataset of the run file carries HDF5's fletcher32 checksum per chunk, so that a reader
    finds changed bytes (:func:`sim.storage.inspect.find_damage`): one frame per chunk of ``value``
    when frames are arrays, 1024 snapshots per chunk otherwise."""
    group.attrs["description"] = description
    group.create_dataset("step", shape=(0,), maxshape=(None,), dtype=np.int64, chunks=(1024,),
                         fletcher32=True)
    time = group.create_dataset("time", shape=(0,), maxshape=(None,), dtype=np.float64,
                                chunks=(1024,), fletcher32=True)
    time.attrs["unit"] = "time"
    chunk = (1, *shape) if shape else (1024,)
    value = group.create_dataset("value", shape=(0, *shape), maxshape=(None, *shape),
                                 dtype=dtype, chunks=chunk,
                                 compression="gzip" if shape else None,
                                 compression_opts=1 if shape else None, fletcher32=True)
    value.attrs["unit"] = unit
    return group


def _write_frames(group, first, steps, times, values):
    """Write frames (sequences of equal length) into an H5MD time-dependent element from
    frame ``first`` on, resizing it to end with them (so a retried write does the same)."""
    for name, items in (("step", steps), ("time", times), ("value", values)):
        dataset = group[name]
        dataset.resize(first + len(items), axis=0)
        dataset[first:] = np.asarray(items)


#: Room kept free on the run file's disk beyond what a write needs: HDF5 adds metadata, and a
#: write that fails half-way leaves a file HDF5 cannot open again.
DISK_MARGIN_BYTES = 64 << 20


#: Room kept below a file-size limit (``ulimit -f``) beyond what a write needs: HDF5 adds
#: metadata, and a write the system refuses half-way leaves a file HDF5 cannot open again.
LIMIT_MARGIN_BYTES = 1 << 20


def hdf5_reason(error):
    """The reason of an HDF5 error in a few words: the system's, when HDF5 names its errno
    (its messages carry times, addresses and line breaks besides)."""
    code = re.search(r"errno = (\d+)", str(error))
    if code:
        return os.strerror(int(code.group(1)))
    return " ".join(str(error).split())


def size_limit():
    """The largest file this process may write (``ulimit -f``, RLIMIT_FSIZE), or inf."""
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    return math.inf if soft == resource.RLIM_INFINITY else soft


#: files whose close failed after a failed write (:meth:`RunWriter.abandon`)
UNCLOSABLE = []


class DiskFullError(OSError):
    """Too little room on the disk for the next write; nothing of it was written."""


def free_bytes(folder):
    """Free bytes on the disk holding ``folder``."""
    return shutil.disk_usage(folder).free


class RunWriter:
    """Creates the run file and appends one frame per :meth:`snapshot`."""

    def __init__(self, path, engine, parameters, mode="w", checkpoint_seconds=30.0,
                 flush_seconds=1.0, buffer_bytes=64 << 20, observers=()):
        self.path = path
        self.observers = list(observers)
        self.checkpoint_seconds = checkpoint_seconds
        self.flush_seconds = flush_seconds
        self.buffer_bytes = buffer_bytes
        self._last_checkpoint = -math.inf
        self._last_flush = -math.inf
        self._frames = []  # buffered (step, time, {particle series: value}, observables)
        self._contacts = []  # buffered rows of the event log
        self._contact_bytes = 0
        self.file = h5py.File(path, mode)
        if mode in ("w", "w-", "x"):
            try:
                self._create(engine, parameters)
            except BaseException:
                self.abandon()  # a half-made file left open can crash HDF5 at exit
                raise
        self._flushed_frames = self.file["particles/disks/position/step"].shape[0]
        if engine.event_log is not None:
            engine.event_sink = self._log_contacts

    def _create(self, engine, parameters):
        self._make_room(engine.n * (engine.radius.itemsize + engine.mass.itemsize
                                    + engine.species.itemsize))
        f = self.file
        h5md = f.create_group("h5md")
        h5md.attrs["version"] = np.array([1, 1])
        f.create_group("h5md/author").attrs["name"] = "sim"
        creator = f.create_group("h5md/creator")
        creator.attrs["name"] = "sim"
        creator.attrs["version"] = sim.__version__
        disks = f.create_group("particles/disks")
        box = disks.create_group("box")
        box.attrs["dimension"] = 2
        box.attrs["boundary"] = np.array(["periodic" if p else "none"
                                          for p in engine.periodic], dtype="S8")
        box.create_dataset("edges", data=engine.box, fletcher32=True).attrs["unit"] = "length"
        n = engine.n
        _time_series(disks.create_group("position"), (n, 2), np.float64, "length",
                     "disk centres, wrapped into the box")
        _time_series(disks.create_group("velocity"), (n, 2), np.float64, "length/time",
                     "disk velocities")
        if engine.spinning:
            _time_series(disks.create_group("angular_velocity"), (n,), np.float64, "1/time",
                         "spins ω about the z axis, counter-clockwise positive")
        for name, values, unit in (("radius", engine.radius, "length"),
                                   ("mass", engine.mass, "mass"),
                                   ("species", engine.species, "1")):
            disks.create_dataset(name, data=values, fletcher32=True).attrs["unit"] = unit
        observables = f.create_group("observables")
        for name, (unit, description) in (
                OBSERVABLES | (SPIN_OBSERVABLES if engine.spinning else {})
                | (GROWTH_OBSERVABLES if engine.growth is not None else {})).items():
            shape = (engine.n_species,) if name.endswith("by_species") else ()
            dtype = np.int64 if name in COUNTS else np.float64
            _time_series(observables.create_group(name), shape, dtype, unit, description)
        for observer in self.observers:
            group = observables.create_group(observer.name)
            _time_series(group, observer.shape, observer.dtype, observer.unit,
                         observer.description)
            group.attrs["dims"] = list(observer.dims)
            for name, values in observer.coords.items():
                group.create_dataset(name, data=values, fletcher32=True)
        if engine.event_log is not None:
            contacts = f.create_dataset("events/contacts", shape=(0, LOG_COLUMNS),
                                        maxshape=(None, LOG_COLUMNS), dtype=np.float64,
                                        chunks=(4096, LOG_COLUMNS), compression="gzip",
                                        compression_opts=1, fletcher32=True)
            contacts.attrs["columns"] = ["time", "disk", "partner", "impulse", "dissipated",
                                         "contact"]
            contacts.attrs["description"] = (
                "every contact: absolute time, disk, partner (a disk, or −1 − wall for walls "
                "0 left, 1 right, 2 bottom, 3 top), normal impulse, energy dissipated, number "
                "of contacts so far")
        p = f.create_group("parameters")
        for key, value in parameters.items():
            p.attrs[key] = value
        p.attrs["stop_reason"] = "running"
        self._flush_file()

    def snapshot(self, engine, time=None, checkpoint=False):
        """Take the state at absolute ``time`` (default: the last event) as a frame. Frames
        reach the file at the next flush (see the module docstring); the engine state is
        checkpointed, after a flush, when ``checkpoint`` is set or when
        ``checkpoint_seconds`` of wall time have passed since the last checkpoint."""
        t = engine.time if time is None else float(time)
        observables = {"kinetic_energy": engine.kinetic_energy(t),
                       "kinetic_energy_by_species": engine.kinetic_energy_by_species(t),
                       "collisions": engine.collisions,
                       "wall_contacts": engine.wall_contacts,
                       "dissipated_energy": engine.dissipated_energy,
                       "collision_virial": engine.virial,
                       "potential_energy": engine.potential_energy(t),
                       "wall_work": engine.wall_work}
        position, velocity = engine.positions(t), engine.velocities(t)
        particles = {"position": position, "velocity": velocity}
        if engine.spinning:
            particles["angular_velocity"] = engine.angular_velocities()
            observables["rotational_energy"] = engine.rotational_energy()
        if engine.growth is not None:
            observables["radius_scale"] = engine.scale(t)
        for observer in self.observers:
            observables[observer.name] = observer(engine, t, position, velocity)
        self._frames.append((engine.contacts, t, particles, observables))
        if engine.event_log is not None:
            engine.drain_event_log()  # into _log_contacts
        now = wallclock.monotonic()
        if checkpoint or now - self._last_checkpoint >= self.checkpoint_seconds:
            self.flush()
            self._checkpoint(engine, t)
            self._last_checkpoint = wallclock.monotonic()
        elif (now - self._last_flush >= self.flush_seconds
              or len(self._frames) * 2 * engine.n * 16 >= self.buffer_bytes):
            self.flush()

    def _log_contacts(self, rows):
        """Buffer rows of the event log; written with the frames, or as soon as they fill
        ``buffer_bytes`` (a run that logs much between snapshots streams them)."""
        self._contacts.append(rows)
        self._contact_bytes += rows.nbytes
        if self._contact_bytes >= self.buffer_bytes:
            self._write_contacts()

    def _write_contacts(self):
        if self._contacts:
            rows = np.concatenate(self._contacts)
            contacts = self.file["events/contacts"]
            first = contacts.shape[0]
            contacts.resize(first + rows.shape[0], axis=0)
            contacts[first:] = rows
            self._contacts.clear()
            self._contact_bytes = 0

    def _make_room(self, nbytes):
        """Raise :class:`DiskFullError` before a write of ``nbytes`` that the disk could not
        take whole (with :data:`DISK_MARGIN_BYTES` to spare), or that would take the file
        past the process's file-size limit (with :data:`LIMIT_MARGIN_BYTES` to spare): the
        file then stays as its last flush left it, readable."""
        free = free_bytes(self.path.parent)
        if free < nbytes + DISK_MARGIN_BYTES:
            raise DiskFullError(errno.ENOSPC, f"{free} bytes free on the disk of {self.path}, "
                                f"the next write needs {nbytes} and {DISK_MARGIN_BYTES} to spare")
        limit = size_limit()
        left = limit - self.file.id.get_filesize()
        if left < nbytes + LIMIT_MARGIN_BYTES:
            raise DiskFullError(errno.EFBIG, f"the file size limit (ulimit -f) of {limit} "
                                f"bytes leaves {left} to {self.path}, the next write needs "
                                f"{nbytes} and {LIMIT_MARGIN_BYTES} to spare")

    def flush(self):
        """Write the buffered frames and flush the file."""
        self._make_room(sum(value.nbytes for _, _, particles, _ in self._frames
                            for value in particles.values())
                        + self._contact_bytes)
        if self._frames:
            steps, times, particles, observables = zip(*self._frames, strict=True)
            disks = self.file["particles/disks"]
            first = self._flushed_frames
            for name in particles[0]:
                _write_frames(disks[name], first, steps, times, [p[name] for p in particles])
            for name in observables[0]:
                _write_frames(self.file["observables"][name], first, steps, times,
                              [o[name] for o in observables])
            self._flushed_frames += len(self._frames)
            self._frames.clear()
        self._write_contacts()
        self._flush_file()
        self._last_flush = wallclock.monotonic()

    def _flush_file(self):
        """Flush the file; HDF5's refusal to write (a size limit, a full disk the free-space
        check could not foresee) is an OSError, as any failed write."""
        try:
            self.file.flush()
        except RuntimeError as error:
            raise OSError(hdf5_reason(error)) from error

    def _checkpoint(self, engine, t):
        """Store the engine state in the older of two slots, then point ``latest`` at it:
        a run killed while writing keeps the previous, complete checkpoint."""
        state = engine.state_dict()
        self._make_room(sum(np.asarray(value).nbytes for value in state.values()))
        root = self.file.require_group("checkpoint")
        slot = "b" if root.attrs.get("latest", "b") == "a" else "a"
        group = root.require_group(slot)
        for name in ("time", "snapshots"):  # incomplete until they are written again
            if name in group.attrs:
                del group.attrs[name]
        self._flush_file()  # on disk as incomplete before any of its data changes
        for key, value in state.items():
            value = np.asarray(value)
            scalar = value.ndim == 0  # stored as [1]: a chunked dataset, so with a checksum
            value = value.reshape(1) if scalar else value
            if key in group and group[key].fletcher32 and group[key].shape[1:] == value.shape[1:]:
                dataset = group[key]
                dataset.resize(value.shape[0], axis=0)
                dataset[...] = value
            else:  # new, or written before checksums
                if key in group:
                    del group[key]
                dataset = group.create_dataset(key, data=value,
                                               maxshape=(None, *value.shape[1:]),
                                               fletcher32=True)
                if scalar:
                    dataset.attrs["scalar"] = True
        stale = []  # arrays of a state of another version of sim
        group.visititems(lambda name, item: stale.append(name)
                         if isinstance(item, h5py.Dataset) and name not in state else None)
        for name in stale:
            del group[name]
        group.attrs["time"] = t
        group.attrs["snapshots"] = self.file["particles/disks/position/step"].shape[0]
        self._flush_file()
        root.attrs["latest"] = slot
        self._flush_file()

    def truncate(self, snapshots, contacts, slot):
        """Before resuming from the checkpoint in ``slot``: make it the latest (so that the
        next checkpoint goes to the other slot, also when ``slot`` is the older one, its newer
        neighbour damaged), and drop frames written after the first ``snapshots`` ones and
        logged contacts after the ``contacts``-th."""
        self.file["checkpoint"].attrs["latest"] = slot
        self._flush_file()
        disks = self.file["particles/disks"]
        for group in [*(disks[name] for name in PARTICLE_SERIES if name in disks),
                      *self.file["observables"].values()]:
            for name in ("step", "time", "value"):
                group[name].resize(snapshots, axis=0)
        self._flushed_frames = snapshots
        if "events/contacts" in self.file:
            log = self.file["events/contacts"]
            kept = int(np.searchsorted(log[:, LOG_CONTACT], contacts, side="right"))
            log.resize(kept, axis=0)

    def finish(self, reason, message=None):
        """Write what is buffered and record the stop reason (and, for a run that broke
        down, the message saying why)."""
        self.flush()
        attrs = self.file["parameters"].attrs
        attrs["stop_reason"] = reason
        if message is not None:
            attrs["stop_message"] = message
        elif "stop_message" in attrs:
            del attrs["stop_message"]
        self.file.flush()

    def record_resume(self, config, snapshot, overrides):
        """A resume from ``snapshot`` with ``overrides`` (``key=value`` strings): the
        config they make replaces the recorded one, and ``/parameters`` attribute
        ``resumes`` (YAML) lists every resume that changed something."""
        attrs = self.file["parameters"].attrs
        if overrides:
            resumes = yaml.safe_load(str(attrs.get("resumes", "[]"))) or []
            resumes.append({"snapshot": int(snapshot), "overrides": list(overrides)})
            attrs["resumes"] = yaml.safe_dump(resumes, sort_keys=False)
            attrs["config"] = config
        attrs["stop_reason"] = "running"
        self.file.flush()

    def close(self):
        if self.file.id.valid:
            self.file.close()

    def give_up(self, reason):
        """Record ``reason`` as the stop reason without writing the buffered frames (the disk
        has no room for them): the file stays as its last flush left it."""
        self._frames.clear()
        self._contacts.clear()
        self._contact_bytes = 0
        try:
            self.file["parameters"].attrs["stop_reason"] = reason
            self.file.flush()
        except (OSError, RuntimeError):
            pass

    def abandon(self, error=None):
        """Close after a failed write, without writing more: HDF5 may refuse to close a file
        whose last write failed, and the error that caused it is the one to report. Such a
        file is kept referenced (:data:`UNCLOSABLE`), with the failed write's ``error`` and so
        the objects of its traceback, so that no garbage collection retries the writes and
        prints HDF5's errors while the process reports its own."""
        try:
            self.close()
        except (OSError, RuntimeError):
            UNCLOSABLE.append((self.file, error))


def _slot_state(group):
    """The engine state stored in a checkpoint slot, or None when a dataset of it does not
    read (fails its checksum)."""
    names = []
    try:
        group.visititems(lambda name, item: names.append(name)
                         if isinstance(item, h5py.Dataset) else None)
        return {name: group[name][()].reshape(()) if group[name].attrs.get("scalar", False)
                else group[name][()] for name in names}
    except DAMAGE:
        return None


def read_checkpoint(file):
    """The engine state of the latest complete checkpoint, its time, its snapshot count and
    its slot. When that slot is damaged, the other slot's older checkpoint, with a
    RuntimeWarning; :class:`sim.storage.errors.RunFileError` when no complete checkpoint is
    intact."""
    root = file["checkpoint"]
    latest = str(root.attrs["latest"])
    state = _slot_state(root[latest]) if latest in root else None  # missing: as damaged
    if state is not None:
        return (state, float(root[latest].attrs["time"]), int(root[latest].attrs["snapshots"]),
                latest)
    older = "b" if latest == "a" else "a"
    complete = older in root and {"time", "snapshots"} <= set(root[older].attrs)
    state = _slot_state(root[older]) if complete else None
    if state is None:
        which = "both checkpoints are" if complete else f"its only checkpoint (slot {latest}) is"
        raise RunFileError(f"{file.filename}: {which} damaged; the run cannot be resumed; "
                           f"start it again")
    time, snapshots = float(root[older].attrs["time"]), int(root[older].attrs["snapshots"])
    warnings.warn(f"{file.filename}: checkpoint slot {latest} is damaged; resuming from slot "
                  f"{older}, the checkpoint of snapshot {snapshots - 1} (t = {time:.6g})",
                  RuntimeWarning, stacklevel=2)
    return state, time, snapshots, older
