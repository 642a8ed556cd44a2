"""Resuming a run file from its last checkpoint, and what a stored run must share with a config.

:func:`resume` continues a run file to the same bits as a run never interrupted; it may change
only the keys of :data:`RESUMABLE`. :func:`stored_config` reads the config a run file records,
:func:`differences` names the keys in which two configs differ, and :func:`check_consistent`
refuses a file whose data do not have the sizes its config implies.
"""

import logging
import time as wallclock
import warnings
from pathlib import Path

import h5py
import numpy as np
from omegaconf import OmegaConf
from omegaconf.errors import ValidationError

from sim.analysis.observers import from_config as observers_from_config
from sim.pipeline import resources
from sim.pipeline.config import ConfigError, SimConfig, flat, validate
from sim.pipeline.engine_from_config import build_engine
from sim.pipeline.run_folder import locked
from sim.pipeline.snapshots import advance, next_snapshot_time
from sim.pipeline.stop_conditions import already_met, check_reachable
from sim.pipeline.writing import open_writer, record
from sim.storage.errors import RunFileError
from sim.storage.h5md import read_checkpoint
from sim.storage.inspect import open_run_file

log = logging.getLogger(__name__)

#: Stop reasons of a run that ended as configured (a resumed run with these has nothing to do).
FINISHED = ("collisions", "contacts", "time", "energy_fraction", "packing_fraction", "jamming",
            "at_rest", "no_events")

#: The stop key that sim 0.1.0 renamed (stop.contacts now) and still stored, always null:
#: dropped from the configs of its run files, refused when set (a run file of an older sim)
RENAMED_STOP = "events"

#: Keys a resume may change: when the run stops, how often it writes, what it shows.
RESUMABLE = ("stop.collisions", "stop.contacts", "stop.time",
             "stop.energy_fraction", "stop.packing_fraction", "stop.jamming", "stop.at_rest",
             "stop.wall_seconds",
             "output.every_collisions", "output.every_time", "output.progress")

#: Keys in which a run asked for again into its own folder may differ from the run there:
#: neither changes what is simulated or written.
COSMETIC = ("stop.wall_seconds", "output.progress")


def differences(stored, cfg, ignore=()):
    """{key: (value in ``stored``, value in ``cfg``)} for every key in which two configs
    differ, but those of ``ignore``."""
    a, b = flat(stored), flat(cfg)
    return {key: (a.get(key), b.get(key)) for key in sorted({*a, *b})
            if key not in ignore and a.get(key) != b.get(key)}


def describe_differences(differ):
    """``"key: a there, b here; …"`` of :func:`differences`."""
    return "; ".join(f"{key}: {a!r} there, {b!r} here" for key, (a, b) in differ.items())


def existing_file(path, key):
    """``path`` as a run file's path: a folder, a missing or empty file or one that is not a
    regular file (a named pipe, a device) is a :class:`ConfigError`."""
    if not str(path).strip():
        raise ConfigError(key, str(path), "the path of a run file")
    path = Path(path)
    if path.is_dir():
        inside = path / "run.h5"
        hint = f" (the run file there is {inside})" if inside.is_file() else ""
        raise ConfigError(key, str(path), f"a run file, not a folder{hint}")
    if not path.exists():
        raise ConfigError(key, str(path), "an existing run file: there is no such file")
    if not path.is_file():  # opening a named pipe would wait for a writer
        raise ConfigError(key, str(path), "a run file: this is not a regular file (a device, "
                                          "pipe or socket)")
    if path.stat().st_size == 0:
        raise ConfigError(key, str(path), "a run file: this file is empty")
    return path


def _literal(text):
    """The YAML ``text`` of a stored config as data: every ``${`` escaped, so that OmegaConf
    reads what the file holds and never resolves an interpolation (a config is stored
    resolved; one found in it was put there since)."""
    def escaped(node):
        if isinstance(node, dict):
            return {key: escaped(value) for key, value in node.items()}
        if isinstance(node, list):
            return [escaped(value) for value in node]
        return node.replace("${", "\\${") if isinstance(node, str) else node
    return escaped(OmegaConf.to_container(OmegaConf.create(text), resolve=False))


def stored_config(path, key="resume"):
    """The config and stop reason recorded in the run file ``path``, the config read as data
    (:func:`_literal`) and validated; a file that is missing, a folder, not a run file or
    damaged, or a stored value not allowed, is a :class:`ConfigError` on ``key``."""
    path = existing_file(path, key)
    try:
        with open_run_file(path) as f:
            attrs = f["parameters"].attrs
            text, reason = str(attrs["config"]), str(attrs["stop_reason"])
        given = _literal(text)
        renamed = (given.get("stop") or {}).pop(RENAMED_STOP, None)
        if renamed is None:
            stored = OmegaConf.merge(OmegaConf.structured(SimConfig), OmegaConf.create(given))
    except RunFileError as error:
        raise ConfigError(key, str(path), f"a readable run file: {error}") from error
    except Exception as error:  # a damaged /parameters: h5py, YAML or schema errors
        # the first line: OmegaConf's errors go on with the context of the failing key
        reason = (str(error).strip().splitlines() or [""])[0]
        where = f"its stored {error.full_key}: " if getattr(error, "full_key", None) else ""
        raise ConfigError(key, str(path), f"a run file with its config intact: {where}"
                          f"{type(error).__name__}: {reason}") from error
    if renamed is not None:
        raise ConfigError(key, str(path), f"a run file of sim 0.1.0 or later: this one stops "
                          f"by stop.{RENAMED_STOP}={renamed}, the name before 0.1.0 (resume it "
                          f"with sim 0.1.0)")
    try:
        validate(stored)
    except (ConfigError, ValidationError) as error:  # a value edited in, read as it stands
        wrong = error if isinstance(error, ConfigError) else ConfigError(
            error.full_key, error.value, str(error.msg).splitlines()[0])
        raise ConfigError(key, str(path), f"a run file with its config intact: its stored "
                          f"{wrong.key}={wrong.value!r} is not allowed ({wrong.allowed})") \
            from error
    return stored, reason


def check_consistent(path, cfg, key="resume"):
    """Refuse (:class:`ConfigError` on ``key``) a run file that has no checkpoint to continue
    from, or whose disks, box or checkpoint do not have the sizes its stored config ``cfg``
    implies (a config edited in the file)."""
    n, _ = resources.disk_count(cfg)
    periodic = cfg.box.boundary == "periodic"
    shown = str(path) if key == "resume" else str(Path(path).parent)  # a folder key: its folder
    try:
        with open_run_file(path) as f:
            disks = f["particles/disks"]
            found = {"disks": disks["radius"].shape[0],
                     "box": [float(x) for x in disks["box/edges"][()]],
                     "boundary": [b.decode() for b in disks["box"].attrs["boundary"]]}
            root = f.get("checkpoint")
            slots = [] if root is None or "latest" not in root.attrs else \
                [slot for slot in (str(root.attrs["latest"]), "a", "b") if slot in root]
            if not slots:
                frames = disks["position/step"].shape[0]
                raise ConfigError(key, shown, f"a run file with a checkpoint to continue "
                                  f"from: it has none, and starting it again would overwrite "
                                  f"its {frames} snapshots; start a new run in another folder")
            found["checkpointed disks"] = root[slots[0]]["disks/table"].shape[0]
    except (KeyError, OSError, RuntimeError) as error:  # RunFileError is an OSError
        raise ConfigError(key, shown, f"a readable run file: "
                          f"{' '.join(str(error).split())}") from error
    wanted = {"disks": n, "box": [float(x) for x in cfg.box.size],
              "boundary": ["periodic" if periodic else "none"] * 2,
              "checkpointed disks": n}
    wrong = [f"{name} {found[name]} in the file, {wanted[name]} by its config"
             for name in found if found[name] != wanted[name]]
    if wrong:
        raise ConfigError(key, shown, f"a run file whose data match its stored config "
                          f"(edited since the run?): {'; '.join(wrong)}")


def check_first_snapshot(path, engine):
    """Refuse (:class:`ConfigError` on ``resume``) a run file whose first snapshot, masses or
    radii are not those its stored config makes (``engine``, built from it and not yet run):
    a seed, mass or placement edited in the file would continue the run with other bits."""
    try:
        with open_run_file(path) as f:
            disks = f["particles/disks"]
            stored = {"positions": disks["position/value"][0],
                      "velocities": disks["velocity/value"][0],
                      "masses": disks["mass"][()], "radii": disks["radius"][()]}
    except (KeyError, OSError, IndexError) as error:  # RunFileError is an OSError
        raise ConfigError("resume", str(path), f"a readable run file: "
                          f"{' '.join(str(error).split())}") from error
    made = {"positions": engine.positions(0.0), "velocities": engine.velocities(0.0),
            "masses": engine.mass, "radii": engine.radius}
    differ = [name for name in stored if not np.array_equal(stored[name], made[name])]
    if differ:
        raise ConfigError("resume", str(path), f"a run file whose stored config makes its "
                          f"first snapshot; the {' and '.join(differ)} it makes differ (a config "
                          f"edited in the file, or a file of another version of sim)")


def resumable(path, overrides=()):
    """The config ``resume(path, overrides)`` would run, validated, after the checks of the
    file that need no engine: a run file, not in use, its data of the sizes its config
    implies, the overrides allowed (:class:`ConfigError`)."""
    path = existing_file(path, "resume")
    with locked(path, "resume"):
        stored, _ = stored_config(path)
        check_consistent(path, stored)
    cfg = apply_overrides(stored, list(overrides))
    validate(cfg)
    return cfg


def resume(path, overrides=()):
    """Continue the run file at ``path`` from its latest checkpoint, appending to it.

    ``overrides`` (``"key=value"`` strings) may change the keys of :data:`RESUMABLE`: a
    complete run continues to new stop conditions; the file's config records them. A path
    that is no run file, a run another process is writing, a checkpoint that does not match
    its config or stop conditions met already are a :class:`ConfigError` on ``resume`` (or
    the key), and leave the file as it was."""
    started = wallclock.perf_counter()
    path = existing_file(path, "resume")
    with locked(path, "resume"):
        stored, reason = stored_config(path)
        check_consistent(path, stored)
        return resume_locked(path, stored, reason, list(overrides), started)


def apply_overrides(stored, overrides):
    """``stored`` with ``overrides`` applied; keys outside :data:`RESUMABLE` are refused
    unless they repeat the stored value."""
    keys = [item.partition("=")[0].lstrip("+~") for item in overrides]
    for key, item in zip(keys, overrides, strict=True):
        if key not in RESUMABLE and not _repeats(stored, item):
            raise ConfigError(key, item.partition("=")[2],
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


def _repeats(stored, item):
    """Whether the override ``item`` (``key=value``) gives its key the value ``stored``
    holds."""
    key = item.partition("=")[0].lstrip("+~")
    try:
        given = OmegaConf.select(OmegaConf.from_dotlist([item]), key)
        return OmegaConf.select(stored, key, default=None) == given
    except Exception:  # not a key of the config, or a value OmegaConf cannot read
        return False


def resume_locked(path, stored, reason, overrides, started):
    """:func:`resume` of ``path`` (config ``stored``, stop reason ``reason``) with its lock
    held; ``started``: a ``time.perf_counter()`` for the wall-clock budget."""
    cfg = apply_overrides(stored, overrides)
    validate(cfg)
    differ = differences(stored, cfg)
    recorded = [item for item in overrides if item.partition("=")[0].lstrip("+~") in differ]
    changed = [item for item in recorded if item.partition("=")[0].lstrip("+~") not in COSMETIC]
    if reason in FINISHED and not changed:
        log.info("%s is complete (stopped by %s); nothing to resume", path, reason)
        return path
    engine = build_engine(cfg)
    check_first_snapshot(path, engine)
    observers = observers_from_config(cfg, engine)  # they remember the start of the run
    try:  # read-only: a refusal leaves the file as it was
        with h5py.File(path, "r") as f:
            state, last_time, snapshots, slot = read_checkpoint(f)
            written = f["particles/disks/position/time"][snapshots:]
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
    if len(written):  # flushed by a run killed between two checkpoints
        warnings.warn(f"{path}: resuming from its checkpoint at t = {last_time:.6g} (snapshot "
                      f"{snapshots - 1}); the {len(written)} snapshots written after it, to "
                      f"t = {written[-1]:.6g}, are dropped; the run goes on from the checkpoint "
                      f"to its stop conditions",
                      RuntimeWarning, stacklevel=2)
    writer = open_writer(path, engine, cfg, mode="r+", observers=observers)

    def from_the_checkpoint(interruption):
        writer.truncate(snapshots, engine.contacts, slot)
        writer.record_resume(OmegaConf.to_yaml(cfg, resolve=True), snapshots, recorded)
        return advance(engine, cfg, writer, last_time, started, interruption)

    record(writer, engine, from_the_checkpoint)
    return path
