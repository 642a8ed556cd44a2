"""The C peer of the speed table (benchmarks/peer/disks.c): it builds, and its gas has the
equation of state of hard disks and keeps its energy. Nothing here is timed."""

import importlib.util
import shutil
from pathlib import Path

import numpy as np
import pytest

from sim.analysis.theory import kolafa_rottner_z
from sim.pipeline.initial import fixed_speed, hexagonal_lattice, radius_for_packing

BENCHMARKS = Path(__file__).parent.parent / "benchmarks"

pytestmark = pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler (cc) found")


def _peer_speed():
    spec = importlib.util.spec_from_file_location("peer_speed", BENCHMARKS / "peer_speed.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_peer_pressure_and_energy(tmp_path):
    """N = 1000 at φ = 0.5 from a lattice, 20 collisions per disk of warm-up, then 20 blocks
    of 200 collisions per disk (4·10⁶ collisions, a few seconds). Z of the run against
    Kolafa & Rottner within four standard errors of the block means plus 1/N relative for
    the finite box, as sim's own validation allows (sim.checks.validation): blocks of 200
    collisions per disk are far longer than the correlation time of Z, so their scatter
    gives the error honestly. That error, 0.04 % of Z for such a run (eight seeds), must
    stay below 0.1 %, so that a broken run cannot pass on a wide tolerance: the tolerance is
    then at most 0.5 %. Energy: elastic contacts conserve it to round-off."""
    peer = _peer_speed()
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
