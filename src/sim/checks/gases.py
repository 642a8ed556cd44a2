"""The gases the validation studies start from (:mod:`sim.checks.validation`,
:mod:`sim.checks.rough`): an equilibrated elastic gas of equal-size disks in the periodic unit
box, and a homogeneous granular gas made from it."""

import numpy as np

from sim.engine.core import Engine
from sim.engine.inputs import Boundary
from sim.pipeline.initial import (
    hexagonal_lattice,
    maxwellian,
    radius_for_packing,
    random_sequential,
    remove_drift,
)


def equilibrated_gas(n, phi, collisions_per_disk, seed=1, mass=1.0, species=None,
                     temperature=1.0, **keywords):
    """Elastic equal-size disks in the periodic unit box at ``temperature`` with zero total
    momentum, with the Engine keywords ``keywords`` (a stepped potential, say), run
    ``collisions_per_disk`` from a lattice (φ > 0.3) or random placement."""
    radius = radius_for_packing(n, phi)
    periodic = (True, True)
    mass = np.broadcast_to(np.asarray(mass, dtype=np.float64), (n,))
    if phi > 0.3:
        position = hexagonal_lattice(n, radius, periodic=periodic, seed=seed)
    else:
        position = random_sequential(np.full(n, radius), periodic=periodic, seed=seed)
    velocity = remove_drift(maxwellian(mass, temperature, seed=seed + 1), mass)
    engine = Engine(position, velocity, radius, mass, species,
                    boundary=Boundary(periodic=periodic), **keywords)
    engine.run(collisions=int(collisions_per_disk * n))
    return engine, radius


def cooling_gas(n, phi, restitution, seed, tc=None, mass=1.0, species=None):
    """A homogeneous granular gas at T = 1: the equilibrated elastic gas (10 collisions per
    disk) continued with restitution ξ."""
    elastic, radius = equilibrated_gas(n, phi, 10, seed, mass, species)
    engine = Engine(elastic.positions(), elastic.velocities(), radius, elastic.mass, species,
                    boundary=elastic.boundary, restitution=restitution, tc=tc)
    return engine, radius
