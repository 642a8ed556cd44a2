"""Advancing a run from snapshot to snapshot until a stop condition, its wall-clock budget or
a signal ends it, with a progress bar on a terminal."""

import math
import sys
import time as wallclock

import numpy as np
from tqdm import tqdm

from sim.pipeline.config import ConfigError
from sim.pipeline.stop_conditions import at_rest


def _progress(cfg, engine):
    total = cfg.stop.collisions
    disable = not (cfg.output.progress and sys.stderr.isatty())
    return tqdm(total=total, initial=engine.collisions, unit="coll", unit_scale=True,
                disable=disable, dynamic_ncols=True)


def every_collisions(cfg, n):
    """Collisions between snapshots: ``output.every_collisions``, or ``n`` (one collision
    per disk) when neither it nor ``output.every_time`` is given; None for a cadence in
    time."""
    out = cfg.output
    if out.every_collisions is not None:
        return int(out.every_collisions)
    return None if out.every_time is not None else int(n)


def next_snapshot_time(last_time, every_time):
    """The first point k Δt of the snapshot grid after ``last_time`` (Δt = ``every_time``;
    None without a cadence in time), or :class:`ConfigError` once float64 cannot tell it from
    ``last_time`` (a long run, a short cadence). Grid points are multiples, never sums, so
    that round-off neither drifts them nor puts a snapshot a round-off before a stop.time
    on the grid; a ``last_time`` within a few ulps of a grid point is on it."""
    if every_time is None:
        return None
    k = last_time / every_time
    nearest = round(k)
    on_grid = abs(k - nearest) <= max(8.0 * np.finfo(float).eps * abs(k), 1e-9)
    next_time = ((nearest if on_grid else math.floor(k)) + 1) * every_time
    if next_time <= last_time or math.ulp(next_time) > 1e-6 * every_time:
        raise ConfigError("output.every_time", every_time,
                          f"a cadence that float64 resolves at t = {last_time:.6g}: above "
                          f"{1e6 * math.ulp(next_time):.3g}")
    return next_time


def advance(engine, cfg, writer, last_time, started, interruption):
    """Run from snapshot to snapshot (the last one at ``last_time``) until a stop condition
    holds, the wall-clock budget (counted from ``started``, a ``time.perf_counter()``, the
    engine's compilation of its loop not counted) is spent, or SIGINT or SIGTERM arrives
    (``interruption``, an entered :class:`sim.pipeline.interruption.Interruption`); returns
    the stop reason."""
    stop, out = cfg.stop, cfg.output
    resting = None if stop.at_rest is None else at_rest(stop.at_rest)
    cadence = every_collisions(cfg, engine.n)

    def until(engine):
        return interruption.requested or (resting is not None and resting(engine))

    def budget():  # the compilation of the event loop is not counted
        if stop.wall_seconds is None:
            return None
        spent = wallclock.perf_counter() - started - engine.compile_seconds
        return max(stop.wall_seconds - spent, 0.0)

    bar = _progress(cfg, engine)
    try:
        while True:
            next_collisions = engine.collisions + cadence if cadence else None
            next_time = next_snapshot_time(last_time, out.every_time)
            collisions = min(x for x in (stop.collisions, next_collisions, math.inf)
                             if x is not None)
            t_stop = min(x for x in (stop.time, next_time, math.inf) if x is not None)
            reason = engine.run(
                contacts=stop.contacts, collisions=None if collisions == math.inf else collisions,
                time=None if t_stop == math.inf else t_stop,
                energy_fraction=stop.energy_fraction, packing_fraction=stop.packing_fraction,
                jamming=stop.jamming, wall_seconds=budget(), until=until)
            snapshot_time = (t_stop if reason == "time"
                             else engine.packing_fraction_time(stop.packing_fraction)
                             if reason == "packing_fraction" else None)
            last_time = engine.time if snapshot_time is None else snapshot_time
            met = {"collisions": stop.collisions is not None
                   and engine.collisions >= stop.collisions,
                   "time": stop.time is not None and last_time >= stop.time,
                   "contacts": True, "energy_fraction": True, "packing_fraction": True,
                   "jamming": True}.get(reason, False)
            if reason in ("time", "no_events") and math.isinf(engine.next_event_time()):
                # nothing will ever move again: the run is over
                reason, met = "no_events", True
                if stop.time is not None:
                    snapshot_time = last_time = max(stop.time, engine.time)
            elif met:
                pass  # a stop condition holds: it names the end, whatever else came
            elif resting is not None and resting(engine):
                reason, met = "at_rest", True  # asked between chunks and at every snapshot
            elif interruption.requested:
                reason, met = interruption.reason, True
            elif budget() == 0.0:
                reason, met = "wall_seconds", True  # also when snapshots outpace chunks
            last = met
            writer.snapshot(engine, snapshot_time, checkpoint=last)
            bar.update(engine.collisions - bar.n)
            bar.set_postfix(t=f"{last_time:.4g}", energy=f"{engine.kinetic_energy():.4g}")
            if last:
                return reason
    finally:
        bar.close()
