"""sim.storage.export: GSD and extended XYZ files read back to what the run file holds, frame
selections, one-line refusals that leave nothing behind, and freud's g(r) of the exported
GSD frames against the run's own ``radial_distribution`` observer.

GSD holds positions, velocities, diameters, masses and the box as float32 (the HOOMD
schema's type, gsd's default single precision): they are compared with the run's float64
values rounded once to float32, exactly; positions after undoing the −L/2 shift agree to half
a float32 ulp of L/2. XYZ holds float64 and is compared bit for bit.
"""

import shlex
import shutil
import signal
import subprocess
import sys

import freud
import gsd.hoomd
import h5py
import numpy as np
import pytest
import yaml

import sim.storage.export
from sim.analysis.datasets import open_run
from sim.pipeline.command import BadInput
from sim.pipeline.run_cache import compose_config
from sim.pipeline.runner import run
from sim.storage.export import export, frame_indices, hoomd_positions, main


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
}


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


def test_an_output_that_cannot_be_written_is_one_line_exit_1(mixture, tmp_path, capsys):
    capsys.readouterr()
    assert sim_export(mixture, "--format", "gsd", "--out", tmp_path / "no" / "x.gsd") == 1
    _, err = capsys.readouterr()
    assert err.startswith("sim-export: cannot write ") and err.count("\n") == 1
    assert not (tmp_path / "no").exists()


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
