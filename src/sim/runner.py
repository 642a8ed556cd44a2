"""The runner: a validated config becomes a run file.

:func:`run` builds the scene and the engine (errors here are config errors, found before a
file exists), then advances the engine in compiled chunks from snapshot to snapshot, writing
each to the H5MD run file, until a stop condition holds. :func:`resume` continues a run file
from its last checkpoint to the same bits as a run never interrupted.
"""

import math
import signal
import subprocess
import sys
import threading
import time as wallclock
from pathlib import Path

import h5py
import numpy as np
from omegaconf import OmegaConf
from tqdm import tqdm

import sim
from sim.config import ConfigError, SimConfig, validate
from sim.engine import Engine
from sim.h5md import DiskFullError, RunWriter, read_checkpoint
from sim.observers import from_config as observers_from_config
from sim.scenes import build_scene

#: Stop reasons of a run that ended as configured (a resumed run with these has nothing to do).
FINISHED = ("collisions", "events", "time", "energy_fraction", "at_rest", "no_events")


class RunFileError(OSError):
    """The run file cannot be created or written (read-only folder, full disk)."""


class Interruption:
    """SIGINT (Ctrl-C) asks the run to stop: the engine finishes its compiled chunk, the
    runner writes a final snapshot and checkpoint, and the run ends with stop reason
    ``interrupted`` (``resume`` continues it). A second SIGINT interrupts at once. Installed
    only in the main thread, and only for the run."""

    def __init__(self):
        self.requested = False
        self._previous = None

    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._request)
        return self

    def _request(self, signum, frame):
        self.requested = True
        signal.signal(signal.SIGINT, self._previous)

    def __exit__(self, *exc):
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
        return False


def at_rest(fraction):
    """Stop predicate of ``stop.at_rest``: the kinetic energy of every species has fallen below
    ``fraction`` of the initial total. Hard-disk dynamics has no energy scale (a run at
    speeds ×λ is the same run in time /λ, unless the TC model's fixed t_c intervenes), so it
    ends runs that differ only in their speeds at the same stage."""
    def predicate(engine):
        return bool(np.all(engine.kinetic_energy_by_species() < fraction * engine.initial_energy))
    return predicate


def _git_commit():
    try:
        out = subprocess.run(["git", "rev-parse", "HEAD"], cwd=Path(__file__).parent,
                             capture_output=True, text=True, timeout=5, check=True)
        return out.stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def parameters(cfg):
    """What /parameters records: the resolved config, seed, versions, commit."""
    import h5py as _h5py
    import numba

    return {"config": OmegaConf.to_yaml(cfg, resolve=True), "seed": int(cfg.seed),
            "versions": f"sim {sim.__version__}, python {sys.version.split()[0]}, numpy "
                        f"{np.__version__}, numba {numba.__version__}, h5py "
                        f"{_h5py.__version__}",
            "git_commit": _git_commit()}


#: rows of the compiled event log between drains (6 float64 each)
EVENT_LOG_ROWS = 1 << 16


def _walls(cfg):
    """The walls that are not plain hard walls, as :class:`sim.engine.Engine` takes them."""
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


def advance(engine, cfg, writer, last_time):
    """Run from snapshot to snapshot (the last one at ``last_time``) until a stop condition
    holds or SIGINT arrives (:class:`Interruption`); returns the stop reason."""
    with Interruption() as interruption:
        return _advance(engine, cfg, writer, last_time, interruption)


def _advance(engine, cfg, writer, last_time, interruption):
    stop, out = cfg.stop, cfg.output
    resting = None if stop.at_rest is None else at_rest(stop.at_rest)

    def until(engine):
        return interruption.requested or (resting is not None and resting(engine))

    started = wallclock.perf_counter()
    bar = _progress(cfg, engine)
    try:
        while True:
            next_collisions = (engine.collisions + out.every_collisions
                               if out.every_collisions else None)
            next_time = last_time + out.every_time if out.every_time else None
            collisions = min(x for x in (stop.collisions, next_collisions, math.inf)
                             if x is not None)
            t_stop = min(x for x in (stop.time, next_time, math.inf) if x is not None)
            budget = (None if stop.wall_seconds is None
                      else max(stop.wall_seconds - (wallclock.perf_counter() - started), 0.0))
            reason = engine.run(
                events=stop.events, collisions=None if collisions == math.inf else collisions,
                time=None if t_stop == math.inf else t_stop,
                energy_fraction=stop.energy_fraction, wall_seconds=budget, until=until)
            snapshot_time = t_stop if reason == "time" else None
            if reason == "no_events" and t_stop < math.inf:
                snapshot_time, reason = t_stop, "time"
            if interruption.requested:
                reason = "interrupted"
            elif reason == "predicate" or (resting is not None and resting(engine)):
                reason = "at_rest"  # checked between chunks and at every snapshot
            last_time = engine.time if snapshot_time is None else snapshot_time
            last = {"collisions": stop.collisions is not None
                    and engine.collisions >= stop.collisions,
                    "time": stop.time is not None and last_time >= stop.time,
                    }.get(reason, True)
            writer.snapshot(engine, snapshot_time, checkpoint=last)
            bar.update(engine.collisions - bar.n)
            bar.set_postfix(t=f"{last_time:.4g}", energy=f"{engine.kinetic_energy():.4g}")
            if last:
                return reason
    finally:
        bar.close()


def _writer(path, engine, cfg, mode="w"):
    """The run file's writer, or :class:`RunFileError` when the file cannot be made."""
    try:
        return RunWriter(path, engine, parameters(cfg), mode=mode,
                         observers=observers_from_config(cfg, engine))
    except OSError as error:
        raise RunFileError(f"cannot write the run file {path}: "
                           f"{error.strerror or error}") from error


def _record(writer, work):
    """Run ``work()`` (which returns the stop reason) and record how the run ended — its
    stop reason or its error — in the file, which is closed on every path. A failed write
    (a full disk) becomes :class:`RunFileError`; the file keeps what its last flush wrote."""
    try:
        writer.finish(work())
    except DiskFullError as error:
        writer.give_up(f"error: disk full: {error.strerror}")
        raise RunFileError(f"stopped before writing to {writer.path}: {error.strerror}. The "
                           f"file holds every snapshot up to its last flush; free some room and "
                           f"resume from its last checkpoint") from error
    except OSError as error:
        writer.abandon()
        reason = " ".join(str(error).split())  # HDF5's messages span lines
        raise RunFileError(f"writing the run file {writer.path} failed: {reason}") from error
    except BaseException as error:
        writer.finish(f"error: {type(error).__name__}: {error}")
        raise
    finally:
        writer.abandon()


def run(cfg, output_dir="."):
    """Run the scene of ``cfg`` into ``output_dir/cfg.output.file``; returns the path."""
    if not OmegaConf.is_config(cfg):
        cfg = OmegaConf.structured(cfg if isinstance(cfg, SimConfig) else SimConfig(**cfg))
    validate(cfg)
    engine = build_engine(cfg)
    path = Path(output_dir) / cfg.output.file
    writer = _writer(path, engine, cfg)

    def from_the_start():
        writer.snapshot(engine, 0.0)
        return advance(engine, cfg, writer, 0.0)

    _record(writer, from_the_start)
    return path


def resume(path):
    """Continue the run file at ``path`` from its latest checkpoint, appending to it."""
    path = Path(path)
    with h5py.File(path, "r") as f:
        config_yaml = f["parameters"].attrs["config"]
        reason = str(f["parameters"].attrs["stop_reason"])
        checkpointed = "checkpoint" in f and "latest" in f["checkpoint"].attrs
    if reason in FINISHED:
        return path  # nothing left to do: the run ended by one of its stop conditions
    cfg = OmegaConf.merge(OmegaConf.structured(SimConfig), OmegaConf.create(config_yaml))
    if not checkpointed:  # stopped before its first checkpoint was complete: start again
        cfg.output.file = path.name
        return run(cfg, path.parent)
    validate(cfg)
    engine = build_engine(cfg)
    writer = _writer(path, engine, cfg, mode="r+")

    def from_the_checkpoint():
        state, last_time, snapshots = read_checkpoint(writer.file)
        engine.load_state_dict(state)
        writer.truncate(snapshots, engine.events)
        return advance(engine, cfg, writer, last_time)

    _record(writer, from_the_checkpoint)
    return path
