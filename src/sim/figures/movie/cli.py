"""``python -m sim.figures.movie RUN.h5 [--out FILE] [--fps N] [--duration SECONDS | --frames N]
[--color speed|species|cluster] [--start T] [--stop T]`` (also ``sim-movie``): a movie of a run.

Frames evenly spaced in time (:mod:`sim.figures.movie.snapshots`), the disks coloured by
speed, species or cluster (:mod:`sim.figures.movie.colors`).

MP4 (frame sides multiples of 16) through imageio-ffmpeg's ffmpeg; a GIF through Pillow when
FILE ends in .gif, or when ffmpeg is unavailable (said in one line). FILE (default: RUN with
.mp4) is written under a hidden name beside it and renamed once complete: exit status 0; 1
when the movie cannot be written; 2, with one line on stderr, for bad input (no run file, a
value out of range); 130 after Ctrl-C, 143 after SIGTERM. Nothing but a whole movie is left
behind.
"""

import sys

from sim.figures.movie.make import make_movie
from sim.pipeline.command import CannotWrite, Parser, run_command
from sim.storage.errors import RunFileError


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
