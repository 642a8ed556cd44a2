"""Same inputs, same bits, across changes of the code: the final states of a set of scenes —
periodic and walled, every effect off and on — are hashed and compared with the hashes kept in
``tests/fingerprints.json``.

A change that must not alter results (a refactor, a speed-up) keeps every hash, whatever the
chunks the loop is called in (:data:`CHUNKS`). A change that
alters results on purpose records them anew, and says why in its commit:
``SIM_RECORD_FINGERPRINTS=1 python -m pytest tests/test_fingerprints.py``.
"""

import hashlib
import json
import os
from pathlib import Path

import numpy as np
import pytest

from conftest import assert_no_overlap, gas
from sim.engine import Boundary, Engine
from sim.pipeline.runner import build_engine
from variants import compose_scene, scenario_params

FINGERPRINTS = Path(__file__).with_name("fingerprints.json")
#: events per call of the compiled loop: Engine.run's default, and a prime far below it, so
#: that the loop stops and resumes thousands of times in a run
CHUNKS = (None, 997)
RECORD = os.environ.get("SIM_RECORD_FINGERPRINTS") == "1"


def fingerprint(engine):
    """SHA-256 of what a run yields: positions, velocities, times, counts, energies, virials,
    wall positions, and where the engine keeps them, windings and the event log."""
    digest = hashlib.sha256()
    parts = [engine.positions(), engine.velocities(), engine.contacts_by_disk(),
             engine.wall_positions(),
             np.array([engine.time, engine.dissipated_energy, engine.wall_work, engine.virial,
                       engine.kinetic_energy()]),
             np.array([engine.collisions, engine.wall_contacts])]
    if engine.virial_tensor is not None:
        parts.append(engine.virial_tensor)
    if engine.event_log is not None:
        parts.append(engine.take_event_log())
    if engine.disks.images is not None:
        parts.append(engine.unwrapped_positions())
    for part in parts:
        digest.update(np.ascontiguousarray(part).tobytes())
    return digest.hexdigest()


def _two_species(n, seed, **options):
    """Disks of two sizes and masses (1:4 in mass, 1:1.5 in radius), half of each."""
    rng = np.random.default_rng(seed)
    species = np.arange(n) % 2
    radius = np.where(species == 0, 0.01, 0.015)
    side = int(np.ceil(np.sqrt(n)))
    grid = (np.stack(np.divmod(np.arange(n), side), axis=1) + 0.5) / side
    position = grid + rng.uniform(-0.005, 0.005, (n, 2))
    velocity = rng.normal(size=(n, 2))
    return Engine(position, velocity, radius, np.where(species == 0, 1.0, 4.0), species,
                  **options)


def _projectile(seed, **options):
    """A bed of small disks and one disk six times their radius flying into it."""
    engine = gas(300, 0.3, seed=seed, speed=0.1)
    position = np.vstack([engine.positions(), [[0.5, 0.9]]])
    radius = np.append(engine.radius, 0.06)
    keep = np.hypot(*(position[:-1] - [0.5, 0.9]).T) > 0.06 + engine.radius[0] + 1e-9
    keep = np.append(keep, True)
    velocity = np.vstack([engine.velocities(), [[0.0, -5.0]]])
    return Engine(position[keep], velocity[keep], radius[keep], **options)


def _moving_thermal_walls(seed):
    """A vibrating floor, a slow piston for a ceiling and a thermal left wall."""
    placed = gas(300, 0.3, seed=seed)
    walls = {"bottom": {"amplitude": 0.01, "frequency": 30.0}, "top": {"speed": -0.02},
             "left": {"temperature": 2.0}}
    return Engine(placed.positions(), placed.velocities(), placed.radius, walls=walls,
                  seed=seed + 3)


#: scene name → (engine factory, stop conditions of engine.run)
ENGINE_SCENES = {
    "periodic_elastic": (lambda: gas(400, 0.3, periodic=(True, True), seed=1),
                         {"contacts": 20_000}),
    "walls_dense": (lambda: gas(400, 0.65, seed=2), {"contacts": 20_000}),
    "periodic_inelastic_tc": (lambda: gas(400, 0.3, periodic=(True, True), seed=3,
                                          restitution=0.8, tc=1e-4), {"contacts": 20_000}),
    "mixture_walls_inelastic": (lambda: _two_species(300, 4, restitution=[[0.9, 0.8],
                                                                          [0.8, 0.7]],
                                                     wall_restitution=0.9),
                                {"contacts": 20_000}),
    "mixture_periodic": (lambda: _two_species(300, 5, boundary=Boundary(periodic=(True,
                                                                                True))),
                         {"contacts": 20_000}),
    "gravity_inelastic_tc": (lambda: gas(300, 0.3, seed=6, restitution=0.9,
                                         wall_restitution=0.8, tc=1e-3, gravity=[0.0, -1.0]),
                             {"time": 2.0}),
    "gravity_periodic_x": (lambda: gas(300, 0.3, periodic=(True, False), seed=7,
                                       gravity=[0.0, -2.0]), {"contacts": 20_000}),
    "moving_thermal_walls": (lambda: _moving_thermal_walls(8), {"time": 3.0}),
    "recorders": (lambda: gas(300, 0.3, periodic=(True, True), seed=9, unwrap=True,
                              pressure_tensor=True, event_log=1000), {"contacts": 20_000}),
    "projectile": (lambda: _projectile(10, restitution=0.9), {"contacts": 20_000}),
    "large_lookahead": (lambda: gas(40_000, 0.5, periodic=(True, True), seed=12),
                        {"contacts": 100_000}),
}


def _recorded():
    return json.loads(FINGERPRINTS.read_text()) if FINGERPRINTS.exists() else {}


def _check(name, engine, record):
    """Compare the fingerprint of ``engine`` with the one recorded under ``name``, or record it
    (``record``: the run that records, when recording)."""
    assert_no_overlap(engine)
    value = fingerprint(engine)
    if RECORD and record:
        recorded = _recorded()
        recorded[name] = value
        FINGERPRINTS.write_text(json.dumps(dict(sorted(recorded.items())), indent=1) + "\n")
        return
    expected = _recorded().get(name)
    assert expected is not None, f"no fingerprint recorded for {name}"
    assert value == expected, f"{name}: the final state changed"


#: engine scenes whose compiled loop is none of the quick suite's (tests/variants.py): their
#: bits are checked by ``make validate``
SLOW_SCENES = {"gravity_periodic_x", "mixture_walls_inelastic", "moving_thermal_walls",
               "projectile"}


@pytest.mark.parametrize("name", [pytest.param(name, marks=pytest.mark.slow)
                                  if name in SLOW_SCENES else name
                                  for name in sorted(ENGINE_SCENES)])
@pytest.mark.parametrize("chunk", CHUNKS)
def test_engine_scene_keeps_its_bits(name, chunk):
    make, stop = ENGINE_SCENES[name]
    engine = make()
    engine.run(**stop, **_chunked(chunk))
    _check(name, engine, record=chunk is None)


@pytest.mark.parametrize("name", scenario_params())
@pytest.mark.parametrize("chunk", CHUNKS)
def test_scenario_keeps_its_bits(name, chunk):
    engine = build_engine(compose_scene(name))
    engine.run(contacts=5_000, **_chunked(chunk))
    _check(f"scenario/{name}", engine, record=chunk is None)


def _chunked(chunk):
    return {} if chunk is None else {"chunk_events": chunk}
