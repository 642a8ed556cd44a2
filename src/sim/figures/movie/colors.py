"""The disks' colours and their key: ``speed`` (one scale for the whole movie, from 0, or on a
log scale from :data:`LOG_DECADES` decades below, up to the fastest disk of any frame, so that
no speed drawn saturates), ``species``, or ``cluster`` (the run's ``clusters`` observable at the
snapshot drawn from, or the same rule, :class:`sim.analysis.observers.Clusters`, applied to the
drawn positions when the run did not observe it: the largest cluster red, other clusters of at
least ten disks dark grey, the rest light grey)."""

from types import SimpleNamespace

import numpy as np
from matplotlib import colormaps
from matplotlib.cm import ScalarMappable
from matplotlib.colors import LogNorm, Normalize, to_rgba
from matplotlib.lines import Line2D

from sim.analysis.observers import Clusters
from sim.figures.movie.layout import TEXT_PIXELS, points

COLORINGS = ("speed", "species", "cluster")
#: speed colour scales: linear from 0, or logarithmic over LOG_DECADES decades
SPEED_SCALES = ("linear", "log")
#: decades of speed the log scale spans below the fastest disk; slower disks (and disks at
#: rest) share its lowest colour
LOG_DECADES = 3
#: clusters of at least this many disks are drawn apart from free disks and small clusters
SHOWN_CLUSTER = 10
#: the gap (units of 2⟨R⟩) of cluster labels computed for a run that did not observe them
DEFAULT_CLUSTER_GAP = 0.1
LARGEST_CLUSTER, LARGE_CLUSTER, SMALL_CLUSTER = "tab:red", "0.35", "0.78"


class SpeedColors:
    """Speed (box units / time) on one colour scale for the whole movie, up to ``fastest``:
    linear from 0, or (``scale`` "log") logarithmic from ``fastest`` / 10^LOG_DECADES."""

    def __init__(self, fastest, scale="linear"):
        top = fastest if fastest > 0.0 else 1.0
        self.norm = (Normalize(0.0, top) if scale == "linear"
                     else LogNorm(top * 10.0**-LOG_DECADES, top))
        self.scale = scale
        self.cmap = colormaps["viridis"]

    def __call__(self, frame):
        """RGBA float64[n, 4] of the disks of ``frame``, and a caption."""
        speed = np.hypot(frame.velocity[:, 0], frame.velocity[:, 1])
        return self.cmap(self.norm(np.maximum(speed, self.norm.vmin))), ""

    def draw_key(self, figure, rect):
        """A colour bar in the strip ``rect`` (figure fractions) beside the box."""
        axes = figure.add_axes([rect[0] + 0.12 * rect[2], rect[1], 0.1 * rect[2], rect[3]])
        figure.colorbar(ScalarMappable(self.norm, self.cmap), cax=axes,
                        extend="neither" if self.scale == "linear" else "min")
        label = "speed (box units / time)"
        axes.set_ylabel(label if self.scale == "linear" else f"{label}, log scale",
                        fontsize=points(TEXT_PIXELS))
        axes.tick_params(labelsize=points(TEXT_PIXELS - 2))


def fastest_speed(frames):
    """The largest speed of any disk in any of ``frames`` (box units / time): the top of the
    speed scale, which nothing drawn exceeds."""
    return max(float(np.max(np.hypot(f.velocity[:, 0], f.velocity[:, 1]))) for f in frames)


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
                            periodic=snapshots.periodic, radii=lambda t: radius)
    observer = Clusters(DEFAULT_CLUSTER_GAP if gap is None else float(gap), disks)
    return lambda position: observer(disks, None, position, None)


def coloring(color, snapshots, times, radius, mass, speed_scale="linear"):
    """The colours named ``color`` (one of :data:`COLORINGS`) of the run's disks, drawn at
    ``times``; speeds on the scale ``speed_scale`` (one of :data:`SPEED_SCALES`)."""
    ds = snapshots.ds
    if color == "speed":
        return SpeedColors(fastest_speed(snapshots.frames(times)), speed_scale)
    if color == "species":
        return SpeciesColors(ds["species_id"].values.astype(np.int64), radius, mass)
    observed = ds["clusters"].values if "clusters" in ds else None
    return ClusterColors(observed, cluster_rule(snapshots, radius))
