"""The disks' colours and their key: ``speed`` (one scale for the whole movie, up to the largest
99th percentile of any frame's speeds), ``species``, or ``cluster`` (the run's ``clusters``
observable at the snapshot drawn from, or the same rule, :class:`sim.analysis.observers.Clusters`,
applied to the drawn positions when the run did not observe it: the largest cluster red, other
clusters of at least ten disks dark grey, the rest light grey)."""

from types import SimpleNamespace

import numpy as np
from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize, to_rgba
from matplotlib.lines import Line2D

from sim.analysis.observers import Clusters
from sim.figures.movie.layout import TEXT_PIXELS, points

COLORINGS = ("speed", "species", "cluster")
#: clusters of at least this many disks are drawn apart from free disks and small clusters
SHOWN_CLUSTER = 10
#: the gap (units of 2⟨R⟩) of cluster labels computed for a run that did not observe them
DEFAULT_CLUSTER_GAP = 0.1
LARGEST_CLUSTER, LARGE_CLUSTER, SMALL_CLUSTER = "tab:red", "0.35", "0.78"


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
        axes.set_ylabel("speed (box units / time)", fontsize=points(TEXT_PIXELS))
        axes.tick_params(labelsize=points(TEXT_PIXELS - 2))


def speed_limit(frames):
    """The largest 99th percentile of the speeds of any of ``frames``: colours saturate only
    for the fastest 1 % of the disks of any frame."""
    return max(float(np.percentile(np.hypot(f.velocity[:, 0], f.velocity[:, 1]), 99.0))
               for f in frames)


def _draw_legend(figure, rect, entries):
    """A key of (colour, label) disks at the top-left of ``rect`` (figure fractions)."""
    handles = [Line2D([], [], ls="", marker="o", ms=points(TEXT_PIXELS), color=color,
                      label=label) for color, label in entries]
    figure.legend(handles=handles, loc="upper left", bbox_to_anchor=(rect[0], rect[1] + rect[3]),
                  bbox_transform=figure.transFigure, frameon=False,
                  fontsize=points(TEXT_PIXELS - 2))


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


def coloring(color, snapshots, times, radius, mass):
    """The colours named ``color`` (one of :data:`COLORINGS`) of the run's disks, drawn at
    ``times``."""
    ds = snapshots.ds
    if color == "speed":
        return SpeedColors(speed_limit(snapshots.frames(times)))
    if color == "species":
        return SpeciesColors(ds["species_id"].values.astype(np.int64), radius, mass)
    observed = ds["clusters"].values if "clusters" in ds else None
    return ClusterColors(observed, cluster_rule(snapshots, radius))
