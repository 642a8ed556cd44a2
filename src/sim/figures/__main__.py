"""``python -m sim.figures [--quick] [--only NAME …]``: make the runs, then every figure.

Figures and their numbers go to ``outputs/figures/`` (``--out``), the runs they read to
``outputs/figures/runs/``; runs whose resolved config is unchanged are not made again. The
wall-clock seconds of each stage (its runs and its drawing) go to ``timings.csv`` there.
"""

import argparse
import csv
import importlib
import time
from pathlib import Path

from sim.figures import STAGES
from sim.figures.style import QUICK_FOLDER
from sim.pipeline.run_cache import ensure_run, ensure_sweep


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small versions (CI)")
    parser.add_argument("--only", nargs="+", choices=STAGES, help="these stages only")
    parser.add_argument("--out", default="outputs/figures", help="output folder")
    args = parser.parse_args(argv)
    out = Path(args.out) / (QUICK_FOLDER if args.quick else "")
    out.mkdir(parents=True, exist_ok=True)
    timings_path = out / "timings.csv"
    timings = {}
    if timings_path.exists():
        with open(timings_path, newline="") as f:
            timings = {row["stage"]: row["seconds"] for row in csv.DictReader(f)}
    for name in args.only or STAGES:
        stage = importlib.import_module(f"sim.figures.{name}")
        started = time.perf_counter()
        wanted_runs = stage.runs(args.quick) if hasattr(stage, "runs") else {}
        wanted_sweeps = stage.sweeps(args.quick) if hasattr(stage, "sweeps") else {}
        runs = {label: ensure_run(label, overrides, out / "runs")
                for label, overrides in wanted_runs.items()}
        sweeps = {label: ensure_sweep(label, overrides, out / "runs")
                  for label, overrides in wanted_sweeps.items()}
        path = stage.draw(runs, sweeps, out)
        seconds = time.perf_counter() - started
        print(f"{stage.NAME}: {path} ({seconds:.1f} s)")
        timings[stage.NAME] = f"{seconds:.1f}"
        with open(timings_path, "w", newline="") as f:
            f.write("stage,seconds\n")
            f.writelines(f"{key},{value}\n" for key, value in timings.items())


if __name__ == "__main__":
    main()
