"""Movies (beyond the study), MP4s drawn by :mod:`sim.figures.movie` beside the figures: the
two-disk scene, the crater impact coloured by speed, and the cooling gas with its largest cluster
red.

Each run writes a snapshot at the time of every frame (``output.every_time``), so that no frame
is drawn in free flight across contacts. Two disks: frames 0.0125 apart, 60 per second, in
which a disk (speed at most 1.3) moves at most 1.6 % of the box, from t = 8, just before
their first collision, to 14.5 (quick: to 10). Crater: frames 0.001 apart (quick 0.002) until
t = 0.13, near the study's stop at 10 % of the energy; the projectile falls 1 % of the box per
frame (quick 2 %) before it hits. Cooling: frames 0.4 apart until t = 100, long enough for the
clusters to grow (quick: 1000 disks until t = 40, a box too small for clusters to last).
"""

from sim.analysis.crater import crater_overrides
from sim.figures.movie import make_movie

NAME = "movies"

#: label: (colour, frames per second, time of the first frame (None: the first snapshot))
MOVIES = {"two_disks": ("speed", 60.0, 8.0), "crater": ("speed", 30.0, None),
          "cooling": ("cluster", 30.0, None)}


def runs(quick):
    bed = [o for o in crater_overrides(quick) if not o.startswith("output.")]
    return {
        "two_disks": ["scenario=two_disks", f"stop.time={10.0 if quick else 14.5}",
                      "output.every_time=0.0125"],
        "crater": [*bed, "stop.energy_fraction=null", "stop.time=0.13",
                   "output.every_collisions=null",
                   f"output.every_time={0.002 if quick else 0.001}"],
        "cooling": ["scenario=cooling", *(["disks.n=1000"] if quick else []),
                    "stop.collisions=null", f"stop.time={40.0 if quick else 100.0}",
                    "output.every_collisions=null", "output.every_time=0.4"],
    }


def draw(runs, sweeps, out_dir):
    paths = [make_movie(runs[label], out_dir / f"movie_{label}.mp4", fps=fps, color=color,
                        start=start)
             for label, (color, fps, start) in MOVIES.items()]
    return ", ".join(str(path) for path in paths)
