"""Damaged run files: every dataset carries a fletcher32 checksum, so bytes flipped on the
disk are found. ``sim.storage.inspect`` names the damaged snapshots and exits 1, ``open_run`` reads
the intact frames and gives NaN for the damaged ones, resume falls back to the older
checkpoint; a file written without checksums still opens, and a file a run is still writing
is named as such."""

import json
import shutil
import subprocess
import sys

import h5py
import numpy as np
import pytest

from sim.analysis.datasets import open_run
from sim.pipeline import runner
from sim.pipeline.config import ConfigError
from sim.pipeline.run_cache import compose_config
from sim.storage.errors import RunFileError
from sim.storage.h5md import RunWriter, read_checkpoint
from sim.storage.inspect import main, summary

#: 300 disks, 17 snapshots, checkpoints at the first snapshot (slot a) and the last (slot b)
RUN = ["disks.n=300", "stop.collisions=4000", "output.every_collisions=250",
       "output.progress=false"]
POSITION = "particles/disks/position/value"


@pytest.fixture(scope="module")
def intact(tmp_path_factory):
    return runner.run(compose_config(RUN), tmp_path_factory.mktemp("intact"))


def flip(path, dataset, chunk):
    """Change four bytes in the middle of chunk number ``chunk`` of ``dataset`` (not by
    inverting them: fletcher32 cannot tell a 16-bit word 0x0000 from 0xFFFF)."""
    with h5py.File(path, "r") as f:
        info = f[dataset].id.get_chunk_info(chunk)
    with open(path, "r+b") as file:
        file.seek(info.byte_offset + info.size // 2)
        data = file.read(4)
        file.seek(info.byte_offset + info.size // 2)
        file.write(bytes(b ^ 0x5A for b in data))


def damaged_copy(intact, folder, *chunks):
    """A copy of ``intact`` in ``folder`` with each (dataset, chunk) of ``chunks`` flipped."""
    path = folder / "run.h5"
    shutil.copy(intact, path)
    for dataset, chunk in chunks:
        flip(path, dataset, chunk)
    return path


def read(path, name):
    with h5py.File(path, "r") as f:
        return f[name][()]


def latest_slot(path):
    with h5py.File(path, "r") as f:
        return str(f["checkpoint"].attrs["latest"])


def test_every_dataset_has_a_checksum_and_an_intact_file_exits_0(intact, capsys):
    with h5py.File(intact, "r") as f:
        datasets = []
        f.visititems(lambda name, item: datasets.append(item)
                     if isinstance(item, h5py.Dataset) else None)
        assert [d.name for d in datasets if not d.fletcher32] == []
    info = summary(intact)
    assert info["damaged"] == [] and info["checksums"] == "all"
    assert main([str(intact)]) == 0
    assert "damaged            nothing" in capsys.readouterr().out


def test_inspect_names_the_damaged_snapshots_and_exits_1(intact, tmp_path, capsys):
    path = damaged_copy(intact, tmp_path, (POSITION, 5), (POSITION, 6),
                        ("observables/kinetic_energy_by_species/value", 3))
    times = read(intact, "particles/disks/position/time")
    assert main([str(path)]) == 1
    lines = capsys.readouterr().out.splitlines()
    assert [line.split(None, 1)[1] for line in lines if line.startswith("damaged")] == [
        f"position at snapshots 5 (t = {times[5]:.6g}), 6 (t = {times[6]:.6g}): checksum "
        f"mismatch; kinetic_energy_by_species at snapshot 3 (t = {times[3]:.6g}): checksum "
        f"mismatch"]
    assert main([str(path), "--json"]) == 1
    info = json.loads(capsys.readouterr().out)
    assert [(d["name"], d["snapshots"], d["times"]) for d in info["damaged"]] == [
        ("position", [5, 6], times[5:7].tolist()),
        ("kinetic_energy_by_species", [3], [times[3]])]
    whole = summary(intact)
    assert {k: v for k, v in info.items() if k not in ("path", "damaged")} == {
        k: v for k, v in whole.items() if k not in ("path", "damaged")}


def test_energies_are_summed_up_over_the_intact_snapshots_only(intact, tmp_path):
    """The scalar observables hold 1024 snapshots per chunk: one flipped byte takes every
    snapshot of this short run, and nothing is left to compute an energy from."""
    path = damaged_copy(intact, tmp_path, ("observables/kinetic_energy/value", 0))
    info = summary(path)
    assert [(d["name"], d["snapshots"]) for d in info["damaged"]] == [
        ("kinetic_energy", list(range(17)))]
    assert info["initial_energy"] is None and info["final_energy"] is None
    assert info["energy_drift"] is None
    assert info["collisions"] == summary(intact)["collisions"]


def test_open_run_gives_nan_for_damaged_snapshots_and_the_rest_bit_for_bit(intact, tmp_path):
    path = damaged_copy(intact, tmp_path, (POSITION, 5),
                        ("observables/kinetic_energy_by_species/value", 3))
    times = read(intact, "particles/disks/position/time")
    with pytest.warns(RuntimeWarning) as opened:
        ds = open_run(path)
    with ds:
        assert [str(w.message) for w in opened] == [
            f"{path}: damaged, read as NaN: kinetic_energy_by_species at snapshot 3 "
            f"(t = {times[3]:.6g}): checksum mismatch"]
        assert ds.attrs["damaged"] == [f"kinetic_energy_by_species at snapshot 3 "
                                       f"(t = {times[3]:.6g}): checksum mismatch"]
        by_species = ds["kinetic_energy_by_species"].values
        whole = read(intact, "observables/kinetic_energy_by_species/value")
        assert np.isnan(by_species[3]).all()
        np.testing.assert_array_equal(np.delete(by_species, 3, 0), np.delete(whole, 3, 0))
        np.testing.assert_array_equal(ds["position"].isel(time=4).values,
                                      read(intact, POSITION)[4])  # no warning: intact
        with pytest.warns(RuntimeWarning) as meeting:
            positions = ds["position"].values
        assert [str(w.message) for w in meeting] == [
            f"{path}: position at snapshot 5 (t = {times[5]:.6g}): checksum mismatch; "
            f"read as NaN"]
        assert np.isnan(positions[5]).all()
        np.testing.assert_array_equal(np.delete(positions, 5, 0),
                                      np.delete(read(intact, POSITION), 5, 0))
        with pytest.warns(RuntimeWarning, match="position at snapshot 5 "):
            assert np.isnan(ds["position"].isel(time=slice(3, 8, 2), disk=0).values[1]).all()
        np.testing.assert_array_equal(ds["velocity"].values,
                                      read(intact, "particles/disks/velocity/value"))


def test_a_damaged_radius_is_an_error_naming_it(intact, tmp_path):
    path = damaged_copy(intact, tmp_path, ("particles/disks/radius", 0))
    with pytest.raises(RunFileError, match=r"particles/disks/radius is damaged \(checksum "
                                           r"mismatch\); the run file cannot be read without"):
        open_run(path)
    assert [d["name"] for d in summary(path)["damaged"]] == ["particles/disks/radius"]


def interrupted(path):
    """Mark the run at ``path`` as stopped before its end, as Ctrl-C leaves it."""
    with h5py.File(path, "r+") as f:
        f["parameters"].attrs["stop_reason"] = "interrupted"


def test_resume_falls_back_to_the_older_checkpoint_when_the_latest_is_damaged(intact, tmp_path):
    slot = latest_slot(intact)
    path = damaged_copy(intact, tmp_path, (f"checkpoint/{slot}/disks/table", 0))
    interrupted(path)
    info = summary(path)
    assert [(d["name"], d["latest"], d["snapshot"]) for d in info["damaged"]] == [
        (f"checkpoint slot {slot}", True, 16)]
    with h5py.File(path, "r") as f, pytest.warns(
            RuntimeWarning, match=f"checkpoint slot {slot} is damaged; resuming from slot a, "
                                  f"the checkpoint of snapshot 0 "):
        assert read_checkpoint(f)[2] == 1
    written = []  # the slot each new checkpoint goes to: never the only intact one
    original = RunWriter._checkpoint

    def recording(self, engine, t):
        written.append("b" if self.file["checkpoint"].attrs["latest"] == "a" else "a")
        original(self, engine, t)

    with pytest.warns(RuntimeWarning, match=f"slot {slot} is damaged"), \
            pytest.warns(RuntimeWarning, match="the 16 snapshots written after it"):
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(RunWriter, "_checkpoint", recording)
            runner.resume(path)
    assert written[0] == slot
    assert summary(path)["stop_reason"] == "collisions"
    assert summary(path)["damaged"] == []  # the damaged slot was written again
    for name in (POSITION, "observables/collisions/value"):
        np.testing.assert_array_equal(read(path, name), read(intact, name), err_msg=name)


def test_resume_refuses_when_both_checkpoints_are_damaged(intact, tmp_path):
    path = damaged_copy(intact, tmp_path, ("checkpoint/a/disks/table", 0),
                        ("checkpoint/b/disks/table", 0))
    interrupted(path)
    message = "both checkpoints are damaged; the run cannot be resumed; start it again"
    with h5py.File(path, "r") as f, pytest.raises(RunFileError, match=message):
        read_checkpoint(f)
    with pytest.raises((RunFileError, ConfigError), match=message):
        runner.resume(path)


def test_a_file_written_without_checksums_opens_and_resumes(intact, tmp_path, monkeypatch):
    create = h5py.Group.create_dataset

    def without_checksum(self, name, *args, fletcher32=False, **kwargs):
        return create(self, name, *args, **kwargs)

    monkeypatch.setattr(h5py.Group, "create_dataset", without_checksum)
    path = runner.run(compose_config(RUN), tmp_path)
    monkeypatch.undo()
    with h5py.File(path, "r+") as f:  # as before checksums: a scalar is a 0-d dataset
        for slot in ("a", "b"):
            energy = f[f"checkpoint/{slot}/initial_energy"][0]
            del f[f"checkpoint/{slot}/initial_energy"]
            f[f"checkpoint/{slot}/initial_energy"] = energy
    info = summary(path)
    assert info["checksums"] == "none" and info["damaged"] == []
    assert main([str(path)]) == 0
    with open_run(path) as ds:
        assert ds.attrs["damaged"] == []
        np.testing.assert_array_equal(ds["position"].values, read(path, POSITION))
    interrupted(path)
    with h5py.File(path, "r+") as f:  # as a run killed after its first checkpoint leaves it
        f["checkpoint"].attrs["latest"] = "a"
    with pytest.warns(RuntimeWarning, match="snapshots written after it"):
        runner.resume(path)  # from snapshot 0; the checkpoints are written again with checksums
    assert summary(path)["stop_reason"] == "collisions"
    np.testing.assert_array_equal(read(path, POSITION), read(intact, POSITION))
    with h5py.File(path, "r") as f:
        assert all(f[f"checkpoint/{slot}/initial_energy"].fletcher32 for slot in "ab")


HOLDER = """import sys, time, h5py
f = h5py.File(sys.argv[1], "a")
print("open", flush=True)
time.sleep(600)
"""


def test_a_file_open_for_writing_in_another_process_is_named_so(intact, tmp_path, capsys):
    path = tmp_path / "run.h5"
    shutil.copy(intact, path)
    with subprocess.Popen([sys.executable, "-c", HOLDER, str(path)], stdout=subprocess.PIPE,
                          text=True) as holder:
        try:
            assert holder.stdout.readline() == "open\n"
            message = (f"{path} is open for writing in another process (a run still going?); "
                       f"read it when that run has ended")
            for reader in (summary, open_run):
                with pytest.raises(RunFileError) as error:
                    reader(path)
                assert str(error.value) == message
            assert main([str(path)]) == 2
            assert capsys.readouterr().err == f"sim-inspect: {message}\n"
        finally:
            holder.kill()


def test_one_error_for_a_run_file_that_cannot_be_read_or_written():
    """The reader's and the runner's errors are one class, an OSError, under its old names."""
    import sim.storage.inspect

    assert sim.storage.inspect.RunFileError is runner.RunFileError is RunFileError
    assert issubclass(RunFileError, OSError)
