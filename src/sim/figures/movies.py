"""Movies (beyond the study), MP4s drawn by :mod:`sim.figures.movie` beside the figures: the
two-disk scene, the crater impact coloured by speed, the cooling gas with its largest cluster
red, and square-well disks splitting into liquid and vapour, their largest drop red.

Every frame is a snapshot of its run, so none is drawn in free flight across contacts. Two
disks: snapshots every 0.0125 (``output.every_time``), 60 frames per second, in which a disk
(speed at most 1.3) moves under 2 % of the box, from t = 8, just before their first
collision, to 14.5 (quick: to 10). Crater: snapshots every 0.001 (quick 0.002) until t = 0.13,
near the study's stop at 10 % of the energy; the projectile, falling at 10, moves 1 % of the
box per frame (quick 2 %) before it hits; speed on a log scale over three decades up to the
fastest disk of any frame (:mod:`sim.figures.movie.colors`), so that neither the impact
saturates nor the bed's slow flow vanishes. Cooling: the gas cools by Haff's law,
T = T0 / (1 + t/t0)², then clusters, so that frames equal in time would move a disk far in
the first frames and hardly at all in the last; instead a frame at each snapshot, every 1500
collisions (``output.every_collisions``: a disk takes part in 1.5 collisions between frames
on average, and so moves about as far at every stage), until t = 100, long enough for the clusters
to grow, the clock showing the unequal steps in time. Quick: 1000 disks, every 200 collisions
(0.4 per disk) until t = 40, a box too small for clusters to last. Square well: the run of
figure 15's third panel (:func:`sim.figures.stepped_potentials.split_run`), a frame at each
snapshot (every 5 collisions per disk), disks linked into clusters within the well.
"""

from sim.analysis.crater import crater_overrides
from sim.figures.movie import make_movie
from sim.figures.stepped_potentials import split_run

NAME = "movies"

#: label: make_movie's options
MOVIES = {"two_disks": {"color": "speed", "fps": 60.0, "start": 8.0},
          "crater": {"color": "speed", "speed_scale": "log", "fps": 30.0},
          "cooling": {"color": "cluster", "fps": 30.0, "at_snapshots": True},
          "square_well": {"color": "cluster", "fps": 30.0, "at_snapshots": True}}


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
                    f"output.every_collisions={200 if quick else 1500}"],
        "square_well": split_run(quick),
    }


def draw(runs, sweeps, out_dir):
    paths = [make_movie(runs[label], out_dir / f"movie_{label}.mp4", **options)
             for label, options in MOVIES.items()]
    return ", ".join(str(path) for path in paths)
