"""The plan of the melting study (:mod:`study`): its groups of state points at the
published sizes, boxes and packing fractions, the rules that end a point's runs, and the
points with their run folders."""

import math
from dataclasses import dataclass
from pathlib import Path

from sim.checks.melting import reference

#: the drift of the production's halves, in standard errors, below which a run is stationary
DRIFT = 3.0
#: a round resumes a point to this many times the length its error asks for
MARGIN = 1.3
#: and to at least 1.5, at most 4 times its length so far
GROWTH = (1.5, 4.0)
#: the fewest production blocks of a point done: blocking has three levels of 8 and more
PRODUCTION_BLOCKS = 64
#: the largest share of its blocks a point done may cut as equilibration. A longer cut is a
#: transient the run is too short for, or rare excursions that MSER took for one: N = 72 in
#: its lattice box at φ = 0.720 leaves its crystal for a few blocks now and then (βP d²
#: 9.1–9.4 against 8.935); a cut of 297 blocks after the last early excursion gave
#: 8.9348 ± 0.0005 at 1000 blocks and 8.9360 ± 0.0007 at 1500 against the published
#: 8.9492 ± 0.0005, and a share of a quarter let the second pass
CUT = 0.10
#: runs of one state point from different starts agree when they differ by at most this many
#: combined standard errors; until they do, both run on
AGREEMENT = 3.0


@dataclass(frozen=True)
class Group:
    """State points of one N and box: ``phis`` (published packing fractions), started as
    ``start`` (``compressed``: a random gas compressed by growing disks; ``melted``: a
    hexagonal lattice melted by a short elastic run; ``lattice``: the hexagonal lattice
    that fills the box, jittered), one run with each of ``seeds``; a snapshot, one block of
    the pressure, every ``block`` collisions per disk; ``first`` collisions per disk in the
    first round, at most ``longest``; an error of βP d² of at most ``target`` for the state
    point and start (:attr:`Point.target`)."""

    name: str
    n: int
    box: str
    phis: tuple
    start: str
    block: int
    first: int
    longest: int
    target: float
    seeds: tuple = (0,)


#: the published sizes and boxes (Li et al. 2022), with the published points dense where the
#: curves bend; N = 128² at the points of its MPMC data, the loop's maximum (0.704) and its
#: lowest published point (0.716, the last: the minimum lies beyond) from both starts. The
#: box of N = 870 made for its 29 × 30 lattice starts from that lattice past the loop's
#: minimum: a fluid compressed there freezes into a crystal turned against the box (at
#: φ = 0.718 by 8.7°, strained: βP d² = 9.23 against the published 9.08), which an MD run
#: does not turn back. N = 128² at φ = 0.716 from the compressed start had an error of
#: 0.0043 at 1.2·10⁶ collisions per disk, where its target asks about 2.7 times that
#: length (``study.next_length``). N = 224 in the coexistence (φ = 0.704–0.712) had errors of
#: 0.006–0.011 at 10⁷ collisions per disk, where its target asks 4–14 times that length.
#: Runs again with other seeds, where one run lies more than 3 combined errors from the
#: published value (N = 72 in its lattice box at φ = 0.696; N = 224 at 0.720, whose
#: compressed fluid froze into one crystal that the run never left, its blocking error ten
#: times below the published one; N = 870 in its square box past the loop, φ = 0.714–0.718,
#: whose compressed fluid can freeze for a while into a strained crystal: at 0.718, seed 0,
#: βP d² ≈ 9.38 from 1.3·10⁵ to 10⁶ collisions per disk, fluid at ≈ 9.0 before and after,
#: and at 0.716 a run called done inside such a crystal, far above the published pressure),
#: or where one run would need more hours than a job holds
#: (N = 128² at 0.716 from the compressed start, about six on one core at 1.6·10⁶ collisions
#: per second): replicas, run side by side, whose weighted mean is the state point's
#: pressure (:func:`tables.estimates`) once they agree (``AGREEMENT``). Each must still be
#: long enough for its own blocking to see the slowest fluctuations (their scale factor in
#: melting.md): replicas save hours of waiting, not processor hours
PLAN = (
    Group("72-square", 72, "1:1", (0.650, 0.660, 0.670, 0.680, 0.686, 0.690, 0.694, 0.698,
                                   0.702, 0.706, 0.710, 0.720),
          "compressed", 1000, 1_000_000, 60_000_000, 0.002),
    Group("72-lattice", 72, "9:8√3/2", (0.650, 0.670, 0.680, 0.684, 0.686, 0.688, 0.690,
                                        0.692, 0.694, 0.696, 0.698, 0.700, 0.706, 0.720),
          "compressed", 1000, 1_000_000, 60_000_000, 0.002),
    Group("72-lattice-replicas", 72, "9:8√3/2", (0.696,),
          "compressed", 1000, 1_000_000, 60_000_000, 0.002, seeds=(1,)),
    Group("224-square", 224, "1:1", (0.670, 0.680, 0.686, 0.690, 0.692, 0.694, 0.698, 0.702,
                                     0.704, 0.706, 0.708, 0.712, 0.720),
          "compressed", 500, 300_000, 60_000_000, 0.003),
    Group("224-square-replicas", 224, "1:1", (0.720,),
          "compressed", 500, 300_000, 60_000_000, 0.003, seeds=(1,)),
    Group("870-square", 870, "1:1", (0.670, 0.680, 0.690, 0.694, 0.698, 0.702, 0.706, 0.710,
                                     0.712, 0.714, 0.716, 0.718),
          "compressed", 200, 100_000, 3_000_000, 0.003),
    Group("870-square-replicas", 870, "1:1", (0.714, 0.716, 0.718),
          "compressed", 200, 100_000, 3_000_000, 0.003, seeds=(1,)),
    Group("870-lattice", 870, "29:30√3/2", (0.670, 0.680, 0.690, 0.694, 0.698, 0.702, 0.706,
                                            0.710, 0.712),
          "compressed", 200, 100_000, 3_000_000, 0.003),
    Group("870-lattice-crystal", 870, "29:30√3/2", (0.714, 0.716, 0.718),
          "lattice", 200, 100_000, 3_000_000, 0.003),
    Group("16384-square", 16384, "1:1", (0.698, 0.704, 0.708, 0.712, 0.716),
          "compressed", 1000, 80_000, 3_200_000, 0.003),
    Group("16384-square-replicas", 16384, "1:1", (0.716,),
          "compressed", 1000, 80_000, 3_200_000, 0.003, seeds=(1, 2, 3, 4)),
    Group("16384-square-melted", 16384, "1:1", (0.704, 0.716),
          "melted", 1000, 80_000, 3_200_000, 0.003),
)

#: a smoke run of the study: two points of N = 72, short, into a folder of the caller's
QUICK = (Group("72-square", 72, "1:1", (0.650, 0.700), "compressed", 500, 10_000, 20_000,
               0.05),)


@dataclass(frozen=True)
class Point:
    """One run of a state point: its group, packing fraction and seed, its run folder, and
    how many runs of its N, box, φ and start the plan holds (``replicas``, itself
    included)."""

    group: Group
    phi: float
    folder: Path
    seed: int = 0
    replicas: int = 1

    @property
    def target(self):
        """The error of βP d² at which the run is done: the group's target times
        √``replicas``, so that the weighted mean of the replicas reaches the group's."""
        return self.group.target * math.sqrt(self.replicas)

    @property
    def aspect(self):
        return reference(self.group.n, self.group.box)[3]

    def overrides(self, collisions_per_disk):
        g = self.group
        return ["scenario=melting", f"disks.n={g.n}", f"disks.packing_fraction={self.phi}",
                f"box.size=[{self.aspect!r},1.0]", f"disks.placement={g.start}",
                f"seed={self.seed}", f"stop.collisions={collisions_per_disk * g.n}",
                f"output.every_collisions={g.block * g.n}", "output.progress=false"]


def points(plan, out):
    """A point per group, φ and seed of ``plan``, its run folder under ``out``/runs (the
    seed's in its name but for seed 0)."""
    runs = [(g, phi, seed) for g in plan for phi in g.phis for seed in g.seeds]
    keys = [(g.n, g.box, round(phi, 6), g.start) for g, phi, _ in runs]
    return [Point(g, phi, Path(out) / "runs" / (f"{g.name}-{phi:.3f}"
                                                + (f"-seed{seed}" if seed else "")),
                  seed, keys.count(key)) for (g, phi, seed), key in zip(runs, keys, strict=True)]


def twins(point, todo):
    """The points of ``todo`` at the state point of ``point`` (N, box, φ) from other starts
    or with other seeds."""
    return [other for other in todo
            if (other.group.start, other.seed) != (point.group.start, point.seed)
            and (other.group.n, other.group.box, other.phi)
            == (point.group.n, point.group.box, point.phi)]
