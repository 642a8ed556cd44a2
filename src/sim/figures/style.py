"""Shared look of the figures: size readable at README width, labelled axes with units."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

plt.rcParams.update({"figure.dpi": 120, "savefig.dpi": 120, "font.size": 10,
                     "axes.grid": True, "grid.alpha": 0.3, "legend.frameon": False})


def figure(ncols=2, width=9.0, height=4.0):
    fig, axes = plt.subplots(1, ncols, figsize=(width, height), constrained_layout=True)
    return fig, axes


def save(fig, out_dir, name):
    path = out_dir / f"{name}.png"
    fig.savefig(path)
    plt.close(fig)
    return path
