"""``python -m sim.figures.movie RUN.h5 [--out FILE] [--fps N] [--duration SECONDS | --frames N]
[--color speed|species|cluster] [--start T] [--stop T]`` (also ``sim-movie``): a movie of a run.

Each frame draws the disks to scale (box units) inside the box: walls as solid lines where they
are at that time (pistons and vibrating walls move; thermal walls red), periodic sides dashed;
the simulated time and the total kinetic energy Σ m v²/2 (mass × (box units / time)²) in the
top-left corner. Colours: ``speed`` (one scale for the whole movie, up to the largest 99th
percentile of any frame's speeds), ``species``, or ``cluster`` (the run's ``clusters``
observable at the snapshot drawn from, or the same rule, :class:`sim.analysis.observers.Clusters`,
applied to the drawn positions when the run did not observe it: the largest cluster red, other
clusters of at least ten disks dark grey, the rest light grey).

Frames are evenly spaced in simulated time from --start to --stop (default: the first and the
last snapshot), one per snapshot in between (at most 30 s of movie) unless --frames or
--duration (seconds of movie at --fps) says otherwise. A frame at time t draws each disk in
free flight from the latest snapshot k at or before t, never back from a later one:
r = r_k + v_k (t − t_k) + ½ g (t − t_k)² and v = v_k + g (t − t_k), g the run's gravity (box
units / time²), r wrapped into the box along periodic axes.
Contacts between snapshots are not drawn: between two snapshots a disk may pass through a
neighbour or a wall. A disk drawn a time s after its snapshot has met something with
probability about s/τ (τ its mean free time); frames between snapshots lie on average half an
interval Δ after theirs, so about Δ/(2τ) of their disks are off their true path. The command
says so in one line when the intervals it draws frames in hold more than 0.1 contacts per disk
on average (Δ > τ/10: more than 5 % of the drawn disks misplaced).

MP4 (H.264, yuv420p, frame sides multiples of 16) through imageio-ffmpeg's ffmpeg; a GIF
through Pillow when FILE ends in .gif, or when ffmpeg is unavailable (said in one line; GIF
delays are whole hundredths of a second). FILE (default: RUN with .mp4) is written under a
hidden name beside it and renamed once complete: exit status 0; 1 when the movie cannot be
written; 2, with one line on stderr, for bad input (no run file, a value out of range); 130
after Ctrl-C, 143 after SIGTERM. Nothing but a whole movie is left behind.
"""

import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import yaml
from matplotlib import colormaps
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.collections import EllipseCollection
from matplotlib.colors import Normalize, to_rgba
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from PIL import Image

from sim.analysis.datasets import open_run
from sim.analysis.observers import Clusters
from sim.effects.gravity import gravity_vector
from sim.effects.walls import wall_motion, wall_state
from sim.engine.box import WALL_NAMES
from sim.pipeline.command import BadInput, CannotWrite, Parser, run_command
from sim.storage.errors import RunFileError

#: contacts per disk per snapshot interval above which frames between snapshots get a note
MISSED_CONTACTS = 0.1
#: pixels of the longer side of the drawn box; text height; margins; the colour key's strip
VIEW_PIXELS, TEXT_PIXELS, MARGIN_PIXELS, HEADER_PIXELS, KEY_PIXELS = 640, 15, 16, 48, 240
#: dots per inch: a power of two, so that a frame's pixel size is exact in float64
DPI = 64
#: the longest movie made by default, one frame per snapshot (seconds)
DEFAULT_MAX_SECONDS = 30.0
#: the fastest frame rate accepted (frames per second)
MAX_FPS = 120.0
#: clusters of at least this many disks are drawn apart from free disks and small clusters
SHOWN_CLUSTER = 10
#: the gap (units of 2⟨R⟩) of cluster labels computed for a run that did not observe them
DEFAULT_CLUSTER_GAP = 0.1
LARGEST_CLUSTER, LARGE_CLUSTER, SMALL_CLUSTER = "tab:red", "0.35", "0.78"
WALL, THERMAL_WALL, PERIODIC_SIDE = "black", "tab:red", "0.55"
COLORINGS = ("speed", "species", "cluster")


def free_flight(position, velocity, elapsed, gravity=None, box=None, periodic=(False, False)):
    """Positions and velocities float64[n, 2] a time ``elapsed`` ≥ 0 after a snapshot's
    ``position`` and ``velocity``, every disk in free flight under ``gravity`` (float64[2] or
    None), positions wrapped into ``box`` along ``periodic`` axes."""
    acceleration = np.zeros(2) if gravity is None else np.asarray(gravity, dtype=np.float64)
    moved = position + velocity * elapsed + 0.5 * acceleration * elapsed**2
    if any(periodic):
        moved = np.where(periodic, np.mod(moved, box), moved)
    return moved, velocity + acceleration * elapsed


def round_off(snapshot_times):
    """The time within which two instants of a run are the same: a few ulps of the largest
    snapshot time (snapshot times are multiples k Δt and frame times come from linspace, so
    the same instant differs between them by round-off only)."""
    return 8.0 * float(np.spacing(np.max(np.abs(snapshot_times))))


def latest_snapshots(snapshot_times, times):
    """For each of ``times``: the index of the latest snapshot at or before it, and the time
    elapsed since (≥ 0); a time within :func:`round_off` of a snapshot is that snapshot's."""
    tolerance = round_off(snapshot_times)
    latest = np.searchsorted(snapshot_times, times + tolerance, side="right") - 1
    latest = np.clip(latest, 0, snapshot_times.size - 1)
    elapsed = times - snapshot_times[latest]
    return latest, np.where(elapsed > tolerance, elapsed, 0.0)


@dataclass
class Frame:
    """The disks at one frame's time, and the snapshot they fly from."""

    time: float
    snapshot: int  # index in the run file of the snapshot the disks fly from
    position: np.ndarray  # float64[n, 2]
    velocity: np.ndarray  # float64[n, 2]


class Snapshots:
    """A run's snapshots, read one at a time (``open_run`` reads positions lazily), and the
    disks at any time between the first and the last, in free flight from the latest snapshot
    at or before it."""

    def __init__(self, ds):
        self.ds = ds
        times = ds["time"].values
        self.readable = np.flatnonzero(np.isfinite(times))  # damaged times are NaN
        if not self.readable.size:
            raise BadInput(f"{ds.attrs['path']} holds no readable snapshot")
        self.times = times[self.readable]
        self.config = yaml.safe_load(ds.attrs["config"]) or {}
        self.gravity = gravity_vector(self.config.get("gravity"))
        self.box = np.asarray(ds.attrs["box"], dtype=np.float64)
        self.periodic = tuple(side == "periodic" for side in ds.attrs["boundary"])
        self._read = (None, None, None)

    def _snapshot(self, index):
        if self._read[0] != index:
            self._read = (index, self.ds["position"][index].values,
                          self.ds["velocity"][index].values)
        return self._read[1:]

    def frames(self, times):
        """The :class:`Frame` at each of ``times``, in order."""
        latest, elapsed = latest_snapshots(self.times, times)
        for time, k, dt in zip(times, latest, elapsed, strict=True):
            index = int(self.readable[k])
            position, velocity = free_flight(*self._snapshot(index), dt, self.gravity, self.box,
                                             self.periodic)
            yield Frame(float(time), index, position, velocity)

    def missed_contacts(self, times):
        """How many of ``times`` fall inside snapshot intervals, the contacts per disk in the
        average such interval, and its mean length (0, 0, 0 when every time is a
        snapshot's)."""
        latest, elapsed = latest_snapshots(self.times, times)
        inside = np.unique(latest[elapsed > 0.0])
        if not inside.size:
            return 0, 0.0, 0.0
        contacts = (2.0 * self.ds["collisions"].values + self.ds["wall_collisions"].values)
        contacts = contacts[self.readable]
        per_disk = (contacts[inside + 1] - contacts[inside]) / self.ds.sizes["disk"]
        interval = self.times[inside + 1] - self.times[inside]
        return (int(np.sum(elapsed > 0.0)), float(np.nanmean(per_disk)),
                float(np.mean(interval)))


class Walls:
    """The box's sides as drawn: two walls on each axis that has walls, at their place at any
    time (:mod:`sim.effects.walls`: pistons and vibrating walls move), thermal ones marked; periodic
    sides at 0 and L."""

    def __init__(self, config, box, periodic):
        self.box = box
        self.periodic = periodic
        specs = {k: (config.get("walls") or {}).get(name) or {}
                 for k, name in enumerate(WALL_NAMES)}
        self.motion = wall_motion({k: spec for k, spec in specs.items()
                                   if not periodic[k >> 1]})
        self.thermal = [specs[k].get("temperature") is not None for k in range(4)]

    def at(self, time):
        """Positions float64[4] of the walls (left, right, bottom, top) at ``time``."""
        if self.motion is None:
            return np.array([0.0, self.box[0], 0.0, self.box[1]])
        return np.array([wall_state(self.motion, k, time, self.box)[0] for k in range(4)])

    def view(self, times):
        """(x0, x1, y0, y1): the box and every place its walls reach at ``times``."""
        places = np.array([self.at(t) for t in times] if self.motion is not None
                          else [self.at(0.0)])
        return (min(0.0, places[:, 0].min()), max(self.box[0], places[:, 1].max()),
                min(0.0, places[:, 2].min()), max(self.box[1], places[:, 3].max()))


def _multiple_of_16(pixels):
    return 16 * math.ceil(pixels / 16)


@dataclass(frozen=True)
class Layout:
    """Pixels of a frame: ``width`` × ``height`` (multiples of 16), the view (x0, x1, y0, y1)
    in box units drawn in the rectangle of ``box_width`` × ``box_height`` pixels whose top-left
    corner is ``left`` pixels from the frame's left and ``top`` from its top; the header above
    it, the colour key to its right."""

    view: tuple
    width: int
    height: int
    left: int
    top: int
    box_width: int
    box_height: int

    @classmethod
    def of_view(cls, view):
        x0, x1, y0, y1 = view
        scale = VIEW_PIXELS / max(x1 - x0, y1 - y0)
        box_width = max(16, round((x1 - x0) * scale))
        box_height = max(16, round((y1 - y0) * scale))
        width = _multiple_of_16(2 * MARGIN_PIXELS + box_width + KEY_PIXELS)
        height = _multiple_of_16(HEADER_PIXELS + box_height + MARGIN_PIXELS)
        return cls(tuple(view), width, height, MARGIN_PIXELS, HEADER_PIXELS, box_width,
                   box_height)

    def pixel(self, position):
        """(column, row) float64[..., 2] of box points ``position`` [..., 2], in pixels from
        the frame's top-left corner (pixel (i, j) covers [i, i + 1) × [j, j + 1))."""
        x0, x1, y0, y1 = self.view
        position = np.asarray(position, dtype=np.float64)
        column = self.left + (position[..., 0] - x0) / (x1 - x0) * self.box_width
        row = self.top + (y1 - position[..., 1]) / (y1 - y0) * self.box_height
        return np.stack([column, row], axis=-1)

    def figure_rect(self, left, top, width, height):
        """[left, bottom, width, height] in figure fractions of a pixel rectangle."""
        return [left / self.width, 1.0 - (top + height) / self.height, width / self.width,
                height / self.height]


def _points(pixels):
    return pixels * 72.0 / DPI


class SpeedColors:
    """Speed on one colour scale for the whole movie."""

    def __init__(self, limit):
        self.norm = Normalize(0.0, limit if limit > 0.0 else 1.0)
        self.cmap = colormaps["viridis"]

    def __call__(self, frame):
        """RGBA float64[n, 4] of the disks of ``frame``, and a caption."""
        return self.cmap(self.norm(np.hypot(frame.velocity[:, 0], frame.velocity[:, 1]))), ""

    def draw_key(self, figure, rect):
        """A colour bar in the strip ``rect`` (figure fractions) beside the box."""
        axes = figure.add_axes([rect[0] + 0.12 * rect[2], rect[1], 0.1 * rect[2], rect[3]])
        figure.colorbar(ScalarMappable(self.norm, self.cmap), cax=axes, extend="max")
        axes.set_ylabel("speed (box units / time)", fontsize=_points(TEXT_PIXELS))
        axes.tick_params(labelsize=_points(TEXT_PIXELS - 2))


def speed_limit(frames):
    """The largest 99th percentile of the speeds of any of ``frames``: colours saturate only
    for the fastest 1 % of the disks of any frame."""
    return max(float(np.percentile(np.hypot(f.velocity[:, 0], f.velocity[:, 1]), 99.0))
               for f in frames)


def _draw_legend(figure, rect, entries):
    """A key of (colour, label) disks at the top-left of ``rect`` (figure fractions)."""
    handles = [Line2D([], [], ls="", marker="o", ms=_points(TEXT_PIXELS), color=color,
                      label=label) for color, label in entries]
    figure.legend(handles=handles, loc="upper left", bbox_to_anchor=(rect[0], rect[1] + rect[3]),
                  bbox_transform=figure.transFigure, frameon=False,
                  fontsize=_points(TEXT_PIXELS - 2))


class SpeciesColors:
    """One colour per species."""

    def __init__(self, species, radius, mass):
        self.species = species
        self.palette = colormaps["tab10"]
        self.entries = [(s, int(np.sum(species == s)), float(radius[species == s][0]),
                         float(mass[species == s][0])) for s in np.unique(species)]

    def __call__(self, frame):
        return self.palette(self.species % 10), ""

    def draw_key(self, figure, rect):
        _draw_legend(figure, rect, [(self.palette(s % 10),
                                     f"species {s}: {n} disk{'s' if n > 1 else ''}\n"
                                     f"R = {r:.4g}, m = {m:.4g}")
                                    for s, n, r, m in self.entries])


class ClusterColors:
    """Cluster labels (0 the largest; :class:`sim.analysis.observers.Clusters`): the run's observed
    labels at the snapshot a frame flies from, or labels of the drawn positions by the same
    rule."""

    def __init__(self, observed, rule):
        self.observed = observed  # [snapshots, n] or None
        self.rule = rule

    def __call__(self, frame):
        labels = (self.observed[frame.snapshot] if self.observed is not None
                  else self.rule(frame.position))
        known = np.isfinite(labels)  # a damaged snapshot of the observable reads as NaN
        sizes = np.bincount(labels[known].astype(np.int64))
        size = np.zeros(labels.shape, dtype=np.int64)
        size[known] = sizes[labels[known].astype(np.int64)]
        colors = np.where(size >= SHOWN_CLUSTER, 1, 2)
        colors[(labels == 0) & (size >= 2)] = 0
        largest = int(np.sum(labels == 0))
        return (np.array([to_rgba(c) for c in (LARGEST_CLUSTER, LARGE_CLUSTER,
                                               SMALL_CLUSTER)])[colors],
                f"largest cluster: {largest} disks ({100.0 * largest / labels.size:.1f} %)")

    def draw_key(self, figure, rect):
        _draw_legend(figure, rect, [(LARGEST_CLUSTER, "largest cluster"),
                                    (LARGE_CLUSTER, f"clusters of ≥ {SHOWN_CLUSTER} disks"),
                                    (SMALL_CLUSTER, "smaller clusters,\nfree disks")])


def cluster_rule(snapshots, radius):
    """Cluster labels of positions float64[n, 2] by the rule of
    :class:`sim.analysis.observers.Clusters`, with the run's gap if it set one."""
    gap = ((snapshots.config.get("observe") or {}).get("clusters") or {}).get("gap")
    disks = SimpleNamespace(radius=radius, n=radius.size, box=snapshots.box,
                            periodic=snapshots.periodic)
    observer = Clusters(DEFAULT_CLUSTER_GAP if gap is None else float(gap), disks)
    return lambda position: observer(disks, None, position, None)


def periodic_images(position, radius, box, periodic):
    """Disk centres float64[m, 2] and the index in ``position`` of each: every disk, and a copy
    shifted by a box side for each periodic side it reaches over."""
    centres, index = [position], [np.arange(len(position))]
    for shift_x in (-1, 0, 1):
        for shift_y in (-1, 0, 1):
            shift = np.array([shift_x, shift_y], dtype=np.float64)
            if not shift.any() or any(s and not p for s, p in zip(shift, periodic, strict=True)):
                continue
            moved = position + shift * box
            reaches = np.all((moved > -radius[:, None]) & (moved < box + radius[:, None]), axis=1)
            centres.append(moved[reaches])
            index.append(np.flatnonzero(reaches))
    return np.concatenate(centres), np.concatenate(index)


class Picture:
    """One figure redrawn for each frame: the disks, the walls, the clock, the kinetic energy
    and the colour key; :meth:`render` gives a frame's pixels."""

    def __init__(self, layout, walls, colors, radius, mass, title, time_decimals):
        self.walls, self.colors = walls, colors
        self.radius, self.mass = radius, mass
        self.time_decimals = time_decimals
        self.figure = Figure(figsize=(layout.width / DPI, layout.height / DPI), dpi=DPI)
        self.canvas = FigureCanvasAgg(self.figure)
        self.axes = self.figure.add_axes(layout.figure_rect(layout.left, layout.top,
                                                            layout.box_width, layout.box_height))
        x0, x1, y0, y1 = layout.view
        self.axes.set(xlim=(x0, x1), ylim=(y0, y1))
        self.axes.set_axis_off()
        box = walls.box
        self.sides = []
        for axis in (0, 1):
            for side in (0, 1):
                if walls.periodic[axis]:
                    along = (0.0, box[1 - axis])
                    place = (side * box[axis],) * 2
                    ends = (place, along) if axis == 0 else (along, place)
                    self.axes.add_line(Line2D(*ends, color=PERIODIC_SIDE, ls="--", lw=1.0,
                                              clip_on=False))
                else:
                    wall = 2 * axis + side
                    color = THERMAL_WALL if walls.thermal[wall] else WALL
                    self.sides.append((wall, self.axes.add_line(
                        Line2D([], [], color=color, lw=_points(2), clip_on=False,
                               solid_capstyle="projecting"))))
        key_left = layout.left + layout.box_width + MARGIN_PIXELS
        text = {"fontsize": _points(TEXT_PIXELS), "va": "center"}
        self.clock = self.figure.text(layout.left / layout.width,
                                      1.0 - 0.5 * HEADER_PIXELS / layout.height, "",
                                      linespacing=1.1,
                                      family="monospace", **text)
        self.figure.text(key_left / layout.width, 1.0 - 0.5 * HEADER_PIXELS / layout.height,
                         title, **text)
        colors.draw_key(self.figure, layout.figure_rect(key_left, layout.top,
                                                        KEY_PIXELS - MARGIN_PIXELS,
                                                        layout.box_height))
        self.caption = self.figure.text(key_left / layout.width,
                                        (layout.height - layout.top - layout.box_height)
                                        / layout.height, "", va="bottom",
                                        fontsize=_points(TEXT_PIXELS - 2))
        self.disks = None

    def _draw_walls(self, time):
        place = self.walls.at(time)
        for wall, line in self.sides:
            axis, other = wall >> 1, 1 - (wall >> 1)
            across = ((0.0, self.walls.box[other]) if self.walls.periodic[other]
                      else (place[2 * other], place[2 * other + 1]))
            at = (place[wall], place[wall])
            line.set_data(*((at, across) if axis == 0 else (across, at)))

    def render(self, frame):
        """The pixels uint8[height, width, 3] of ``frame``."""
        if self.disks is not None:
            self.disks.remove()
        centres, index = periodic_images(frame.position, self.radius, self.walls.box,
                                         self.walls.periodic)
        diameter = 2.0 * self.radius[index]
        colors, caption = self.colors(frame)
        self.disks = self.axes.add_collection(EllipseCollection(
            diameter, diameter, np.zeros_like(diameter), units="xy", offsets=centres,
            offset_transform=self.axes.transData, facecolors=colors[index],
            linewidths=0))
        self._draw_walls(frame.time)
        energy = 0.5 * float(np.sum(self.mass * np.sum(frame.velocity**2, axis=1)))
        self.clock.set_text(f"t = {frame.time:.{self.time_decimals}f}\n"
                            f"kinetic energy {energy:.4g}")
        self.caption.set_text(caption)
        self.canvas.draw()
        return np.ascontiguousarray(np.asarray(self.canvas.buffer_rgba())[..., :3])


def ffmpeg_missing():
    """Why imageio-ffmpeg cannot write an MP4 here (not installed, or no ffmpeg found), or
    None when it can; imageio-ffmpeg is imported only to write MP4s, GIFs do without it."""
    try:
        import imageio_ffmpeg

        imageio_ffmpeg.get_ffmpeg_exe()
    except (ImportError, RuntimeError) as error:
        return " ".join(str(error).split())
    return None


def write_mp4(path, pictures, size, fps, count):
    """Encode ``count`` RGB frames (uint8[h, w, 3]) as H.264 (yuv420p) at ``fps`` into
    ``path``, then count the frames the file holds: OSError unless all are there."""
    import imageio_ffmpeg

    writer = imageio_ffmpeg.write_frames(str(path), size, fps=fps,
                                         pix_fmt_out="yuv420p", ffmpeg_log_level="error",
                                         output_params=["-preset", "veryfast"])
    writer.send(None)
    try:
        for picture in pictures:
            writer.send(picture)
    finally:
        writer.close()
    try:
        written, _ = imageio_ffmpeg.count_frames_and_secs(str(path))
    except RuntimeError as error:
        raise OSError(f"ffmpeg cannot read back {path}: {str(error).splitlines()[0]}") from error
    if written != count:
        raise OSError(f"ffmpeg wrote {written} of {count} frames into {path}")


def write_gif(path, pictures, fps):
    """Write RGB frames (uint8[h, w, 3]) into an animated GIF through Pillow."""
    images = (Image.fromarray(picture) for picture in pictures)
    first = next(images)
    first.save(path, save_all=True, append_images=images, duration=round(1000.0 / fps),
               loop=0)


def write_whole(out, write):
    """``write(path)`` to a hidden name beside ``out``, renamed to ``out`` once it returns;
    removed when it fails."""
    partial = out.with_name(f".{out.stem}.{os.getpid()}.part{out.suffix}")
    try:
        write(partial)
        os.replace(partial, out)
    except BaseException:
        partial.unlink(missing_ok=True)
        raise


def frame_times(snapshot_times, fps, frames=None, duration=None, start=None, stop=None):
    """Times float64[F] of the frames, evenly spaced from ``start`` to ``stop`` (default the
    first and last snapshot): ``frames`` of them, or ``duration`` × ``fps``, or one per
    snapshot in between (at most DEFAULT_MAX_SECONDS of movie). Bad values: BadInput."""
    if not 0.0 < fps <= MAX_FPS:
        raise BadInput(f"--fps {fps}: a frame rate above 0 and at most {MAX_FPS:g}")
    first, last = float(snapshot_times[0]), float(snapshot_times[-1])
    start = first if start is None else start
    stop = last if stop is None else stop
    if not first <= start <= stop <= last:
        raise BadInput(f"--start {start:.6g} and --stop {stop:.6g}: the run's snapshots span "
                         f"t = {first:.6g} to {last:.6g}; a frame is drawn only from a snapshot "
                         f"before it, so give {first:.6g} ≤ start ≤ stop ≤ {last:.6g}")
    if duration is not None:
        if not 0.0 < duration < math.inf:
            raise BadInput(f"--duration {duration}: seconds of movie, above 0")
        frames = round(duration * fps)
        if frames < 1:
            raise BadInput(f"--duration {duration} at --fps {fps:g} is less than one frame")
    elif frames is None:
        inside = snapshot_times[(snapshot_times >= start) & (snapshot_times <= stop)]
        distinct = int(np.sum(np.diff(inside) > round_off(snapshot_times))) + 1
        frames = max(1 if start == stop else 2, min(distinct, round(DEFAULT_MAX_SECONDS * fps)))
    if frames < 1:
        raise BadInput(f"--frames {frames}: at least one frame")
    if frames > 1 and start == stop:
        raise BadInput(f"--start and --stop are both {start:.6g}: one frame only "
                         f"(--frames 1)")
    return np.linspace(start, stop, frames)


def _output(run_path, out):
    """The movie's path: ``out``, or the run file's with .mp4; BadInput for a name that is
    neither .mp4 nor .gif or a folder that does not exist."""
    out = Path(run_path).with_suffix(".mp4") if out is None else Path(out)
    if out.suffix.lower() not in (".mp4", ".gif"):
        raise BadInput(f"--out {out}: a movie name ending in .mp4 or .gif")
    if not out.parent.is_dir():
        raise BadInput(f"--out {out}: no folder {out.parent}")
    return out


def make_movie(run_path, out=None, fps=30.0, frames=None, duration=None, color="speed",
               start=None, stop=None, note=print):
    """Write the movie of the run file ``run_path`` (the command's options as arguments) and
    return its path: ``out``, or the same name with .gif when ffmpeg is unavailable. Notes (a
    GIF instead of an MP4, frames drawn across contacts) go to ``note``, one line each.
    BadInput or :class:`sim.storage.errors.RunFileError` for bad input, another OSError when the
    movie cannot be written."""
    if color not in COLORINGS:
        raise BadInput(f"--color {color}: one of {', '.join(COLORINGS)}")
    out = _output(run_path, out)
    with open_run(run_path) as ds:
        snapshots = Snapshots(ds)
        times = frame_times(snapshots.times, fps, frames, duration, start, stop)
        spacing = (times[-1] - times[0]) / max(times.size - 1, 1)
        between, missed, interval = snapshots.missed_contacts(times)
        if missed > MISSED_CONTACTS:
            note(f"sim-movie: note: {between} of {times.size} frames lie between snapshots "
                 f"{interval:.3g} time units apart (frames {spacing:.3g}), in which a disk makes "
                 f"{missed:.2g} contacts on average; drawn in free flight, disks pass through "
                 f"each other and walls there; snapshots every "
                 f"{interval * MISSED_CONTACTS / missed:.2g} time units (output.every_time) "
                 f"would keep that below {MISSED_CONTACTS}")
        missing = ffmpeg_missing() if out.suffix.lower() == ".mp4" else None
        if missing:
            note(f"sim-movie: {missing}; writing {out.with_suffix('.gif')} through Pillow "
                 f"instead")
            out = out.with_suffix(".gif")
        radius = ds["radius"].values.astype(np.float64)
        mass = ds["mass"].values.astype(np.float64)
        if color == "speed":
            colors = SpeedColors(speed_limit(snapshots.frames(times)))
        elif color == "species":
            colors = SpeciesColors(ds["species_id"].values.astype(np.int64), radius, mass)
        else:
            observed = ds["clusters"].values if "clusters" in ds else None
            colors = ClusterColors(observed, cluster_rule(snapshots, radius))
        walls = Walls(snapshots.config, snapshots.box, snapshots.periodic)
        layout = Layout.of_view(walls.view(times))
        decimals = 4 if spacing <= 0.0 else min(9, max(0, math.ceil(-math.log10(spacing)) + 1))
        picture = Picture(layout, walls, colors, radius, mass,
                          f"{ds.attrs['scene']}: {ds.sizes['disk']} disks", decimals)
        pictures = (picture.render(frame) for frame in snapshots.frames(times))
        if out.suffix.lower() == ".gif":
            write_whole(out, lambda path: write_gif(path, pictures, fps))
        else:
            size = (layout.width, layout.height)
            write_whole(out, lambda path: write_mp4(path, pictures, size, fps, times.size))
    return out


def main(argv=None):
    parser = Parser(prog="sim-movie", description=__doc__.splitlines()[0])
    parser.add_argument("run", help="run file (run.h5)")
    parser.add_argument("--out", help="movie file, .mp4 or .gif (default: RUN with .mp4)")
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second (30)")
    length = parser.add_mutually_exclusive_group()
    length.add_argument("--duration", type=float, help="seconds of movie")
    length.add_argument("--frames", type=int, help="number of frames")
    parser.add_argument("--color", default="speed", help="speed (default), species or cluster")
    parser.add_argument("--start", type=float, help="time of the first frame (first snapshot)")
    parser.add_argument("--stop", type=float, help="time of the last frame (last snapshot)")

    def body():
        args = parser.parse_args(argv)
        try:
            out = make_movie(args.run, args.out, args.fps, args.frames, args.duration,
                             args.color, args.start, args.stop,
                             note=lambda line: print(line, file=sys.stderr, flush=True))
        except RunFileError:  # the run file read, not the movie written: bad input
            raise
        except OSError as error:
            reason = str(error).strip().splitlines()[0] if str(error).strip() else repr(error)
            raise CannotWrite(f"the movie could not be written: {reason}") from error
        print(f"sim-movie: wrote {out}")

    return run_command("sim-movie", body, bad_input=(RunFileError,), unwritten="no movie written")


if __name__ == "__main__":
    sys.exit(main())
