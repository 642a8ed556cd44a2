"""The movie of a run file: its frames chosen (:mod:`.snapshots`), coloured (:mod:`.colors`),
drawn (:mod:`.picture`) and written whole (:mod:`.encode`). One line of note when the snapshot
intervals the frames lie in hold more than :data:`MISSED_CONTACTS` contacts per disk on average
(Δ > τ/10: more than 5 % of the drawn disks misplaced), and when a GIF replaces an MP4 for want
of ffmpeg."""

import math
from pathlib import Path

import numpy as np

from sim.analysis.datasets import open_run
from sim.figures.movie.colors import COLORINGS, coloring
from sim.figures.movie.encode import ffmpeg_missing, write_gif, write_mp4, write_whole
from sim.figures.movie.layout import Layout
from sim.figures.movie.picture import Picture, Walls
from sim.figures.movie.snapshots import Snapshots, frame_times
from sim.pipeline.command import BadInput

#: contacts per disk per snapshot interval above which frames between snapshots get a note
MISSED_CONTACTS = 0.1


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
        colors = coloring(color, snapshots, times, radius, mass)
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
