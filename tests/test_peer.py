"""The C peer of the speed table (benchmarks/peer/disks.c): it builds, and its gas has the
equation of state of hard disks and keeps its energy; the table's figure is drawn from rows
of its JSON (benchmarks/speed_figure.py). Nothing here is timed."""

import importlib.util
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from sim.analysis.theory import kolafa_rottner_z
from sim.figures.web import LARGEST_IMAGE, WIDEST
from sim.pipeline.initial import fixed_speed, hexagonal_lattice, radius_for_packing

BENCHMARKS = Path(__file__).parent.parent / "benchmarks"


def _benchmark(name):
    """The module ``benchmarks/<name>.py``."""
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler (cc) found")
def test_peer_pressure_and_energy(tmp_path):
    """N = 1000 at φ = 0.5 from a lattice, 20 collisions per disk of warm-up, then 20 blocks
    of 200 collisions per disk (4·10⁶ collisions, a few seconds). Z of the run against
    Kolafa & Rottner within four standard errors of the block means plus 1/N relative for
    the finite box, as sim's own validation allows (sim.checks.validation): blocks of 200
    collisions per disk are far longer than the correlation time of Z, so their scatter
    gives the error honestly. That error, 0.04 % of Z for such a run (eight seeds), must
    stay below 0.1 %, so that a broken run cannot pass on a wide tolerance: the tolerance is
    then at most 0.5 %. Energy: elastic contacts conserve it to round-off."""
    peer = _benchmark("peer_speed")
    executable = peer.build_peer(tmp_path)
    n, phi, blocks, per_block = 1000, 0.5, 20, 200
    radius = radius_for_packing(n, phi)
    position = hexagonal_lattice(n, radius, periodic=(True, True), seed=1)
    state = tmp_path / "state.bin"
    peer.write_state(state, position, fixed_speed(n, 1.0, seed=2), radius)
    process = peer.start_peer(executable, state, shell=2.0, warmup=20, z=True)
    answers, _ = process.communicate(f"{per_block * n}\n" * blocks, timeout=120)
    assert process.returncode == 0
    lines = answers.splitlines()
    assert lines[0] == "ready"
    rate, z, energy_change = np.array([line.split() for line in lines[1:]], float).T
    assert len(z) == blocks and np.all(rate > 0.0)
    expected = kolafa_rottner_z(phi)
    error = z.std(ddof=1) / np.sqrt(blocks)
    assert error < 1e-3 * expected
    assert abs(z.mean() - expected) < 4.0 * error + expected / n
    assert np.max(np.abs(energy_change)) < 1e-9


def _speed_row(n, phi, rounds, per_round):
    """A row of peer_speed's JSON with made-up rates (collisions per second), with or without
    each round's rates."""
    c = [1e6 * (1.0 + 0.01 * k) for k in range(rounds)]
    row = {"n": n, "phi": phi, "shell": 2.0, "chunk": 1000, "rounds": rounds,
           "c_collisions_per_s": round(max(c)), "sim_collisions_per_s": round(1.5 * max(c)),
           "sim_over_c": 1.5, "sim_over_c_q1": 1.4, "sim_over_c_q3": 1.6}
    if per_round:
        row["c_rates_per_round"] = [round(rate) for rate in c]
        row["sim_rates_per_round"] = [round(1.5 * rate) for rate in c]
    return row


@pytest.mark.parametrize("per_round", [False, True])
def test_speed_figure_from_rows(tmp_path, per_round):
    """The figure of a JSON shaped like peer_speed's (two φ, three N; each round's rates or
    only the best chunk's) is a PNG within the web limits."""
    rows = [_speed_row(n, phi, 4, per_round) for phi in (0.3, 0.5) for n in (100, 1000, 10000)]
    machine = {"processor": "a processor", "cores": 2, "numba": "0", "compiler": "cc",
               "flags": "-O3", "date": "2000-01-01T00:00:00+00:00"}
    measured = tmp_path / "speed.json"
    measured.write_text(json.dumps({"machine": machine, "rows": rows}))
    figure = tmp_path / "speed.png"
    _benchmark("speed_figure").plot(measured, figure)
    assert figure.stat().st_size <= LARGEST_IMAGE
    with Image.open(figure) as image:
        assert image.format == "PNG" and 0 < image.width <= WIDEST
