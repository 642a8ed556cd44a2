"""A SLURM cluster of one node on this machine, for ``make cluster-test``.

:func:`local_slurm` installs Debian's ``slurm-wlm`` and ``munge`` when their programs are
missing (``apt-get``, as root), writes a ``slurm.conf`` of one controller and one node (this
machine, its cores and memory) and one partition into a folder of its own, starts ``munged``,
``slurmctld`` and ``slurmd`` with it, waits until ``sinfo`` shows the node idle and, whatever
happens, stops all three at the end. Every SLURM command the tests run, submitit's ``sbatch``
among them, finds the cluster through ``SLURM_CONF``, set in the environment while it runs.
:class:`Unavailable` says in one line why there can be no cluster here (not root, no
``apt-get``).
"""

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

#: the programs a cluster needs, and the Debian packages that bring them
PROGRAMS = ("munged", "slurmctld", "slurmd", "sinfo", "sbatch", "squeue", "scancel", "sacct")
PACKAGES = ("slurm-wlm", "munge")
#: the partition of the cluster, and its time limit (minutes)
PARTITION, MAX_MINUTES = "sim", 1440
#: seconds to wait for the node to come up idle, and for a daemon to stop
STARTUP_SECONDS, STOP_SECONDS = 60.0, 20.0


class Unavailable(Exception):
    """No cluster can be made on this machine; the message says why, in one line."""


def install():
    """Install the packages of :data:`PROGRAMS` that are missing, saying so; Unavailable
    without root, or without apt-get when a program is missing."""
    missing = [p for p in PROGRAMS if shutil.which(p) is None]
    if os.geteuid() != 0:
        raise Unavailable("the cluster's daemons (munged, slurmctld, slurmd) run as root"
                          + (f", and {', '.join(missing)} are missing" if missing else ""))
    if not missing:
        return
    if shutil.which("apt-get") is None:
        raise Unavailable(f"{', '.join(missing)} missing, and installing "
                          f"{' '.join(PACKAGES)} needs root and apt-get")
    print(f"cluster: installing {' '.join(PACKAGES)} ({', '.join(missing)} missing)",
          flush=True)
    quiet = {"env": dict(os.environ, DEBIAN_FRONTEND="noninteractive"),
             "stdout": subprocess.DEVNULL}
    subprocess.run(["apt-get", "update", "-q"], check=True, **quiet)
    subprocess.run(["apt-get", "install", "-y", "-q", "--no-install-recommends", *PACKAGES],
                   check=True, **quiet)


def memory_mb():
    """The machine's memory (MB), less a quarter for what is not the jobs'."""
    pages = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    return int(0.75 * pages / 2**20)


def write_config(folder, cores=None):
    """``slurm.conf`` in ``folder`` for a controller and one node on this host, ``cores``
    CPUs (all of the machine's) and :func:`memory_mb`, in one partition :data:`PARTITION`
    whose jobs may run :data:`MAX_MINUTES`;
    returns its path. Jobs are tracked by process group (no cgroups in a container); a job
    cancelled gets SIGTERM and KillWait seconds before SIGKILL."""
    host = socket.gethostname()
    folder = Path(folder)
    (folder / "state").mkdir(parents=True, exist_ok=True)
    (folder / "spool").mkdir(exist_ok=True)
    config = folder / "slurm.conf"
    config.write_text(f"""\
ClusterName=simtest
SlurmctldHost={host}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation={folder / "state"}
SlurmdSpoolDir={folder / "spool"}
SlurmctldPidFile={folder / "slurmctld.pid"}
SlurmdPidFile={folder / "slurmd.pid"}
SlurmctldLogFile={folder / "slurmctld.log"}
SlurmdLogFile={folder / "slurmd.log"}
SlurmdDebug=debug
ProctrackType=proctrack/pgid
TaskPlugin=task/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
KillWait=30
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SlurmdTimeout=60
InactiveLimit=0
MinJobAge=600
NodeName={host} CPUs={cores or os.cpu_count()} RealMemory={memory_mb()} State=UNKNOWN
PartitionName={PARTITION} Nodes={host} Default=YES MaxTime={MAX_MINUTES} State=UP
""")
    return config


def _stop(process):
    """Stop a daemon started by :func:`local_slurm`: SIGTERM, then SIGKILL."""
    if process.poll() is not None:
        return
    process.send_signal(signal.SIGTERM)
    try:
        process.wait(STOP_SECONDS)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def _drain(environment):
    """Cancel every job of the cluster and wait (at most STOP_SECONDS) until none is left:
    a job step that outlives the controller waits for it for ever (its ``slurmstepd`` was
    seen still there 20 minutes on)."""
    subprocess.run(["scancel", f"--partition={PARTITION}"], env=environment,
                   capture_output=True)
    deadline = time.monotonic() + STOP_SECONDS
    while time.monotonic() < deadline:
        listed = subprocess.run(["squeue", "--noheader"], env=environment,
                                capture_output=True, text=True)
        if listed.returncode != 0 or not listed.stdout.strip():
            return
        time.sleep(0.5)


def _node_idle(environment):
    state = subprocess.run(["sinfo", "--noheader", "--format=%t"], env=environment,
                           capture_output=True, text=True)
    return state.returncode == 0 and state.stdout.split() == ["idle"]


@contextlib.contextmanager
def local_slurm(folder, cores=None):
    """A running one-node cluster configured in ``folder`` (:func:`write_config`), its
    ``SLURM_CONF`` set in ``os.environ`` while it runs; yields the config's path."""
    install()
    config = write_config(folder, cores)
    environment = dict(os.environ, SLURM_CONF=str(config))
    started = []
    previous = os.environ.get("SLURM_CONF")
    try:
        munge = Path("/run/munge")
        munge.mkdir(parents=True, exist_ok=True)
        shutil.chown(munge, "munge", "munge")
        started.append(subprocess.Popen(["munged", "--foreground", "--force"],
                                        env=environment, stderr=subprocess.DEVNULL))
        for daemon in ("slurmctld", "slurmd"):
            started.append(subprocess.Popen([daemon, "-D"], env=environment,
                                            stdout=subprocess.DEVNULL,
                                            stderr=subprocess.DEVNULL))
        deadline = time.monotonic() + STARTUP_SECONDS
        while not _node_idle(environment):
            ended = [p.args[0] for p in started if p.poll() is not None]
            if ended or time.monotonic() > deadline:
                raise RuntimeError(f"the cluster did not come up: "
                                   f"{', '.join(ended) + ' ended' if ended else 'no idle node'}"
                                   f" (logs in {folder})")
            time.sleep(0.5)
        os.environ["SLURM_CONF"] = str(config)
        yield config
    finally:
        if previous is None:
            os.environ.pop("SLURM_CONF", None)
        else:
            os.environ["SLURM_CONF"] = previous
        if len(started) == 3 and all(p.poll() is None for p in started):
            _drain(environment)
        for process in reversed(started):
            _stop(process)
