"""The runner: a validated config becomes a run file.

:func:`run` builds the scene and the engine (:mod:`sim.pipeline.engine_from_config`; errors
here are config errors, found before a file exists), then advances the engine in compiled
chunks from snapshot to snapshot (:mod:`sim.pipeline.snapshots`), writing each to the H5MD run
file (:mod:`sim.pipeline.writing`), until a stop condition holds. :func:`resume`
(:mod:`sim.pipeline.resume`) continues a run file from its last checkpoint to the same bits as
a run never interrupted.

One run file, one process (:mod:`sim.pipeline.run_folder`): a run holds the lock of its run file
from the first look at its folder to its last write, writes a new file under a hidden name until
its first checkpoint is on disk, and finds in its folder either nothing, its own run (complete:
returned as it is; cut short: resumed) or another config's run (refused, naming the keys that
differ). Every run ends by a stop condition, its wall-clock budget, SIGINT or SIGTERM (a final
snapshot and checkpoint, resumable, :class:`sim.pipeline.interruption.Interruption`), or a
breakdown of the physics (recorded as the stop reason,
:class:`sim.engine.errors.PhysicsBreakdown`).
"""

import logging
import time as wallclock
from pathlib import Path

from omegaconf import OmegaConf

from sim.pipeline import resources
from sim.pipeline.config import ConfigError, SimConfig, validate
from sim.pipeline.engine_from_config import build_engine
from sim.pipeline.interruption import Interruption
from sim.pipeline.resume import (
    COSMETIC,
    FINISHED,
    RESUMABLE,
    check_consistent,
    describe_differences,
    differences,
    resume,
    resume_locked,
    stored_config,
)
from sim.pipeline.run_folder import cannot_write, locked
from sim.pipeline.snapshots import advance, next_snapshot_time
from sim.pipeline.stop_conditions import check_reachable
from sim.pipeline.writing import new_run, parameters
from sim.storage.errors import RunFileError

__all__ = ["COSMETIC", "RESUMABLE", "Interruption", "RunFileError", "advance", "build_engine",
           "differences", "next_snapshot_time", "parameters", "resume", "run"]

log = logging.getLogger(__name__)


def _as_config(cfg):
    if not OmegaConf.is_config(cfg):
        cfg = OmegaConf.structured(cfg if isinstance(cfg, SimConfig) else SimConfig(**cfg))
    return cfg


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
        raise cannot_write(path, error) from error
    with locked(path, folder_key):
        if path.exists():
            return _existing_run(path, cfg, folder_key, started)
        resources.check([cfg], path.parent)
        engine = build_engine(cfg)
        check_reachable(cfg, engine)
        return new_run(path, engine, cfg, overrides, started)


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
    check_consistent(path, stored, key)
    if reason in FINISHED:
        log.info("%s is complete (stopped by %s); not run again", path, reason)
        return path
    return resume_locked(path, stored, reason, _cosmetic(cfg), started)


def _cosmetic(cfg):
    """The :data:`COSMETIC` keys of ``cfg`` as overrides."""
    def text(value):
        return "null" if value is None else str(value).lower() if isinstance(value, bool) \
            else str(value)
    return [f"{key}={text(OmegaConf.select(cfg, key))}" for key in COSMETIC]
