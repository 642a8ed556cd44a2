"""The command line (``python -m sim``, :mod:`sim.__main__`): run a scene, or a sweep with
``-m``, from the YAML in ``conf/``.

Before any work, every override of the command line (each combination of a sweep) is
composed and validated, its memory and file size estimated against what the machine has,
and its run folder made: a folder of its own for every run (``TIME``, ``TIME-2``, … when
runs start in the same second), checked writable. Bad input prints one line and exits with
status 2, and nothing is written. The exit statuses:

  0    the run ended by its stop conditions or wall budget (or was complete already)
  1    the run file could not be written (read-only folder, full disk), or jobs of a sweep
       failed (listed in its sweep_summary.yaml)
  2    bad input: a config value, a resume path, a folder another run is using or that holds
       another config's run, a run too large for the machine; nothing is written
  3    the physics broke down (inelastic collapse, a stalled clock, a jammed piston): the run
       file keeps the state where it happened, and its stop reason says which
  130  stopped by SIGINT (Ctrl-C), 143 by SIGTERM: final snapshot and checkpoint written;
       ``resume=`` continues the run (a sweep: the same command with its hydra.sweep.dir)
"""

import atexit
import itertools
import logging
import math
import os
import re
import signal
import sys
import warnings
from collections import OrderedDict
from pathlib import Path

import hydra
from hydra import compose, initialize_config_dir
from hydra.core.hydra_config import HydraConfig
from hydra.core.override_parser.overrides_parser import OverridesParser
from hydra.types import RunMode
from omegaconf import OmegaConf
from omegaconf.errors import KeyValidationError, ValidationError

from sim.__main__ import caused_by_a_signal, leave
from sim.engine.errors import PhysicsBreakdown
from sim.pipeline import callbacks, resources
from sim.pipeline.config import ConfigError, integer_keys, register, validate
from sim.pipeline.run_folder import FolderBusyError, RunLock, new_folder
from sim.pipeline.runner import (
    COSMETIC,
    Interruption,
    describe_differences,
    differences,
    resumable,
    resume,
    run,
    stored_config,
)
from sim.storage.errors import RunFileError
from sim.storage.h5md import hdf5_reason
from sim.storage.inspect import summary

CONF_DIR = str((Path(__file__).resolve().parents[3] / "conf"))
EXIT_BAD_CONFIG = 2
EXIT_RUN_FILE = 1
EXIT_BREAKDOWN = 3
#: single runs that a signal stopped: (run file, stop reason)
INTERRUPTED = []
#: the folders ``main`` made for this command (removed again, if empty, when it is refused)
MADE_FOLDERS = []
#: the signal that stopped the command before or between runs (SIGINT unless SIGTERM came)
STOPPED_BY = [signal.SIGINT]
INTEGER_KEYS = frozenset(integer_keys())
SWEEP_FLAGS = ("-m", "--multirun")

register()


def _fail(message, status=EXIT_BAD_CONFIG):
    print(f"sim: {' '.join(str(message).split())}", file=sys.stderr, flush=True)
    _remove_made_folders()
    sys.exit(status)


def _remove_made_folders():
    for folder in reversed(MADE_FOLDERS):
        try:
            folder.rmdir()  # only if nothing was written into it
        except OSError:
            pass


def _make_folder(folder):
    """``mkdir -p folder``, remembering in :data:`MADE_FOLDERS` each folder it made."""
    missing = [f for f in (folder, *folder.parents) if not f.exists()]
    folder.mkdir(parents=True, exist_ok=True)
    MADE_FOLDERS.extend(reversed(missing))


def _first_line(error):
    """The innermost cause's first line: what the user needs, without Hydra's framing."""
    while error.__cause__ is not None:
        error = error.__cause__
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    return lines[0] if lines else type(error).__name__


def _type_error(error):
    """A value of the wrong type, as a :class:`ConfigError` naming the key (or None)."""
    while error.__cause__ is not None:
        error = error.__cause__
    key = getattr(error, "full_key", None)
    if not isinstance(error, ValidationError) or isinstance(error, KeyValidationError) \
            or not key:
        return None
    message = getattr(error, "msg", "") or ""
    kinds = {"Integer": "a whole number", "Float": "a number", "Boolean": "true or false",
             "is not a subclass of": "a section of keys, not a single value"}
    allowed = next((text for word, text in kinds.items() if word in message),
                   message.splitlines()[0] if message else "a value of another type")
    return ConfigError(key, getattr(error, "value", None), allowed)


def _explain_key(combination):
    """Why a key of the command line does not exist: the keys allowed beside a misspelt one
    (disks.nn -> n, radius, …), or the scenario a section belongs to."""
    scenario = [c.partition("=")[2] for c in combination if c.startswith("scenario=")]
    with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
        cfg = compose("config", overrides=[f"scenario={s}" for s in scenario])
    for item in combination:
        key = item.partition("=")[0].lstrip("+~")
        parent = key.rpartition(".")[0]
        if not parent or key.startswith("scenario"):
            continue
        head = parent.split(".")[0]
        if head in cfg and cfg[head] is None:
            return f"{key}: the scene '{cfg.scene}' has no '{head}' section (choose a " \
                   f"scenario that has one, e.g. scenario=crater for projectile and bed)"
        node = OmegaConf.select(cfg, parent)
        if OmegaConf.is_dict(node) and key.rpartition(".")[2] not in node:
            return f"{key}: no such key; allowed keys there: " + ", ".join(map(str, node))
    return None


_FLOAT = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def whole_numbers(args):
    """The command line with numbers written as ``2e6`` or ``1000.0`` given to integer keys
    (``stop.collisions=2e6``) written as integers; a sweep's comma list item by item."""
    out = []
    for arg in args:
        key, equals, value = arg.partition("=")
        if equals and key.lstrip("+~") in INTEGER_KEYS:
            items = [_integer(item.strip()) if _FLOAT.fullmatch(item.strip()) else item
                     for item in value.split(",")]
            arg = f"{key}={','.join(items)}"
        out.append(arg)
    return out


def _integer(text):
    value = float(text)
    if math.isfinite(value) and value == int(value) and not re.fullmatch(r"[+-]?\d+", text):
        return str(int(value))
    return text


def combinations(args):
    """Every job the command line asks for, as lists of overrides, in the order and numbering
    of Hydra's basic sweeper (a repeated key: the last one counts)."""
    overrides = [a for a in args if not a.startswith("-")]
    try:
        parsed = OverridesParser.create().parse_overrides(overrides)
    except Exception as error:
        _fail(_first_line(error))
    choices = OrderedDict()
    for o in parsed:
        key = o.get_key_element()
        if o.is_sweep_override():
            choices[key] = [f"{key}={v}" for v in o.sweep_string_iterator()]
        else:
            choices[key] = [f"{key}={o.get_value_element_as_str()}"]
    return [list(c) for c in itertools.product(*choices.values())]


def _compose(combination, hydra_config=False):
    with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
        return compose("config", overrides=list(combination),
                       return_hydra_config=hydra_config)


def _hydra_config(args):
    """The config composed with Hydra's own node, from the command line's ``hydra…``
    overrides (its folders, launcher, subdir)."""
    return _compose([a for a in args if a.lstrip("+~").startswith("hydra")], hydra_config=True)


def _task(combination):
    return [c for c in combination if not c.lstrip("+~").startswith("hydra")]


def check_command_line(args):
    """Compose and validate every job the command line asks for; exit 2 on the first bad
    one. Returns the composed configs, one per job."""
    sweeping = any(a in SWEEP_FLAGS for a in args)
    configs = []
    for combination in combinations(args):
        try:
            cfg = _compose(combination)
            if cfg.resume is None:
                validate(cfg)
            else:
                if sweeping:
                    raise ConfigError("resume", cfg.resume, "a single run, not a sweep (-m)")
                resumable(cfg.resume,
                          [c for c in _task(combination) if not c.startswith("resume=")])
            configs.append(cfg)
        except ConfigError as error:
            _fail(str(error))
        except RunFileError as error:  # a resume in a folder where nothing can be written
            _fail(str(error), EXIT_RUN_FILE)
        except Exception as error:
            if caused_by_a_signal(error):
                raise KeyboardInterrupt from error
            typed = _type_error(error)
            if typed is not None:
                _fail(str(typed))
            try:
                explanation = _explain_key(combination)
            except Exception:
                explanation = None
            if explanation is None and "scenario/" in str(error):
                names = sorted(p.stem for p in Path(CONF_DIR, "scenario").glob("*.yaml"))
                explanation = (f"{' '.join(c for c in combination if 'scenario' in c)}: no "
                               f"such scenario; allowed: {', '.join(names)}")
            _fail(explanation or
                  f"{' '.join(combination) or 'default config'}: {_first_line(error)}")
    return configs


def _given(args, key):
    """The value the command line gives ``key`` (the last, as Hydra takes it), unquoted by
    Hydra's own grammar, or None."""
    items = [a for a in args if a.partition("=")[0] == key]
    if not items:
        return None
    value = OverridesParser.create().parse_override(items[-1]).value()
    return None if value is None else str(value)


def _quoted(text):
    """``text`` as a value of Hydra's override grammar."""
    if re.fullmatch(r"[\w./:+-]+", text):
        return text
    return "'" + text.replace("'", "\\'") + "'"


def _with(args, key, value):
    """The command line with ``key=value`` in place of what it gave ``key``, first (Hydra
    takes overrides before its flags, such as -m)."""
    return [f"{key}={_quoted(str(value))}", *(a for a in args if a.partition("=")[0] != key)]


def _writable(folder):
    """Make ``folder`` (and its parents) and check that files can be made in it (access(2),
    which a read-only file system fails too); one line and exit 1 when not."""
    try:
        _make_folder(folder)
    except OSError as error:
        _fail(f"cannot write in the run folder {folder}: {error.strerror or error}",
              EXIT_RUN_FILE)
    if not os.access(folder, os.W_OK | os.X_OK):
        _fail(f"cannot write in the run folder {folder}: no permission to write there, or a "
              f"read-only file system", EXIT_RUN_FILE)


def run_folder(args):
    """The command line with the folder of the run (``hydra.run.dir``) or sweep
    (``hydra.sweep.dir``) made and given: the folder the user named, checked writable, or a
    new one from the config's pattern that no other process has (:func:`new_folder`)."""
    sweeping = any(a in SWEEP_FLAGS for a in args)
    key = "hydra.sweep.dir" if sweeping else "hydra.run.dir"
    resume = _given(args, "resume")
    if not sweeping and resume is not None and _given(args, key) is None:
        return _with(args, key, Path(resume).parent)  # no new folder for a resume
    # the folder as Hydra would make it, interpolations such as ${now:…} resolved once here
    given = Path(OmegaConf.select(_hydra_config(args), key))
    if _given(args, key) is not None:
        _writable(given)
        return _with(args, key, given)
    try:
        _make_folder(given.parent)
        folder = new_folder(given)
    except OSError as error:
        _fail(f"cannot make the run folder {given}: {error.strerror or error}",
              EXIT_RUN_FILE)
    MADE_FOLDERS.append(folder)
    _writable(folder)
    return _with(args, key, folder)


def check_resources(args, configs):
    """Refuse (exit 2) jobs that cannot fit (:func:`sim.pipeline.resources.check`): in the memory of
    this machine as many at once as the launcher runs (joblib: one per core), or each within
    the memory a scheduler gives a job (submitit's ``mem_gb``); and all their files on the
    disk of the run folder. Warn about run files of several GB."""
    sweeping = any(a in SWEEP_FLAGS for a in args)
    folder = Path(_given(args, "hydra.sweep.dir" if sweeping else "hydra.run.dir"))
    fresh = [cfg for cfg in configs if cfg.resume is None]
    if not fresh:
        return
    launcher = _hydra_config(args).hydra.launcher
    job_memory = (float(launcher.mem_gb) * 2**30
                  if sweeping and launcher.get("mem_gb") is not None else None)
    concurrent = 1
    if sweeping and launcher.get("n_jobs") is not None:
        n_jobs = int(launcher.n_jobs)
        concurrent = min(len(fresh), (os.cpu_count() or 1) if n_jobs < 0 else n_jobs)
    try:
        resources.check(fresh, folder, concurrent, job_memory)
    except ConfigError as error:
        _fail(str(error))
    for cfg in fresh:
        resources.warn_large(cfg)


def check_sweep_folder(args, configs):
    """A sweep into a folder that holds runs already (the same sweep run again): every job
    folder must hold nothing, or the same config's run, and no live run; else exit 2 before
    any job starts."""
    folder = Path(_given(args, "hydra.sweep.dir"))
    subdir = _hydra_config(args).hydra.sweep._get_node("subdir")._value()
    if subdir != "${hydra.job.num}":
        return  # job folders named otherwise: each job checks its own folder as it starts
    for number, cfg in enumerate(configs):
        path = folder / str(number) / cfg.output.file
        if not path.exists():
            continue
        try:
            with RunLock(path):
                stored, _ = stored_config(path, "hydra.sweep.dir")
        except FolderBusyError as error:
            _fail(ConfigError("hydra.sweep.dir", str(folder), f"a folder no other run is "
                              f"using: {error.holder} is writing {path}"))
        except ConfigError as error:  # not a run file
            _fail(ConfigError("hydra.sweep.dir", str(folder), f"a folder without foreign "
                              f"files: job {number}'s {error.allowed}"))
        except OSError:
            continue  # the job itself reports what it cannot write
        differ = differences(stored, cfg, ignore=COSMETIC)
        if differ:
            _fail(ConfigError("hydra.sweep.dir", str(folder), f"a folder without another "
                              f"sweep's runs; job {number} there differs in "
                              f"{describe_differences(differ)}"))


@hydra.main(config_path=CONF_DIR, config_name="config", version_base="1.3")
def hydra_main(cfg):
    sweeping = HydraConfig.get().mode == RunMode.MULTIRUN
    output_dir = HydraConfig.get().runtime.output_dir
    overrides = list(HydraConfig.get().overrides.task)
    path = Path(cfg.resume) if cfg.resume is not None else Path(output_dir) / cfg.output.file
    try:
        if cfg.resume is not None:
            resume(path, [o for o in overrides if not o.startswith("resume=")])
        else:
            run(cfg, output_dir, overrides,
                folder_key="hydra.sweep.dir" if sweeping else "hydra.run.dir")
    except ConfigError as error:
        if not sweeping:
            _fail(str(error))
        return {"failed": f"ConfigError: {error}"}
    except RunFileError as error:
        if not sweeping:
            _remove_made_folders()
            # a file whose write failed can crash HDF5 when Python tears down: leave now
            leave(f"sim: {' '.join(str(error).split())}", EXIT_RUN_FILE)
        return {"failed": f"RunFileError: {error}"}
    except PhysicsBreakdown as error:
        if not sweeping:
            _fail(f"{str(error).rstrip('.')}. The run file {path} keeps the state where it "
                  f"happened (stop reason {error.stop_reason}).", EXIT_BREAKDOWN)
        return {"failed": f"{type(error).__name__}: {error}"}
    except KeyboardInterrupt:
        if sweeping:
            raise
        where = (f"the run file {path} keeps what was written; continue with: python -m sim "
                 f"resume={path}" if path.exists() else "nothing was written")
        _remove_made_folders()
        leave(f"sim: {_stopped()}; {where}", 128 + STOPPED_BY[-1])
    except Exception as error:
        if not sweeping:
            raise
        logging.getLogger(__name__).exception("job failed")
        return {"failed": f"{type(error).__name__}: {error}"}
    if not sweeping:  # the run is over: a late signal must not break the report
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    info = summary(path, verify=False)  # the file was just written: no pass over it
    print(f"{info['scene']}: {info['n']} disks, {info['collisions']} collisions to t = "
          f"{info['time_span'][1]:.6g}, {info['snapshots']} snapshots, energy "
          f"{info['final_energy']:.6g} (dissipated {info['dissipated_energy']:.3g}, balance "
          f"error {info['energy_drift']:.1e}), stopped by {info['stop_reason']}\n"
          f"run file: {path}", flush=True)
    if info["stop_reason"] in ("interrupted", "terminated"):
        if sweeping:
            raise KeyboardInterrupt  # a signal stops the whole sweep, not one job
        INTERRUPTED.append((path, info["stop_reason"]))
    return str(path)


def _terminate(signum, frame):
    STOPPED_BY.append(signal.Signals(signum))
    raise KeyboardInterrupt


def _stopped():
    return "terminated" if STOPPED_BY[-1] == signal.SIGTERM else "interrupted"


def _stop_at_once(signum):
    """A second SIGINT or SIGTERM during a run: leave at once, as SIGKILL would (the run file
    keeps every snapshot up to its last flush)."""
    print(f"sim: {signum.name} again: stopped at once; the run file keeps every snapshot up "
          f"to its last flush, and resume= continues from its last checkpoint",
          file=sys.stderr, flush=True)
    os._exit(128 + signum)


def _warn_in_one_line(message, category, filename, lineno, file=None, line=None):
    """Warnings as the command line's other messages: one line."""
    print(f"sim: warning: {' '.join(str(message).split())}", file=sys.stderr, flush=True)


def _failed_hdf5_write(error):
    return isinstance(error, (OSError, RuntimeError)) and "write failed" in str(error)


#: HDF5 write failures that h5py reported on its own (see :func:`_quiet_hdf5_teardown`)
PASSED_OVER = []


def _quiet_hdf5_teardown(unraisable):
    """HDF5 tries a failed write again as it releases the objects of that file (a dataset
    closed after a write it could not finish, wherever the writer's wall-clock flush left
    it), and h5py reports each failure: its traceback through ``sys.excepthook``, then
    "Exception ignored" through ``sys.unraisablehook``. Both hooks keep these in
    :data:`PASSED_OVER` instead: the run's one-line report of the failure, which ends the
    process, covers them; a process that ends without that report says the first of them
    in one line and ends with status 1 (:func:`_report_passed_over`)."""
    if _failed_hdf5_write(unraisable.exc_value):
        PASSED_OVER.append(unraisable.exc_value)
    else:
        sys.__unraisablehook__(unraisable)


def _quiet_hdf5_traceback(kind, error, traceback):
    if _failed_hdf5_write(error):
        PASSED_OVER.append(error)
    else:
        sys.__excepthook__(kind, error, traceback)


def _report_passed_over():
    """At exit (after any uncaught exception): a failed write that nothing reported."""
    if PASSED_OVER:
        leave(f"sim: writing the run file failed: {hdf5_reason(PASSED_OVER[0])}",
              EXIT_RUN_FILE)


def main():
    """The command line's entry point (see the module docstring)."""
    signal.signal(signal.SIGTERM, _terminate)  # before the run: SIGTERM as Ctrl-C
    sys.unraisablehook = _quiet_hdf5_teardown
    sys.excepthook = _quiet_hdf5_traceback
    atexit.register(_report_passed_over)
    warnings.showwarning = _warn_in_one_line
    Interruption.at_second_signal = _stop_at_once
    args = whole_numbers(sys.argv[1:])
    sweeping = any(a in SWEEP_FLAGS for a in args)
    if sweeping:  # an interrupted joblib sweep leaves its semaphores to this helper process
        os.environ.setdefault("PYTHONWARNINGS", "ignore:resource_tracker:UserWarning")
    try:
        configs = check_command_line(args)
        args = run_folder(args)
        check_resources(args, configs)
        if sweeping and _given(args, "hydra.sweep.dir") is not None:
            check_sweep_folder(args, configs)
        sys.argv[1:] = args
        hydra_main()
    except KeyboardInterrupt:
        _remove_made_folders()
        if sweeping:
            folder = _given(args, "hydra.sweep.dir")
            leave(f"sim: sweep {_stopped()}; the same command with hydra.sweep.dir={folder} "
                  f"continues its jobs", 128 + STOPPED_BY[-1])
        leave(f"sim: {_stopped()} before the run started; nothing was written",
              128 + STOPPED_BY[-1])
    if callbacks.FAILED_JOBS:
        sys.exit(EXIT_RUN_FILE)
    if INTERRUPTED:
        path, reason = INTERRUPTED[0]
        print(f"sim: {reason}; continue with: python -m sim resume={path}", file=sys.stderr)
        sys.exit(128 + (signal.SIGTERM if reason == "terminated" else signal.SIGINT))
