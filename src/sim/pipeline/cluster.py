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

In a job on the cluster (:func:`slurm_job`, :func:`take_signals`), a signal stops that job
alone, not the sweep: ``scancel`` (SIGTERM), the warning submitit asks SLURM to send
``signal_delay_s`` seconds before the time limit (:func:`time_limit_warning`) and SLURM's
SIGTERM at the limit end the run with its final snapshot and checkpoint, stop reason
``terminated``, and the job's status records the signal and its SLURM id; one that comes
while the job starts, before its run, leaves it unrun.
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
from sim.pipeline.interruption import Interruption
from sim.pipeline.overrides import hydra_settings, value_of, with_value

#: collisions per second a run is assumed to make on a cluster's core (a slow core: this
#: machine's engine runs 1–3·10⁶ at N = 10⁴ to 10⁶), and the time limit is twice its time
ASSUMED_RATE = 1e6
#: minutes added to every job's time limit for its start (compilation, placement, files)
START_MINUTES = 5
#: the memory asked of the scheduler over the estimate
MEMORY_MARGIN = 1.25
#: what SLURM's refusals speak of, and the launcher's setting for it
REFUSED_SETTINGS = (("partition", "partition"), ("time limit", "timeout_min"),
                    ("memory", "mem_gb"), ("account", "account"), ("qos", "qos"))


def time_limit_warning():
    """The signal SLURM sends a job (submitit's ``--signal``) before its time limit:
    ``SUBMITIT_PREEMPT_SIGNAL``, by default SIGUSR2."""
    return signal.Signals["SIG" + os.environ.get("SUBMITIT_PREEMPT_SIGNAL", "USR2")]


def _sends_to_slurm(launcher):
    """Whether the launcher config ``launcher`` is submitit's SLURM launcher."""
    return str(launcher.get("_target_", "")).endswith("SlurmLauncher")


def slurm_job(launcher):
    """Whether this process runs a job that submitit started on SLURM for a sweep whose
    launcher config is ``launcher``."""
    return os.environ.get("SUBMITIT_EXECUTOR") == "slurm" and _sends_to_slurm(launcher)


def _ignored(signum):
    """A repeated signal to a job on the cluster: its run stops already, SIGKILL follows."""


def take_signals():
    """In a job on the cluster, from its start: SIGTERM and the time-limit warning stop this
    job's run (:meth:`sim.pipeline.interruption.Interruption.take_early` until it begins,
    then the run's own handler), not the sweep; a repeated one is passed over."""
    Interruption.time_limit_warning = time_limit_warning()
    Interruption.early = Interruption.last_signal = None
    Interruption.at_second_signal = _ignored
    for number in (signal.SIGTERM, Interruption.time_limit_warning):
        signal.signal(number, Interruption.take_early)


def slurm_launcher(args):
    """Whether the command line's sweep goes to SLURM through submitit."""
    return _sends_to_slurm(hydra_settings(args).hydra.launcher)


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


def stopped_job(signum, reason):
    """The status a job on the cluster records when ``signum`` stopped its run with stop
    reason ``reason``: the signal and the job's SLURM id (``<array>_<task>`` in an array)."""
    env = os.environ
    task = env.get("SLURM_ARRAY_TASK_ID")
    slurm_id = (f"{env['SLURM_ARRAY_JOB_ID']}_{task}" if task is not None
                else env.get("SLURM_JOB_ID", ""))
    return {"stopped": reason, "signal": signal.Signals(signum).name, "slurm_job": slurm_id}


def _answer(command):
    try:
        return subprocess.run(command, capture_output=True, text=True, timeout=60).stdout
    except (subprocess.SubprocessError, OSError):
        return ""


def scheduler_states(slurm_ids):
    """{SLURM id: state} (``TIMEOUT``, ``CANCELLED`` …) of the jobs ``slurm_ids`` from the
    cluster's accounting (one ``sacct``) or, without it, from the controller (``scontrol``,
    which keeps an ended job for ``MinJobAge`` seconds); a job neither knows is left out."""
    listed = _answer(["sacct", "--noheader", "--allocations", "--parsable2",
                      "--format=JobID,State", "--jobs", ",".join(slurm_ids)])
    states = {}
    for line in listed.splitlines():
        slurm_id, _, state = line.partition("|")
        if slurm_id in slurm_ids and state:
            states[slurm_id] = state.split()[0]
    for slurm_id in set(slurm_ids) - set(states):
        if found := re.search(r"JobState=(\w+)", _answer(["scontrol", "show", "job", slurm_id])):
            states[slurm_id] = found.group(1)
    return states


def report_stopped(stopped, sweep_dir, timeout):
    """One line on the jobs of a SLURM sweep that a signal stopped (``stopped``: their
    status entries), naming the time limit when it was the cause: the warning before it
    came, or SLURM says so."""
    numbers = ", ".join(str(job["job"]) for job in stopped)
    states = scheduler_states([job["slurm_job"] for job in stopped if job.get("slurm_job")])
    limit = [job for job in stopped if job.get("signal") == time_limit_warning().name
             or states.get(job.get("slurm_job")) == "TIMEOUT"]
    one = len(stopped) == 1
    cause = (f"reached the time limit hydra.launcher.timeout_min={timeout}" if limit
             else f"{'was' if one else 'were'} cancelled (scancel, or the scheduler)")
    return (f"sim: {'job' if one else 'jobs'} {numbers} of the sweep {cause}; what they "
            f"wrote is kept, and the same command with hydra.sweep.dir={sweep_dir} continues "
            f"them"
            + (" (with a longer hydra.launcher.timeout_min)" if limit else ""))


def refused(error):
    """Whether submitit's ``error`` is SLURM refusing the jobs (``sbatch`` failed): nothing
    was queued."""
    return "Batch job submission failed" in str(error)


def scheduler_error(error, sweep_dir, launcher):
    """One line for an error of submitit: the scheduler refused the jobs (its messages, and
    the launcher's setting they speak of, from the launcher config ``launcher``), or a job
    ended without a result (killed by the scheduler, a node lost)."""
    if refused(error):
        said = [line.split("sbatch: error:", 1)[1].strip() for line in str(error).splitlines()
                if "sbatch: error:" in line]
        text = "; ".join(part.replace("Batch job submission failed: ", "") for part in said)
        setting = next((f" (hydra.launcher.{key}={launcher.get(key)})"
                        for word, key in REFUSED_SETTINGS if word in text.lower()), "")
        return f"sim: SLURM refused the jobs{setting}: {text}"
    first = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
    return (f"sim: a job of the sweep ended without a result ({first}); the same command "
            f"with hydra.sweep.dir={sweep_dir} continues its jobs")


def resource_table():
    """The Markdown table of what each job asks of the scheduler by default (the docs'
    cluster page)."""
    return "\n".join([
        "| setting | from |", "| --- | --- |",
        f"| `hydra.launcher.mem_gb` | the largest run's memory estimate × {MEMORY_MARGIN:g} |",
        f"| `hydra.launcher.timeout_min` | twice the longest run's `stop.collisions` (or "
        f"`stop.contacts`) at {ASSUMED_RATE:,.0f} collisions per second, or its "
        f"`stop.wall_seconds`, and {START_MINUTES} minutes for its start; runs that none of "
        f"them bounds (a crater to its energy fraction) keep the launcher's value |",
        "| `hydra.launcher.partition` | the cluster's default partition |"])
