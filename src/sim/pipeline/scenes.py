"""Scenes: from a validated config to the initial state of the engine.

Every scene is one :class:`SceneSpec` in :data:`SCENES`: its builder ``f(cfg) -> Scene``,
how many disks it makes and how densely they lie, how it places them in words, the schema
sections it needs, the checks of its own keys, its fixed number of disks if it has one, and
whether it is a gas filling the box. The config's list of scenes and its per-scene checks
(:func:`sim.pipeline.config.validate`), :data:`BUILDERS`, :data:`PREPARATIONS` and the
resource estimates (:mod:`sim.pipeline.resources`) all come from it. Adding a scene is its
builder and entry here, its section of the schema (:mod:`sim.pipeline.schema`) if it has keys
of its own, and ``conf/scenario/<name>.yaml``; ``tests/test_scene_registry.py`` checks that
they agree. Positions and velocities are float64[n, 2] in box units.
"""

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from sim.effects.values import MAX_DISKS, ConfigError, pair, positive, resolvable, within
from sim.engine.box import nearest_images
from sim.engine.core import Engine
from sim.engine.inputs import Boundary
from sim.pipeline.initial import (
    COMPRESSION_RATE,
    COMPRESSION_START,
    MELT_COLLISIONS_PER_DISK,
    RSA_JAMMING,
    PlacementError,
    compressed,
    fixed_speed,
    hexagonal_lattice,
    maxwellian,
    melted_lattice,
    radius_for_packing,
    random_sequential,
    remove_drift,
    two_sizes,
)


@dataclass
class Scene:
    """An initial state: float64[n, 2] positions and velocities, radii, masses, species."""

    position: np.ndarray
    velocity: np.ndarray
    radius: np.ndarray
    mass: np.ndarray
    species: np.ndarray
    boundary: Boundary


def _as_given(cfg):
    return "placed as the scene's keys say"


def _no_checks(c):
    """A scene without keys of its own."""


def given_count(cfg):
    """``disks.n`` disks, and the key that sets them."""
    return int(cfg.disks.n), "disks.n"


def _always(n):
    """The disk count ``f(cfg) -> (n, "disks.n")`` of a scene that always has ``n`` disks."""
    return lambda cfg: (n, "disks.n")


def box_packing(cfg, n):
    """The packing fraction of ``n`` disks over the box: ``disks.packing_fraction``, or that of
    ``disks.radius``, at most 0.9 (0.9 when neither is given)."""
    d = cfg.disks
    if d.packing_fraction is not None:
        return float(d.packing_fraction)
    if d.radius is None:
        return 0.9
    return min(0.9, n * math.pi * float(d.radius) ** 2
               / (float(cfg.box.size[0]) * float(cfg.box.size[1])))


@dataclass(frozen=True)
class SceneSpec:
    """A scene: the name the config gives it, how it is built and described, how many disks
    it makes, and how its keys are checked."""

    name: str
    #: ``f(cfg) -> Scene``: the initial state
    builder: Callable
    #: ``f(cfg) -> (n, key)``: how many disks the scene makes, and the key that sets that many
    disk_count: Callable
    #: ``f(cfg) -> str``: how the initial state is made, in words
    preparation: Callable = _as_given
    #: the optional sections of the schema the scene needs (``bed``, ``projectile``, …)
    sections: tuple = ()
    #: ``f(c)``: :class:`ConfigError` on the first bad key of the scene's own, once the keys
    #: every scene shares and the presence of :attr:`sections` are checked
    check: Callable = _no_checks
    #: the number of disks the scene always has, which ``disks.n`` must not contradict
    fixed_count: Optional[int] = None
    #: a gas: ``disks.n`` disks fill the box at ``disks.packing_fraction``
    gas_like: bool = False
    #: ``f(cfg, n) -> φ``: the packing fraction where the ``n`` disks lie (the resource
    #: estimates count the pairs of g(r) by it)
    packing_fraction: Callable = box_packing


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


#: Above this packing fraction ``auto`` compresses a random gas rather than melt a lattice:
#: the melt's ten collisions per disk leave the lattice's order behind (N = 2000 equal disks
#: in a periodic box, three seeds: |Ψ₆| 0.02–0.05 at φ = 0.60, a fluid's, but 0.09–0.14 at
#: 0.62, 0.22 at 0.64 and 0.35–0.41 at 0.66, where the compressed gas has 0.05 at 0.68), and
#: its pressure starts below the fluid's (8–11 % below at φ = 0.68 over the first 20
#: collisions per disk, the compressed gas 1–4 % above).
MELT_LIMIT = 0.6


def _placement(cfg, n, radius, region=None):
    """The placement ``disks.placement`` asks for, ``auto`` resolved: random addition where
    it reaches the packing comfortably (φ < 0.8 × its jamming φ), the melted lattice up to
    :data:`MELT_LIMIT`, a compressed random gas above."""
    if cfg.disks.placement != "auto":
        return cfg.disks.placement
    box = (float(cfg.box.size[0]), float(cfg.box.size[1]))
    (x0, x1), (y0, y1) = region or ((0.0, box[0]), (0.0, box[1]))
    phi = n * np.pi * radius**2 / ((x1 - x0) * (y1 - y0))
    if phi < 0.8 * RSA_JAMMING:
        return "random"
    return "melted" if phi <= MELT_LIMIT else "compressed"


PLACEMENTS = {"random": "random sequential addition",
              "lattice": "hexagonal lattice (jittered)",
              "melted": f"hexagonal lattice melted by {MELT_COLLISIONS_PER_DISK} elastic "
                        f"collisions per disk",
              "compressed": f"random gas at φ = {COMPRESSION_START} compressed by growing "
                            f"disks at ṡ = {COMPRESSION_RATE} √(T/m)"}


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
        if placement == "compressed":
            return compressed(np.full(n, radius), box=box, region=region, periodic=periodic,
                              seed=cfg.seed)
        place = melted_lattice if placement == "melted" else hexagonal_lattice
        return place(n, radius, box=box, region=region, periodic=periodic, seed=cfg.seed)
    except PlacementError as error:
        area = (float(np.prod(box)) if region is None
                else (region[0][1] - region[0][0]) * (region[1][1] - region[1][0]))
        phi = n * np.pi * radius**2 / area
        raise ConfigError(key, round(phi, 4) if key.endswith("fraction") else n,
                          error.reason) from error


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


def gas(cfg):
    n = cfg.disks.n
    radius = _gas_radius(cfg)
    mass = np.full(n, float(cfg.disks.mass))
    return Scene(_place(cfg, radius, n), _velocities(cfg, mass), np.full(n, radius), mass,
                 np.zeros(n, np.int32), _boundary(cfg))


def _check_mixture(c):
    """One mass per species, fractions that sum to 1 and give every species a disk."""
    m, n = c.mixture, c.disks.n
    if len(m.masses) != len(m.fractions) or len(m.masses) < 1:
        raise ConfigError("mixture.masses", list(m.masses),
                          "one mass per entry of mixture.fractions")
    if any(not (x > 0) for x in m.masses):
        raise ConfigError("mixture.masses", list(m.masses), "positive masses")
    if any(not (x > 0) for x in m.fractions) or abs(sum(m.fractions) - 1.0) > 1e-9:
        raise ConfigError("mixture.fractions", list(m.fractions),
                          "positive fractions that sum to 1")
    counts = [math.floor(x * n) for x in m.fractions]
    if min(counts[1:], default=1) < 1:
        raise ConfigError("mixture.fractions", list(m.fractions),
                          f"fractions that give every species at least one of the "
                          f"disks.n={n} disks (a species gets floor(fraction × n))")


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


def _check_compress(c):
    """A radius ratio of at least 1, a fraction of large disks in [0, 1], a growth rate, and
    a placement at random (the scene starts from a random dilute gas)."""
    k = c.compress
    if not 1.0 <= k.radius_ratio <= 100.0:
        raise ConfigError("compress.radius_ratio", k.radius_ratio,
                          "a ratio of large to small radius from 1 to 100")
    within("compress.large_fraction", k.large_fraction, 0.0, 1.0, "a number fraction in [0, 1]")
    if c.growth.rate <= 0.0:
        raise ConfigError("growth.rate", c.growth.rate, "a rate > 0: the compress scene grows "
                          "its disks")
    if c.disks.placement not in ("random", "auto"):
        raise ConfigError("disks.placement", c.disks.placement,
                          "random or auto: the compress scene starts from a random gas")


def _compress_radii(cfg):
    """Radii float64[n] and species int32[n] of the compress scene (:func:`two_sizes`): the
    small radius ``disks.radius``, or set by ``disks.packing_fraction``."""
    d, k = cfg.disks, cfg.compress
    area = float(cfg.box.size[0]) * float(cfg.box.size[1])
    large = round(float(k.large_fraction) * d.n)
    phi = (d.packing_fraction if d.radius is None else math.pi * float(d.radius) ** 2
           * (d.n - large + large * float(k.radius_ratio) ** 2) / area)
    return two_sizes(int(d.n), float(phi), float(k.radius_ratio), float(k.large_fraction),
                     area, cfg.seed + 2)


def _compress_preparation(cfg):
    return f"random sequential addition; {_gas_preparation(cfg).split('; ', 1)[1]}"


def compress(cfg):
    """A random dilute gas of two sizes, which the scene's growth compresses."""
    radius, species = _compress_radii(cfg)
    mass = np.full(radius.size, float(cfg.disks.mass))
    box = (float(cfg.box.size[0]), float(cfg.box.size[1]))
    try:
        position = random_sequential(radius, box=box, periodic=_boundary(cfg).periodic,
                                     seed=cfg.seed)
    except PlacementError as error:
        raise ConfigError("disks.packing_fraction", cfg.disks.packing_fraction,
                          error.reason) from error
    return Scene(position, _velocities(cfg, mass), radius, mass, species, _boundary(cfg))


def single_disk(cfg):
    radius = _gas_radius(cfg)
    ly = float(cfg.box.size[1])
    speed = cfg.disks.speed if cfg.disks.speed is not None else 1.0
    velocity = speed * np.array([[1.0, 1.0]]) / np.sqrt(2.0)
    return Scene(np.array([[radius, 0.5 * ly]]), velocity, np.array([radius]),
                 np.array([float(cfg.disks.mass)]), np.zeros(1, np.int32), _boundary(cfg))


def _check_two_disks(c):
    """Two positions and two velocities; the disks apart, across a periodic side too."""
    position = pair(c, "two_disks.positions", "two points [[x, y], [x, y]]")
    pair(c, "two_disks.velocities", "two velocities [[vx, vy], [vx, vy]]")
    if c.disks.radius is None:
        raise ConfigError("disks.radius", None, "the radius of the two disks")
    box = np.array([float(x) for x in c.box.size])
    r = nearest_images(position[0] - position[1], box, [c.box.boundary == "periodic"] * 2)
    if np.hypot(*r) < 2.0 * c.disks.radius:
        raise ConfigError("two_disks.positions", position.tolist(),
                          f"two points [[x, y], [x, y]] at least 2 R = "
                          f"{2.0 * c.disks.radius:.6g} apart (the disks must not overlap)")


def two_disks(cfg):
    """Positions and velocities as given, checked by :func:`_check_two_disks`."""
    radius = _gas_radius(cfg)
    return Scene(np.array(cfg.two_disks.positions, dtype=np.float64),
                 np.array(cfg.two_disks.velocities, dtype=np.float64), np.full(2, radius),
                 np.full(2, float(cfg.disks.mass)), np.zeros(2, np.int32), _boundary(cfg))


def _check_scattering(c):
    """A target of positive size and mass; an impact parameter up to the contact distance."""
    s, radius = c.scattering, c.disks.radius
    positive("scattering.target_radius", s.target_radius, allow_none=False)
    resolvable(c, "scattering.target_radius", s.target_radius)
    positive("scattering.target_mass", s.target_mass, allow_none=False)
    if radius is None:
        raise ConfigError("disks.radius", None, "the scattering projectile needs a radius")
    within("scattering.impact_parameter", s.impact_parameter, 0.0, s.target_radius + radius,
           f"between 0 and the contact distance {s.target_radius + radius}")


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


def _check_bed(c):
    """Bed disks of positive size and mass, in a bed at most 0.85 full inside the box."""
    b = c.bed
    positive("bed.radius", b.radius, allow_none=False)
    resolvable(c, "bed.radius", b.radius)
    positive("bed.mass", b.mass, allow_none=False)
    if not 1 <= b.n < MAX_DISKS:
        raise ConfigError("bed.n", b.n, f"from 1 to {MAX_DISKS - 1} disks")
    lx, ly = c.box.size
    within("bed.height", b.height, 1e-12, ly, f"between 0 and the box height {ly}")
    bed_phi = b.n * math.pi * b.radius**2 / (lx * b.height)
    if bed_phi > 0.85:
        raise ConfigError("bed.n", b.n, f"at most a packing fraction of 0.85 in the bed "
                          f"region (this is {bed_phi:.3f}): fewer or smaller bed disks, or "
                          f"a higher bed.height")


def _bed_region(cfg):
    return (0.0, float(cfg.box.size[0])), (0.0, float(cfg.bed.height))


def _bed_count(cfg):
    return int(cfg.bed.n), "bed.n"


def _bed_packing(cfg, n):
    """The packing fraction of ``n`` disks of the bed's radius in the bed, at most 0.9."""
    return min(0.9, n * math.pi * float(cfg.bed.radius) ** 2
               / (float(cfg.box.size[0]) * float(cfg.bed.height)))


def _bed(cfg):
    """Positions float64[n, 2] of the bed disks, at rest in 0 ≤ y ≤ bed.height."""
    b = cfg.bed
    return _place(cfg, float(b.radius), int(b.n), region=_bed_region(cfg), key="bed.n")


def _bed_placement(cfg):
    b = cfg.bed
    return PLACEMENTS[_placement(cfg, int(b.n), float(b.radius), _bed_region(cfg))]


def _bed_preparation(cfg):
    return f"bed: {_bed_placement(cfg)}, at rest"


def _check_vibrated_bed(c):
    """The bed, which starts where it is placed."""
    _check_bed(c)
    if c.bed.settle_time is not None:
        raise ConfigError("bed.settle_time", c.bed.settle_time,
                          "null: the vibrated bed starts at rest where it is placed (only the "
                          "crater scene settles its bed first)")


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


def _crater_preparation(cfg):
    settle_time = cfg.bed.settle_time
    if settle_time is None:
        return _bed_preparation(cfg)
    return f"bed: {_bed_placement(cfg)}, then settled for t = {settle_time} under gravity"


def _crater_count(cfg):
    """The bed and the projectile."""
    return int(cfg.bed.n) + 1, "bed.n"


#: the longest settling of a bed, in free-fall times √(2L/g) across the box
SETTLE_FALLS = 100


def _check_crater(c):
    """The bed and its settling under gravity; the projectile inside the box, above the bed."""
    _check_bed(c)
    p, b = c.projectile, c.bed
    positive("bed.settle_time", b.settle_time)
    if b.settle_time is not None and not any(c.gravity):
        raise ConfigError("bed.settle_time", b.settle_time,
                          "null without gravity (nothing settles); set gravity=[0,-1]")
    if b.settle_time is not None:  # a bed settles within a few free-fall times
        fall = math.sqrt(2.0 * float(max(c.box.size)) / math.hypot(*c.gravity))
        if b.settle_time > SETTLE_FALLS * fall:
            raise ConfigError("bed.settle_time", b.settle_time,
                              f"at most {SETTLE_FALLS} free-fall times across the box, "
                              f"{SETTLE_FALLS} √(2L/g) = {SETTLE_FALLS * fall:.4g} here (a bed "
                              f"settles within a few)")
    positive("projectile.radius", p.radius, allow_none=False)
    resolvable(c, "projectile.radius", p.radius)
    positive("projectile.speed", p.speed, zero=True, allow_none=False)
    positive("projectile.mass", p.mass)
    lx, ly = c.box.size
    x, y = p.position
    if not (p.radius <= x <= lx - p.radius and p.radius <= y <= ly - p.radius):
        raise ConfigError("projectile.position", list(p.position),
                          f"inside the box, at least projectile.radius={p.radius} from "
                          f"every wall")
    if y - p.radius < b.height and b.settle_time is None:
        raise ConfigError("projectile.position", list(p.position),
                          f"above the bed (bed.height={b.height}) by at least its radius")


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


#: every scene, by name, in the order the config lists them
SCENES = {spec.name: spec for spec in (
    SceneSpec("single_disk", single_disk, _always(1), fixed_count=1),
    SceneSpec("two_disks", two_disks, _always(2), sections=("two_disks",),
              check=_check_two_disks, fixed_count=2),
    SceneSpec("scattering", scattering, _always(2), sections=("scattering",),
              check=_check_scattering, fixed_count=2),
    SceneSpec("gas", gas, given_count, preparation=_gas_preparation, gas_like=True),
    SceneSpec("mixture", mixture, given_count, preparation=_gas_preparation,
              sections=("mixture",), check=_check_mixture, gas_like=True),
    SceneSpec("compress", compress, given_count, preparation=_compress_preparation,
              sections=("compress",), check=_check_compress, gas_like=True),
    SceneSpec("crater", crater, _crater_count, preparation=_crater_preparation,
              sections=("projectile", "bed"), check=_check_crater, packing_fraction=_bed_packing),
    SceneSpec("melting", gas, given_count, preparation=_gas_preparation, gas_like=True),
    SceneSpec("cooling", gas, given_count, preparation=_gas_preparation, gas_like=True),
    SceneSpec("driven", gas, given_count, preparation=_gas_preparation, gas_like=True),
    SceneSpec("rough_cooling", gas, given_count, preparation=_gas_preparation, gas_like=True),
    SceneSpec("square_well", gas, given_count, preparation=_gas_preparation, gas_like=True),
    SceneSpec("square_shoulder", gas, given_count, preparation=_gas_preparation,
              gas_like=True),
    SceneSpec("vibrated_bed", vibrated_bed, _bed_count, preparation=_bed_preparation,
              sections=("bed",), check=_check_vibrated_bed, packing_fraction=_bed_packing),
)}

#: scene name → ``f(cfg) -> Scene``
BUILDERS = {name: spec.builder for name, spec in SCENES.items()}
#: scene name → ``f(cfg) -> str``: how the scene's initial state is made, in words
PREPARATIONS = {name: spec.preparation for name, spec in SCENES.items()}


def preparation(cfg):
    """How the initial state of ``cfg``'s scene is made, in words (recorded in /parameters
    as ``preparation`` and named on the figures)."""
    return PREPARATIONS[cfg.scene](cfg)


def build_scene(cfg):
    """The initial state of the scene named by ``cfg.scene``."""
    return BUILDERS[cfg.scene](cfg)
