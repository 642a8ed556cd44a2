"""Sweeps on a SLURM cluster through Hydra's submitit launcher (``hydra/launcher=cluster`` or
``submitit_slurm``).

Before anything is submitted, :func:`job_resources` gives every job what its runs need
unless the command line says otherwise: ``hydra.launcher.mem_gb`` the largest run's memory
estimate (:func:`sim.pipeline.resources.estimate`) and a margin, ``hydra.launcher.timeout_min``
twice the time of the longest run at :data:`ASSUMED_RATE` collisions per second, and
:data:`START_MINUTES` for its start (from ``stop.collisions``, ``stop.contacts`` or
``stop.wall_seconds``; runs that none of them bound keep the launcher's value), and checks
them and ``hydra.launcher.partition`` against the cluster's partitions (``sinfo``): a
partition that does not exist, or a time limit beyond the partition's, is one line naming the
setting and exit status 2, before anything is written.

In a job on the cluster (:func:`in_slurm_job`), a signal stops that job alone, not the
sweep: ``scancel`` (SIGTERM) and the warning submitit asks SLURM to send
``signal_delay_s`` seconds before the time limit (SIGUSR2) end the run with its final
snapshot and checkpoint, stop reason ``terminated``, and the job's status records the signal.
The sweep's process reports such jobs at the end in one line (:func:`report_stopped`), and
the same command continues them; the scheduler's refusals and jobs that ended without a
result reach the user as one line too (:func:`scheduler_error`).
"""

import math
import os
import re
import shutil
import signal
import subprocess

from sim.pipeline import resources
from sim.pipeline.config import ConfigError
from sim.pipeline.overrides import hydra_settings, value_of, with_value

#: collisions per second a run is assumed to make on a cluster's core (a slow core: this
#: machine's engine runs 1–3·10⁶ at N = 10⁴ to 10⁶), and the time limit is twice its time
ASSUMED_RATE = 1e6
#: minutes added to every job's time limit for its start (compilation, placement, files)
START_MINUTES = 5
#: the memory asked of the scheduler over the estimate
MEMORY_MARGIN = 1.25
#: the signal SLURM sends (through submitit's ``--signal``) before a job's time limit
TIME_LIMIT_WARNING = signal.SIGUSR2


def in_slurm_job():
    """Whether this process runs a job that submitit started on SLURM."""
    return os.environ.get("SUBMITIT_EXECUTOR") == "slurm"


def slurm_launcher(args):
    """Whether the command line's sweep goes to SLURM through submitit."""
    target = str(hydra_settings(args).hydra.launcher.get("_target_", ""))
    return target.endswith("SlurmLauncher")


def minutes(text):
    """A SLURM time (``minutes``, ``m:s``, ``h:m:s``, ``d-h``, ``d-h:m``, ``d-h:m:s``) in
    minutes; None for ``infinite`` or ``UNLIMITED``."""
    text = text.strip()
    if text.lower() in ("infinite", "unlimited"):
        return None
    days, _, clock = text.rpartition("-")
    parts = [int(p) for p in clock.split(":")]
    if days:
        hours, mins, secs = (parts + [0, 0])[:3]
    elif len(parts) == 3:
        hours, mins, secs = parts
    else:
        hours, (mins, secs) = 0, (parts + [0])[:2]
    return (int(days or 0) * 24 + hours) * 60 + mins + secs / 60.0


def run_minutes(cfg):
    """The time limit for a run (minutes), or None when its stop conditions bound neither
    its collisions nor its wall time."""
    s = cfg.stop
    bounds = [float(b) for b in (s.collisions, s.contacts) if b is not None]
    limits = []
    if bounds:
        limits.append(2.0 * min(bounds) / ASSUMED_RATE / 60.0)
    if s.wall_seconds is not None:
        limits.append(float(s.wall_seconds) / 60.0)
    return START_MINUTES + min(limits) if limits else None


def partitions():
    """{name: time limit in minutes or None} of the cluster's partitions, and the default's
    name; None when ``sinfo`` is not here or does not answer."""
    if shutil.which("sinfo") is None:
        return None
    try:
        listed = subprocess.run(["sinfo", "--noheader", "--format=%P %l"], capture_output=True,
                                text=True, timeout=60, check=True).stdout
    except (subprocess.SubprocessError, OSError):
        return None
    found, default = {}, None
    for line in listed.split("\n"):
        if not line.strip():
            continue
        name, limit = line.split()
        if name.endswith("*"):
            name = name[:-1]
            default = name
        found[name] = minutes(limit)
    return found, default


def job_resources(args, configs):
    """The command line of a sweep to SLURM with ``hydra.launcher.mem_gb`` and
    ``hydra.launcher.timeout_min`` from the runs' estimates where it gives none, checked
    against the cluster's partitions; a :class:`ConfigError` names the setting that cannot
    be. Returns (command line, one line that says what each job asks)."""
    launcher = hydra_settings(args).hydra.launcher
    if value_of(args, "hydra.launcher.mem_gb") is None:
        largest = max(resources.estimate(cfg)["memory"][0] for cfg in configs)
        args = with_value(args, "hydra.launcher.mem_gb",
                          max(1, math.ceil(MEMORY_MARGIN * largest / 2**30)))
    timeout, how = launcher.timeout_min, "hydra.launcher.timeout_min"
    if value_of(args, "hydra.launcher.timeout_min") is None:
        estimated = [run_minutes(cfg) for cfg in configs]
        if None not in estimated:
            timeout, how = math.ceil(max(estimated)), "estimated"
            args = with_value(args, "hydra.launcher.timeout_min", timeout)
        else:
            how = ("hydra.launcher.timeout_min: the runs' stop conditions bound no count of "
                   "collisions to estimate it from")
    partition = value_of(args, "hydra.launcher.partition") or launcher.get("partition")
    known = partitions()
    if known is not None:
        limits, default = known
        if partition is not None and partition not in limits:
            raise ConfigError("hydra.launcher.partition", partition,
                              f"a partition of this cluster: {', '.join(sorted(limits))}")
        name = partition or default
        limit = limits.get(name)
        if limit is not None and int(timeout) > limit:
            raise ConfigError("hydra.launcher.timeout_min", timeout,
                              f"at most the {limit:g} minutes of partition {name} (runs of "
                              f"fewer collisions, or a partition with a longer limit)")
    memory = value_of(args, "hydra.launcher.mem_gb")
    return args, (f"sim: each SLURM job asks for {memory} GB and {timeout} min ({how}), "
                  f"partition {partition or 'the default'}")


def stopped_job(signum):
    """The status a job on the cluster records when ``signum`` stopped it."""
    return {"stopped": "terminated", "signal": signal.Signals(signum).name}


def report_stopped(stopped, sweep_dir, timeout):
    """One line on the jobs of a SLURM sweep that a signal stopped (``stopped``: their
    status entries), naming the time limit when it was the cause."""
    numbers = ", ".join(str(job["job"]) for job in stopped)
    limit = [job for job in stopped if job.get("signal") == TIME_LIMIT_WARNING.name]
    cause = (f"reached the time limit hydra.launcher.timeout_min={timeout}" if limit
             else "were cancelled (scancel, or the scheduler)")
    return (f"sim: jobs {numbers} of the sweep {cause}; their run files keep what was written, "
            f"and the same command with hydra.sweep.dir={sweep_dir} continues them"
            + (" (with a longer hydra.launcher.timeout_min)" if limit else ""))


def scheduler_error(error, sweep_dir):
    """One line for an error of submitit: the scheduler refused the jobs (its message), or
    a job ended without a result (killed by the scheduler, a node lost)."""
    text = " ".join(str(error).split())
    match = re.search(r"sbatch: error: ([^:]*: )?(.*?)(sbatch: error|$)", text)
    if match:
        return f"sim: SLURM refused the jobs: {match.group(2).strip()}"
    first = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
    return (f"sim: a job of the sweep ended without a result ({first}); the same command "
            f"with hydra.sweep.dir={sweep_dir} continues its jobs")
