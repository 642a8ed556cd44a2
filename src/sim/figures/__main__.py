"""``python -m sim.figures [--quick] [--only NAME …] [--jobs J]``: make the runs, then every
figure.

Figures and their numbers go to ``outputs/figures/`` (``--out``), the runs they read to
``outputs/figures/runs/``; runs whose resolved config is unchanged are not made again. The
stages run in ``--jobs`` processes at once, the longest first by the seconds they last took:
by default one process more than the cores, as a process that waits for a variant of the
event loop another compiles (each is compiled once, :mod:`sim.engine.compilation`), or for
its sweep's jobs, leaves its core to the others. Stages that read a common run or sweep run
one after the other in one process. The wall-clock seconds of each stage in its process (its
runs, its drawing, and any wait) go to ``timings.csv`` there.

Ctrl-C (or SIGTERM) stops it with one line and exit status 130 (143): the runs it reaches stop at
their next chunk with a checkpoint (a figure that reads them is not drawn), the stages not
begun are dropped, a worker finishes the figure it is drawing, and no figure is left
half-written (:func:`sim.figures.style.save`).
"""

import csv
import os
import sys
from concurrent.futures import FIRST_EXCEPTION, ProcessPoolExecutor, wait
from multiprocessing import get_context
from pathlib import Path

from sim.figures import QUICK_FOLDER, STAGES
from sim.pipeline.command import Parser, run_command
from sim.pipeline.interruption import between_jobs, held_back, passed_over
from sim.storage.whole_file import whole_file


def _cores():
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()


def main(argv=None):
    """The command; its exit status (:func:`sim.pipeline.command.run_command`: 2 bad input,
    130 or 143 stopped by SIGINT or SIGTERM)."""
    return run_command("figures", lambda: _figures(argv),
                       unwritten="the runs made so far are kept, and the same command goes "
                                 "on from them")


def _figures(argv):
    parser = Parser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small versions (CI)")
    parser.add_argument("--only", nargs="+", choices=STAGES, help="these stages only")
    parser.add_argument("--out", default="outputs/figures", help="output folder")
    parser.add_argument("--jobs", type=int, default=_cores() + 1,
                        help="stages at once (default: one more than the cores; 1: all in "
                             "this process)")
    args = parser.parse_args(argv)
    from sim.figures.making import batches, stage_module  # matplotlib, Hydra, the engine

    out = Path(args.out) / (QUICK_FOLDER if args.quick else "")
    out.mkdir(parents=True, exist_ok=True)
    timings_path = out / "timings.csv"
    timings = {}
    if timings_path.exists():
        with open(timings_path, newline="") as f:
            timings = {row["stage"]: row["seconds"] for row in csv.DictReader(f)}
    names = list(args.only or STAGES)
    groups = sorted(batches(names, args.quick, out),
                    key=lambda g: -sum(float(timings.get(stage_module(n).NAME, 0.0)) for n in g))
    for stage_name, path, seconds in made(groups, args.quick, out, args.jobs):
        print(f"{stage_name}: {path} ({seconds:.1f} s)", flush=True)
        timings[stage_name] = f"{seconds:.1f}"
        with whole_file(timings_path) as partial:
            partial.write_text("stage,seconds\n" + "".join(
                f"{key},{value}\n" for key, value in timings.items()))


def made(groups, quick, out, jobs):
    """(stage NAME, what it wrote, seconds) of every stage of ``groups`` as it is made: in
    ``jobs`` processes, or in this one for a single job."""
    from sim.figures.making import make_stages

    if jobs <= 1:
        for group in groups:
            yield from make_stages(group, quick, out)
        return
    # a worker passes SIGINT and SIGTERM over: Ctrl-C reaches the whole process group, the
    # runs of a worker's stage stop by themselves (the stage then fails), a figure being
    # drawn is finished, and this process cancels the stages not begun
    with ProcessPoolExecutor(jobs, mp_context=get_context("spawn"), initializer=between_jobs,
                             initargs=(passed_over,)) as pool:
        with held_back():  # the workers it starts
            pending = {pool.submit(make_stages, group, quick, out) for group in groups}
        try:
            while pending:
                done, pending = wait(pending, return_when=FIRST_EXCEPTION)
                for future in done:
                    if future.exception() is not None:
                        raise future.exception()
                    yield from future.result()
        except BaseException:
            for other in pending:
                other.cancel()  # those not started; the running ones finish
            raise


if __name__ == "__main__":
    sys.exit(main())
