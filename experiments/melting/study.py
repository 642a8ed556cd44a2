"""The melting of hard disks: the equation of state βP d² through liquid–hexatic coexistence
at the sizes and in the boxes of the published references, each point run until its error
reaches its group's target.

Every point of ``PLAN`` (a state point, start and seed) is one run of the ``melting`` scene
in a folder of its own under ``--out`` (``runs/<group>-<φ>/run.h5``, ``-seed<s>`` after the
φ but for seed 0), which also keeps the point's analysis (``point.json``) and the processor
seconds it took (``cpu_seconds``). A point is run in rounds: the first runs ``first``
collisions per disk; after each, :func:`sim.analysis.equation_of_state.run_pressure` drops
the equilibration blocks by the MSER rule and finds the blocking error of the rest, and the
point is done when that error is at most its target (the group's, times √(replicas):
``plan.Point.target``), the blocking has converged, the means of the production's two halves
agree within ``DRIFT`` standard errors, ``PRODUCTION_BLOCKS`` blocks are kept and the cut is
at most a share ``CUT`` of the blocks. Otherwise it is resumed to the length its error asks
for (:func:`next_length`), at most ``longest`` collisions per disk; a point that reaches it
stays as it is, its error in the tables. The runs go to a pool of ``--jobs`` worker
processes, the longest first (``--shortest-first``: the shortest), each point given its next
run as soon as one ends; or with ``--cluster slurm``, in rounds of jobs, to SLURM through
submitit.

Interrupted (Ctrl-C, a killed job, the end of a session), the study starts again where it
was: a run resumes from its last checkpoint (written every 30 s of wall time and at every
stop), a finished point is not run again, and a second ``make melting`` with every point done
only reads the analyses and draws.

Writes into ``--results`` (default outputs/melting/results; ``make melting`` copies them
into docs/results/): ``melting.csv`` (one row per run: n, aspect, phi, start, seed,
collisions_per_disk, bPd2, err, psi6), ``melting_reference.csv`` (the published value of
each row's N, box and φ with its source), ``melting.md`` (the runs against the published
values, the replicas' weighted means, the loops' extrema, the processor hours),
``melting.json`` (per point the whole analysis and processor seconds; the replicas' weighted
means; per group the published loop's extrema and ours), ``melting_eos.png``,
``melting_psi6.png`` and ``melting_starts.png`` (web versions; the full figures, PNG and
PDF, in ``--out``/figures).

The study's other modules: ``plan.py`` (the groups, the rules' numbers, the points),
``tables.py`` (the tables, the replicas' weighted means, the loops' extrema, melting.md) and
``figures.py``.

    python experiments/melting/study.py [--groups 72-square …] [--jobs 2] [--shortest-first]
                                        [--quick] [--report]
"""

import argparse
import json
import math
import os
import signal
import sys
import time
from dataclasses import asdict
from pathlib import Path

import numpy as np
from figures import TRACED, draw_bond_order, draw_equation_of_state, draw_starts, trace
from plan import (
    AGREEMENT,
    CUT,
    DRIFT,
    GROWTH,
    MARGIN,
    PLAN,
    PRODUCTION_BLOCKS,
    QUICK,
    points,
    twins,
)
from tables import (
    estimates,
    extrema,
    processor_hours,
    scale_factor,
    write_markdown,
    write_tables,
)

from sim.analysis.datasets import global_bond_order, open_run
from sim.analysis.equation_of_state import run_pressure
from sim.pipeline.command import interrupt
from sim.pipeline.config import ConfigError
from sim.pipeline.interruption import Interruption, between_jobs, held_back
from sim.pipeline.resume import resume, stored_config
from sim.pipeline.run_cache import compose_config
from sim.pipeline.runner import run
from sim.storage.whole_file import whole_file

#: the committed results, from which a study goes on (:func:`adopt`)
LEDGER = Path(__file__).resolve().parents[2] / "docs" / "results" / "melting.json"
#: the version of :func:`analyse`'s rules a record was made with; a record of another is
#: made anew from its run file when the study starts
ANALYSIS = 4
#: the stop reasons of a run file whose round has not reached its length: stopped by a
#: signal, or still "running" in the file of a killed process
CUT_SHORT = ("interrupted", "terminated", "running")


def _record(point):
    path = point.folder / "point.json"
    return json.loads(path.read_text()) if path.exists() else None


def reached(point, record, scale=1.0):
    """Whether the point's run meets its target (:attr:`plan.Point.target`): error (times
    ``scale``, :func:`_scale`), convergence, no drift and ``PRODUCTION_BLOCKS`` blocks kept,
    at most a share ``CUT`` of the blocks cut."""
    return (record["err"] * scale <= point.target and record["converged"]
            and abs(record["drift"]) < DRIFT and record["blocks"] >= PRODUCTION_BLOCKS
            and record["cut"] <= CUT * (record["cut"] + record["blocks"]))


def agrees(record, others):
    """Whether the run's βP d² agrees with that of every run of the same state point from
    another start or with another seed (``others``: their records, :func:`_others`) within
    ``AGREEMENT`` combined errors."""
    return all(abs(record["bPd2"] - other["bPd2"])
               <= AGREEMENT * math.hypot(record["err"], other["err"])
               for other in others if "bPd2" in other)


def _scale(point, record, others):
    """The scale factor S (:func:`tables.scale_factor`) of the run and its replicas among
    ``others`` (the same start, other seeds): 1 without any. Replicas that scatter more than
    their errors say have not yet sampled what their errors claim, short runs whose blocking
    missed the slowest fluctuations, and each runs on until S times its error meets its
    target."""
    same = [other for other in others if other.get("start") == point.group.start]
    return scale_factor([record, *same]) if same else 1.0


def status(point, record, others=()):
    """``done`` (its target met, with its replicas' scale factor, and its βP d² that of the
    runs from other starts or seeds, ``others``: their records), ``longest`` (run to its
    group's longest, not done), ``failed`` (the reason in its record) or ``running``."""
    if "failed" in record:
        return "failed"
    if reached(point, record, _scale(point, record, others)) and agrees(record, others):
        return "done"
    return "longest" if record["collisions_per_disk"] >= point.group.longest else "running"


def _others(point, todo):
    """The records of ``point``'s twins (:func:`plan.twins`) in ``todo`` that are finished on
    their own: their target met (:func:`reached`) or their longest run made. A twin still on
    its way, such as a replica begun later and still equilibrating, counts against no run."""
    return [r for twin in twins(point, todo) if (r := _record(twin)) is not None
            and "bPd2" in r and (reached(twin, r)
                                 or r["collisions_per_disk"] >= twin.group.longest)]


def next_length(point, record, others=()):
    """Collisions per disk the point runs to in its next round, or None when it has none
    (:func:`status` other than ``running``): the length its error (times its replicas' scale
    factor, :func:`_scale`) asks for, to ``MARGIN``,
    from ``GROWTH`` [0] to [1] times its length so far, at most its group's longest, a
    whole number of blocks."""
    g = point.group
    if status(point, record, others) != "running":
        return None
    length = record["collisions_per_disk"]
    production = length * record["blocks"] / (record["blocks"] + record["cut"])
    error = record["err"] * _scale(point, record, others)
    ratio = (error / point.target) ** 2 if math.isfinite(error) else math.inf
    asked = length - production + max(production * MARGIN * ratio, PRODUCTION_BLOCKS * g.block)
    asked = min(max(asked, GROWTH[0] * length), GROWTH[1] * length, g.longest)
    return int(math.ceil(asked / g.block) * g.block)


def advance(point, collisions_per_disk):
    """Run or resume ``point`` to ``collisions_per_disk`` and analyse it; its record."""
    started = time.process_time()
    path = point.folder / "run.h5"
    overrides = point.overrides(collisions_per_disk)
    try:
        if path.exists():  # cut short, or to be run longer
            stored, _ = stored_config(path)
            collisions = max(stored.stop.collisions, collisions_per_disk * point.group.n)
            resume(path, [f"stop.collisions={collisions}"])
        else:
            run(compose_config(overrides), point.folder, overrides=overrides)
    finally:  # a round cut short by a signal counts too
        _spend(point, time.process_time() - started)
    record = analyse(point)
    if record is None:  # the run stopped at a signal: so does the study
        raise KeyboardInterrupt
    return record


def _spend(point, seconds):
    """Add ``seconds`` to the processor seconds the point has taken (its ``cpu_seconds``)."""
    point.folder.mkdir(parents=True, exist_ok=True)
    path = point.folder / "cpu_seconds"
    before = (float(path.read_text()) if path.exists()
              else (_record(point) or {}).get("cpu_seconds", 0.0))
    with whole_file(path) as partial:
        partial.write_text(repr(before + seconds))


def analyse(point):
    """The point's record from its run file, written to its ``point.json``: βP d² and its
    analysis (:func:`run_pressure`), the mean |Ψ₆| of the production's snapshots, the
    processor seconds of every round so far; or its reason to have none (``failed``). None
    for a run cut short by a signal."""
    g = point.group
    spent = point.folder / "cpu_seconds"
    record = {"group": g.name, "n": g.n, "box": g.box, "aspect": point.aspect,
              "phi": point.phi, "start": g.start, "analysis": ANALYSIS,
              "cpu_seconds": (float(spent.read_text()) if spent.exists()
                              else (_record(point) or {}).get("cpu_seconds", 0.0))}
    with open_run(point.folder / "run.h5") as dataset:
        reason = dataset.attrs["stop_reason"]
        if reason in ("interrupted", "terminated"):
            return None  # cut short by a signal: a later round goes on
        record["seed"] = int(dataset.attrs["seed"])
        snapshots = dataset["collisions"].values
        record["collisions_per_disk"] = int(snapshots[-1]) / g.n
        try:
            if reason != "collisions":
                raise ValueError(f"a run to its collisions, not one stopped by {reason}")
            eos = run_pressure(dataset)
        except ValueError as error:  # reported, never run again
            record["failed"] = str(error)
        else:
            psi = global_bond_order(dataset).values[snapshots > eos.production_start]
            record |= {"bPd2": eos.mean, "err": eos.error, "converged": bool(eos.converged),
                       "cut": eos.cut, "blocks": eos.blocks, "drift": eos.drift,
                       "psi6": float(np.mean(psi))}
            if (drawn := trace(dataset, g.n)) is not None:
                record["trace"] = drawn
    with whole_file(point.folder / "point.json") as partial:
        partial.write_text(json.dumps(record, indent=1))
    return record


def adopt(todo, ledger):
    """Take the records of ``ledger`` (the melting.json of an earlier study: for
    ``make melting`` the committed docs/results/melting.json) for the points of ``todo``
    that have neither a record nor a run here, so that a fresh clone goes on where the
    committed results stand. A point done by today's rules (:data:`ANALYSIS`) is not run
    again, unless the figure of the two starts needs its trace (:func:`figures.trace`);
    one not done runs from its start to the length its record asks for (the same bits as
    the run resumed); one of older rules runs again to its recorded length. Their processor
    seconds count on."""
    if ledger is None or not ledger.exists():
        return
    recorded = {(r["group"], r["n"], r["box"], round(r["phi"], 6), r["start"], r["seed"]): r
                for r in json.loads(ledger.read_text(encoding="utf-8"))["points"]}
    for point in todo:
        g = point.group
        record = recorded.get((g.name, g.n, g.box, round(point.phi, 6), g.start, point.seed))
        if record is None or _record(point) is not None or (point.folder / "run.h5").exists():
            continue
        point.folder.mkdir(parents=True, exist_ok=True)
        record = {k: v for k, v in record.items() if k != "status"}
        with whole_file(point.folder / "point.json") as partial:
            partial.write_text(json.dumps(record, indent=1))


def _pending(todo):
    """(point, collisions per disk) of every point that has a round to run."""
    rounds = []
    for point in todo:
        record = _record(point)
        path = point.folder / "run.h5"
        try:
            stored, reason = stored_config(path) if path.exists() else (None, None)
        except ConfigError as error:  # a damaged run file: no round until someone looks
            print(f"melting: {point.folder.name} passed over: {error}", flush=True)
            continue
        if stored is not None and (record is None or reason in CUT_SHORT):
            # cut short (a signal, a killed job) before the length of its round, which may be
            # its adopted record's: it goes on to that length
            rounds.append((point, stored.stop.collisions // point.group.n))
            continue
        adopted = record is not None and stored is None
        if adopted and "failed" not in record and (
                record.get("analysis") != ANALYSIS  # of older rules
                or ("trace" not in record and point.group.n == TRACED
                    and twins(point, todo))):  # the figure of the two starts draws it
            rounds.append((point, max(point.group.first, int(record["collisions_per_disk"]))))
            continue
        if record is not None and record.get("analysis") != ANALYSIS:
            record = analyse(point)  # analysed by an older rule: read its run again
        if record is None:
            rounds.append((point, point.group.first))
        elif (length := next_length(point, record, _others(point, todo))) is not None:
            rounds.append((point, length))
    return rounds


def _cost_of(round_):
    point, collisions_per_disk = round_
    return point.group.n * collisions_per_disk


def urgency(shortest_first=False):
    """The key whose largest round is handed out next: its cost in collisions, the longest
    first, which ends a pool of rounds soonest; or with ``shortest_first`` its negative, the
    shortest first, which ends as many rounds as can be in a job of a few hours."""
    return (lambda round_: -_cost_of(round_)) if shortest_first else _cost_of


def _report(point, record, others):
    print(f"melting: {point.folder.name} at {record['collisions_per_disk']:.3g} collisions "
          f"per disk: " + (f"βP d² = {record['bPd2']:.4f} ± {record['err']:.4f}, "
                           f"{status(point, record, others)}" if "bPd2" in record
                           else f"failed: {record['failed']}"), flush=True)


def _run_here(todo, key):
    """Every point's rounds in this process, in the order of ``key`` (:func:`urgency`)."""
    while rounds := _pending(todo):
        point, collisions_per_disk = max(rounds, key=key)
        _report(point, advance(point, collisions_per_disk), _others(point, todo))


def _run_in_pool(todo, jobs, key):
    """Every point's rounds in ``jobs`` worker processes (spawned: the engine compiles in each,
    from numba's cache), in the order of ``key`` (:func:`urgency`); a point whose round ends
    is given its next at once, and no more runs are handed out than there are workers.
    Stopped by SIGINT or SIGTERM (to this process alone or to its group), it asks its
    workers to stop their runs, which write their checkpoints, and raises KeyboardInterrupt."""
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from multiprocessing import active_children, get_context

    waiting = sorted(_pending(todo), key=key)
    previous = signal.signal(signal.SIGTERM, interrupt)
    # Ctrl-C reaches the whole process group: a worker not running takes SIGINT or SIGTERM as
    # a request that its next run stop at its first chunk, not as a KeyboardInterrupt out of
    # its start-up or its wait for work (a traceback from every worker not running)
    try:
        with ProcessPoolExecutor(max_workers=jobs, mp_context=get_context("spawn"),
                                 initializer=between_jobs,
                                 initargs=(Interruption.take_early,)) as pool:
            running = {}
            try:
                while waiting or running:
                    while waiting and len(running) < jobs:
                        point, collisions_per_disk = waiting.pop()
                        with held_back():  # a worker it starts: between_jobs
                            running[pool.submit(advance, point, collisions_per_disk)] = point
                    finished, _ = wait(running, return_when=FIRST_COMPLETED)
                    for future in finished:
                        point = running.pop(future)
                        record = future.result()  # KeyboardInterrupt: a run stopped
                        _report(point, record, _others(point, todo))
                        busy = {p.folder for p in running.values()} | {p.folder for p, _ in
                                                                       waiting}
                        # the point, and its twins: one done may no longer agree with it
                        for again in (point, *twins(point, todo)):
                            if again.folder in busy or (last := _record(again)) is None:
                                continue
                            length = next_length(again, last, _others(again, todo))
                            if length is not None:
                                waiting.append((again, length))
                        waiting.sort(key=key)
            except KeyboardInterrupt:
                for worker in active_children():  # each run stops at its next chunk
                    os.kill(worker.pid, signal.SIGINT)
                raise
    finally:
        signal.signal(signal.SIGTERM, previous)


def _run_on_cluster(todo, cluster, out, partition):
    """Rounds of every point's next run, each a job of ``cluster`` through submitit (a
    SLURM array, or local processes with ``local``)."""
    import submitit

    executor = submitit.AutoExecutor(folder=Path(out) / "submitit", cluster=cluster)
    executor.update_parameters(timeout_min=24 * 60, cpus_per_task=1,
                               **({"slurm_partition": partition} if partition else {}))
    while rounds := _pending(todo):
        print(f"melting: a round of {len(rounds)} jobs, "
              f"{sum(map(_cost_of, rounds)):.3g} collisions", flush=True)
        for (point, _), job in zip(rounds, executor.map_array(advance, *zip(*rounds,
                                                                          strict=True)),
                                   strict=True):
            _report(point, job.result())


def simulate(todo, out, jobs, cluster=None, partition=None, shortest_first=False):
    """Run every point of ``todo`` until it has no more run to make (:func:`next_length`):
    in this process (``jobs`` 1), in a pool of ``jobs`` processes, the longest rounds first
    or the shortest (:func:`urgency`), or through submitit on ``cluster``."""
    states = [status(p, r, _others(p, todo)) if (r := _record(p)) is not None
              else "not begun" for p in todo]
    print("melting: " + ", ".join(f"{states.count(state)} {state}" for state in
                                  ("done", "running", "not begun", "longest", "failed")
                                  if state in states) + f" of {len(todo)} points",
          flush=True)
    if cluster is not None:
        _run_on_cluster(todo, cluster, out, partition)
    elif jobs == 1:
        _run_here(todo, urgency(shortest_first))
    else:
        _run_in_pool(todo, jobs, urgency(shortest_first))


def summarise(todo, out, results, ledger=None):
    """The tables, the figures, melting.md and melting.json of the points of ``todo`` that
    have a record, each with its :func:`status`; the coexistence snapshot of the ``ledger``'s
    folder where no run file of N = 128² is here (:func:`figures.draw_bond_order`)."""
    records = [dict(record, status=status(p, record, _others(p, todo)), replicas=p.replicas)
               for p in todo if (record := _record(p)) is not None]
    measured = [r for r in records if "bPd2" in r]
    results.mkdir(parents=True, exist_ok=True)
    write_tables(measured, results)
    found = extrema(measured)
    write_markdown(records, found, results)
    draw_equation_of_state(measured, out, results)
    draw_bond_order(measured, todo, out, results,
                    kept_in=None if ledger is None else Path(ledger).parent)
    draw_starts(measured, out, results)
    hours, _ = processor_hours(records)
    summary = {"points": records, "extrema": found,
               "replicas": [e for e in estimates(measured) if e["replicas"] > 1],
               "cpu_hours": sum(hours.values()),
               "plan": [asdict(g) for g in PLAN if g.name in {r["group"] for r in records}],
               "rules": {"drift": DRIFT, "margin": MARGIN, "growth": GROWTH,
                         "production_blocks": PRODUCTION_BLOCKS, "cut": CUT,
                         "agreement": AGREEMENT}}
    with whole_file(results / "melting.json") as partial:
        partial.write_text(json.dumps(summary, indent=1, default=float))
    print(f"melting: {len(records)} points, {sum(hours.values()):.2f} processor hours, "
          f"into {results}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=Path("outputs/melting"))
    parser.add_argument("--results", type=Path, default=Path("outputs/melting/results"))
    parser.add_argument("--groups", nargs="*", help="names of the groups of PLAN to run")
    parser.add_argument("--jobs", type=int, default=os.cpu_count())
    parser.add_argument("--cluster", choices=("slurm", "local"), default=None,
                        help="run the rounds through submitit instead of joblib")
    parser.add_argument("--partition", default=None, help="the SLURM partition of the jobs")
    parser.add_argument("--shortest-first", action="store_true",
                        help="hand out the shortest rounds first, not the longest: as many "
                             "rounds finished as can be in a few hours")
    parser.add_argument("--quick", action="store_true", help="a smoke run: two short points")
    parser.add_argument("--report", action="store_true",
                        help="run nothing: the results of the points done so far")
    parser.add_argument("--ledger", type=Path, default=None,
                        help="the melting.json of an earlier study to go on from (default: "
                             "the committed results; none with --quick)")
    args = parser.parse_args(argv)
    plan = QUICK if args.quick else PLAN
    if args.groups:
        unknown = set(args.groups) - {g.name for g in plan}
        if unknown:
            parser.error(f"--groups: {', '.join(sorted(unknown))}: no such group; allowed: "
                         + ", ".join(g.name for g in plan))
    # the points of the whole plan, so that a point's replicas are counted in every case
    todo = [p for p in points(plan, args.out)
            if not args.groups or p.group.name in args.groups]
    ledger = args.ledger or (None if args.quick else LEDGER)
    adopt(todo, ledger)
    try:
        if not args.report:
            simulate(todo, args.out, args.jobs, args.cluster, args.partition,
                     args.shortest_first)
    except KeyboardInterrupt:
        print("melting: interrupted; run it again to go on where it stopped", file=sys.stderr)
        return 130
    summarise(todo, args.out, args.results, ledger)
    return 0


if __name__ == "__main__":
    sys.exit(main())
