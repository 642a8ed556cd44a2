"""Where the event engine spends its time: a sampling profile of its compiled functions.

``perf`` (Linux) samples the instruction pointer of this process while the engine runs
elastic disks in a periodic box. The compiled functions are JIT code without symbols, so
they are compiled afresh here (into a temporary numba cache, which takes 10–20 s) and each
is asked for its address and machine code; every sample is then named by the function it
falls in. For the functions that take at least ``--min-share`` of the samples, the hottest
instructions follow, each with the instruction before it: a sample lands just after an
instruction that made the CPU wait, so a load before a hot instruction is a cache miss.
Needs ``perf``, ``nm`` and ``objdump`` on the PATH, and the right to profile a process.

    python benchmarks/profile_engine.py --n 100000 --phi 0.5
"""

import argparse
import collections
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

TOOLS = ("perf", "nm", "objdump")


def compiled_functions(folder):
    """Every compiled specialisation of sim's functions, each found in the module that
    defines it: (name, address, size, machine code as (offset, instruction) pairs). The
    machine code comes from numba's private ``_get_compiled_object``, which only code compiled
    in this process has."""
    from numba.core.registry import CPUDispatcher

    found = []
    for module_name, module in list(sys.modules.items()):
        if module_name != "sim" and not module_name.startswith("sim."):
            continue
        for attribute, value in vars(module).items():
            if not isinstance(value, CPUDispatcher) or value.__module__ != module_name:
                continue
            for k, compiled in enumerate(value.overloads.values()):
                symbol = compiled.fndesc.llvm_func_name
                obj = Path(folder) / f"{module_name}.{attribute}.{k}.o"
                obj.write_bytes(compiled.library._get_compiled_object())
                found.append((f"{module_name}.{attribute}",
                              compiled.library.get_pointer_to_function(symbol),
                              *_disassemble(obj, symbol)))
    return found


def _disassemble(obj, symbol):
    """Size of ``symbol`` in the object file ``obj`` and its instructions as (offset, text)."""
    size, start = 0, 0
    for line in subprocess.run(["nm", "-S", obj], capture_output=True, text=True,
                               check=True).stdout.splitlines():
        fields = line.split()
        if len(fields) == 4 and fields[3] == symbol:
            start, size = int(fields[0], 16), int(fields[1], 16)
    listing = subprocess.run(["objdump", "-d", "--no-show-raw-insn", obj], capture_output=True,
                             text=True, check=True).stdout.splitlines()
    instructions = []
    for line in listing:
        match = re.match(r"\s*([0-9a-f]+):\s*(.*)", line)
        if match and start <= int(match.group(1), 16) < start + size:
            instructions.append((int(match.group(1), 16) - start, match.group(2)))
    return size, instructions


def profile(n, phi, collisions, frequency, folder):
    """Run the engine under ``perf record``; return the sampled addresses and the compiled
    functions."""
    from engine_rate import equal_disks
    from sim.engine import Boundary, Engine

    position, velocity, radius = equal_disks(n, phi)
    engine = Engine(position, velocity, radius, boundary=Boundary(periodic=(True, True)))
    engine.run(collisions=10 * n)
    functions = compiled_functions(folder)
    data = Path(folder) / "perf.data"
    recorder = subprocess.Popen(["perf", "record", "-q", "-e", "cpu-clock", "-F",
                                 str(frequency), "-p", str(os.getpid()), "-o", data])
    engine.run(collisions=engine.collisions + collisions)
    recorder.send_signal(signal.SIGINT)
    if recorder.wait() not in (0, -signal.SIGINT):
        raise SystemExit("perf record failed (is profiling allowed? see "
                         "/proc/sys/kernel/perf_event_paranoid)")
    samples = subprocess.run(["perf", "script", "-F", "ip", "-i", data], capture_output=True,
                             text=True, check=True).stdout.split()
    return [int(ip, 16) for ip in samples], functions


def report(samples, functions, min_share, top):
    by_function = collections.Counter()
    by_offset = collections.defaultdict(collections.Counter)
    for ip in samples:
        name = "other (Python, numpy, kernel)"
        for function, address, size, _ in functions:
            if address <= ip < address + size:
                name = function
                by_offset[function][ip - address] += 1
                break
        by_function[name] += 1
    total = len(samples)
    print(f"{total} samples\n\nfunction | samples | share\n--- | --- | ---")
    for name, count in by_function.most_common():
        print(f"{name} | {count} | {count / total:.1%}")
    for function, _, _, instructions in functions:
        counts = by_offset[function]
        own = sum(counts.values())
        if own < min_share * total:
            continue
        print(f"\n{function}: hottest instructions (share of the function's samples)")
        hottest = sorted(range(1, len(instructions)), reverse=True,
                         key=lambda k: counts[instructions[k][0]])[:top]
        for k in sorted(hottest):
            offset, text = instructions[k]
            print(f"  {counts[offset] / own:6.1%}  +{offset:<6x} {text:<48.48}  after: "
                  f"{instructions[k - 1][1]:.48}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=100_000)
    parser.add_argument("--phi", type=float, default=0.5)
    parser.add_argument("--collisions", type=int, default=5_000_000, help="profiled collisions")
    parser.add_argument("--frequency", type=int, default=2000, help="samples per second")
    parser.add_argument("--min-share", type=float, default=0.05,
                        help="show instructions of functions with at least this share")
    parser.add_argument("--top", type=int, default=8, help="instructions shown per function")
    args = parser.parse_args(argv)
    missing = [tool for tool in TOOLS if shutil.which(tool) is None]
    if missing:
        raise SystemExit(f"profile_engine.py needs {', '.join(missing)} on the PATH")
    with tempfile.TemporaryDirectory() as folder:
        os.environ["NUMBA_CACHE_DIR"] = folder  # compile afresh: cached code has no object
        samples, functions = profile(args.n, args.phi, args.collisions, args.frequency,
                                     folder)
        report(samples, functions, args.min_share, args.top)


if __name__ == "__main__":
    main()
