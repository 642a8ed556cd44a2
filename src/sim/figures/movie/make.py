"""The movie of a run file: its frames chosen (:mod:`.snapshots`), coloured (:mod:`.colors`),
drawn (:mod:`.picture`) and written whole (:mod:`sim.storage.whole_file`, :mod:`.encode`).
Everything that needs no run file is checked first (the colouring, the movie's name, the
number of frames against :func:`frame_limit`, that the movie's folder can be written), then
the run is read (and the number of frames at its snapshots checked, when asked for). One line
of note when the snapshot intervals the frames lie in hold more than :data:`MISSED_CONTACTS`
contacts per disk on average (Δ > τ/10: more than 5 % of the drawn disks misplaced), and when
a GIF replaces an MP4 for want of ffmpeg."""

import math
from pathlib import Path

import numpy as np

from sim.analysis.datasets import open_run
from sim.figures.movie.colors import COLORINGS, SPEED_SCALES, coloring
from sim.figures.movie.encode import ffmpeg_missing, write_gif, write_mp4
from sim.figures.movie.layout import Layout
from sim.figures.movie.picture import Picture, Walls
from sim.figures.movie.snapshots import (
    MAX_FRAMES,
    Snapshots,
    frame_count,
    frame_times,
    snapshot_frame_times,
)
from sim.pipeline.command import BadInput
from sim.pipeline.resources import available_memory
from sim.storage.whole_file import whole_file

#: contacts per disk per snapshot interval above which frames between snapshots get a note
MISSED_CONTACTS = 0.1
_SQUARE = Layout.of_view((0.0, 1.0, 0.0, 1.0))
#: bytes a GIF frame holds until the GIF is written: Pillow keeps every frame, one byte (a
#: palette index) per pixel, and the largest frame is that of a square view (912 × 704)
GIF_FRAME_BYTES = _SQUARE.width * _SQUARE.height
#: the share of the available memory a GIF's frames may take
GIF_MEMORY_SHARE = 0.5


def _output(run_path, out):
    """The movie's path: ``out``, or the run file's with .mp4; BadInput for a name that is
    neither .mp4 nor .gif."""
    out = Path(run_path).with_suffix(".mp4") if out is None else Path(out)
    if out.suffix.lower() not in (".mp4", ".gif"):
        raise BadInput(f"--out {out}: a movie name ending in .mp4 or .gif")
    return out


def frame_limit(gif):
    """The most frames of a movie, and why: :data:`MAX_FRAMES` (an MP4 is drawn and encoded
    frame by frame); for a GIF also as many as fit in :data:`GIF_MEMORY_SHARE` of the
    available memory (:func:`sim.pipeline.resources.available_memory`), Pillow holding every
    frame, :data:`GIF_FRAME_BYTES` each, until it writes the file."""
    if gif:
        available = available_memory()
        if GIF_MEMORY_SHARE * available < MAX_FRAMES * GIF_FRAME_BYTES:
            return (int(GIF_MEMORY_SHARE * available // GIF_FRAME_BYTES),
                    f"a GIF's frames stay in memory until it is written, "
                    f"{GIF_FRAME_BYTES / 1e6:.2f} MB each, and may take half of the "
                    f"{available / 1e9:.3g} GB available")
    return MAX_FRAMES, "each is drawn in some 30 ms: an hour for the most"


def clock_decimals(times):
    """Decimals of the clock: enough to tell apart the two closest frames of ``times``, one
    more than the first significant place of their step (a step a few ulps below 0.1 counts as
    0.1; 4 for a single frame, at most 9)."""
    steps = np.diff(times)
    step = float(np.min(steps)) if steps.size else 0.0
    if step <= 0.0:
        return 4
    return min(9, max(0, math.ceil(-math.log10(step) - 1e-9) + 1))


def make_movie(run_path, out=None, fps=30.0, frames=None, duration=None, color="speed",
               start=None, stop=None, at_snapshots=False, speed_scale="linear", note=print):
    """Write the movie of the run file ``run_path`` (the command's options as arguments;
    ``at_snapshots``: a frame at each snapshot, ``speed_scale``: linear or log) and return its
    path: ``out``, or the same name with .gif when ffmpeg is unavailable. Notes (a GIF instead
    of an MP4, frames drawn across contacts) go to ``note``, one line each. BadInput or
    :class:`sim.storage.errors.RunFileError` for bad input, another OSError when the movie
    cannot be written."""
    if color not in COLORINGS:
        raise BadInput(f"--color {color}: one of {', '.join(COLORINGS)}")
    if speed_scale not in SPEED_SCALES:
        raise BadInput(f"--speed-scale {speed_scale}: one of {', '.join(SPEED_SCALES)}")
    out = _output(run_path, out)
    missing = ffmpeg_missing() if out.suffix.lower() == ".mp4" else None
    if missing:
        out = out.with_suffix(".gif")
    gif = out.suffix.lower() == ".gif"
    limit, why = frame_limit(gif)
    count = frame_count(fps, frames, duration, limit, why, at_snapshots)
    with whole_file(out) as partial, open_run(run_path) as ds:
        snapshots = Snapshots(ds)
        times = (snapshot_frame_times(snapshots.times, start, stop, limit, why) if at_snapshots
                 else frame_times(snapshots.times, fps, count, start, stop, limit))
        between, missed, interval = snapshots.missed_contacts(times)
        if missed > MISSED_CONTACTS:
            spacing = (times[-1] - times[0]) / max(times.size - 1, 1)
            note(f"sim-movie: note: {between} of {times.size} frames lie between snapshots "
                 f"{interval:.3g} time units apart (frames {spacing:.3g}), in which a disk makes "
                 f"{missed:.2g} contacts on average; drawn in free flight, disks pass through "
                 f"each other and walls there; snapshots every "
                 f"{interval * MISSED_CONTACTS / missed:.2g} time units (output.every_time) "
                 f"would keep that below {MISSED_CONTACTS}")
        if missing:
            note(f"sim-movie: {missing}; writing {out} through Pillow instead")
        radius = ds["radius"].values.astype(np.float64)
        mass = ds["mass"].values.astype(np.float64)
        colors = coloring(color, snapshots, times, radius, mass, speed_scale)
        walls = Walls(snapshots.config, snapshots.box, snapshots.periodic)
        layout = Layout.of_view(walls.view(times))
        picture = Picture(layout, walls, colors, radius, mass,
                          f"{ds.attrs['scene']}: {ds.sizes['disk']} disks",
                          clock_decimals(times),
                          float((snapshots.config.get("growth") or {}).get("rate", 0.0)))
        pictures = (picture.render(frame) for frame in snapshots.frames(times))
        if gif:
            write_gif(partial, pictures, fps)
        else:
            write_mp4(partial, pictures, (layout.width, layout.height), fps, times.size)
    return out
