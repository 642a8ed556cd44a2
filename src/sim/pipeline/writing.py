"""Writing a run file: what /parameters records, the writer, a new file put in place once its
first snapshot and checkpoint are on disk, and how the run ended recorded on every path."""

import errno
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import yaml
from omegaconf import OmegaConf

import sim
from sim.analysis.observers import from_config as observers_from_config
from sim.engine.errors import PhysicsBreakdown
from sim.pipeline.interruption import Interruption
from sim.pipeline.run_folder import cannot_write, held, part_path, publish
from sim.pipeline.scenes import preparation
from sim.pipeline.snapshots import advance
from sim.storage.errors import RunFileError
from sim.storage.h5md import DiskFullError, RunWriter, hdf5_reason


def _git_commit():
    """The commit of the checkout sim runs from, or ``unknown``: a repository that does not
    track this file (an installed copy in a venv inside someone's project) is not sim's."""
    here = Path(__file__)
    try:
        subprocess.run(["git", "ls-files", "--error-unmatch", here.name], cwd=here.parent,
                       capture_output=True, timeout=5, check=True)
        out = subprocess.run(["git", "rev-parse", "HEAD"], cwd=here.parent,
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


def open_writer(path, engine, cfg, overrides=(), mode="w-", observers=None):
    """The run file's writer, or :class:`RunFileError` when the file cannot be made.
    ``observers``: made for ``engine`` as it starts, by default now."""
    if observers is None:
        observers = observers_from_config(cfg, engine)
    try:
        return RunWriter(path, engine, parameters(cfg, overrides), mode=mode,
                         observers=observers)
    except OSError as error:
        raise cannot_write(path, error) from error


def record(writer, engine, work):
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


def new_run(path, engine, cfg, overrides, started):
    """Write the run file under its hidden name until the first snapshot and checkpoint are
    on disk, then put it in place (:func:`sim.pipeline.run_folder.publish`) and run on."""
    part = part_path(path)
    published = []
    try:
        writer = open_writer(part, engine, cfg, overrides)
        writer.path = path  # its name in messages; the file is ``part`` until published

        def from_the_start(interruption):
            writer.snapshot(engine, 0.0, checkpoint=True)
            publish(part, path)
            published.append(path)
            return advance(engine, cfg, writer, 0.0, started, interruption)

        with held(part):  # the file, under every name it will have
            record(writer, engine, from_the_start)
    except RunFileError as error:
        if published:
            raise
        raise cannot_write(path, error.__cause__ or error, "; nothing was written") \
            from error
    finally:
        part.unlink(missing_ok=True)
    return path
