"""The checks of ``python -m sim`` before any work: every job composed and validated (a
resume's file read), its run folder made and checked writable, the jobs sized against the
machine, and a sweep's folder checked for another sweep's runs; the first refusal is one line
and an exit status (:mod:`sim.pipeline.cli_exits`)."""

import os
from pathlib import Path

from hydra.errors import ConfigCompositionException, MissingConfigException
from omegaconf import OmegaConf
from omegaconf.errors import KeyValidationError, ValidationError

from sim.pipeline import cli_exits, resources, sweep_stop
from sim.pipeline.cli_exits import EXIT_RUN_FILE, fail, first_line, make_folder
from sim.pipeline.config import ConfigError, validate
from sim.pipeline.leaving import caused_by_a_signal
from sim.pipeline.overrides import (
    CONF_DIR,
    SWEEP_FLAGS,
    combinations,
    compose_overrides,
    hydra_settings,
    task_overrides,
    value_of,
    with_value,
)
from sim.pipeline.resume import (
    COSMETIC,
    describe_differences,
    differences,
    resumable,
    stored_config,
)
from sim.pipeline.run_folder import FolderBusyError, RunLock, new_folder
from sim.storage.errors import RunFileError


def _type_error(error):
    """A value of the wrong type, as a :class:`ConfigError` naming the key (or None)."""
    while not isinstance(error, ValidationError):
        # Hydra raises its composition error inside the except of the one it reports
        error = error.__cause__ or (error.__context__
                                    if isinstance(error, ConfigCompositionException) else None)
        if error is None:
            return None
    key = getattr(error, "full_key", None)
    if isinstance(error, KeyValidationError) or not key:
        return None
    message = getattr(error, "msg", "") or ""
    kinds = {"Integer": "a whole number", "Float": "a number", "Boolean": "true or false",
             "is not a subclass of": "a section of keys, not a single value"}
    allowed = next((text for word, text in kinds.items() if word in message),
                   message.splitlines()[0] if message else "a value of another type")
    return ConfigError(key, getattr(error, "value", None), allowed)


def _explain_key(combination):
    """Why a key of the command line does not exist: the keys allowed beside a misspelt one
    (disks.nn -> n, radius, …), or the scenario a section belongs to; or cannot be deleted
    (~key)."""
    scenario = [c.partition("=")[2] for c in combination if c.startswith("scenario=")]
    cfg = compose_overrides([f"scenario={s}" for s in scenario])
    for item in combination:
        key = item.partition("=")[0].lstrip("+~")
        if item.startswith("~") and not key.startswith(("scenario", "hydra")):
            return (f"~{key} is not allowed: a key of the config can be set but not deleted "
                    f"(every key has a value; null where it is off): {key}=…")
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


def check_command_line(args):
    """Compose and validate every job the command line asks for; exit 2 on the first bad
    one. Returns the composed configs, one per job (a resume's: the config it runs)."""
    sweeping = any(a in SWEEP_FLAGS for a in args)
    configs = []
    for combination in combinations(args):
        try:
            cfg = compose_overrides(combination)
            if cfg.resume is None:
                validate(cfg)
            else:
                if sweeping:
                    raise ConfigError("resume", cfg.resume, "a single run, not a sweep (-m)")
                task = task_overrides(combination)
                cfg = resumable(cfg.resume, [c for c in task if not c.startswith("resume=")])
            configs.append(cfg)
        except ConfigError as error:
            fail(str(error))
        except RunFileError as error:  # a resume in a folder where nothing can be written
            fail(str(error), EXIT_RUN_FILE)
        except Exception as error:
            if caused_by_a_signal(error):
                raise KeyboardInterrupt from error
            typed = _type_error(error)
            if typed is not None:
                fail(str(typed))
            try:
                explanation = _explain_key(combination)
            except Exception:
                explanation = None
            if explanation is None and isinstance(error, MissingConfigException) \
                    and "scenario/" in str(error):
                names = sorted(p.stem for p in Path(CONF_DIR, "scenario").glob("*.yaml"))
                explanation = (f"{' '.join(c for c in combination if 'scenario' in c)}: no "
                               f"such scenario; allowed: {', '.join(names)}")
            fail(explanation or
                 f"{' '.join(combination) or 'default config'}: {first_line(error)}")
    return configs


def _writable(folder):
    """Make ``folder`` (and its parents) and check that files can be made in it (access(2),
    which a read-only file system fails too); one line and exit 1 when not."""
    try:
        make_folder(folder)
    except OSError as error:
        fail(f"cannot write in the run folder {folder}: {error.strerror or error}",
             EXIT_RUN_FILE)
    if not os.access(folder, os.W_OK | os.X_OK):
        fail(f"cannot write in the run folder {folder}: no permission to write there, or a "
             f"read-only file system", EXIT_RUN_FILE)


def run_folder(args):
    """The command line with the folder of the run (``hydra.run.dir``) or sweep
    (``hydra.sweep.dir``) made and given: the folder the user named, checked writable, or a
    new one from the config's pattern that no other process has (:func:`new_folder`)."""
    sweeping = any(a in SWEEP_FLAGS for a in args)
    key = "hydra.sweep.dir" if sweeping else "hydra.run.dir"
    resume = value_of(args, "resume")
    if not sweeping and resume is not None:  # no new folder for a resume
        home, named = Path(resume).parent, value_of(args, key)
        if named is not None and Path(named).resolve() != home.resolve():
            fail(ConfigError(key, named, f"left out, or the folder of the run file it resumes "
                                         f"({home}): a resume continues the file where it is"))
        return with_value(args, key, home)
    # the folder as Hydra would make it, interpolations such as ${now:…} resolved once here
    given = Path(OmegaConf.select(hydra_settings(args), key))
    if value_of(args, key) is not None:
        _writable(given)
        return with_value(args, key, given)
    try:
        make_folder(given.parent)
        folder = new_folder(given)
    except OSError as error:
        fail(f"cannot make the run folder {given}: {error.strerror or error}",
             EXIT_RUN_FILE)
    cli_exits.MADE_FOLDERS.append(folder)
    _writable(folder)
    return with_value(args, key, folder)


def check_resources(args, configs):
    """Refuse (exit 2) jobs that cannot fit (:func:`sim.pipeline.resources.check`): in the memory of
    this machine as many at once as the launcher runs (joblib: one per core), or each within
    the memory a scheduler gives a job (submitit's ``mem_gb``); and all their files on the
    disk of the run folder. Warn about run files of several GB."""
    sweeping = any(a in SWEEP_FLAGS for a in args)
    folder = Path(value_of(args, "hydra.sweep.dir" if sweeping else "hydra.run.dir"))
    fresh = [cfg for cfg in configs if cfg.resume is None]
    if not fresh:
        return
    launcher = hydra_settings(args).hydra.launcher
    job_memory = (float(launcher.mem_gb) * 2**30
                  if sweeping and launcher.get("mem_gb") is not None else None)
    concurrent = 1
    if sweeping and launcher.get("n_jobs") is not None:
        n_jobs = int(launcher.n_jobs)
        concurrent = min(len(fresh), (os.cpu_count() or 1) if n_jobs < 0 else n_jobs)
    try:
        resources.check(fresh, folder, concurrent, job_memory)
    except ConfigError as error:
        fail(str(error))
    for cfg in fresh:
        resources.warn_large(cfg)


def joblib_workers(args, jobs):
    """The command line of a sweep of ``jobs`` jobs with the joblib launcher's ``n_jobs`` set
    to no more workers than jobs, unless the command line sets it
    (:func:`sim.pipeline.sweep_stop.worker_count`)."""
    launcher = hydra_settings(args).hydra.launcher
    if not str(launcher.get("_target_", "")).endswith("JoblibLauncher"):
        return args
    n_jobs = int(launcher.n_jobs) if launcher.get("n_jobs") is not None else -1
    cores = os.cpu_count() or 1
    if n_jobs == 0 or n_jobs < -cores:
        fail(ConfigError("hydra.launcher.n_jobs", n_jobs, f"the number of workers, a whole "
                         f"number ≥ 1, or −1 … −{cores} for all the {cores} cores but "
                         f"|n_jobs| − 1"))
    if value_of(args, "hydra.launcher.n_jobs") is not None:
        return args
    return with_value(args, "hydra.launcher.n_jobs",
                      sweep_stop.worker_count(n_jobs, jobs, cores))


def check_job_folders(args):
    """A sweep whose job folders (``hydra.sweep.subdir``, resolved for each job as the
    launcher will) are not all different: exit 2 before any job starts, since jobs that
    share a folder write one run file and all but one run are lost."""
    subdir = hydra_settings(args).hydra.sweep._get_node("subdir")._value()
    if subdir == "${hydra.job.num}":
        return
    jobs = {}
    inside = "a folder name inside hydra.sweep.dir that differs between jobs, such as " \
             "${hydra.job.num}"
    for number, combination in enumerate(combinations(args)):
        cfg = compose_overrides(combination, hydra_config=True)
        cfg.hydra.job.num = number
        cfg.hydra.job.id = f"job_{number}"  # unique, as every launcher's
        try:
            folder = os.path.normpath(str(cfg.hydra.sweep.subdir))
        except Exception:  # a resolver only a running job has: each job checks its folder
            return
        if os.path.isabs(folder) or folder.split(os.sep)[0] in (os.pardir, os.curdir):
            fail(ConfigError("hydra.sweep.subdir", subdir,
                             f"{inside} (job {number} would write {folder})"))
        if folder in jobs:
            fail(ConfigError("hydra.sweep.subdir", subdir, f"{inside} (jobs {jobs[folder]} "
                             f"and {number} would both write {folder})"))
        jobs[folder] = number


def check_sweep_folder(args, configs):
    """A sweep into a folder that holds runs already (the same sweep run again): every job
    folder must hold nothing, or the same config's run, and no live run; else exit 2 before
    any job starts."""
    folder = Path(value_of(args, "hydra.sweep.dir"))
    subdir = hydra_settings(args).hydra.sweep._get_node("subdir")._value()
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
            fail(ConfigError("hydra.sweep.dir", str(folder), f"a folder no other run is "
                             f"using: {error.holder} is writing {path}"))
        except ConfigError as error:  # not a run file
            fail(ConfigError("hydra.sweep.dir", str(folder), f"a folder without foreign "
                             f"files: job {number}'s {error.allowed}"))
        except OSError:
            continue  # the job itself reports what it cannot write
        differ = differences(stored, cfg, ignore=COSMETIC)
        if differ:
            fail(ConfigError("hydra.sweep.dir", str(folder), f"a folder without another "
                             f"sweep's runs; job {number} there differs in "
                             f"{describe_differences(differ)}"))
