"""From run files to numbers: xarray datasets of runs and sweeps (:mod:`sim.analysis.datasets`),
the observers computed at snapshots, the grid of cells and its granular temperature, the closed
forms of the theory, and the crater measure.

``open_run``, ``open_sweep`` and the other readers of :mod:`sim.analysis.datasets` are
importable from here.
"""

_DATASETS = ("open_run", "open_sweep", "at_last_snapshot", "contacts", "pressure_tensor",
             "velocity_autocorrelation", "granular_temperatures")


def __getattr__(name):
    if name not in _DATASETS:
        raise AttributeError(f"module 'sim.analysis' has no attribute {name!r}")
    from sim.analysis import datasets

    return getattr(datasets, name)
