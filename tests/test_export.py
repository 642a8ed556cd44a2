"""sim.storage.export: GSD and extended XYZ files read back to what the run file holds, frame
selections, one-line refusals that leave nothing behind, and freud's g(r) of the exported
GSD frames against the run's own ``radial_distribution`` observer.

GSD holds positions, velocities, diameters, masses and the box as float32 (the HOOMD
schema's type, gsd's default single precision): they are compared with the run's float64
values rounded once to float32, exactly; positions after undoing the −L/2 shift agree to half
a float32 ulp of L/2. XYZ holds float64 and is compared bit for bit. Rough disks: GSD's
moment_inertia and angmom against the run's ω and I = q m a², XYZ's spin column to the bit.
"""

import errno
import os
import shlex
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import freud
import gsd.hoomd
import h5py
import numpy as np
import pytest
import xarray as xr
import yaml

import sim.storage.export
from sim.analysis.datasets import open_run
from sim.pipeline.command import BadInput
from sim.pipeline.run_cache import compose_config
from sim.pipeline.runner import run
from sim.storage.export import CANNOT_HOLD, export, frame_indices, hoomd_positions, main, not_held


def make_run(folder, *overrides):
    return run(compose_config([*overrides, "output.progress=false"]), folder)


@pytest.fixture(scope="module")
def mixture(tmp_path_factory):
    """Two species (masses 1 and 4) in a walled box: 200 disks, 6 snapshots."""
    return make_run(tmp_path_factory.mktemp("mixture"), "scenario=mixture", "disks.n=200",
                    "stop.collisions=2000", "output.every_collisions=400")


@pytest.fixture(scope="module")
def gas(tmp_path_factory):
    """A periodic gas observing g(r) over 50 bins up to 4σ: 1000 disks, 21 snapshots."""
    return make_run(tmp_path_factory.mktemp("gas"), "box.boundary=periodic", "disks.n=1000",
                    "observe.radial_distribution.bins=50", "stop.collisions=10000",
                    "output.every_collisions=500")


@pytest.fixture(scope="module")
def rough(tmp_path_factory):
    """Rough disks cooling (spins from rest, β = 0.5): 200 disks, 5 snapshots."""
    return make_run(tmp_path_factory.mktemp("rough"), "scenario=rough_cooling", "disks.n=200",
                    "stop.collisions=2000", "output.every_collisions=500")


def sim_export(*argv):
    """The exit status of ``sim-export argv``, run in this process."""
    try:
        return main([str(a) for a in argv])
    except SystemExit as usage_error:
        return usage_error.code


def read_xyz(path):
    """Every frame of an extended XYZ file: the comment line's key=value pairs and the disk
    lines split into words."""
    frames = []
    with open(path) as f:
        while count := f.readline():
            keys = dict(item.split("=", 1) for item in shlex.split(f.readline()))
            frames.append((keys, [f.readline().split() for _ in range(int(count))]))
    return frames


@pytest.mark.parametrize("name", ["mixture", "gas"])
def test_gsd_frames_are_the_snapshots_in_float32(name, request, tmp_path):
    path = request.getfixturevalue(name)
    out = tmp_path / "run.gsd"
    assert sim_export(path, "--format", "gsd", "--out", out) == 0
    with open_run(path) as ds, gsd.hoomd.open(out) as trajectory:
        box = np.array(ds.attrs["box"])
        periodic = np.array([b == "periodic" for b in ds.attrs["boundary"]])
        half = box.astype(np.float32) / 2
        assert len(trajectory) == ds.sizes["time"]
        for i, frame in enumerate(trajectory):
            position, velocity = ds["position"][i].values, ds["velocity"][i].values
            assert frame.configuration.step == ds["step"].values[i]
            assert frame.log["sim/time"][0] == ds["time"].values[i]
            assert frame.log["sim/kinetic_energy"][0] == pytest.approx(
                ds["kinetic_energy"].values[i], rel=1e-12)
            assert frame.configuration.dimensions == 2
            np.testing.assert_array_equal(frame.configuration.box,
                                          np.float32([*box, 0, 0, 0, 0]))
            assert frame.particles.types == ["A", "B"][:ds.sizes["species"]]
            np.testing.assert_array_equal(frame.particles.typeid, ds["species_id"].values)
            np.testing.assert_array_equal(frame.particles.diameter,
                                          (2.0 * ds["radius"].values).astype(np.float32))
            np.testing.assert_array_equal(frame.particles.mass,
                                          ds["mass"].values.astype(np.float32))
            np.testing.assert_array_equal(frame.particles.velocity[:, :2],
                                          velocity.astype(np.float32))
            xy = frame.particles.position[:, :2]
            shifted = (position - box / 2).astype(np.float32)
            on_edge = periodic & (shifted == half)  # written at the image −L/2
            np.testing.assert_array_equal(xy, np.where(on_edge, -half, shifted))
            assert np.all((-half <= xy) & (xy < half))  # inside, as HOOMD requires
            unshifted = xy + box / 2 + np.where(on_edge, box, 0.0)
            assert np.all(np.abs(unshifted - position) <= 0.5 * np.spacing(half))
            assert not frame.particles.position[:, 2].any()
            assert not frame.particles.velocity[:, 2].any()


@pytest.mark.parametrize(("name", "pbc"), [("mixture", "F F F"), ("gas", "T T F")])
def test_xyz_frames_are_the_snapshots_to_the_bit(name, pbc, request, tmp_path):
    path = request.getfixturevalue(name)
    out = tmp_path / "run.xyz"
    assert sim_export(path, "--format", "xyz", "--out", out) == 0
    frames = read_xyz(out)
    with open_run(path) as ds:
        lx, ly = ds.attrs["box"]
        slab = 2.0 * ds["radius"].values.max()
        assert len(frames) == ds.sizes["time"]
        for i, (keys, lines) in enumerate(frames):
            assert keys["Properties"] == "type:I:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1"
            assert [float(x) for x in keys["Lattice"].split()] == [lx, 0, 0, 0, ly, 0, 0, 0,
                                                                   slab]
            assert [float(x) for x in keys["Origin"].split()] == [0, 0, -slab / 2]
            assert keys["pbc"] == pbc
            assert float(keys["Time"]) == ds["time"].values[i]
            assert int(keys["Step"]) == ds["step"].values[i]
            table = np.array(lines, dtype=np.float64)
            np.testing.assert_array_equal(table[:, 0], ds["species_id"].values)
            np.testing.assert_array_equal(table[:, 1:3], ds["position"][i].values)
            np.testing.assert_array_equal(table[:, 4:6], ds["velocity"][i].values)
            assert not table[:, [3, 6]].any()
            np.testing.assert_array_equal(table[:, 7], ds["radius"].values)
            np.testing.assert_array_equal(table[:, 8], ds["mass"].values)


def test_rough_disks_carry_their_spins_in_both_formats(rough, tmp_path):
    """GSD: moment_inertia (0, 0, I) and angmom (0, 0, 0, 2 I ω), HOOMD's P = 2 o ⊗ (0, S)
    for S = (0, 0, I ω) and the identity orientation o, so that S = ½ im(o* ⊗ P) gives back
    I ω; XYZ: a column spin, ω to the bit. I = q m a² is checked against the run's own
    rotational energy Σ I ω²/2."""
    gsd_file = export(rough, "gsd", tmp_path / "rough.gsd")
    xyz_file = export(rough, "xyz", tmp_path / "rough.xyz")
    with open_run(rough) as ds, gsd.hoomd.open(gsd_file) as trajectory:
        q = yaml.safe_load(ds.attrs["config"])["disks"]["inertia_factor"]
        inertia = q * ds["mass"].values * ds["radius"].values ** 2
        spin = ds["angular_velocity"].values
        np.testing.assert_allclose(0.5 * np.sum(inertia * spin**2, axis=1),
                                   ds["rotational_energy"].values, rtol=1e-12)
        assert np.abs(spin[-1]).max() > 10.0  # the disks turn
        assert len(trajectory) == spin.shape[0]
        for frame, omega in zip(trajectory, spin, strict=True):
            np.testing.assert_array_equal(frame.particles.moment_inertia[:, 2],
                                          inertia.astype(np.float32))
            assert not frame.particles.moment_inertia[:, :2].any()
            np.testing.assert_array_equal(frame.particles.angmom[:, 3],
                                          (2.0 * inertia * omega).astype(np.float32))
            assert not frame.particles.angmom[:, :3].any()
            np.testing.assert_array_equal(frame.particles.orientation, [[1, 0, 0, 0]] * omega.size)
            body = 0.5 * frame.particles.angmom[:, 3]  # ½ im(o* ⊗ P), o = 1
            np.testing.assert_allclose(body / frame.particles.moment_inertia[:, 2], omega,
                                       rtol=1e-6)
        frames = read_xyz(xyz_file)
        assert len(frames) == spin.shape[0]
        for (keys, lines), omega in zip(frames, spin, strict=True):
            assert keys["Properties"].endswith(":mass:R:1:spin:R:1")
            np.testing.assert_array_equal(np.array(lines, dtype=np.float64)[:, 9], omega)


def test_spins_without_an_inertia_factor_are_refused_for_gsd(rough, tmp_path, capsys):
    """A run file whose config lacks disks.inertia_factor (a script's RunWriter): no moments
    of inertia, so no GSD; xyz needs none."""
    path = tmp_path / "run.h5"
    shutil.copy(rough, path)
    with h5py.File(path, "r+") as f:
        config = yaml.safe_load(f["parameters"].attrs["config"])
        del config["disks"]["inertia_factor"]
        f["parameters"].attrs["config"] = yaml.safe_dump(config)
    capsys.readouterr()
    assert sim_export(path, "--format", "gsd") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no disks.inertia_factor" in err
    assert [p.name for p in tmp_path.iterdir()] == ["run.h5"]
    assert sim_export(path, "--format", "xyz") == 0


def test_smooth_disks_keep_the_defaults_of_gsd(mixture, tmp_path):
    """No spins in the run: no moment of inertia (HOOMD turns no such particle) and no
    angular momentum."""
    with gsd.hoomd.open(export(mixture, "gsd", tmp_path / "smooth.gsd")) as trajectory:
        assert not trajectory[0].particles.moment_inertia.any()
        assert not trajectory[-1].particles.angmom.any()


@pytest.mark.parametrize(("name", "fmt", "says"), [
    ("mixture", "gsd", "the walls along x and y read as periodic sides"),
    ("mixture", "xyz", None), ("gas", "gsd", None), ("rough", "xyz", None)])
def test_a_note_says_what_of_the_run_the_format_cannot_hold(name, fmt, says, request, tmp_path,
                                                            capsys):
    capsys.readouterr()
    assert sim_export(request.getfixturevalue(name), "--format", fmt, "--out",
                      tmp_path / f"x.{fmt}") == 0
    out, err = capsys.readouterr()
    assert out == ""
    if says is None:
        assert err == ""
    else:
        assert err.startswith("sim-export: note: ") and err.count("\n") == 1 and says in err


@pytest.mark.parametrize(("boundary", "walls", "gsd_note", "xyz_note"), [
    (["none", "none"], {"bottom": {"amplitude": 0.01, "frequency": 20.0}}, 2, 1),
    (["none", "none"], {"top": {"speed": -0.1}, "left": None}, 2, 1),
    (["none", "periodic"], {"top": {"speed": -0.1}}, 1, 0),  # no wall there: nothing moves
    (["none", "none"], {"top": {"temperature": 1.0}}, 1, 0),
    (["periodic", "periodic"], None, 0, 0),
])
def test_moving_walls_are_noted_in_either_format(boundary, walls, gsd_note, xyz_note):
    run = xr.Dataset(attrs={"boundary": boundary, "config": yaml.safe_dump({"walls": walls})})
    assert len(not_held(run, "gsd")) == gsd_note
    assert len(not_held(run, "xyz")) == xyz_note
    assert any("motion" in item for item in not_held(run, "xyz")) == bool(xyz_note)


def test_the_help_says_what_the_formats_cannot_hold(capsys):
    assert sim_export("--help") == 0
    assert " ".join(CANNOT_HOLD.split()) in " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize(("spec", "indices"), [
    (None, list(range(10))), ("::3", [0, 3, 6, 9]), ("2:5", [2, 3, 4]), ("-2:", [8, 9]),
    ("7:100", [7, 8, 9]), ("9:2:-3", [9, 6, 3]), (" 1, 4,-1", [1, 4, 9]), ("5", [5])])
def test_frames_select_as_a_python_slice_or_a_list(spec, indices):
    assert frame_indices(spec, 10) == indices


def test_only_the_frames_asked_for_are_written(mixture, tmp_path):
    gsd_file = export(mixture, "gsd", tmp_path / "some.gsd", "1,3")
    xyz_file = export(mixture, "xyz", tmp_path / "some.xyz", "-2:")
    with open_run(mixture) as ds, gsd.hoomd.open(gsd_file) as trajectory:
        steps = ds["step"].values
        assert [frame.configuration.step for frame in trajectory] == list(steps[[1, 3]])
        assert [int(keys["Step"]) for keys, _ in read_xyz(xyz_file)] == list(steps[-2:])


def test_both_formats_are_made_as_every_file_is(mixture, tmp_path):
    """The umask decides the permissions (gsd alone makes its files 0640)."""
    made = tmp_path / "plain"
    made.touch()
    for fmt in ("gsd", "xyz"):
        written = export(mixture, fmt, tmp_path / f"x.{fmt}")
        assert written.stat().st_mode == made.stat().st_mode, fmt


def test_the_default_output_is_beside_the_run_file(mixture, tmp_path):
    path = tmp_path / "mine.h5"
    shutil.copy(mixture, path)
    assert sim_export(path, "--format", "gsd") == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine.gsd", "mine.h5"]
    with pytest.raises(BadInput, match="unknown format 'pdb'"):
        export(path, "pdb")


def _not_a_run(folder):
    path = folder / "notes.h5"
    path.write_text("not HDF5")
    return path


def _another_hdf5_file(folder):
    path = folder / "other.h5"
    with h5py.File(path, "w") as f:
        f["x"] = [1, 2, 3]
    return path


#: (arguments, a word the error line names), given the run file and a scratch folder
BAD_INPUT = {
    "missing file": lambda run, folder: ([folder / "nope.h5", "--format", "gsd"], "nope.h5"),
    "not HDF5": lambda run, folder: ([_not_a_run(folder), "--format", "gsd"], "notes.h5"),
    "not a run file": lambda run, folder: ([_another_hdf5_file(folder), "--format", "xyz"],
                                           "other.h5"),
    "unknown format": lambda run, folder: ([run, "--format", "pdb"], "pdb"),
    "no format": lambda run, folder: ([run], "--format"),
    "bad spec": lambda run, folder: ([run, "--format", "gsd", "--frames", "1-3"], "1-3"),
    "zero step": lambda run, folder: ([run, "--format", "xyz", "--frames", "::0"], "::0"),
    "out of range": lambda run, folder: ([run, "--format", "gsd", "--frames", "0,6"], "6"),
    "no frame": lambda run, folder: ([run, "--format", "gsd", "--frames", "6:"], "6:"),
    "the run file": lambda run, folder: ([run, "--format", "xyz", "--out", run], "itself"),
    "no folder": lambda run, folder: ([run, "--format", "gsd", "--out", folder / "no" / "x.gsd"],
                                      "no folder"),
    "a file as folder": lambda run, folder: ([run, "--format", "gsd", "--out", run / "x.gsd"],
                                             "no folder"),
    "a folder": lambda run, folder: ([run, "--format", "xyz", "--out", folder], "a folder"),
    "in /proc": lambda run, folder: ([run, "--format", "gsd", "--out", "/proc/x.gsd"],
                                     "--out /proc/x.gsd: cannot write in /proc"),
    # a device (/dev/full, /dev/null) was replaced by the file: a pipe stands for them here
    "a pipe": lambda run, folder: ([run, "--format", "xyz", "--out", _pipe(folder)],
                                   "not a regular file"),
}


def _pipe(folder):
    """A named pipe in ``folder``: a file that is not a regular one."""
    os.mkfifo(folder / "pipe.xyz")
    return folder / "pipe.xyz"


@pytest.mark.parametrize("case", list(BAD_INPUT), ids=list(BAD_INPUT))
def test_bad_input_is_one_line_exit_2_and_leaves_nothing(case, mixture, tmp_path, capsys):
    path = tmp_path / "run.h5"
    shutil.copy(mixture, path)
    argv, named = BAD_INPUT[case](path, tmp_path)
    before = sorted(tmp_path.rglob("*"))
    capsys.readouterr()
    assert sim_export(*argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("sim-export: ") and err.count("\n") == 1
    assert named in err and "Traceback" not in err
    assert sorted(tmp_path.rglob("*")) == before
    assert all(p.is_dir() or p.is_file() or p.is_fifo() and p.name == "pipe.xyz"
               for p in before)  # the pipe is still one


@pytest.fixture
def read_only_folder(tmp_path, monkeypatch):
    """A folder on a read-only file system, as the kernel has it (root, who runs some test
    machines, writes through chmod): making a file there and removing one fail with EROFS,
    even removing one that is not there (the kernel asks the mount for write access before it
    looks the name up)."""
    folder = tmp_path / "read_only"
    folder.mkdir()

    def read_only(call):
        def on_the_mount(path, *args, **kwargs):
            if Path(os.fsdecode(path)).parent == folder:
                raise OSError(errno.EROFS, os.strerror(errno.EROFS), os.fsdecode(path))
            return call(path, *args, **kwargs)
        return on_the_mount

    monkeypatch.setattr(os, "open", read_only(os.open))
    monkeypatch.setattr(os, "unlink", read_only(os.unlink))
    return folder


@pytest.mark.parametrize("fmt", ["gsd", "xyz"])
def test_a_read_only_folder_is_one_line_exit_2(fmt, mixture, read_only_folder, capsys):
    """Refused before any snapshot is read, naming the path and the OS's reason; no traceback
    from removing the hidden file that could not be made."""
    out = read_only_folder / f"x.{fmt}"
    capsys.readouterr()
    assert sim_export(mixture, "--format", fmt, "--out", out) == 2
    _, err = capsys.readouterr()
    assert err == (f"sim-export: --out {out}: cannot write in {read_only_folder} (Read-only "
                   f"file system); a file in a folder that exists and may be written\n")
    assert list(read_only_folder.iterdir()) == []


def test_a_write_that_fails_midway_is_one_line_exit_1(mixture, tmp_path, monkeypatch, capsys):
    """A full disk half-way through: one line, exit status 1, neither the output nor its
    hidden part left."""
    def disk_full(path, run, frames):
        path.write_bytes(b"half a file")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))

    monkeypatch.setitem(sim.storage.export.WRITERS, "gsd", disk_full)
    capsys.readouterr()
    assert sim_export(mixture, "--format", "gsd", "--out", tmp_path / "x.gsd") == 1
    _, err = capsys.readouterr()
    assert err == f"sim-export: cannot write {tmp_path / 'x.gsd'} (No space left on device)\n"
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_the_export_leaves_nothing(signum, mixture, tmp_path, monkeypatch,
                                                   capsys):
    """A signal half-way through the writing (as the handler raises it): one line, 128 +
    the signal's number, and neither the output nor its hidden part."""
    def interrupted(path, run, frames):
        path.write_bytes(b"half a file")
        raise KeyboardInterrupt(signum)

    monkeypatch.setitem(sim.storage.export.WRITERS, "gsd", interrupted)
    capsys.readouterr()
    assert sim_export(mixture, "--format", "gsd", "--out", tmp_path / "x.gsd") == 128 + signum
    _, err = capsys.readouterr()
    assert err.startswith("sim-export: ") and "nothing written" in err and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_the_command_refuses_in_one_line(tmp_path):
    done = subprocess.run([sys.executable, "-m", "sim.storage.export", str(tmp_path / "nope.h5"),
                           "--format", "gsd"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert done.stderr == f"sim-export: {tmp_path / 'nope.h5'}: no such file\n"


def test_a_damaged_snapshot_stops_the_export_and_leaves_nothing(mixture, tmp_path, capsys):
    """The last snapshot's positions fail their checksum: the frames before it are written,
    then removed; without it the export goes through."""
    path = tmp_path / "run.h5"
    shutil.copy(mixture, path)
    with h5py.File(path, "r") as f:
        last = f["particles/disks/position/value"].shape[0] - 1
        chunk = f["particles/disks/position/value"].id.get_chunk_info(last)
    with open(path, "r+b") as file:
        file.seek(chunk.byte_offset + chunk.size // 2)
        word = file.read(4)
        file.seek(chunk.byte_offset + chunk.size // 2)
        file.write(bytes(b ^ 0x5A for b in word))
    capsys.readouterr()
    assert sim_export(path, "--format", "xyz") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"snapshot {last} is damaged" in err
    assert [p.name for p in tmp_path.iterdir()] == ["run.h5"]
    assert sim_export(path, "--format", "xyz", "--frames", f":{last}") == 0
    assert len(read_xyz(tmp_path / "run.xyz")) == last


def test_a_disk_that_rounds_onto_the_periodic_edge_is_written_at_its_image():
    box = [1.0, 1.3]
    position = np.array([[1.0 - 1e-12, 1.3 - 1e-12], [0.5, 0.65]])
    half = np.float32(box) / 2
    centred = hoomd_positions(position, box, [True, True])
    np.testing.assert_array_equal(centred, [[-half[0], -half[1], 0.0], [0.0, 0.0, 0.0]])


def test_freud_finds_the_observers_pair_distribution_in_the_gsd_frames(gas, tmp_path):
    """g(r) of freud.density.RDF on each exported frame against the run's observer.

    Conventions: both bin r in [0, r_max] into equal bins, and ``r`` (in σ = 2⟨R⟩) is
    freud's bin centres; the observer divides the pair count by its ideal-gas value
    ½ N (N − 1) 2π r Δr / A, freud's default (``exact``) by ½ N² 2π r Δr / A, so freud's
    g(r) is multiplied by N/(N − 1). Fifty bins up to 4σ put no bin edge at contact r = σ,
    where the pair colliding at each snapshot sits and rounding alone would pick its bin.

    Tolerances: the mean over frames agrees within 3 σ_g per bin, σ_g the observer's
    frame-to-frame standard deviation over √frames (at least one pair in one frame, for bins
    below contact); as both count the same pairs, each frame's counts, g × the ideal count,
    must moreover differ by a whole number of pairs, at most one moved across an edge by
    float32 rounding; whole to 2 × bins × ε₃₂ of the ideal count, about the float32 precision
    of freud's shell areas (r₂² − r₁² loses r/Δr ≤ bins in relative precision). This catches
    the N/(N − 1) normalisation, a 0.1 % effect well inside σ_g."""
    out = export(gas, "gsd", tmp_path / "gas.gsd")
    with open_run(gas) as ds:
        observed = ds["radial_distribution"].values
        centres = ds["r"].values
        n = ds.sizes["disk"]
        sigma = 2.0 * float(np.mean(ds["radius"].values))
        area = float(np.prod(ds.attrs["box"]))
        settings = yaml.safe_load(ds.attrs["config"])["observe"]["radial_distribution"]
    bins, r_max = settings["bins"], settings["r_max"] * sigma
    rdf = freud.density.RDF(bins, r_max)
    with gsd.hoomd.open(out) as trajectory:
        oracle = np.array([rdf.compute((freud.box.Box.from_box(frame.configuration.box,
                                                                dimensions=2),
                                        frame.particles.position)).rdf * (n / (n - 1))
                           for frame in trajectory])
    edges = np.linspace(0.0, r_max, bins + 1)
    np.testing.assert_allclose(rdf.bin_edges, edges, rtol=1e-6)
    np.testing.assert_allclose(rdf.bin_centers, centres * sigma, rtol=1e-6)
    ideal = 0.5 * n * (n - 1) * np.pi * np.diff(edges**2) / area
    moved = (oracle - observed) * ideal
    float32_shells = 2 * bins * np.finfo(np.float32).eps
    assert np.all(np.abs(moved - np.round(moved)) <= float32_shells * ideal)
    assert np.abs(np.round(moved)).max() <= 1
    frames = observed.shape[0]
    sigma_g = np.maximum(observed.std(axis=0, ddof=1), 1.0 / ideal) / np.sqrt(frames)
    deviation = np.abs(oracle.mean(axis=0) - observed.mean(axis=0)) / sigma_g
    assert deviation.max() < 3.0, f"max |Δg| = {deviation.max():.2f} σ_g"
