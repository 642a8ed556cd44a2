"""A run's snapshots and the times of a movie's frames.

Frames are evenly spaced in simulated time from --start to --stop (default: the first and the
last snapshot), one per snapshot in between (at most 30 s of movie, and at most the limit of
:func:`frame_count`) unless --frames or --duration (seconds of movie at --fps) says otherwise;
a count asked for above that limit is refused before any work. With --at-snapshots, a frame
is drawn at each snapshot from --start to --stop instead, at the snapshot's own time
(:func:`snapshot_frame_times`; the limit checked once the run's times are read): frames as far
apart as the snapshots, e.g. a fixed number of collisions (``output.every_collisions``), which
for a cooling gas keeps the motion per frame about even where equal steps in time would not.
A frame at time t draws each disk in free flight from the latest snapshot k at or before t,
never back from a later one: r = r_k + v_k (t − t_k) + ½ g (t − t_k)² and
v = v_k + g (t − t_k), g the run's gravity (box units / time²), r wrapped into the box along
periodic axes.
Contacts between snapshots are not drawn: between two snapshots a disk may pass through a
neighbour or a wall. A disk drawn a time s after its snapshot has met something with
probability about s/τ (τ its mean free time); frames between snapshots lie on average half an
interval Δ after theirs, so about Δ/(2τ) of their disks are off their true path
(:meth:`Snapshots.missed_contacts` measures Δ/τ).
"""

import math
from dataclasses import dataclass

import numpy as np
import yaml

from sim.effects.gravity import gravity_vector
from sim.engine.box import folded
from sim.pipeline.command import BadInput

#: the longest movie made by default, one frame per snapshot (seconds)
DEFAULT_MAX_SECONDS = 30.0
#: the fastest frame rate accepted (frames per second)
MAX_FPS = 120.0
#: the slowest frame rate accepted: one frame a second (a GIF's frame delay is a 16-bit count
#: of hundredths of a second, and ffmpeg refuses rates far below)
MIN_FPS = 1.0
#: the most frames of a movie: frames are drawn and encoded one at a time (some 30 ms each for
#: 200 disks, more for more disks), so time, not memory, bounds an MP4: 100 000 frames are
#: 56 min of movie at 30 fps and about an hour of drawing; what is kept per frame (its time,
#: its snapshot, the walls' places) takes a few hundred bytes, some 25 MB for the most
MAX_FRAMES = 100_000


def free_flight(position, velocity, elapsed, gravity=None, box=None, periodic=(False, False)):
    """Positions and velocities float64[n, 2] a time ``elapsed`` ≥ 0 after a snapshot's
    ``position`` and ``velocity``, every disk in free flight under ``gravity`` (float64[2] or
    None), positions wrapped into ``box`` along ``periodic`` axes."""
    acceleration = np.zeros(2) if gravity is None else np.asarray(gravity, dtype=np.float64)
    moved = position + velocity * elapsed + 0.5 * acceleration * elapsed**2
    if any(periodic):
        moved = folded(moved, box, periodic)
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
        contacts = (2.0 * self.ds["collisions"].values + self.ds["wall_contacts"].values)
        contacts = contacts[self.readable]
        per_disk = (contacts[inside + 1] - contacts[inside]) / self.ds.sizes["disk"]
        interval = self.times[inside + 1] - self.times[inside]
        return (int(np.sum(elapsed > 0.0)), float(np.nanmean(per_disk)),
                float(np.mean(interval)))


def frame_count(fps, frames, duration, limit, why, at_snapshots=False):
    """The number of frames asked for: ``frames``, or ``duration`` × ``fps`` rounded; None when
    neither is given (one per snapshot, :func:`frame_times`, or at each snapshot when
    ``at_snapshots``, :func:`snapshot_frame_times`). BadInput, before any work, for a rate, a
    length or a count out of range, a count above ``limit`` (``why``: its reason), or a count
    given with ``at_snapshots``."""
    if not MIN_FPS <= fps <= MAX_FPS:
        raise BadInput(f"--fps {fps}: a frame rate from {MIN_FPS:g} to {MAX_FPS:g} frames a "
                       f"second")
    if at_snapshots and (frames is not None or duration is not None):
        raise BadInput("--at-snapshots draws one frame at each snapshot: give neither "
                       "--frames nor --duration with it")
    beyond = f"at most {limit} frames ({why})"
    if duration is not None:
        if not 0.0 < duration < math.inf:
            raise BadInput(f"--duration {duration}: seconds of movie, above 0 and finite")
        if duration * fps >= limit + 0.5:
            raise BadInput(f"--duration {duration:g} at --fps {fps:g} is {duration * fps:.3g} "
                           f"frames: {beyond}, so --duration up to {limit / fps:.6g}")
        frames = round(duration * fps)
        if frames < 1:
            raise BadInput(f"--duration {duration} at --fps {fps:g} is less than one frame")
    elif frames is not None and not 1 <= frames <= limit:
        raise BadInput(f"--frames {frames}: at least one frame and {beyond}")
    return frames


def _span(snapshot_times, start, stop):
    """(start, stop) of the frames: the first and last snapshot when None; BadInput unless
    first ≤ start ≤ stop ≤ last."""
    first, last = float(snapshot_times[0]), float(snapshot_times[-1])
    start = first if start is None else start
    stop = last if stop is None else stop
    if not first <= start <= stop <= last:
        raise BadInput(f"--start {start:.6g} and --stop {stop:.6g}: the run's snapshots span "
                         f"t = {first:.6g} to {last:.6g}; a frame is drawn only from a snapshot "
                         f"before it, so give {first:.6g} ≤ start ≤ stop ≤ {last:.6g}")
    return start, stop


def snapshot_frame_times(snapshot_times, start=None, stop=None, limit=MAX_FRAMES,
                         why="MAX_FRAMES"):
    """Times float64[F] of the frames drawn at the snapshots: each distinct snapshot time from
    ``start`` to ``stop`` (default the first and last snapshot; times within
    :func:`round_off` are one). BadInput when none lies there or more than ``limit`` do
    (``why``: the limit's reason)."""
    start, stop = _span(snapshot_times, start, stop)
    tolerance = round_off(snapshot_times)
    inside = snapshot_times[(snapshot_times >= start - tolerance)
                            & (snapshot_times <= stop + tolerance)]
    if not inside.size:
        raise BadInput(f"--at-snapshots: no snapshot from t = {start:.6g} to {stop:.6g}")
    times = inside[np.append(np.diff(inside) > tolerance, True)]
    if times.size > limit:
        raise BadInput(f"--at-snapshots: {times.size} snapshots from t = {start:.6g} to "
                       f"{stop:.6g}, at most {limit} frames ({why}): narrow --start and --stop")
    return times


def frame_times(snapshot_times, fps, count=None, start=None, stop=None, limit=MAX_FRAMES):
    """Times float64[F] of the frames, evenly spaced from ``start`` to ``stop`` (default the
    first and last snapshot): ``count`` of them (:func:`frame_count`), or one per snapshot in
    between (at most DEFAULT_MAX_SECONDS of movie at ``fps`` and at most ``limit``). Bad
    values: BadInput."""
    start, stop = _span(snapshot_times, start, stop)
    if count is None:
        inside = snapshot_times[(snapshot_times >= start) & (snapshot_times <= stop)]
        distinct = int(np.sum(np.diff(inside) > round_off(snapshot_times))) + 1
        count = max(1 if start == stop else 2,
                    min(distinct, round(DEFAULT_MAX_SECONDS * fps), limit))
    if count > 1 and start == stop:
        raise BadInput(f"--start and --stop are both {start:.6g}: one frame only "
                         f"(--frames 1)")
    return np.linspace(start, stop, count)
