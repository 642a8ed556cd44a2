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

The work is split: :mod:`sim.pipeline.overrides` reads the command line,
:mod:`sim.pipeline.preflight` checks it before any work, :mod:`sim.pipeline.cli_exits` ends it
in one line and an exit status, and :func:`hydra_main` runs each job.
"""

import atexit
import contextlib
import logging
import os
import shutil
import signal
import sys
import warnings
from concurrent.futures import BrokenExecutor
from pathlib import Path

import hydra
from hydra.core.hydra_config import HydraConfig
from hydra.types import RunMode
from omegaconf import OmegaConf

from sim.engine.errors import PhysicsBreakdown
from sim.pipeline import callbacks, cli_exits, cluster, sweep_stop
from sim.pipeline.cli_exits import (
    EXIT_BAD_CONFIG,
    EXIT_BREAKDOWN,
    EXIT_RUN_FILE,
    fail,
    first_line,
    quiet_hdf5_teardown,
    quiet_hdf5_traceback,
    remove_made_folders,
    report_passed_over,
    stop_at_once,
    stopped,
    stopped_by,
    stopped_status,
    terminate,
    warn_in_one_line,
)
from sim.pipeline.config import ConfigError, register
from sim.pipeline.interruption import Interruption
from sim.pipeline.leaving import leave
from sim.pipeline.overrides import (
    CONF_DIR,
    SWEEP_FLAGS,
    flags_last,
    hydra_arguments,
    hydra_settings,
    prints_only,
    value_of,
    whole_numbers,
)
from sim.pipeline.preflight import (
    check_command_line,
    check_job_folders,
    check_resources,
    check_sweep_folder,
    joblib_workers,
    run_folder,
)
from sim.pipeline.resume import resume
from sim.pipeline.runner import run
from sim.storage.errors import RunFileError
from sim.storage.inspect import summary

#: single runs that a signal stopped: (run file, stop reason)
INTERRUPTED = []

register()


@hydra.main(config_path=CONF_DIR, config_name="config", version_base="1.3")
def hydra_main(cfg):
    """One job: run or resume it and say what the run file holds; in a sweep a failing job
    returns ``{"failed": message}`` (:mod:`sim.pipeline.callbacks`), one a signal stopped
    ``{"stopped": reason}`` (:mod:`sim.pipeline.sweep_stop`)."""
    sweeping = HydraConfig.get().mode == RunMode.MULTIRUN
    output_dir = HydraConfig.get().runtime.output_dir
    warnings.showwarning = warn_in_one_line  # also in a sweep's workers
    Interruption.sweep_dir = HydraConfig.get().sweep.dir if sweeping else None
    if sweeping and cluster.slurm_job(HydraConfig.get().launcher):
        return _cluster_job(cfg, output_dir)
    if sweeping:
        with sweep_stop.job(Interruption.sweep_dir, stop_at_once):
            asked = sweep_stop.requested(Interruption.sweep_dir)
            if asked is not None:  # the sweep was stopped before this job began
                return {"stopped": Interruption.REASONS[asked]}
            outcome = _job(cfg, sweeping, output_dir)
        if sweep_stop.orphaned():  # no one is left to take the outcome or give more jobs
            sys.stdout.flush()
            os._exit(128 + signal.SIGTERM)
        return outcome
    return _job(cfg, sweeping, output_dir)


def _cluster_job(cfg, output_dir):
    """A job of a sweep on a SLURM cluster, in its folder ``output_dir``: a signal stops it
    alone (:mod:`sim.pipeline.cluster`); one that came before its run began, nothing run."""
    cluster.take_signals()
    asked = sweep_stop.requested(Interruption.sweep_dir)
    if asked is not None:  # the sweep was stopped (Ctrl-C to its command) before this job
        return {"stopped": Interruption.REASONS[asked]}
    if Interruption.early is not None:  # cancelled while it started
        return cluster.stopped_job(Interruption.early, "terminated")
    return _job(cfg, True, output_dir, alone=True)


def _job(cfg, sweeping, output_dir, alone=False):
    """:func:`hydra_main`'s job, in its folder ``output_dir``; ``alone``: a job on a
    cluster, which a signal stops without its sweep."""
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
            fail(str(error))
        return {"failed": f"ConfigError: {error}"}
    except RunFileError as error:
        if not sweeping:
            remove_made_folders()
            # a file whose write failed can crash HDF5 when Python tears down: leave now
            leave(f"sim: {' '.join(str(error).split())}", EXIT_RUN_FILE)
        return {"failed": f"RunFileError: {error}"}
    except PhysicsBreakdown as error:
        if not sweeping:
            fail(f"{str(error).rstrip('.')}. The run file {path} keeps the state where it "
                 f"happened (stop reason {error.stop_reason}).", EXIT_BREAKDOWN)
        return {"failed": f"{type(error).__name__}: {error}"}
    except KeyboardInterrupt:
        if sweeping:
            return _stop_the_sweep(stopped(), alone)
        where = (f"the run file {path} keeps what was written; continue with: python -m sim "
                 f"resume={path}" if path.exists() else "nothing was written")
        remove_made_folders()
        leave(f"sim: {stopped()}; {where}", stopped_status())
    except Exception as error:
        if not sweeping:
            raise
        logging.getLogger(__name__).exception("job failed")
        return {"failed": f"{type(error).__name__}: {error}"}
    if not sweeping:  # the run is over: a late signal must not break the report
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
    info = summary(path, verify=False)  # the file was just written: no pass over it
    balance = ("no balance: the disks grow" if info["growth_rate"] > 0.0
               else "no balance: no snapshot has every energy" if info["energy_drift"] is None
               else f"balance error {info['energy_drift']:.1e}")
    print(f"{info['scene']}: {info['n']} disks, {info['collisions']} collisions to t = "
          f"{info['time_span'][1]:.6g}, {info['snapshots']} snapshots, energy "
          f"{info['final_energy']:.6g} (dissipated {info['dissipated_energy']:.3g}, "
          f"{balance}), stop reason: {info['stop_reason']}\n"
          f"run file: {path}", flush=True)
    if info["stop_reason"] in ("interrupted", "terminated"):
        if sweeping:
            return _stop_the_sweep(info["stop_reason"], alone)
        INTERRUPTED.append((path, info["stop_reason"]))
    return str(path)


def _forget_submission(sweep_dir):
    """A sweep folder this command made, whose jobs SLURM refused (none was queued): what
    was written into it (submitit's folder, Hydra's multirun.yaml) removed with it. A folder
    of an earlier sweep keeps its files."""
    folder = Path(sweep_dir).resolve()
    if folder in {made.resolve() for made in cli_exits.MADE_FOLDERS}:
        shutil.rmtree(folder / ".submitit", ignore_errors=True)
        (folder / "multirun.yaml").unlink(missing_ok=True)
    remove_made_folders()


def _stop_the_sweep(reason, alone=False):
    """A job a signal stopped (``reason``: interrupted or terminated) stops its whole sweep,
    and returns so that the launcher waits for the others to end; a job on a cluster
    (``alone``) stops without it (:mod:`sim.pipeline.cluster`)."""
    signum = signal.SIGTERM if reason == "terminated" else signal.SIGINT
    if alone:
        return cluster.stopped_job(Interruption.last_signal or signum, reason)
    sweep_stop.request(HydraConfig.get().sweep.dir, signum)
    return {"stopped": reason}


def main():
    """The command line's entry point (see the module docstring)."""
    signal.signal(signal.SIGTERM, terminate)  # before the run: SIGTERM as Ctrl-C
    sys.unraisablehook = quiet_hdf5_teardown
    sys.excepthook = quiet_hdf5_traceback
    atexit.register(report_passed_over)
    warnings.showwarning = warn_in_one_line
    logging.raiseExceptions = False  # a log line to a closed pipe (| head) is dropped, silently
    Interruption.at_second_signal = stop_at_once
    args = whole_numbers(sys.argv[1:])
    sweeping = any(a in SWEEP_FLAGS for a in args)
    if sweeping:  # an interrupted joblib sweep leaves its semaphores to this helper process
        os.environ.setdefault("PYTHONWARNINGS", "ignore:resource_tracker:UserWarning")
    try:
        configs = check_command_line(args)
        if value_of(args, "resume") is not None and hydra_arguments(args).cfg == "job":
            print(OmegaConf.to_yaml(configs[0]), end="")  # what it runs, not Hydra's defaults
            return
        if not prints_only(args):  # --cfg, --info, --hydra-help: no run, no folder
            if sweeping:
                check_job_folders(args)
            if sweeping and cluster.slurm_launcher(args):
                try:
                    args, asked = cluster.job_resources(args, configs)
                except ConfigError as error:
                    fail(str(error))
                print(asked, file=sys.stderr, flush=True)
            args = run_folder(args)
            check_resources(args, configs)
        if sweeping and value_of(args, "hydra.sweep.dir") is not None:
            check_sweep_folder(args, configs)
        guard = contextlib.nullcontext()
        if sweeping:
            args = joblib_workers(args, len(configs))
            sweep_dir = value_of(args, "hydra.sweep.dir")
            sweep_stop.clear(sweep_dir)  # left by a sweep killed there before
            sweep_stop.use_sweep_workers()
            os.environ["HYDRA_FULL_ERROR"] = "1"  # the launcher's errors come here
            guard = sweep_stop.guarded(sweep_dir, stopped_by, stop_at_once)
        sys.argv[1:] = flags_last(args)
        try:
            try:
                with guard:
                    hydra_main()
            except BrokenExecutor as error:  # a worker was killed (kill -9, the OOM killer)
                if sweep_stop.requested(sweep_dir) is None:  # not while the sweep stopped
                    remove_made_folders()
                    how = next((line.strip() for line in str(error).splitlines()
                                if "exit codes" in line), first_line(error))
                    leave(f"sim: sweep stopped: a worker process ended ({how}); the same "
                          f"command with hydra.sweep.dir={sweep_dir} continues its jobs",
                          EXIT_RUN_FILE)
            except Exception as error:  # SLURM refused the jobs, or lost one
                if not (sweeping and cluster.slurm_launcher(args)
                        and type(error).__module__.startswith("submitit.")):
                    raise
                refused = cluster.refused(error)  # nothing was queued
                if refused:
                    _forget_submission(sweep_dir)
                leave(cluster.scheduler_error(error, sweep_dir,
                                              hydra_settings(args).hydra.launcher),
                      EXIT_BAD_CONFIG if refused else EXIT_RUN_FILE)
            if sweeping:  # the sweep is over: a late signal must not break the report
                signal.signal(signal.SIGINT, signal.SIG_IGN)
                signal.signal(signal.SIGTERM, signal.SIG_IGN)
        except SystemExit as stop:
            if stop.code not in (0, None):
                remove_made_folders()  # those still empty: a refusal leaves none behind
            raise
    except KeyboardInterrupt:
        remove_made_folders()
        if sweeping:
            folder = value_of(args, "hydra.sweep.dir")
            leave(f"sim: sweep {stopped()}; the same command with hydra.sweep.dir={folder} "
                  f"continues its jobs", stopped_status())
        leave(f"sim: {stopped()} before the run started; nothing was written",
              stopped_status())
    if sweeping and (asked := sweep_stop.requested(sweep_dir)) is not None:
        sweep_stop.clear(sweep_dir)
        if len(cli_exits.STOPPED_BY) == 1:  # the signal came to a worker, not here
            stopped_by(asked)
        begun = any(Path(sweep_dir).rglob(configs[0].output.file))
        print(f"sim: sweep {stopped()}" + (
            f"; the same command with hydra.sweep.dir={sweep_dir} continues its jobs" if begun
            else f" before any run began; the same command with hydra.sweep.dir={sweep_dir} "
                 f"runs it whole"), file=sys.stderr)
        sys.exit(stopped_status())  # atexit ends joblib's workers
    if callbacks.FAILED_JOBS:
        sys.exit(EXIT_RUN_FILE)
    if sweeping and callbacks.STOPPED_JOBS and cluster.slurm_launcher(args):  # each alone
        print(cluster.report_stopped(callbacks.STOPPED_JOBS, sweep_dir,
                                     hydra_settings(args).hydra.launcher.get("timeout_min")),
              file=sys.stderr)
        sys.exit(128 + signal.SIGTERM)
    if INTERRUPTED:
        path, reason = INTERRUPTED[0]
        print(f"sim: {reason}; continue with: python -m sim resume={path}", file=sys.stderr)
        sys.exit(128 + (signal.SIGTERM if reason == "terminated" else signal.SIGINT))
