"""``python -m sim.figures.movie RUN.h5 [--out FILE] [--fps N]
[--duration SECONDS | --frames N | --at-snapshots] [--color speed|species|cluster]
[--speed-scale linear|log] [--start T] [--stop T]`` (also ``sim-movie``): a movie of a run.

Frames evenly spaced in time, or one at each snapshot (:mod:`sim.figures.movie.snapshots`),
the disks coloured by speed (a linear or log scale up to the fastest disk drawn), species or
cluster (:mod:`sim.figures.movie.colors`).

MP4 (frame sides multiples of 16) through imageio-ffmpeg's ffmpeg; a GIF through Pillow when
FILE ends in .gif, or when ffmpeg is unavailable (said in one line). At most 100 000 frames
(:data:`sim.figures.movie.snapshots.MAX_FRAMES`: frames are drawn one at a time, some 30 ms
each); a GIF also at most as many as fit in half the available memory, Pillow keeping every
frame (up to 912 × 704 bytes) until it writes the file
(:func:`sim.figures.movie.make.frame_limit`).
FILE (default: RUN with .mp4) is written under a hidden name beside it, made before any work,
and renamed once complete: exit status 0; 2, with one line on stderr, for bad input (no run
file, a value out of range, too many frames, a FILE whose folder does not exist or cannot be
written), checked before the run's snapshots are read; 1 when writing fails later (a full
disk); 130 after Ctrl-C, 143 after SIGTERM. Nothing but a whole movie is left behind.
"""

import argparse
import math
import sys

from sim.figures.movie.colors import LOG_DECADES
from sim.figures.movie.make import GIF_FRAME_BYTES, make_movie
from sim.figures.movie.snapshots import DEFAULT_MAX_SECONDS, MAX_FPS, MAX_FRAMES, MIN_FPS
from sim.pipeline.command import CannotWrite, Parser, run_command
from sim.storage.errors import RunFileError


def whole_number(text):
    """``--frames`` as written: a whole number, also as ``2e3`` or ``2000.0``; anything else
    is the option's refusal (argparse's "invalid value")."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: a whole number of frames") from None
    if not (math.isfinite(value) and value == int(value)):
        raise argparse.ArgumentTypeError(f"{text!r}: a whole number of frames")
    return int(value)


def main(argv=None):
    parser = Parser(prog="sim-movie", description="A movie of a run file (MP4, or a GIF).")
    parser.add_argument("run", help="run file (run.h5)")
    parser.add_argument("--out", help="movie file, .mp4 or .gif (default: RUN with .mp4)")
    parser.add_argument("--fps", type=float, default=30.0,
                        help=f"frames per second, from {MIN_FPS:g} to {MAX_FPS:g} (30)")
    length = parser.add_mutually_exclusive_group()
    limit = (f"at most {MAX_FRAMES} frames (each is drawn in some 30 ms), for a GIF also no more "
             f"than fit in half the available memory ({GIF_FRAME_BYTES / 1e6:.2f} MB a frame)")
    length.add_argument("--duration", type=float,
                        help=f"seconds of movie: --duration × --fps frames, {limit} (default: one "
                             f"frame per snapshot, at most {DEFAULT_MAX_SECONDS:g} s)")
    length.add_argument("--frames", type=whole_number, help=f"number of frames, {limit}")
    length.add_argument("--at-snapshots", action="store_true",
                        help="a frame at each snapshot from --start to --stop, at its own time "
                             "(frames as far apart as the snapshots, e.g. in collisions)")
    parser.add_argument("--color", default="speed", help="speed (default), species or cluster")
    parser.add_argument("--speed-scale", default="linear",
                        help=f"speed colours from 0 (linear, default) or over {LOG_DECADES} "
                             f"decades (log), up to the fastest disk drawn")
    parser.add_argument("--start", type=float, help="time of the first frame (first snapshot)")
    parser.add_argument("--stop", type=float, help="time of the last frame (last snapshot)")

    def body():
        args = parser.parse_args(argv)
        try:
            out = make_movie(args.run, args.out, args.fps, args.frames, args.duration,
                             args.color, args.start, args.stop, args.at_snapshots,
                             args.speed_scale,
                             note=lambda line: print(line, file=sys.stderr, flush=True))
        except RunFileError:  # the run file read, not the movie written: bad input
            raise
        except OSError as error:
            reason = str(error).strip().splitlines()[0] if str(error).strip() else repr(error)
            raise CannotWrite(f"the movie could not be written: {reason}") from error
        print(f"sim-movie: wrote {out}")

    return run_command("sim-movie", body, bad_input=(RunFileError,), unwritten="no movie written")
