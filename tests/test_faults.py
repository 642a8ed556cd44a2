"""Faults: runs killed at random moments, Ctrl-C, a full disk, a folder that cannot be
written; each leaves a readable file (or none) and a clear message, and resume continues to
the same bits."""

import resource
import signal
import subprocess
import sys
import time
import warnings

import h5py
import numpy as np
import pytest

import sim.storage.h5md
from sim.pipeline import runner
from sim.pipeline.run_cache import compose_config
from sim.storage.errors import RunFileError
from sim.storage.inspect import summary

#: a gas that runs for a few seconds, to be killed in the middle: 2000 disks, 300 snapshots;
#: frames are flushed at least every second, and only the first snapshot is checkpointed
#: before the end (checkpoints come every 30 s), so resume starts from it and makes every frame
#: after it again
LONG_RUN = ["disks.n=2000", "stop.collisions=6000000", "output.every_collisions=20000",
            "output.progress=false"]


def cli(*args, cwd, **options):
    return subprocess.Popen([sys.executable, "-m", "sim", *args], cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **options)


def frames(path):
    with h5py.File(path, "r") as f:
        return (f["particles/disks/position/step"][()], f["particles/disks/position/value"][()],
                str(f["parameters"].attrs["stop_reason"]))


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("whole")
    return runner.run(compose_config(LONG_RUN), folder)


def run_until_killed(folder, after_seconds, how):
    process = cli(*LONG_RUN, f"hydra.run.dir={folder}", cwd=folder)
    for _ in range(12000):  # compiling; the clock starts with the run file
        if (folder / "run.h5").exists() or process.poll() is not None:
            break
        time.sleep(0.05)
    time.sleep(after_seconds)
    process.send_signal(how)
    out, err = process.communicate(timeout=300)
    return process.returncode, err


@pytest.mark.parametrize("after_seconds", [0.3, pytest.param(1.1, marks=pytest.mark.slow)])
def test_a_run_killed_at_any_moment_opens_and_resumes_to_the_same_bits(
        after_seconds, uninterrupted, tmp_path):
    code, _ = run_until_killed(tmp_path, after_seconds, signal.SIGKILL)
    assert code == -signal.SIGKILL
    path = tmp_path / "run.h5"
    info = summary(path)  # opens, with every frame flushed before the kill
    assert info["stop_reason"] == "running"
    with h5py.File(path, "r") as f:  # frames flushed after the last checkpoint
        root = f["checkpoint"]
        dropped = info["snapshots"] - root[root.attrs["latest"]].attrs["snapshots"]
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        runner.resume(path)
    assert [str(w.message).split("; ")[1].split(",")[0] for w in said] == (
        [f"the {dropped} snapshots written after it"] if dropped else [])
    steps, positions, reason = frames(path)
    whole_steps, whole_positions, _ = frames(uninterrupted)
    assert reason == "collisions"
    np.testing.assert_array_equal(steps, whole_steps)
    np.testing.assert_array_equal(positions, whole_positions)


@pytest.mark.slow
@pytest.mark.parametrize("after_seconds", np.round(np.random.default_rng(9).uniform(0.0, 4.0, 20),
                                                   2).tolist())
def test_twenty_random_kills(after_seconds, uninterrupted, tmp_path):
    test_a_run_killed_at_any_moment_opens_and_resumes_to_the_same_bits(
        after_seconds, uninterrupted, tmp_path)


def test_ctrl_c_stops_with_a_final_snapshot_and_resume_finishes_the_run(uninterrupted,
                                                                         tmp_path):
    """SIGINT: the chunk ends, a final snapshot and checkpoint are written, the run ends as
    ``interrupted`` with exit status 130 and a hint; resume gives the uninterrupted frames,
    and at most the interruption's own frame between them (none when it came at a snapshot,
    as here: a snapshot interval is shorter than a compiled chunk)."""
    code, err = run_until_killed(tmp_path, 1.0, signal.SIGINT)
    assert code == 130
    assert "resume=" in err.strip().splitlines()[-1]
    path = tmp_path / "run.h5"
    steps, _, reason = frames(path)
    assert reason == "interrupted"
    with h5py.File(path, "r") as f:  # the final frame is the checkpointed state
        checkpoint = f["checkpoint"][f["checkpoint"].attrs["latest"]]
        assert checkpoint.attrs["snapshots"] == steps.size
    runner.resume(path)
    steps, positions, reason = frames(path)
    whole_steps, whole_positions, _ = frames(uninterrupted)
    assert reason == "collisions"
    common = np.isin(steps, whole_steps)
    assert common.sum() == whole_steps.size and (~common).sum() <= 1
    np.testing.assert_array_equal(positions[common], whole_positions)


def test_a_disk_that_fills_up_stops_the_run_before_a_write_and_keeps_the_file(
        tmp_path, monkeypatch):
    calls = {"n": 0}

    def filling_up(folder):
        calls["n"] += 1
        return 10**12 if calls["n"] <= 3 else sim.storage.h5md.DISK_MARGIN_BYTES // 2

    monkeypatch.setattr(sim.storage.h5md, "free_bytes", filling_up)
    cfg = compose_config(["disks.n=500", "stop.collisions=200000",
                          "output.every_collisions=1000", "output.progress=false"])
    with pytest.raises(RunFileError, match="free some room and resume"):
        runner.run(cfg, tmp_path)
    monkeypatch.undo()
    info = summary(tmp_path / "run.h5")
    assert info["stop_reason"].startswith("error: disk full")
    assert info["snapshots"] >= 1
    runner.resume(tmp_path / "run.h5")
    assert summary(tmp_path / "run.h5")["stop_reason"] == "collisions"


def test_a_write_the_system_refuses_ends_with_one_line(tmp_path):
    """A file-size limit (``ulimit -f``) is checked before every write as the disk's free
    room is: the run stops before the write that would cross it, exit status 1, one line,
    and the file stays readable."""
    def limited():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (4 << 20, 4 << 20))

    process = cli("disks.n=2000", "output.every_collisions=1000", f"hydra.run.dir={tmp_path}",
                  cwd=tmp_path, preexec_fn=limited)
    _, err = process.communicate(timeout=300)
    assert process.returncode == 1
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("sim: stopped before writing to")
    assert "ulimit -f" in lines[0]
    info = summary(tmp_path / "run.h5")  # readable, with what its last flush wrote
    assert info["stop_reason"].startswith("error: file size limit") and info["snapshots"] >= 1


#: the command line with a file-size limit that the writer's check cannot see: the operating
#: system refuses a write half-way, as a disk that fills up faster than checked would
UNFORESEEN_LIMIT = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, (4 << 20, 4 << 20))
import sim.storage.h5md
sim.storage.h5md.size_limit = lambda: float("inf")
from sim.pipeline.cli import main
sys.argv = ["sim", *sys.argv[1:]]
main()
"""


def test_a_write_the_system_refuses_unforeseen_ends_with_one_line(tmp_path):
    process = subprocess.run([sys.executable, "-c", UNFORESEEN_LIMIT, "disks.n=2000",
                              "output.every_collisions=1000", "output.progress=false",
                              f"hydra.run.dir={tmp_path}"], cwd=tmp_path, capture_output=True,
                             text=True, timeout=300)
    lines = [line for line in process.stderr.splitlines() if line.strip()]
    assert process.returncode == 1
    assert len(lines) == 1 and lines[0].startswith("sim: writing the run file"), lines


#: a failed HDF5 write that escapes every report of the run: h5py's own traceback of it is
#: passed over, so the command must still say it, in one line, at exit
UNREPORTED_FAILURE = """
import atexit, sys
from sim.pipeline import cli_exits
sys.excepthook = cli_exits.quiet_hdf5_traceback
atexit.register(cli_exits.report_passed_over)
raise OSError("Driver write request failed (file write failed: errno = 27, "
              "error message = 'File too large')")
"""


def test_a_failed_write_that_nothing_reported_is_said_at_exit(tmp_path):
    process = subprocess.run([sys.executable, "-c", UNREPORTED_FAILURE], cwd=tmp_path,
                             capture_output=True, text=True, timeout=300)
    lines = [line for line in process.stderr.splitlines() if line.strip()]
    assert process.returncode == 1
    assert len(lines) == 1 and lines[0].startswith("sim: writing the run file failed:"), lines


def test_a_folder_that_cannot_be_written_is_a_clear_error(tmp_path):
    cfg = compose_config(["disks.n=100", "output.progress=false"])
    with pytest.raises(RunFileError, match="cannot write the run file /proc/x/run.h5"):
        runner.run(cfg, "/proc/x")
    process = cli("disks.n=100", "hydra.run.dir=/proc/x", cwd=tmp_path)
    _, err = process.communicate(timeout=300)
    assert process.returncode == 1
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("sim: cannot write in the run folder /proc/x")
