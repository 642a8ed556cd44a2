"""Making the figures: a stage's runs and sweeps (made once per resolved config,
:mod:`sim.pipeline.run_cache`) and its drawing; the stages grouped so that processes making
them at once never make one run together."""

import importlib
import time

from sim.pipeline.run_cache import (
    cached_run_folder,
    cached_sweep_folder,
    ensure_run,
    ensure_sweep,
)


def stage_module(name):
    """The module of the stage ``name`` (:mod:`sim.figures`)."""
    return importlib.import_module(f"sim.figures.{name}")


def _wanted(stage, quick):
    """({label: overrides} of the stage's runs, the same of its sweeps)."""
    return (stage.runs(quick) if hasattr(stage, "runs") else {},
            stage.sweeps(quick) if hasattr(stage, "sweeps") else {})


def make_stages(names, quick, out):
    """Make the runs and sweeps of the stages ``names``, in order, and draw each; a list of
    (stage NAME, what it wrote, seconds)."""
    made = []
    for name in names:
        stage = stage_module(name)
        started = time.perf_counter()
        wanted_runs, wanted_sweeps = _wanted(stage, quick)
        runs = {label: ensure_run(label, overrides, out / "runs")
                for label, overrides in wanted_runs.items()}
        sweeps = {label: ensure_sweep(label, overrides, out / "runs")
                  for label, overrides in wanted_sweeps.items()}
        path = stage.draw(runs, sweeps, out)
        made.append((stage.NAME, path, time.perf_counter() - started))
    return made


def batches(names, quick, out):
    """``names`` in groups, each in the order of ``names``, such that no two groups read a
    common run or sweep folder (two processes would make it at once)."""
    reads = {}
    for name in names:
        wanted_runs, wanted_sweeps = _wanted(stage_module(name), quick)
        reads[name] = ({cached_run_folder(label, o, out / "runs")
                        for label, o in wanted_runs.items()}
                       | {cached_sweep_folder(label, o, out / "runs")
                          for label, o in wanted_sweeps.items()})
    groups = []
    for name in names:
        joined = [g for g in groups if any(reads[name] & reads[other] for other in g)]
        groups = [g for g in groups if g not in joined]
        groups.append([n for n in names if n == name or any(n in g for g in joined)])
    return groups
