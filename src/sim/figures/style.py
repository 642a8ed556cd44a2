"""Shared look of the figures: size readable at README width, labelled axes with units; each
saved as PNG (for the README) and PDF (vector, for papers). Quick figures (``--quick``) are
saved in a folder named :data:`sim.figures.QUICK_FOLDER` and say "quick" on the image."""

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import EllipseCollection  # noqa: E402

from sim.figures import QUICK_FOLDER  # noqa: E402
from sim.storage.whole_file import whole_file  # noqa: E402

plt.rcParams.update({"figure.dpi": 120, "savefig.dpi": 120, "font.size": 10,
                     "axes.grid": True, "grid.alpha": 0.3, "legend.frameon": False})


def figure(ncols=2, width=9.0, height=4.0):
    fig, axes = plt.subplots(1, ncols, figsize=(width, height), constrained_layout=True)
    return fig, axes


def draw_disks(ax, position, radius, colors=None, values=None, cmap="viridis", clim=None):
    """Disks at their true size (data units) on ``ax``: ``position`` float64[n, 2], ``radius``
    [n], coloured by ``colors`` or by ``values`` through ``cmap``; returns the collection
    (for a colorbar)."""
    disks = EllipseCollection(2 * radius, 2 * radius, np.zeros_like(radius), units="xy",
                              offsets=position, offset_transform=ax.transData,
                              facecolors=colors, linewidths=0, cmap=cmap)
    if values is not None:
        disks.set_array(values)
        disks.set_clim(*(clim or (values.min(), values.max())))
    ax.add_collection(disks)
    return disks


def save(fig, out_dir, name):
    """``name``.png and ``name``.pdf in ``out_dir``; returns the PNG's path."""
    if out_dir.name == QUICK_FOLDER:
        fig.text(0.995, 0.005, "quick (small runs)", ha="right", va="bottom", fontsize=8,
                 color="C3")
    path = out_dir / f"{name}.png"
    for target in (path, path.with_suffix(".pdf")):
        with whole_file(target) as partial:  # whole or not at all, stopped midway
            fig.savefig(partial)
    plt.close(fig)
    return path
