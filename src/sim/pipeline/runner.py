"""The runner: a validated config becomes a run file.

:func:`run` builds the scene and the engine (errors here are config errors, found before a
file exists), then advances the engine in compiled chunks from snapshot to snapshot, writing
each to the H5MD run file, until a stop condition holds. :func:`resume` continues a run file
from its last checkpoint to the same bits as a run never interrupted.

One run file, one process (:mod:`sim.pipeline.run_folder`): a run holds the lock of its run file
from the first look at its folder to its last write, writes a new file under a hidden name until
its first checkpoint is on disk, and finds in its folder either nothing, its own run (complete:
returned as it is; cut short: resumed) or another config's run (refused, naming the keys that
differ). Every run ends by a stop condition, its wall-clock budget, SIGINT or SIGTERM (a final
snapshot and checkpoint, resumable), or a breakdown of the physics (recorded as the stop
reason, :class:`sim.engine.errors.PhysicsBreakdown`).
"""

import errno
import logging
import math
import signal
import subprocess
import sys
import threading
import time as wallclock
from contextlib import contextmanager
from pathlib import Path

import h5py
import numpy as np
import yaml
from omegaconf import OmegaConf
from omegaconf.errors import ValidationError
from tqdm import tqdm

import sim
from sim.analysis.observers import from_config as observers_from_config
from sim.engine.core import Engine
from sim.engine.errors import PhysicsBreakdown
from sim.pipeline import resources
from sim.pipeline.config import ConfigError, SimConfig, flat, validate
from sim.pipeline.run_folder import FolderBusyError, RunLock, part_path, publish
from sim.pipeline.scenes import build_scene, preparation
from sim.pipeline.stop_conditions import already_met, at_rest, check_reachable
from sim.storage.errors import RunFileError
from sim.storage.h5md import DiskFullError, RunWriter, hdf5_reason, read_checkpoint
from sim.storage.inspect import open_run_file

log = logging.getLogger(__name__)

#: Stop reasons of a run that ended as configured (a resumed run with these has nothing to do).
FINISHED = ("collisions", "events", "time", "energy_fraction", "at_rest", "no_events")

#: Keys a resume may change: when the run stops, how often it writes, what it shows.
RESUMABLE = ("stop.collisions", "stop.events", "stop.time", "stop.energy_fraction",
             "stop.at_rest", "stop.wall_seconds", "output.every_collisions",
             "output.every_time", "output.progress")

#: Keys in which a run asked for again into its own folder may differ from the run there:
#: neither changes what is simulated or written.
COSMETIC = ("stop.wall_seconds", "output.progress")


def _cannot_write(path, error, then=""):
    """:class:`RunFileError` for a run file that could not be made, and why."""
    return RunFileError(f"cannot write the run file {path}: {hdf5_reason(error)}{then}")


class Interruption:
    """SIGINT (Ctrl-C) or SIGTERM (a batch scheduler's time limit) asks the run to stop: the
    engine finishes its compiled chunk, the runner writes a final snapshot and checkpoint,
    and the run ends with stop reason ``interrupted`` or ``terminated`` (``resume``
    continues it). A second signal acts at once: :attr:`at_second_signal` (the command line
    leaves the process there, as SIGKILL would; by default a KeyboardInterrupt is raised).
    Installed only in the main thread, and only for the run."""

    REASONS = {signal.SIGINT: "interrupted", signal.SIGTERM: "terminated"}
    #: ``f(signal)`` called at a second signal; None: raise KeyboardInterrupt
    at_second_signal = None

    def __init__(self):
        self.signal = None
        self._previous = {}

    @property
    def requested(self):
        return self.signal is not None

    @property
    def reason(self):
        return self.REASONS[self.signal]

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            for number in self.REASONS:
                self._previous[number] = signal.signal(number, self._request)
        return self

    def _request(self, signum, frame):
        if self.signal is None:
            self.signal = signal.Signals(signum)
        elif Interruption.at_second_signal is not None:
            Interruption.at_second_signal(signal.Signals(signum))
        else:
            raise KeyboardInterrupt

    def __exit__(self, *exc):
        for number, previous in self._previous.items():
            signal.signal(number, previous)
        return False


def _git_commit():
    try:
        out = subprocess.run(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent,
                             capture_output=True, text=True, timeout=5, check=True)
        return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def parameters(cfg, overrides=()):
    """What /parameters records: the resolved config, the overrides that made it, seed, how
    the initial state was made, versions, commit."""
    import numba

    return {"config": OmegaConf.to_yaml(cfg, resolve=True), "seed": int(cfg.seed),
            "overrides": yaml.safe_dump(list(overrides)), "preparation": preparation(cfg),
            "versions": f"sim {sim.__version__}, python {sys.version.split()[0]}, numpy "
                        f"{np.__version__}, numba {numba.__version__}, h5py "
                        f"{h5py.__version__}",
            "git_commit": _git_commit()}


#: rows of the compiled event log between drains (6 float64 each)
EVENT_LOG_ROWS = 1 << 16


def _walls(cfg):
    """The walls that are not plain hard walls, as :class:`sim.engine.core.Engine` takes them."""
    walls = {}
    for name, wall in OmegaConf.to_container(cfg.walls).items():
        if wall["temperature"] is not None or wall["speed"] or wall["amplitude"]:
            walls[name] = wall
    return walls


def build_engine(cfg):
    """Scene and engine for a validated config; bad values raise :class:`ConfigError`."""
    scene = build_scene(cfg)
    restitution = float(cfg.restitution.disk)
    observe = cfg.observe
    try:
        return Engine(scene.position, scene.velocity, scene.radius, scene.mass, scene.species,
                      boundary=scene.boundary, restitution=restitution,
                      wall_restitution=float(cfg.restitution.wall), tc=cfg.tc.time,
                      gravity=list(cfg.gravity), walls=_walls(cfg), seed=int(cfg.seed),
                      unwrap=observe.mean_squared_displacement,
                      pressure_tensor=observe.pressure_tensor,
                      event_log=EVENT_LOG_ROWS if observe.event_log else None)
    except ValueError as error:
        raise ConfigError("scene", cfg.scene, str(error)) from error


def _progress(cfg, engine):
    total = cfg.stop.collisions
    disable = not (cfg.output.progress and sys.stderr.isatty())
    return tqdm(total=total, initial=engine.collisions, unit="coll", unit_scale=True,
                disable=disable, dynamic_ncols=True)


def every_collisions(cfg, n):
    """Collisions between snapshots: ``output.every_collisions``, or ``n`` (one collision
    per disk) when neither it nor ``output.every_time`` is given; None for a cadence in
    time."""
    out = cfg.output
    if out.every_collisions is not None:
        return int(out.every_collisions)
    return None if out.every_time is not None else int(n)


def next_snapshot_time(last_time, every_time):
    """The first point k Δt of the snapshot grid after ``last_time`` (Δt = ``every_time``;
    None without a cadence in time), or :class:`ConfigError` once float64 cannot tell it from
    ``last_time`` (a long run, a short cadence). Grid points are multiples, never sums, so
    that round-off neither drifts them nor puts a snapshot a round-off before a stop.time
    on the grid; a ``last_time`` within a few ulps of a grid point is on it."""
    if every_time is None:
        return None
    k = last_time / every_time
    nearest = round(k)
    on_grid = abs(k - nearest) <= max(8.0 * np.finfo(float).eps * abs(k), 1e-9)
    next_time = ((nearest if on_grid else math.floor(k)) + 1) * every_time
    if next_time <= last_time or math.ulp(next_time) > 1e-6 * every_time:
        raise ConfigError("output.every_time", every_time,
                          f"a cadence that float64 resolves at t = {last_time:.6g}: above "
                          f"{1e6 * math.ulp(next_time):.3g}")
    return next_time


def advance(engine, cfg, writer, last_time, started, interruption):
    """Run from snapshot to snapshot (the last one at ``last_time``) until a stop condition
    holds, the wall-clock budget (counted from ``started``, a ``time.perf_counter()``) is
    spent, or SIGINT or SIGTERM arrives (``interruption``, an entered
    :class:`Interruption`); returns the stop reason."""
    stop, out = cfg.stop, cfg.output
    resting = None if stop.at_rest is None else at_rest(stop.at_rest)
    cadence = every_collisions(cfg, engine.n)

    def until(engine):
        return interruption.requested or (resting is not None and resting(engine))

    def budget():
        if stop.wall_seconds is None:
            return None
        return max(stop.wall_seconds - (wallclock.perf_counter() - started), 0.0)

    bar = _progress(cfg, engine)
    try:
        while True:
            next_collisions = engine.collisions + cadence if cadence else None
            next_time = next_snapshot_time(last_time, out.every_time)
            collisions = min(x for x in (stop.collisions, next_collisions, math.inf)
                             if x is not None)
            t_stop = min(x for x in (stop.time, next_time, math.inf) if x is not None)
            reason = engine.run(
                events=stop.events, collisions=None if collisions == math.inf else collisions,
                time=None if t_stop == math.inf else t_stop,
                energy_fraction=stop.energy_fraction, wall_seconds=budget(), until=until)
            snapshot_time = t_stop if reason == "time" else None
            last_time = engine.time if snapshot_time is None else snapshot_time
            met = {"collisions": stop.collisions is not None
                   and engine.collisions >= stop.collisions,
                   "time": stop.time is not None and last_time >= stop.time,
                   "events": True, "energy_fraction": True}.get(reason, False)
            if reason in ("time", "no_events") and math.isinf(engine.next_event_time()):
                # nothing will ever move again: the run is over
                reason, met = "no_events", True
                if stop.time is not None:
                    snapshot_time = last_time = max(stop.time, engine.time)
            elif met:
                pass  # a stop condition holds: it names the end, whatever else came
            elif resting is not None and resting(engine):
                reason, met = "at_rest", True  # asked between chunks and at every snapshot
            elif interruption.requested:
                reason, met = interruption.reason, True
            elif budget() == 0.0:
                reason, met = "wall_seconds", True  # also when snapshots outpace chunks
            last = met
            writer.snapshot(engine, snapshot_time, checkpoint=last)
            bar.update(engine.collisions - bar.n)
            bar.set_postfix(t=f"{last_time:.4g}", energy=f"{engine.kinetic_energy():.4g}")
            if last:
                return reason
    finally:
        bar.close()


def _writer(path, engine, cfg, overrides=(), mode="w-", observers=None):
    """The run file's writer, or :class:`RunFileError` when the file cannot be made.
    ``observers``: made for ``engine`` as it starts, by default now."""
    if observers is None:
        observers = observers_from_config(cfg, engine)
    try:
        return RunWriter(path, engine, parameters(cfg, overrides), mode=mode,
                         observers=observers)
    except OSError as error:
        raise _cannot_write(path, error) from error


def _record(writer, engine, work):
    """Run ``work(interruption)`` (which returns the stop reason) under an
    :class:`Interruption` and record how the run ended — its stop reason, its breakdown or
    its error — in the file, which is closed on every path. A failed write (a full disk)
    becomes :class:`RunFileError`; the file keeps what its last flush wrote. A breakdown of
    the physics (:class:`PhysicsBreakdown`) is recorded with a final snapshot of the state
    where it happened, then raised."""
    with Interruption() as interruption:
        _record_interruptible(writer, engine, lambda: work(interruption))


def _record_interruptible(writer, engine, work):
    try:
        writer.finish(work())
    except DiskFullError as error:
        full = "disk full" if error.errno == errno.ENOSPC else "file size limit"
        writer.give_up(f"error: {full}: {error.strerror}")
        remedy = ("free some room" if error.errno == errno.ENOSPC
                  else "raise the file size limit (ulimit -f)")
        raise RunFileError(f"stopped before writing to {writer.path}: {error.strerror}. The "
                           f"file holds every snapshot up to its last flush; {remedy} and "
                           f"resume from its last checkpoint") from error
    except OSError as error:
        writer.abandon(error)
        reason = hdf5_reason(error)
        raise RunFileError(f"writing the run file {writer.path} failed: {reason}") from error
    except PhysicsBreakdown as error:
        try:
            writer.snapshot(engine, checkpoint=True)
            writer.finish(error.stop_reason, message=str(error))
        except OSError:  # no room for the last snapshot: the cause, at least
            writer.give_up(error.stop_reason)
        raise
    except BaseException as error:
        writer.finish(f"error: {type(error).__name__}: {error}")
        raise
    finally:
        writer.abandon()


def _as_config(cfg):
    if OmegaConf.is_config(cfg):
        return cfg
    return OmegaConf.structured(cfg if isinstance(cfg, SimConfig) else SimConfig(**cfg))


def differences(stored, cfg, ignore=()):
    """{key: (value in ``stored``, value in ``cfg``)} for every key in which two configs
    differ, but those of ``ignore``."""
    a, b = flat(stored), flat(cfg)
    return {key: (a.get(key), b.get(key)) for key in sorted({*a, *b})
            if key not in ignore and a.get(key) != b.get(key)}


def describe_differences(differ):
    """``"key: a there, b here; …"`` of :func:`differences`."""
    return "; ".join(f"{key}: {a!r} there, {b!r} here" for key, (a, b) in differ.items())


def _existing_file(path, key):
    """``path`` as a run file's path: a folder or a missing file is a :class:`ConfigError`."""
    if not str(path).strip():
        raise ConfigError(key, str(path), "the path of a run file")
    path = Path(path)
    if path.is_dir():
        inside = path / "run.h5"
        hint = f" (the run file there is {inside})" if inside.is_file() else ""
        raise ConfigError(key, str(path), f"a run file, not a folder{hint}")
    if not path.exists():
        raise ConfigError(key, str(path), "an existing run file: there is no such file")
    return path


def stored_config(path, key="resume"):
    """The resolved config and stop reason recorded in the run file ``path``; a file that is
    missing, a folder, not a run file or damaged is a :class:`ConfigError` on ``key``."""
    path = _existing_file(path, key)
    try:
        with open_run_file(path) as f:
            attrs = f["parameters"].attrs
            text, reason = str(attrs["config"]), str(attrs["stop_reason"])
        stored = OmegaConf.merge(OmegaConf.structured(SimConfig), OmegaConf.create(text))
    except RunFileError as error:
        raise ConfigError(key, str(path), f"a readable run file: {error}") from error
    except Exception as error:  # a damaged /parameters: h5py, YAML or schema errors
        raise ConfigError(key, str(path), f"a run file with its config intact: "
                          f"{type(error).__name__}: {error}") from error
    return stored, reason


def _check_consistent(path, cfg, key="resume"):
    """Refuse (:class:`ConfigError` on ``key``) a run file whose disks, box or checkpoint do
    not have the sizes its stored config ``cfg`` implies (a config edited in the file)."""
    n, _ = resources.disk_count(cfg)
    periodic = cfg.box.boundary == "periodic"
    try:
        with open_run_file(path) as f:
            disks = f["particles/disks"]
            found = {"disks": disks["radius"].shape[0],
                     "box": [float(x) for x in disks["box/edges"][()]],
                     "boundary": [b.decode() for b in disks["box"].attrs["boundary"]]}
            root = f.get("checkpoint")
            if root is not None and "latest" in root.attrs:
                found["checkpointed disks"] = root[root.attrs["latest"]]["disks/table"].shape[0]
    except (KeyError, OSError, RuntimeError) as error:  # RunFileError is an OSError
        raise ConfigError(key, str(path), f"a readable run file: "
                          f"{' '.join(str(error).split())}") from error
    wanted = {"disks": n, "box": [float(x) for x in cfg.box.size],
              "boundary": ["periodic" if periodic else "none"] * 2,
              "checkpointed disks": n}
    wrong = [f"{name} {found[name]} in the file, {wanted[name]} by its config"
             for name in found if found[name] != wanted[name]]
    if wrong:
        raise ConfigError(key, str(path), f"a run file whose data match its stored config "
                          f"(edited since the run?): {'; '.join(wrong)}")


def resumable(path, overrides=()):
    """The config ``resume(path, overrides)`` would run, validated, after the checks of the
    file that need no engine: a run file, not in use, its data of the sizes its config
    implies, the overrides allowed (:class:`ConfigError`)."""
    path = _existing_file(path, "resume")
    with _locked(path, "resume"):
        stored, _ = stored_config(path)
        _check_consistent(path, stored)
    cfg = _apply(stored, list(overrides))
    validate(cfg)
    return cfg


@contextmanager
def _locked(path, key):
    """Hold the lock of the run file ``path`` (:class:`sim.pipeline.run_folder.RunLock`): another
    process's lock is a :class:`ConfigError` on ``key``, a folder where no lock file can
    be made a :class:`RunFileError`."""
    lock = RunLock(path)
    try:  # released whatever ends the run, a signal inside the taking of the lock included
        try:
            lock.__enter__()
        except FolderBusyError as error:
            what = "run file" if key == "resume" else "folder"
            raise ConfigError(key, str(path if key == "resume" else path.parent),
                              f"a {what} that no other run is using: {error.holder} is "
                              f"writing {path}; wait for it to end, or choose another") from None
        except OSError as error:
            raise _cannot_write(path, error) from error
        yield
    finally:
        lock.__exit__()


def run(cfg, output_dir=".", overrides=(), folder_key="output_dir"):
    """Run the scene of ``cfg`` into ``output_dir/cfg.output.file``; returns the path.

    The folder decides, under the run file's lock: no run file there, the run is made;
    the same config's run (all keys but :data:`COSMETIC`) complete, it is returned as it is;
    cut short, it is resumed; another config's run or a file that is not a run file,
    :class:`ConfigError` on ``folder_key`` (named in the message). ``overrides``: the
    command-line overrides that made ``cfg``, recorded in the file.
    """
    started = wallclock.perf_counter()
    cfg = _as_config(cfg)
    validate(cfg)
    path = Path(output_dir) / cfg.output.file
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise _cannot_write(path, error) from error
    with _locked(path, folder_key):
        if path.exists():
            return _existing_run(path, cfg, folder_key, started)
        resources.check([cfg], path.parent)
        engine = build_engine(cfg)
        check_reachable(cfg, engine)
        return _new_run(path, engine, cfg, overrides, started)


def _new_run(path, engine, cfg, overrides, started):
    """Write the run file under its hidden name until the first snapshot and checkpoint are
    on disk, then put it in place (:func:`sim.pipeline.run_folder.publish`) and run on."""
    part = part_path(path)
    published = []
    try:
        writer = _writer(part, engine, cfg, overrides)
        writer.path = path  # its name in messages; the file is ``part`` until published

        def from_the_start(interruption):
            writer.snapshot(engine, 0.0, checkpoint=True)
            publish(part, path)
            published.append(path)
            return advance(engine, cfg, writer, 0.0, started, interruption)

        _record(writer, engine, from_the_start)
    except RunFileError as error:
        if published:
            raise
        raise _cannot_write(path, error.__cause__ or error, "; nothing was written") \
            from error
    finally:
        part.unlink(missing_ok=True)
    return path


def _existing_run(path, cfg, key, started):
    """The folder of ``cfg``'s run file holds a run already: return it complete, resume it,
    or refuse it (:class:`ConfigError` on ``key``)."""
    try:
        stored, reason = stored_config(path, key)
    except ConfigError as error:
        raise ConfigError(key, str(path.parent), f"a folder without a foreign file at "
                          f"{path.name}: {error.allowed}") from error
    differ = differences(stored, cfg, ignore=COSMETIC)
    if differ:
        raise ConfigError(key, str(path.parent),
                          f"a folder without another config's run; its {path.name} differs "
                          f"in {describe_differences(differ)}; choose another folder")
    _check_consistent(path, stored, key)
    if reason in FINISHED:
        log.info("%s is complete (stopped by %s); not run again", path, reason)
        return path
    return _resume_locked(path, stored, reason, _cosmetic(cfg), started)


def _cosmetic(cfg):
    """The :data:`COSMETIC` keys of ``cfg`` as overrides."""
    def text(value):
        return "null" if value is None else str(value).lower() if isinstance(value, bool) \
            else str(value)
    return [f"{key}={text(OmegaConf.select(cfg, key))}" for key in COSMETIC]


def resume(path, overrides=()):
    """Continue the run file at ``path`` from its latest checkpoint, appending to it.

    ``overrides`` (``"key=value"`` strings) may change the keys of :data:`RESUMABLE`: a
    complete run continues to new stop conditions; the file's config records them. A path
    that is no run file, a run another process is writing, a checkpoint that does not match
    its config or stop conditions met already are a :class:`ConfigError` on ``resume`` (or
    the key), and leave the file as it was."""
    started = wallclock.perf_counter()
    path = _existing_file(path, "resume")
    with _locked(path, "resume"):
        stored, reason = stored_config(path)
        _check_consistent(path, stored)
        return _resume_locked(path, stored, reason, list(overrides), started)


def _apply(stored, overrides):
    """``stored`` with ``overrides`` applied; keys outside :data:`RESUMABLE` are refused."""
    keys = [item.partition("=")[0].lstrip("+~") for item in overrides]
    fixed = [k for k, key in enumerate(keys) if key not in RESUMABLE]
    if fixed:
        raise ConfigError(keys[fixed[0]], overrides[fixed[0]].partition("=")[2],
                          f"unchanged on resume (it would change what the run file "
                          f"holds); a resume may change {', '.join(RESUMABLE)}")
    try:
        cfg = OmegaConf.merge(stored, OmegaConf.from_dotlist(list(overrides)))
    except ValidationError as error:
        raise ConfigError(error.full_key, error.value, str(error.msg).splitlines()[0]) \
            from error
    if any(k == "output.every_time" for k in keys) and "output.every_collisions" not in keys:
        cfg.output.every_collisions = None  # a cadence in time replaces one in collisions
    if any(k == "output.every_collisions" for k in keys) and "output.every_time" not in keys:
        cfg.output.every_time = None
    return cfg


def _resume_locked(path, stored, reason, overrides, started):
    cfg = _apply(stored, overrides)
    validate(cfg)
    differ = differences(stored, cfg)
    recorded = [item for item in overrides if item.partition("=")[0].lstrip("+~") in differ]
    changed = [item for item in recorded if item.partition("=")[0].lstrip("+~") not in COSMETIC]
    with h5py.File(path, "r") as f:
        checkpointed = "checkpoint" in f and "latest" in f["checkpoint"].attrs
        made_by = yaml.safe_load(str(f["parameters"].attrs.get("overrides", "[]"))) or []
    if not checkpointed:  # a file of a run that never reached its first checkpoint
        engine = build_engine(cfg)
        check_reachable(cfg, engine)
        path.unlink()
        return _new_run(path, engine, cfg, made_by, started)
    if reason in FINISHED and not changed:
        log.info("%s is complete (stopped by %s); nothing to resume", path, reason)
        return path
    engine = build_engine(cfg)
    observers = observers_from_config(cfg, engine)  # they remember the start of the run
    try:  # read-only: a refusal leaves the file as it was
        with h5py.File(path, "r") as f:
            state, last_time, snapshots, slot = read_checkpoint(f)
        engine.load_state_dict(state)
    except RunFileError as error:  # both checkpoints damaged
        raise ConfigError("resume", str(path), "a run file with an intact checkpoint; "
                          + str(error).partition(": ")[2]) from error
    except (ValueError, KeyError, OSError) as error:
        raise ConfigError("resume", str(path), f"a checkpoint that matches its config: "
                          f"{' '.join(str(error).split())}") from error
    met = already_met(engine, cfg)
    if met is not None:
        keys = [item.partition("=")[0].lstrip("+~") for item in changed]
        if met[0] in keys:
            raise ConfigError(*met)
        if keys:
            raise ConfigError(keys[0], OmegaConf.select(cfg, keys[0]),
                              f"a change to a run that is complete ({met[0]}={met[1]} holds "
                              f"already); raise a stop condition to continue it")
        log.info("%s is complete; nothing to resume", path)
        return path
    check_reachable(cfg, engine)
    next_snapshot_time(last_time, cfg.output.every_time)
    writer = _writer(path, engine, cfg, mode="r+", observers=observers)

    def from_the_checkpoint(interruption):
        writer.truncate(snapshots, engine.events, slot)
        writer.record_resume(OmegaConf.to_yaml(cfg, resolve=True), snapshots, recorded)
        return advance(engine, cfg, writer, last_time, started, interruption)

    _record(writer, engine, from_the_checkpoint)
    return path
