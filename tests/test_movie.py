"""Movies of runs (sim.figures.movie): frames evenly spaced in time or at the snapshots, disks in
free flight from the latest snapshot, drawn where the positions say, speeds on a scale up to the
fastest; MP4 or GIF written whole; bad input is one line and exit status 2."""

import os
import subprocess
import sys
import warnings

import imageio_ffmpeg
import numpy as np
import pytest
from matplotlib import colormaps
from PIL import Image
from scipy import ndimage

from sim.analysis.datasets import open_run
from sim.figures import movie
from sim.figures.movie.colors import (
    LOG_DECADES,
    SpeedColors,
    cluster_rule,
    coloring,
    fastest_speed,
)
from sim.figures.movie.layout import Layout
from sim.figures.movie.make import clock_decimals
from sim.figures.movie.picture import Picture
from sim.figures.movie.snapshots import (
    Frame,
    Snapshots,
    free_flight,
    latest_snapshots,
    snapshot_frame_times,
)
from sim.pipeline.command import BadInput
from sim.pipeline.run_cache import compose_config
from sim.pipeline.runner import run

#: the two disks of the two_disks scene, their snapshots 0.01 apart
TWO_DISKS = ["scenario=two_disks", "stop.time=2", "output.every_time=0.01",
             "output.progress=false"]
#: with gravity, inelastic with the TC model: the settling bed's compiled variant (variants.py)
SCENES = {"walls_and_gravity": [*TWO_DISKS, "gravity=[0,-1]", "restitution.disk=0.9",
                                "restitution.wall=0.9", "tc.time=1e-6"],
          "periodic": [*TWO_DISKS, "box.boundary=periodic", "observe.clusters.gap=3"]}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Run files by scene name, made once for the module."""
    made = {}
    for name, overrides in SCENES.items():
        folder = tmp_path_factory.mktemp(name)
        made[name] = run(compose_config(overrides), folder)
    return made


def read_mp4(path):
    """(width, height) and the frames uint8[h, w, 3] of an MP4."""
    with warnings.catch_warnings():
        # read_frames leaves ffmpeg's pipes to the garbage collector when ffmpeg ends first
        warnings.simplefilter("ignore", ResourceWarning)
        reader = imageio_ffmpeg.read_frames(str(path))
        width, height = next(reader)["size"]
        frames = [np.frombuffer(f, np.uint8).reshape(height, width, 3) for f in reader]
    return (width, height), frames


@pytest.mark.parametrize("scene", sorted(SCENES))
def test_free_flight_from_sparse_snapshots_gives_the_dense_ones_between_contacts(runs, scene):
    with open_run(runs[scene]) as ds:
        time = ds["time"].values
        position, velocity = ds["position"].values, ds["velocity"].values
        contacts = ds["collisions"].values + ds["wall_contacts"].values
        snapshots = Snapshots(ds)
        gravity, box, periodic = snapshots.gravity, snapshots.box, snapshots.periodic
    assert (gravity is not None) == (scene == "walls_and_gravity")
    sparse = np.arange(0, time.size, 10)
    latest, elapsed = latest_snapshots(time[sparse], time)
    k = sparse[latest]
    assert np.all(time[k] <= time) and np.all(elapsed >= 0.0)  # never predicted backwards
    free = contacts[k] == contacts  # no contact between the sparse snapshot and this one
    assert free.sum() > 0.8 * time.size and np.sum(elapsed[free] > 0.0) > 100
    for j in np.flatnonzero(free):
        r, v = free_flight(position[k[j]], velocity[k[j]], elapsed[j], gravity, box, periodic)
        np.testing.assert_allclose(v, velocity[j], rtol=0.0, atol=1e-12)
        apart = r - position[j]
        apart -= np.where(periodic, box * np.round(apart / box), 0.0)  # x = 0 is x = L
        np.testing.assert_allclose(apart, 0.0, rtol=0.0, atol=1e-12)
        if any(periodic):
            assert np.all((r >= 0.0) & (r <= box))
    wrapped = np.flatnonzero(np.any(np.abs(np.diff(position, axis=0)) > 0.5, axis=(1, 2)))
    assert (wrapped.size > 0) == (scene == "periodic")  # the periodic disks crossed a side


def test_frames_show_the_disks_where_free_flight_puts_them(runs, tmp_path):
    out = tmp_path / "two.mp4"
    times = np.linspace(0.105, 1.9, 12)  # between snapshots, from the latest before each
    movie.make_movie(runs["walls_and_gravity"], out, fps=10, frames=times.size,
                     start=times[0], stop=times[-1], color="species")
    layout = Layout.of_view((0.0, 1.0, 0.0, 1.0))
    size, frames = read_mp4(out)
    assert size == (layout.width, layout.height) and len(frames) == times.size
    assert layout.width % 16 == 0 and layout.height % 16 == 0
    with open_run(runs["walls_and_gravity"]) as ds:
        expected = [f.position for f in Snapshots(ds).frames(times)]
        radius = float(ds["radius"][0])
    radius_pixels = radius * layout.box_width
    checked = 0
    for picture, position in zip(frames, expected, strict=True):
        by_a_wall = np.any((position < 2 * radius) | (position > 1 - 2 * radius))
        if by_a_wall or np.hypot(*(position[0] - position[1])) < 3 * radius:
            continue  # blobs would be clipped by a wall's line or merge
        rgb = picture.astype(np.int64)
        colored = rgb.max(axis=2) - rgb.min(axis=2) > 60  # the species colour: not grey
        inside = np.zeros_like(colored)  # the box, not the colour key beside it
        inside[layout.top:layout.top + layout.box_height,
               layout.left:layout.left + layout.box_width] = True
        blobs, _ = ndimage.label(colored & inside)
        areas = np.bincount(blobs.ravel())[1:]
        disks = 1 + np.flatnonzero(areas > 0.5 * np.pi * radius_pixels**2)  # not codec specks
        assert disks.size == 2
        centres = np.array(ndimage.center_of_mass(colored, blobs, disks))[:, ::-1] + 0.5
        np.testing.assert_allclose(areas[disks - 1], np.pi * radius_pixels**2, rtol=0.03)
        pixels = layout.pixel(position)
        distance = np.hypot(*(centres[:, None, :] - pixels[None, :, :]).transpose(2, 0, 1))
        assert distance.min(axis=1).max() < 1.0, distance
        checked += 1
    assert checked >= 4


def test_gif_by_name_and_when_ffmpeg_is_unavailable(runs, tmp_path, monkeypatch, capsys):
    gif = tmp_path / "clusters.gif"  # the run has no clusters observable: labels computed
    assert movie.main([str(runs["walls_and_gravity"]), "--out", str(gif), "--frames", "4",
                       "--color", "cluster"]) == 0
    with Image.open(gif) as image:
        assert image.n_frames == 4
        width, height = image.size
    layout = Layout.of_view((0.0, 1.0, 0.0, 1.0))
    assert (width, height) == (layout.width, layout.height)

    def unavailable():
        raise RuntimeError("No ffmpeg exe could be found.")

    monkeypatch.setattr(imageio_ffmpeg, "get_ffmpeg_exe", unavailable)
    capsys.readouterr()
    assert movie.main([str(runs["periodic"]), "--out", str(tmp_path / "asked.mp4"),
                       "--duration", "0.5", "--fps", "6"]) == 0
    notes = capsys.readouterr().err.splitlines()
    assert len(notes) == 1 and "through Pillow" in notes[0]
    assert not (tmp_path / "asked.mp4").exists()
    with Image.open(tmp_path / "asked.gif") as image:
        assert image.n_frames == 3


def test_a_movie_that_fails_leaves_no_file(runs, tmp_path, monkeypatch):
    render = Picture.render
    drawn = []

    def failing(picture, frame):
        drawn.append(frame.time)
        if len(drawn) == 3:
            raise OSError("disk full")
        return render(picture, frame)

    monkeypatch.setattr(Picture, "render", failing)
    assert movie.main([str(runs["periodic"]), "--out", str(tmp_path / "m.mp4"),
                       "--frames", "5"]) == 1
    assert list(tmp_path.iterdir()) == []


def test_frames_across_contacts_are_noted_in_one_line(runs, tmp_path, capsys):
    with open_run(runs["walls_and_gravity"]) as ds:
        time = ds["time"].values
        gained = np.diff(2 * ds["collisions"].values + ds["wall_contacts"].values)
    # two frames inside one snapshot interval: one without contacts, then one with a contact
    # (0.5 or more contacts per disk, above the 0.1 that makes the note)
    for k, noted in ((np.flatnonzero(gained == 0)[0], False), (np.flatnonzero(gained)[0], True)):
        assert movie.main([str(runs["walls_and_gravity"]), "--out", str(tmp_path / f"{k}.gif"),
                           "--frames", "2", "--start", str(time[k] + 0.002),
                           "--stop", str(time[k] + 0.008)]) == 0
        notes = capsys.readouterr().err.splitlines()
        assert len(notes) == noted
    assert "note: 2 of 2 frames lie between snapshots" in notes[0]


def test_frames_at_snapshots_are_the_distinct_snapshot_times_in_the_span():
    # uneven, as by collisions; the fourth is the third but for round-off, and counts as it
    times = np.array([0.0, 0.1, 0.15, np.nextafter(0.15, 1.0), 0.7, 2.0])
    np.testing.assert_array_equal(snapshot_frame_times(times), times[[0, 1, 3, 4, 5]])
    np.testing.assert_array_equal(snapshot_frame_times(times, 0.1, 0.7), times[[1, 3, 4]])
    np.testing.assert_array_equal(snapshot_frame_times(times, 0.12, 1.12), times[[3, 4]])
    with pytest.raises(BadInput, match="no snapshot from t = 0.2 to 0.3"):
        snapshot_frame_times(times, 0.2, 0.3)
    with pytest.raises(BadInput, match="5 snapshots from t = 0 to 2, at most 4 frames"):
        snapshot_frame_times(times, limit=4, why="a test's limit")
    with pytest.raises(BadInput, match="--start"):
        snapshot_frame_times(times, -1.0)


def test_a_movie_at_snapshots_draws_each_snapshot_at_its_own_time(runs, tmp_path, monkeypatch):
    render = Picture.render
    drawn = []

    def recording(picture, frame):
        drawn.append(frame)
        return render(picture, frame)

    monkeypatch.setattr(Picture, "render", recording)
    out = tmp_path / "m.gif"
    assert movie.main([str(runs["periodic"]), "--out", str(out), "--at-snapshots",
                       "--start", "0.505", "--stop", "0.6"]) == 0
    with open_run(runs["periodic"]) as ds:
        time = ds["time"].values
        position = ds["position"].values
    inside = np.flatnonzero((time >= 0.505) & (time <= 0.6))
    assert inside.size == 10  # snapshots 0.51, …, 0.60
    assert [f.snapshot for f in drawn] == inside.tolist()
    assert [f.time for f in drawn] == time[inside].tolist()
    for frame in drawn:  # no free flight: the snapshot itself
        np.testing.assert_array_equal(frame.position, position[frame.snapshot])
    with Image.open(out) as image:
        assert image.n_frames == inside.size


def test_a_count_with_frames_at_snapshots_is_refused_before_any_work(runs, no_work):
    for count in ({"frames": 3}, {"duration": 1.0}):
        with pytest.raises(BadInput, match="--at-snapshots draws one frame at each snapshot"):
            movie.make_movie(runs["periodic"], at_snapshots=True, **count)


def test_more_snapshots_than_a_gif_holds_are_refused(runs, tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(movie.make, "available_memory", lambda: 2 * 3 * 912 * 704)
    assert movie.main([str(runs["periodic"]), "--out", str(tmp_path / "m.gif"),
                       "--at-snapshots"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--at-snapshots: 201 snapshots" in err
    assert "at most 3 frames" in err
    assert list(tmp_path.iterdir()) == []


def test_the_clock_tells_the_closest_frames_apart():
    assert clock_decimals(np.linspace(8.0, 14.5, 521)) == 3  # 0.0125 apart
    assert clock_decimals(np.linspace(0.0, 1.0, 11)) == 2  # 0.1 apart, less round-off
    assert clock_decimals(np.array([0.0, 0.004, 0.5, 3.0])) == 4  # the closest two
    assert clock_decimals(np.array([2.0])) == 4


def speed_frame(speeds):
    """A :class:`Frame` of disks moving along x at ``speeds``."""
    speeds = np.asarray(speeds, dtype=np.float64)
    velocity = np.stack([speeds, np.zeros_like(speeds)], axis=1)
    return Frame(0.0, 0, np.zeros_like(velocity), velocity)


def test_the_speed_scale_reaches_the_fastest_disk_without_saturating():
    # an impact: a projectile at 10 above a bed moving at most 1, the 99th percentile of the
    # speeds
    impact = speed_frame(np.append(np.linspace(0.0, 1.0, 200), 10.0))
    fastest = fastest_speed([impact, speed_frame([0.0, 5.0])])
    assert fastest == 10.0
    viridis = colormaps["viridis"]
    linear, log = SpeedColors(fastest), SpeedColors(fastest, "log")
    np.testing.assert_allclose(linear.norm([0.0, 5.0, 10.0]), [0.0, 0.5, 1.0])
    floor = fastest * 10.0**-LOG_DECADES
    np.testing.assert_allclose(log.norm([floor, fastest * 10.0**(-LOG_DECADES / 2), fastest]),
                               [0.0, 0.5, 1.0], atol=1e-12)
    for scale in (linear, log):  # the projectile on the top colour, the bed well below it
        colors = scale(impact)[0]
        np.testing.assert_array_equal(colors[-1], viridis(1.0))
        assert not np.any(np.all(colors[:-1] == viridis(1.0), axis=1))
    # disks at rest, and slower than the log scale's floor, take its lowest colour
    np.testing.assert_array_equal(log(speed_frame([0.0, 0.1 * floor]))[0], viridis([0.0, 0.0]))


def test_a_movie_coloured_by_speed_scales_to_its_fastest_disk(runs, tmp_path):
    with open_run(runs["walls_and_gravity"]) as ds:
        snapshots = Snapshots(ds)
        speed = np.hypot(*ds["velocity"].values.transpose(2, 0, 1))
        times = snapshots.times
        for scale in ("linear", "log"):
            colors = coloring("speed", snapshots, times, ds["radius"].values,
                              ds["mass"].values, scale)
            assert colors.norm.vmax == speed.max()
            assert colors.norm.vmin == (0.0 if scale == "linear"
                                        else speed.max() * 10.0**-LOG_DECADES)
    out = tmp_path / "log.gif"
    assert movie.main([str(runs["walls_and_gravity"]), "--out", str(out), "--frames", "2",
                       "--speed-scale", "log"]) == 0
    assert out.is_file()


def test_cluster_labels_follow_the_rule_of_the_observer(runs):
    with open_run(runs["periodic"]) as ds:
        labels = cluster_rule(Snapshots(ds), ds["radius"].values)
        observed = ds["clusters"].values
        position = ds["position"].values
    assert all(np.array_equal(labels(p), o) for p, o in zip(position, observed, strict=True))
    assert {tuple(o) for o in observed} >= {(0, 0), (0, 1)}  # together and apart


@pytest.mark.parametrize("args, says", [
    (["missing.h5"], "no such file"),
    (["not_a_run.h5"], "not a readable HDF5 file"),
    (["RUN", "--fps", "0"], "--fps"),
    (["RUN", "--fps", "fast"], "--fps"),
    (["RUN", "--frames", "0"], "--frames"),
    (["RUN", "--frames", "3", "--duration", "2"], "not allowed with"),
    (["RUN", "--start", "-1"], "--start"),
    (["RUN", "--stop", "99"], "--stop"),
    (["RUN", "--color", "mood"], "--color"),
    (["RUN", "--speed-scale", "loud"], "--speed-scale loud: one of linear, log"),
    (["RUN", "--at-snapshots", "--frames", "3"], "not allowed with"),
    (["RUN", "--at-snapshots", "--start", "0.101", "--stop", "0.109"], "no snapshot"),
    (["RUN", "--out", "movie.avi"], ".mp4 or .gif"),
    (["RUN", "--out", "nowhere/movie.mp4"], "no folder"),
    (["RUN", "--out", "not_a_run.h5/movie.mp4"], "no folder"),
])
def test_bad_input_is_one_line_and_status_2(runs, tmp_path, monkeypatch, capsys, args, says):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "not_a_run.h5").write_text("hello")
    argv = [str(runs["periodic"]) if a == "RUN" else a for a in args]
    assert movie.main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and says in err and err.startswith("sim-movie: ")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["not_a_run.h5"]
    assert not any(p.suffix in (".mp4", ".gif") for p in runs["periodic"].parent.iterdir())


@pytest.fixture
def no_work(monkeypatch):
    """A movie that reads its run or starts ffmpeg fails the test: refusals come first."""
    def work(*args, **kwargs):
        raise AssertionError("the run was read or ffmpeg started before the refusal")

    monkeypatch.setattr(movie.make, "open_run", work)
    monkeypatch.setattr(imageio_ffmpeg, "write_frames", work)


@pytest.mark.parametrize("args, says", [
    (["--duration", "1e9"], "--duration 1e+09 at --fps 30 is 3e+10 frames: at most 100000"),
    (["--frames", "100000000"], "--frames 100000000: at least one frame and at most 100000"),
    (["--frames", "300000000", "--out", "m.gif"], "--frames 300000000"),
    (["--fps", "120", "--duration", "1e6"], "--duration 1e+06 at --fps 120 is 1.2e+08 frames"),
    (["--fps", "120", "--duration", "1e308"], "--duration 1e+308 at --fps 120 is inf frames"),
    (["--frames", "100001"], "at most 100000 frames"),
    (["--duration", "inf"], "--duration inf"),
    (["--duration", "nan"], "--duration nan"),
    (["--duration", "-1"], "--duration -1"),
    (["--duration", "0"], "--duration 0"),
    (["--frames", "-5"], "--frames -5"),
    (["--fps", "nan"], "--fps nan"),
    (["--fps", "inf"], "--fps inf"),
    (["--fps", "-30"], "--fps -30"),
    (["--fps", "0.001", "--duration", "3000", "--out", "m.gif"], "--fps 0.001"),  # Pillow's
    (["--fps", "1e-300", "--duration", "1e300"], "--fps 1e-300"),  # ffmpeg's broken pipe
    (["--frames", "2.5"], "whole number"),
    (["--frames", "nan"], "whole number"),
])
def test_frames_out_of_range_are_refused_before_any_work(runs, tmp_path, monkeypatch, capfd,
                                                          no_work, args, says):
    """The count of frames (--frames, or --fps × --duration) is checked against
    MAX_FRAMES before the run is read: no allocation of one time per frame, no rendering."""
    monkeypatch.chdir(tmp_path)
    assert movie.main([str(runs["periodic"]), *args]) == 2
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and err.startswith("sim-movie: ") and says in err, err
    assert list(tmp_path.iterdir()) == []


def test_frames_written_as_a_float_are_taken_when_whole(runs, tmp_path):
    out = tmp_path / "m.gif"
    assert movie.main([str(runs["periodic"]), "--out", str(out), "--frames", "2e0"]) == 0
    assert out.is_file()


def test_the_help_begins_with_what_the_command_makes(capsys):
    with pytest.raises(SystemExit):
        movie.main(["--help"])
    assert "A movie of a run file" in capsys.readouterr().out


def test_a_gif_is_limited_to_the_frames_that_fit_in_memory(runs, tmp_path, monkeypatch, capfd,
                                                           no_work):
    """Pillow keeps every frame of a GIF (one byte a pixel, at most 912 × 704) until it writes
    the file: with 1 GB available, half of it holds 778 of them."""
    monkeypatch.setattr(movie.make, "available_memory", lambda: 1e9)
    limit = int(0.5e9 // (912 * 704))
    out = tmp_path / "m.gif"
    for frames, status in ((limit + 1, 2), (50 * limit, 2)):
        assert movie.main([str(runs["periodic"]), "--out", str(out), "--frames",
                           str(frames)]) == status
        err = capfd.readouterr().err
        assert err.count("\n") == 1 and f"at most {limit} frames" in err and "GIF" in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("out, says", [
    ("/proc/x.mp4", "--out /proc/x.mp4: cannot write in /proc"),
    ("/proc/x.gif", "--out /proc/x.gif: cannot write in /proc"),
    ("FOLDER", "a folder"),
    ("PIPE", "not a regular file"),  # for a device such as /dev/null, which it replaced
])
def test_an_output_that_cannot_be_written_is_refused_before_ffmpeg_starts(
        runs, tmp_path, capfd, no_work, out, says):
    """One line naming the path and the OS's reason, exit 2, before the run is read and
    before ffmpeg starts (no ffmpeg lines, no "Broken pipe"), and nothing left behind."""
    if out == "FOLDER":
        out = tmp_path / "folder.mp4"
        out.mkdir()
    elif out == "PIPE":
        out = tmp_path / "pipe.mp4"
        os.mkfifo(out)
    capfd.readouterr()
    assert movie.main([str(runs["periodic"]), "--out", str(out), "--frames", "3"]) == 2
    err = capfd.readouterr().err
    assert err.count("\n") == 1 and err.startswith("sim-movie: ") and says in err, err
    assert "Broken pipe" not in err and "Traceback" not in err
    left = {"a folder": ["folder.mp4"], "not a regular file": ["pipe.mp4"]}.get(says, [])
    assert [p.name for p in tmp_path.rglob("*")] == left
    assert says != "not a regular file" or out.is_fifo()


def test_the_command_runs_as_a_module():
    out = subprocess.run([sys.executable, "-m", "sim.figures.movie", "--help"],
                         capture_output=True, text=True, check=True)
    assert out.stdout.startswith("usage: sim-movie")
