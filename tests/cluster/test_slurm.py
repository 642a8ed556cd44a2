"""Sweeps through a real SLURM (``make cluster-test``, not part of ``make test``): a cluster of
one node on this machine (:mod:`slurm`), and ``python -m sim … hydra/launcher=submitit_slurm
-m`` as a user types it.

A sweep of the melting scene (N = 72 at two φ) has one job cancelled with ``scancel`` while
it runs; the same command then finishes that job alone and the sweep ends on the bits of the
same sweep never interrupted (run here without a cluster); a compress sweep runs whole. What
each job asks of the scheduler comes from the runs' estimates; a partition that does not
exist, a time limit beyond the partition's and one too short for the runs reach the user as
one line naming the setting."""

import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np
import pytest
import slurm

from sim.analysis.datasets import open_sweep

pytestmark = pytest.mark.cluster

#: the melting sweep: N = 72 at two φ, long enough (10⁸ collisions, some 30 s) to be
#: cancelled while it runs
MELTING = ["scenario=melting", "disks.n=72", "disks.packing_fraction=0.70,0.71",
           "stop.collisions=100000000", "output.every_collisions=1000000"]
COMPRESS = ["scenario=compress", "disks.n=100", "growth.rate=0.3,1.0"]
SLURM = ["hydra/launcher=submitit_slurm"]
#: seconds a sweep may take before the test gives up on it
PATIENCE = 600


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    try:
        with slurm.local_slurm(tmp_path_factory.mktemp("slurm")) as config:
            yield config
    except slurm.Unavailable as why:
        pytest.skip(f"no SLURM cluster here: {why}")


def sim(*args, folder, wait=True):
    """``python -m sim ARGS hydra.sweep.dir=folder -m`` from the repository's root: the
    finished process (stdout and stderr as text), or the running one."""
    command = [sys.executable, "-m", "sim", *args, f"hydra.sweep.dir={folder}", "-m"]
    root = Path(__file__).resolve().parents[2]
    if not wait:
        return subprocess.Popen(command, cwd=root, stdout=subprocess.PIPE,
                                stderr=subprocess.PIPE, text=True)
    return subprocess.run(command, cwd=root, capture_output=True, text=True, timeout=PATIENCE)


def said(process_or_result, stderr=None):
    """The lines sim said (those that begin with ``sim:``)."""
    text = stderr if stderr is not None else process_or_result.stderr
    return [line for line in text.splitlines() if line.startswith("sim:")]


def running_jobs():
    """SLURM ids (``<array>_<task>``) of the jobs running now."""
    listed = subprocess.run(["squeue", "--noheader", "--array", "--format=%i %T"],
                            capture_output=True, text=True, check=True).stdout.split("\n")
    return [line.split()[0] for line in listed if line.strip().endswith("RUNNING")]


def last_frames(folder):
    """{job folder: (positions, velocities) of its run's last snapshot}."""
    frames = {}
    for path in sorted(Path(folder).glob("*/run.h5")):
        with h5py.File(path) as f:
            frames[path.parent.name] = (f["particles/disks/position/value"][-1],
                                        f["particles/disks/velocity/value"][-1])
    return frames


def test_a_job_cancelled_goes_on_alone_to_the_bits_of_a_sweep_never_interrupted(cluster,
                                                                                 tmp_path):
    sweep = tmp_path / "slurm"
    started = sim(*MELTING, *SLURM, folder=sweep, wait=False)
    deadline = time.monotonic() + PATIENCE
    while not (begun := [job for job in running_jobs()
                         if (sweep / job.partition("_")[2] / "run.h5").exists()]):
        assert started.poll() is None and time.monotonic() < deadline, started.communicate()
        time.sleep(0.5)
    time.sleep(2.0)  # well into its run
    subprocess.run(["scancel", begun[0]], check=True)
    _, stderr = started.communicate(timeout=PATIENCE)
    assert started.returncode == 143, stderr
    lines = said(None, stderr)
    assert lines[0].startswith("sim: each SLURM job asks for")
    assert "cancelled (scancel" in lines[-1] and f"hydra.sweep.dir={sweep}" in lines[-1]
    summary = (sweep / "sweep_summary.yaml").read_text()
    assert "stopped: 1" in summary and "signal: SIGTERM" in summary
    whole = {p: p.stat().st_mtime_ns for p in sweep.glob("*/run.h5")
             if "COMPLETED" in (p.parent / "job_status.yaml").read_text()}
    assert len(whole) == 1
    again = sim(*MELTING, *SLURM, folder=sweep)  # the same command
    assert again.returncode == 0, again.stderr
    assert {p: p.stat().st_mtime_ns for p in whole} == whole  # the finished job not rerun
    never = tmp_path / "here"
    assert sim(*MELTING, folder=never).returncode == 0
    slurm_frames, frames = last_frames(sweep), last_frames(never)
    assert slurm_frames.keys() == frames.keys() == {"0", "1"}
    for job, (position, velocity) in frames.items():
        assert np.array_equal(slurm_frames[job][0], position)
        assert np.array_equal(slurm_frames[job][1], velocity)
    read = open_sweep(sweep)
    assert read.sizes["disks_packing_fraction"] == 2
    assert set(read["stop_reason"].values.ravel()) == {"collisions"}


def test_a_job_cancelled_as_it_starts_is_left_unrun_and_the_same_command_runs_it(cluster,
                                                                                tmp_path):
    """SIGTERM while the job starts, before its run (submitit would pass it over and SLURM's
    SIGKILL follow, leaving no result): the job ends stopped at once, and the same command
    runs it whole."""
    one = [*MELTING[:2], "disks.packing_fraction=0.70", "stop.collisions=7200000",
           MELTING[-1]]
    started = sim(*one, *SLURM, folder=tmp_path, wait=False)
    deadline = time.monotonic() + PATIENCE
    while not (tmp_path / "0").exists():  # Hydra made its folder: the job has begun
        assert started.poll() is None and time.monotonic() < deadline, started.communicate()
        time.sleep(0.05)
    subprocess.run(["scancel", running_jobs()[0]], check=True)
    _, stderr = started.communicate(timeout=PATIENCE)
    assert started.returncode == 143, stderr
    assert "cancelled (scancel" in said(None, stderr)[-1]
    assert "status: STOPPED" in (tmp_path / "0" / "job_status.yaml").read_text()
    again = sim(*one, *SLURM, folder=tmp_path)
    assert again.returncode == 0, again.stderr
    with h5py.File(tmp_path / "0" / "run.h5") as f:
        assert f["parameters"].attrs["stop_reason"] == "collisions"


def test_each_job_asks_what_its_runs_need_and_a_compress_sweep_runs_whole(cluster, tmp_path):
    done = sim(*COMPRESS, *SLURM, folder=tmp_path)
    assert done.returncode == 0, done.stderr
    # no count of collisions bounds a compression: the launcher's time limit stands
    assert "the runs' stop conditions bound no count of collisions" in said(done)[0]
    script = next(tmp_path.glob(".submitit/*/*_submission.sh")).read_text()
    assert "#SBATCH --mem=1GB" in script
    read = open_sweep(tmp_path)
    assert read.sizes["growth_rate"] == 2
    assert set(read["stop_reason"].values.ravel()) == {"jamming"}


def test_the_schedulers_refusals_are_one_line_naming_the_setting(cluster, tmp_path):
    small = ["scenario=melting", "disks.n=72", "disks.packing_fraction=0.70,0.71",
             "stop.collisions=72000"]
    for setting, allowed in (("hydra.launcher.partition=nowhere", "a partition of this "
                                                                  "cluster: sim"),
                             ("hydra.launcher.timeout_min=100000", "at most the 1440 "
                                                                   "minutes of partition sim")):
        refused = sim(*small, *SLURM, setting, folder=tmp_path / "refused")
        assert refused.returncode == 2
        assert said(refused) == [line for line in refused.stderr.splitlines() if line]
        assert len(said(refused)) == 1 and setting.split("=")[0] in said(refused)[0]
        assert allowed in said(refused)[0]
        assert not (tmp_path / "refused").exists()
    # memory no node has: sbatch refuses (its own lines come first, as submitit prints them)
    memory = sim(*small, *SLURM, "hydra.launcher.mem_gb=100000", folder=tmp_path / "memory")
    assert memory.returncode == 2
    assert said(memory)[-1].startswith("sim: SLURM refused the jobs (hydra.launcher.mem_gb="
                                       "100000): Memory specification can not be satisfied")
    assert not (tmp_path / "memory").exists()
    endless = [*MELTING[:-2], "stop.collisions=1000000000"]  # far beyond a minute
    short = sim(*endless, *SLURM, "hydra.launcher.timeout_min=1", folder=tmp_path / "short")
    assert short.returncode == 143, short.stderr
    assert "reached the time limit hydra.launcher.timeout_min=1" in said(short)[-1]
    # SLURM's warning before the limit (SIGUSR2), or its SIGTERM at the limit
    assert "stopped: 2" in (tmp_path / "short" / "sweep_summary.yaml").read_text()
    with h5py.File(next((tmp_path / "short").glob("*/run.h5"))) as f:
        assert f["parameters"].attrs["stop_reason"] == "terminated"

