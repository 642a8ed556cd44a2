"""Speed of sim against the C peer: the published design for hard disks, measured together.

``benchmarks/peer/disks.c`` ports to 2D the design of Smallenburg (Eur. Phys. J. E 45, 22
(2022)), the fastest published event-driven code for hard spheres; it is compiled here with
``-O3 -march=native`` into a build folder outside the source tree (``--build-dir``, else a
temporary one). The C peer, a sim worker and, with ``--minimal``, the numba minimal design of
``minimal_design.py`` each start in a process of their own from the same lattice
(``engine_rate.equal_disks``), with the same shell diameter r_n (sim's default for φ unless
``--shell``), and each runs ``--warmup`` collisions per disk. Then, round after round, each
runs one chunk of collisions, in a shuffled order (as ``compare_builds.py`` does), and times
it itself (C with CLOCK_MONOTONIC, Python with perf_counter). Printed per (N, φ): the
best-chunk rate of each (the rate the machine disturbed least) and the median and quartiles
over rounds of the same-round ratio sim / C; ``--json PATH`` writes the rows (with each
round's rates) with the machine, the versions, the date and the command, and ``--markdown
PATH`` the table with a line saying where and how it was measured (``make speed`` writes both
into ``docs/results/``, and ``speed_figure.py`` draws the JSON).

    python benchmarks/peer_speed.py --n 10000 100000 --phi 0.5 --rounds 6
    python benchmarks/peer_speed.py --n 10000 --phi 0.5 --state 16384:0.708   # and a dense one
    python benchmarks/peer_speed.py --minimal --json outputs/peer_speed.json
"""

import argparse
import json
import os
import platform
import random
import shlex
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).parent / "peer" / "disks.c"


def compiler():
    """The C compiler: gcc, else cc; None when there is neither."""
    return shutil.which("gcc") or shutil.which("cc")


def build_peer(directory):
    """Compile the C peer into ``directory``; returns the executable's path."""
    executable = Path(directory) / "disks"
    subprocess.run([compiler(), "-O3", "-march=native", "-o", str(executable), str(SOURCE),
                    "-lm"], check=True)
    return executable


def write_state(path, position, velocity, radius, side=1.0):
    """The C peer's state file: float64 N, box side, radius, N (x, y), N (vx, vy)."""
    np.concatenate([[len(position), side, radius], np.ravel(position),
                    np.ravel(velocity)]).astype(np.float64).tofile(path)


def start_peer(executable, state, shell, warmup, z=False):
    """The C peer serving chunks (one collision count per line, one answer per line) once
    its ``warmup`` collisions per disk are done."""
    command = [str(executable), "-w", str(warmup), "-s", str(shell), str(state)]
    if z:
        command.insert(1, "-z")
    return subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)


def worker(kind, n, phi, shell, warmup):
    """Serve chunks like the C peer: sim's engine or the minimal numba design."""
    from engine_rate import equal_disks

    position, velocity, radius = equal_disks(n, phi)
    if kind == "sim":
        from sim.engine import Boundary, Engine

        engine = Engine(position, velocity, radius, boundary=Boundary(periodic=(True, True)),
                        shell=shell)

        def run(collisions):
            engine.run(collisions=engine.collisions + collisions)
    else:
        from minimal_design import MinimalEngine

        run = MinimalEngine(position, velocity, radius, shell).run
    run(int(warmup * n))
    print("ready", flush=True)
    for line in sys.stdin:
        started = time.perf_counter()
        run(int(line))
        print(int(line) / (time.perf_counter() - started), flush=True)


def ask(process, collisions):
    """Send one chunk; the rate in collisions per second (the first number of the answer)."""
    process.stdin.write(f"{collisions}\n")
    process.stdin.flush()
    answer = process.stdout.readline()
    if not answer:
        raise RuntimeError("a worker ended (its error is printed above)")
    return float(answer.split()[0])


def measure(executable, folder, n, phi, chunk, rounds, warmup, shell, minimal, seed=0):
    """One row: best-chunk rates, each round's rates (collisions per second) and the
    median and quartiles of the round-by-round ratios to the C peer."""
    from engine_rate import equal_disks
    from sim.engine.sizing import shell_ratio

    shell = shell_ratio(phi) if shell is None else shell
    state = Path(folder) / f"state_{n}_{phi}.bin"
    position, velocity, radius = equal_disks(n, phi)
    write_state(state, position, velocity, radius)
    kinds = ["c", "sim"] + (["minimal"] if minimal else [])
    processes = {}
    try:
        for kind in kinds:
            processes[kind] = start_peer(executable, state, shell, warmup) if kind == "c" else (
                subprocess.Popen([sys.executable, __file__, "--worker", kind, "--n", str(n),
                                  "--phi", str(phi), "--shell", str(shell),
                                  "--warmup", str(warmup)],
                                 stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True))
        for process in processes.values():
            if process.stdout.readline().strip() != "ready":
                raise RuntimeError("a worker failed to start (its error is printed above)")
        rates = {kind: [] for kind in kinds}
        shuffle = random.Random(seed)
        for _ in range(rounds):
            order = list(kinds)
            shuffle.shuffle(order)
            for kind in order:
                rates[kind].append(ask(processes[kind], chunk))
    finally:
        for process in processes.values():
            process.stdin.close()
            process.wait()
    row = {"n": n, "phi": phi, "shell": round(shell, 3), "chunk": chunk, "rounds": rounds}
    for kind in kinds:
        row[f"{kind}_collisions_per_s"] = round(max(rates[kind]))
        row[f"{kind}_rates_per_round"] = [round(rate) for rate in rates[kind]]
    for kind in kinds[1:]:
        ratios = [a / c for a, c in zip(rates[kind], rates["c"], strict=True)]
        quartiles = statistics.quantiles(ratios, n=4) if rounds > 1 else [ratios[0]] * 3
        row[f"{kind}_over_c"] = round(statistics.median(ratios), 3)
        row[f"{kind}_over_c_q1"] = round(quartiles[0], 3)
        row[f"{kind}_over_c_q3"] = round(quartiles[2], 3)
    return row


def machine():
    """What the rows were measured on and with."""
    import numba

    processor = platform.processor() or platform.machine()
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.exists():
        names = [line.split(":", 1)[1].strip() for line in cpuinfo.read_text().splitlines()
                 if line.startswith("model name")]
        processor = names[0] if names else processor
    gcc = subprocess.run([compiler(), "--version"], capture_output=True, text=True)
    return {"processor": processor, "cores": os.cpu_count(),
            "python": platform.python_version(), "numba": numba.__version__,
            "compiler": gcc.stdout.splitlines()[0],
            "flags": "-O3 -march=native",
            "date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "command": shlex.join(["python", *sys.argv])}


def state(text):
    """``N:PHI`` as (int, float), for ``--state``."""
    n, _, phi = text.partition(":")
    try:
        return int(n), float(phi)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: N:PHI, say 16384:0.708") from None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, nargs="+", default=[10_000, 100_000, 1_000_000])
    parser.add_argument("--phi", type=float, nargs="+", default=[0.5])
    parser.add_argument("--state", nargs="+", default=[], metavar="N:PHI", type=state,
                        help="further states, each N disks at packing fraction PHI, after "
                             "those of --n × --phi")
    parser.add_argument("--chunk", type=int, default=1_000_000, help="collisions per round")
    parser.add_argument("--rounds", type=int, default=8)
    parser.add_argument("--warmup", type=float, default=10.0, help="collisions per disk")
    parser.add_argument("--shell", type=float, default=None,
                        help="shell diameter r_n/σ for all (default: sim's for each φ)")
    parser.add_argument("--minimal", action="store_true",
                        help="also run the numba minimal design (minimal_design.py)")
    parser.add_argument("--build-dir", default=None,
                        help="folder for the C build and state files (default: a temporary one)")
    parser.add_argument("--json", metavar="PATH", default=None,
                        help="also write the rows and the machine to this JSON file")
    parser.add_argument("--markdown", metavar="PATH", default=None,
                        help="also write the table and how it was measured to this file")
    parser.add_argument("--worker", choices=["sim", "minimal"], help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker(args.worker, args.n[0], args.phi[0], args.shell, args.warmup)
        return
    if compiler() is None:
        sys.exit("no C compiler (gcc or cc) found")
    with tempfile.TemporaryDirectory() as scratch:
        folder = Path(args.build_dir or scratch)
        folder.mkdir(parents=True, exist_ok=True)
        executable = build_peer(folder)
        header = ["N", "φ", "shell r_n/σ", "C, best chunk", "sim, best chunk",
                  "sim / C, median of rounds", "quartiles"]
        if args.minimal:
            header += ["minimal, best chunk", "minimal / C, median of rounds", "quartiles"]
        table = [f"| {' | '.join(header)} |", f"|{' --- |' * len(header)}"]
        print("\n".join(table))
        rows = []
        for n, phi in [*((n, phi) for n in args.n for phi in args.phi), *args.state]:
            row = measure(executable, folder, n, phi, args.chunk, args.rounds, args.warmup,
                          args.shell, args.minimal)
            rows.append(row)
            cells = [n, phi, row["shell"], f"{row['c_collisions_per_s'] / 1e6:.3f} M"]
            for kind in ["sim"] + (["minimal"] if args.minimal else []):
                cells += [f"{row[f'{kind}_collisions_per_s'] / 1e6:.3f} M",
                          row[f"{kind}_over_c"],
                          f"{row[f'{kind}_over_c_q1']}–{row[f'{kind}_over_c_q3']}"]
            table.append(f"| {' | '.join(str(c) for c in cells)} |")
            print(table[-1], flush=True)
    about = machine()
    note = (f"Rates: the best chunk of {args.rounds} rounds of {args.chunk} collisions, one "
            f"thread; ratios: median and quartiles over rounds of the same-round ratio. "
            f"Measured {about['date'][:10]} on {about['processor']} ({about['cores']} cores), "
            f"Python {about['python']}, numba {about['numba']}, {about['compiler']} "
            f"{about['flags']}, with `{about['command']}`.")
    print(f"\n{note}")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps({"machine": about, "rows": rows}, indent=1)
                                   + "\n")
    if args.markdown:
        Path(args.markdown).parent.mkdir(parents=True, exist_ok=True)
        Path(args.markdown).write_text("\n".join(table) + f"\n\n{note}\n")


if __name__ == "__main__":
    main()
