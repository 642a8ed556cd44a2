"""Rows of the validation table: :class:`Check`, the standard error of independent blocks,
and the table in Markdown (:mod:`sim.checks.validation` lists the studies that make them)."""

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


def table(rows):
    """The rows as a Markdown table."""
    lines = ["| check | measured | reference | tolerance | pass | seconds | source |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for r in rows:
        lines.append(f"| {r.name} | {r.measured:.6g} | {r.reference:.6g} | ± {r.tolerance:.2g} | "
                     f"{'pass' if r.passed else 'FAIL'} | "
                     f"{'same run' if r.seconds is None else f'{r.seconds:.1f}'} | {r.source} |")
    return "\n".join(lines) + "\n"
