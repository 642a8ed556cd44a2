"""Scenes: from a validated config to the initial state of the engine.

Each scene is a function registered under its name (``@scene("crater", _bed_preparation)``)
that returns a :class:`Scene`, with a function saying in words how it places its disks;
adding a scene is adding them here and a YAML file in ``conf/scenario/``. Positions and
velocities are float64[n, 2] in box units.
"""

from dataclasses import dataclass

import numpy as np

from sim.engine.core import Boundary, Engine
from sim.pipeline.config import ConfigError
from sim.pipeline.initial import (
    MELT_COLLISIONS_PER_DISK,
    RSA_JAMMING,
    PlacementError,
    fixed_speed,
    hexagonal_lattice,
    maxwellian,
    melted_lattice,
    radius_for_packing,
    random_sequential,
    remove_drift,
)

BUILDERS = {}


@dataclass
class Scene:
    position: np.ndarray
    velocity: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    species: np.ndarray
    boundary: Boundary


#: scene name → ``f(cfg) -> str``: how the scene's initial state is made, in words
PREPARATIONS = {}


def scene(name, preparation=None):
    """Register a scene builder ``f(cfg) -> Scene`` under ``name``, and ``preparation(cfg)``
    saying how it places its disks (default: as the config gives them)."""
    def register(builder):
        BUILDERS[name] = builder
        PREPARATIONS[name] = preparation or (lambda cfg: "placed as the scene's keys say")
        return builder
    return register


def preparation(cfg):
    """How the initial state of ``cfg``'s scene is made, in words (recorded in /parameters
    as ``preparation`` and named on the figures)."""
    return PREPARATIONS[cfg.scene](cfg)


def build_scene(cfg):
    """The initial state of the scene named by ``cfg.scene``."""
    return BUILDERS[cfg.scene](cfg)


def _boundary(cfg):
    periodic = cfg.box.boundary == "periodic"
    return Boundary(size=(float(cfg.box.size[0]), float(cfg.box.size[1])),
                    periodic=(periodic, periodic))


def _gas_radius(cfg):
    d = cfg.disks
    area = float(cfg.box.size[0]) * float(cfg.box.size[1])
    if d.radius is not None:
        return float(d.radius)
    if d.packing_fraction is None:
        raise ConfigError("disks.packing_fraction", None,
                          "give disks.radius or disks.packing_fraction")
    return radius_for_packing(d.n, d.packing_fraction, area)


def _placement(cfg, n, radius, region=None):
    """The placement ``disks.placement`` asks for, ``auto`` resolved: random addition where
    it reaches the packing comfortably (φ < 0.8 × its jamming φ), else the melted lattice."""
    if cfg.disks.placement != "auto":
        return cfg.disks.placement
    box = (float(cfg.box.size[0]), float(cfg.box.size[1]))
    (x0, x1), (y0, y1) = region or ((0.0, box[0]), (0.0, box[1]))
    phi = n * np.pi * radius**2 / ((x1 - x0) * (y1 - y0))
    return "random" if phi < 0.8 * RSA_JAMMING else "melted"


PLACEMENTS = {"random": "random sequential addition",
              "lattice": "hexagonal lattice (jittered)",
              "melted": f"hexagonal lattice melted by {MELT_COLLISIONS_PER_DISK} elastic "
                        f"collisions per disk"}


def _place(cfg, radius, n, region=None, key="disks.packing_fraction"):
    """Positions float64[n, 2] by :func:`_placement`; a packing that cannot be placed is a
    :class:`ConfigError` on ``key``."""
    box = (float(cfg.box.size[0]), float(cfg.box.size[1]))
    periodic = _boundary(cfg).periodic
    placement = _placement(cfg, n, radius, region)
    try:
        if placement == "random":
            return random_sequential(np.full(n, radius), box=box, region=region,
                                     periodic=periodic, seed=cfg.seed)
        place = melted_lattice if placement == "melted" else hexagonal_lattice
        return place(n, radius, box=box, region=region, periodic=periodic, seed=cfg.seed)
    except PlacementError as error:
        area = (float(np.prod(box)) if region is None
                else (region[0][1] - region[0][0]) * (region[1][1] - region[1][0]))
        phi = n * np.pi * radius**2 / area
        raise ConfigError(key, round(phi, 4) if key.endswith("fraction") else n,
                          str(error)) from error


def _velocities(cfg, mass):
    d = cfg.disks
    if d.temperature is not None:
        velocity = maxwellian(mass, d.temperature, seed=cfg.seed + 1)
    else:
        velocity = fixed_speed(mass.size, d.speed, seed=cfg.seed + 1)
    return remove_drift(velocity, mass) if d.zero_momentum else velocity


def _gas_preparation(cfg):
    d = cfg.disks
    velocities = (f"Maxwellian at T = {d.temperature}" if d.temperature is not None
                  else f"speed {d.speed} in random directions")
    return (f"{PLACEMENTS[_placement(cfg, d.n, _gas_radius(cfg))]}; {velocities}"
            + (", zero total momentum" if d.zero_momentum else ""))


@scene("gas", _gas_preparation)
def gas(cfg):
    n = cfg.disks.n
    radius = _gas_radius(cfg)
    mass = np.full(n, float(cfg.disks.mass))
    return Scene(_place(cfg, radius, n), _velocities(cfg, mass), np.full(n, radius), mass,
                 np.zeros(n, np.int32), _boundary(cfg))


scene("cooling", _gas_preparation)(gas)
scene("driven", _gas_preparation)(gas)


@scene("mixture", _gas_preparation)
def mixture(cfg):
    base = gas(cfg)
    n = cfg.disks.n
    counts = np.floor(np.asarray(cfg.mixture.fractions) * n).astype(int)
    counts[0] += n - counts.sum()
    species = np.repeat(np.arange(counts.size, dtype=np.int32), counts)
    species = np.random.default_rng(cfg.seed + 2).permutation(species)
    base.species = species
    base.mass = np.asarray(cfg.mixture.masses, dtype=np.float64)[species]
    base.velocity = _velocities(cfg, base.mass)
    return base


@scene("single_disk")
def single_disk(cfg):
    radius = _gas_radius(cfg)
    ly = float(cfg.box.size[1])
    speed = cfg.disks.speed if cfg.disks.speed is not None else 1.0
    velocity = speed * np.array([[1.0, 1.0]]) / np.sqrt(2.0)
    return Scene(np.array([[radius, 0.5 * ly]]), velocity, np.array([radius]),
                 np.array([float(cfg.disks.mass)]), np.zeros(1, np.int32), _boundary(cfg))


@scene("two_disks")
def two_disks(cfg):
    """Positions and velocities as given, checked by :func:`sim.pipeline.config.validate`."""
    radius = _gas_radius(cfg)
    return Scene(np.array(cfg.two_disks.positions, dtype=np.float64),
                 np.array(cfg.two_disks.velocities, dtype=np.float64), np.full(2, radius),
                 np.full(2, float(cfg.disks.mass)), np.zeros(2, np.int32), _boundary(cfg))


@scene("scattering")
def scattering(cfg):
    s = cfg.scattering
    lx, ly = (float(x) for x in cfg.box.size)
    r = float(cfg.disks.radius)
    target = [0.6 * lx, 0.5 * ly]
    projectile = [r + 0.05 * lx, 0.5 * ly + float(s.impact_parameter)]
    speed = cfg.disks.speed if cfg.disks.speed is not None else 1.0
    return Scene(np.array([projectile, target]), np.array([[speed, 0.0], [0.0, 0.0]]),
                 np.array([r, float(s.target_radius)]),
                 np.array([float(cfg.disks.mass), float(s.target_mass)]),
                 np.array([0, 1], np.int32), _boundary(cfg))


def _bed_region(cfg):
    return (0.0, float(cfg.box.size[0])), (0.0, float(cfg.bed.height))


def _bed(cfg):
    """Positions float64[n, 2] of the bed disks, at rest in 0 ≤ y ≤ bed.height."""
    b = cfg.bed
    return _place(cfg, float(b.radius), int(b.n), region=_bed_region(cfg), key="bed.n")


def _bed_preparation(cfg):
    b = cfg.bed
    placed = PLACEMENTS[_placement(cfg, int(b.n), float(b.radius), _bed_region(cfg))]
    if cfg.scene == "crater" and b.settle_time is not None:
        return f"bed: {placed}, then settled for t = {b.settle_time} under gravity"
    return f"bed: {placed}, at rest"


@scene("vibrated_bed", _bed_preparation)
def vibrated_bed(cfg):
    b = cfg.bed
    n = int(b.n)
    return Scene(_bed(cfg), np.zeros((n, 2)), np.full(n, float(b.radius)),
                 np.full(n, float(b.mass)), np.zeros(n, np.int32), _boundary(cfg))


def _settled(cfg, position):
    """The bed after ``bed.settle_time`` alone under the scene's gravity, restitution and TC
    model: (positions, velocities) float64[n, 2]."""
    b = cfg.bed
    engine = Engine(position, np.zeros_like(position), float(b.radius), float(b.mass),
                    boundary=_boundary(cfg), restitution=float(cfg.restitution.disk),
                    wall_restitution=float(cfg.restitution.wall), tc=cfg.tc.time,
                    gravity=list(cfg.gravity), seed=cfg.seed)
    engine.run(time=float(b.settle_time))
    return engine.positions(b.settle_time), engine.velocities(b.settle_time)


@scene("crater", _bed_preparation)
def crater(cfg):
    p, b = cfg.projectile, cfg.bed
    bed = _bed(cfg)
    bed_velocity = np.zeros_like(bed)
    if b.settle_time is not None:
        bed, bed_velocity = _settled(cfg, bed)
        gap = np.hypot(*(bed - np.asarray(p.position)).T) - float(b.radius) - float(p.radius)
        if gap.min() <= 0.0:
            raise ConfigError("projectile.position", list(p.position),
                              f"above the settled bed, whose top is at y = "
                              f"{(bed[:, 1] + float(b.radius)).max():.4g}")
    n = int(b.n) + 1
    position = np.vstack([bed, [list(p.position)]])
    velocity = np.vstack([bed_velocity, [[0.0, -float(p.speed)]]])
    radius = np.append(np.full(n - 1, float(b.radius)), float(p.radius))
    projectile_mass = (float(p.mass) if p.mass is not None
                       else float(b.mass) * (float(p.radius) / float(b.radius)) ** 2)
    mass = np.append(np.full(n - 1, float(b.mass)), projectile_mass)
    species = np.append(np.zeros(n - 1, np.int32), 1).astype(np.int32)
    return Scene(position, velocity, radius, mass, species, _boundary(cfg))
