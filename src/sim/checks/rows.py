"""Rows of the validation table: :class:`Check`, the statistics of independent runs (the
standard error of their means, the ratio of two means with its jackknife error, a relative
difference with its error) and the table in Markdown (:mod:`sim.checks.validation` lists the
studies that make them)."""

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Check:
    """One row of the validation table; ``tolerance`` is absolute, on ``measured``."""

    name: str
    measured: float
    reference: float
    tolerance: float
    source: str
    seconds: float | None  # wall-clock seconds of the run; None for further rows of one run

    @property
    def passed(self):
        return bool(abs(self.measured - self.reference) <= self.tolerance)


def block_means(values):
    """Mean and its standard error from independent blocks."""
    values = np.asarray(values)
    return float(values.mean()), float(values.std(ddof=1) / math.sqrt(values.size))


def ratio_of_means(pairs, window):
    """The ratio of two quantities over independent runs, ``pairs`` float64[runs, snapshots,
    2] (numerator in [..., 1], denominator in [..., 0]): the ratio of their means over the runs
    at each snapshot (a mean of per-run ratios would carry the bias E[a/b] − E[a]/E[b], about
    1/N of a quantity summed over N disks), and its mean over the snapshots where ``window``
    (bool[snapshots]) holds, each with its jackknife standard error over the runs (leave one
    run out). Returns (curve float64[snapshots], its error, window mean, its error)."""
    runs = pairs.shape[0]
    curve = pairs[:, :, 1].mean(axis=0) / pairs[:, :, 0].mean(axis=0)
    left_out = np.array([np.delete(pairs, j, axis=0).mean(axis=0) for j in range(runs)])
    curves = left_out[:, :, 1] / left_out[:, :, 0]  # [runs, snapshots]
    means = curves[:, window].mean(axis=1)

    def jackknife(values):
        return np.sqrt((runs - 1) / runs * np.sum((values - values.mean(axis=0)) ** 2, axis=0))

    return curve, jackknife(curves), float(curve[window].mean()), float(jackknife(means))


def relative_difference(measured, error, reference, reference_error=0.0):
    """measured/reference − 1 and its standard error (independent errors, first order)."""
    return (measured / reference - 1.0,
            math.hypot(error / reference, measured * reference_error / reference**2))


def table(rows):
    """The rows as a Markdown table."""
    lines = ["| check | measured | reference | tolerance | pass | seconds | source |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r.name} | {r.measured:.6g} | {r.reference:.6g} | ± {r.tolerance:.2g} | "
                     f"{'pass' if r.passed else 'FAIL'} | "
                     f"{'same run' if r.seconds is None else f'{r.seconds:.1f}'} | {r.source} |")
    return "\n".join(lines) + "\n"
