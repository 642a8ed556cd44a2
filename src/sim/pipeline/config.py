"""The typed configuration of a scene: dataclasses registered in Hydra's ConfigStore, and
the range checks that types cannot express.

Hydra rejects unknown keys and wrong types when it composes the config; :func:`validate`
then checks every value against what is allowed and raises :class:`ConfigError` naming the
key, the value and the allowed range. ``conf/config.yaml`` holds the defaults with a comment
on every key; ``conf/scenario/*.yaml`` are the scenes.
"""

import math
from dataclasses import dataclass, field, fields, is_dataclass
from typing import Any, Optional

import numpy as np
from hydra.core.config_store import ConfigStore
from omegaconf import MISSING, DictConfig, OmegaConf

from sim.engine.core import RESOLUTION_LIMIT, SCALE_LIMIT
from sim.pipeline.initial import RSA_JAMMING

SCENES = ("single_disk", "two_disks", "scattering", "gas", "mixture", "crater", "cooling",
          "driven", "vibrated_bed")

#: Scenes with a fixed number of disks, which ``disks.n`` must not contradict.
FIXED_COUNT = {"single_disk": 1, "two_disks": 2, "scattering": 2}

#: Every dimensional number of a scene (a length, speed, mass, time, temperature or
#: acceleration) is 0 or of a magnitude in [SMALLEST, LARGEST], the engine's own range
#: (:data:`sim.engine.core.SCALE_LIMIT`): squares and products stay inside float64's.
SMALLEST, LARGEST = 1.0 / SCALE_LIMIT, SCALE_LIMIT

#: Smallest disk radius, as a fraction of the box's longer side (the engine's
#: :data:`sim.engine.core.RESOLUTION_LIMIT`, against the far edge of the disks, which the box
#: side bounds): float64 positions resolve 2⁻⁵² of the side, and smaller disks' contacts
#: drown in round-off.
SMALLEST_RADIUS = RESOLUTION_LIMIT

#: Largest seed: the compiled generator of thermal walls keys its draws with an int64.
MAX_SEED = 2**63 - 1
#: Largest number of disks: the engine numbers them with int32.
MAX_DISKS = 2**31 - 1
#: Largest collision or contact count: int64 counters, with room to add a chunk.
MAX_COUNT = 2**62


class ConfigError(ValueError):
    """A config value outside what is allowed."""

    def __init__(self, key, value, allowed):
        self.key, self.value, self.allowed = key, value, allowed
        super().__init__(f"{key}={value!r} is not allowed: {allowed}")

    def __reduce__(self):  # survives the trip back from a sweep's worker process
        return type(self), (self.key, self.value, self.allowed)


@dataclass
class BoxConfig:
    size: list = field(default_factory=lambda: [1.0, 1.0])
    boundary: str = "walls"


@dataclass
class DisksConfig:
    n: int = 2000
    radius: Optional[float] = None
    packing_fraction: Optional[float] = None
    mass: float = 1.0
    speed: Optional[float] = 1.0
    temperature: Optional[float] = None
    placement: str = "auto"
    zero_momentum: bool = False


@dataclass
class RestitutionConfig:
    disk: float = 1.0
    wall: float = 1.0


@dataclass
class WallConfig:
    temperature: Optional[float] = None
    speed: float = 0.0
    amplitude: float = 0.0
    frequency: float = 0.0


@dataclass
class WallsConfig:
    left: WallConfig = field(default_factory=WallConfig)
    right: WallConfig = field(default_factory=WallConfig)
    bottom: WallConfig = field(default_factory=WallConfig)
    top: WallConfig = field(default_factory=WallConfig)


@dataclass
class TCConfig:
    time: Optional[float] = None


@dataclass
class StopConfig:
    collisions: Optional[int] = None
    events: Optional[int] = None
    time: Optional[float] = None
    energy_fraction: Optional[float] = None
    at_rest: Optional[float] = None
    wall_seconds: Optional[float] = None


@dataclass
class OutputConfig:
    every_collisions: Optional[int] = None
    every_time: Optional[float] = None
    file: str = "run.h5"
    progress: bool = True


@dataclass
class RadialDistributionConfig:
    bins: Optional[int] = None
    r_max: float = 4.0


@dataclass
class ClustersConfig:
    gap: Optional[float] = None


@dataclass
class LocalFieldsConfig:
    cells: Optional[int] = None


@dataclass
class ObserveConfig:
    radial_distribution: RadialDistributionConfig = field(
        default_factory=RadialDistributionConfig)
    clusters: ClustersConfig = field(default_factory=ClustersConfig)
    local_fields: LocalFieldsConfig = field(default_factory=LocalFieldsConfig)
    mean_squared_displacement: bool = False
    velocity_autocorrelation: bool = False
    pressure_tensor: bool = False
    event_log: bool = False


@dataclass
class ProjectileConfig:
    radius: float = 0.05
    speed: float = 10.0
    mass: Optional[float] = None
    position: list = field(default_factory=lambda: [0.5, 0.75])


@dataclass
class BedConfig:
    n: int = 4000
    radius: float = 0.0045
    mass: float = 1.0
    height: float = 0.5
    settle_time: Optional[float] = None


@dataclass
class MixtureConfig:
    masses: list = field(default_factory=lambda: [1.0, 4.0])
    fractions: list = field(default_factory=lambda: [0.5, 0.5])


@dataclass
class ScatteringConfig:
    impact_parameter: float = 0.0
    target_radius: float = 0.1
    target_mass: float = 1.0e6


@dataclass
class TwoDisksConfig:
    positions: list = field(default_factory=lambda: [[0.25, 0.5], [0.75, 0.52]])
    velocities: list = field(default_factory=lambda: [[1.0, 0.3], [-0.5, 0.8]])


@dataclass
class SimConfig:
    scene: str = MISSING
    seed: int = 0
    box: BoxConfig = field(default_factory=BoxConfig)
    disks: DisksConfig = field(default_factory=DisksConfig)
    restitution: RestitutionConfig = field(default_factory=RestitutionConfig)
    tc: TCConfig = field(default_factory=TCConfig)
    gravity: list = field(default_factory=lambda: [0.0, 0.0])
    walls: WallsConfig = field(default_factory=WallsConfig)
    stop: StopConfig = field(default_factory=StopConfig)
    output: OutputConfig = field(default_factory=OutputConfig)
    observe: ObserveConfig = field(default_factory=ObserveConfig)
    projectile: Optional[ProjectileConfig] = None
    bed: Optional[BedConfig] = None
    mixture: Optional[MixtureConfig] = None
    scattering: Optional[ScatteringConfig] = None
    two_disks: Optional[TwoDisksConfig] = None
    resume: Optional[str] = None


def register():
    """Put the schema in Hydra's ConfigStore as ``sim_schema`` (conf/config.yaml extends it)."""
    ConfigStore.instance().store(name="sim_schema", node=SimConfig)


def integer_keys(node=SimConfig, prefix=""):
    """Dotted keys of the schema typed int (``disks.n``, ``stop.collisions``, …)."""
    keys = []
    for f in fields(node):
        kind = f.type
        inner = [a for a in getattr(kind, "__args__", ()) if a is not type(None)]
        if kind is int or inner == [int]:
            keys.append(prefix + f.name)
        elif is_dataclass(kind) or (inner and is_dataclass(inner[0])):
            keys += integer_keys(kind if is_dataclass(kind) else inner[0], f"{prefix}{f.name}.")
    return keys


def flat(cfg):
    """{dotted key: value} of every leaf of a config, interpolations resolved (lists stay
    whole)."""
    def walk(node, prefix):
        for key, value in node.items():
            if isinstance(value, dict) and value:
                yield from walk(value, f"{prefix}{key}.")
            else:
                yield f"{prefix}{key}", value
    return dict(walk(OmegaConf.to_container(cfg, resolve=True), ""))


def _leaves(value):
    """The items of a value, nested lists flattened."""
    if isinstance(value, (list, tuple)):
        return [leaf for item in value for leaf in _leaves(item)]
    return [value]


def _check_numbers(c):
    """Every number of the config finite, and every dimensional one 0 or within
    [SMALLEST, LARGEST]; seeds and counts have their own ranges."""
    counts = set(integer_keys())
    for key, value in flat(c).items():
        if key in counts or key == "resume":
            continue
        if isinstance(value, list) and None in _leaves(value):
            raise ConfigError(key, value, "numbers, not null")
        for x in (x for x in _leaves(value)
                  if isinstance(x, (int, float)) and not isinstance(x, bool)):
            if not math.isfinite(x):
                raise ConfigError(key, value, "finite numbers")
            if x != 0 and not SMALLEST <= abs(x) <= LARGEST:
                raise ConfigError(key, value, f"0 or a magnitude between {SMALLEST:g} and "
                                  f"{LARGEST:g}")
    if not 0 <= c.seed <= MAX_SEED:
        raise ConfigError("seed", c.seed, f"an integer from 0 to 2^63 − 1 = {MAX_SEED}")


def _resolvable(c, key, radius, value=None):
    """Refuse a disk radius that float64 positions in this box cannot resolve."""
    side = max(float(x) for x in c.box.size)
    if radius is not None and radius < SMALLEST_RADIUS * side:
        raise ConfigError(key, radius if value is None else value,
                          f"disks of radius at least 2^-40 of the box's longer "
                          f"side ({SMALLEST_RADIUS * side:.3g} here; this gives "
                          f"{radius:.3g}): float64 positions resolve 2^-52 of the side")


def _positive(cfg, key, value, allow_none=True, zero=False):
    if value is None:
        if allow_none:
            return
        raise ConfigError(key, value, "a number is required")
    if not (value > 0 or (zero and value == 0)):
        raise ConfigError(key, value, "must be ≥ 0" if zero else "must be > 0")


def _within(key, value, low, high, text):
    if value is not None and not low <= value <= high:
        raise ConfigError(key, value, text)


def _validate_gravity_and_walls(c):
    g = list(c.gravity)
    if len(g) != 2 or not all(math.isfinite(x) for x in g):
        raise ConfigError("gravity", g, "two finite numbers [gx, gy] (acceleration; [0, 0] = "
                          "off)")
    periodic = c.box.boundary == "periodic"
    if periodic and any(g):
        raise ConfigError("gravity", g, "[0, 0] in a periodic box, where nothing stops the "
                          "fall: use box.boundary=walls")
    for name in ("left", "right", "bottom", "top"):
        wall = c.walls[name]
        key = f"walls.{name}"
        _positive(c, f"{key}.temperature", wall.temperature)
        _positive(c, f"{key}.amplitude", wall.amplitude, allow_none=False, zero=True)
        _positive(c, f"{key}.frequency", wall.frequency, allow_none=False, zero=True)
        if not math.isfinite(wall.speed):
            raise ConfigError(f"{key}.speed", wall.speed, "a finite speed")
        moves = wall.speed != 0.0 or wall.amplitude != 0.0 or wall.temperature is not None
        if moves and periodic:
            raise ConfigError(f"{key}", OmegaConf.to_container(wall),
                              "thermal or moving walls need box.boundary=walls")
        if wall.amplitude > 0.0 and wall.frequency == 0.0:
            raise ConfigError(f"{key}.frequency", wall.frequency,
                              "an angular frequency > 0 for a wall with an amplitude")


def _validate_bed(c):
    b = c.bed
    if b is None:
        raise ConfigError("scene", c.scene, f"the {c.scene} scene needs a bed")
    _positive(c, "bed.radius", b.radius, allow_none=False)
    _resolvable(c, "bed.radius", b.radius)
    _positive(c, "bed.mass", b.mass, allow_none=False)
    if not 1 <= b.n < MAX_DISKS:
        raise ConfigError("bed.n", b.n, f"from 1 to {MAX_DISKS - 1} disks")
    lx, ly = c.box.size
    _within("bed.height", b.height, 1e-12, ly, f"between 0 and the box height {ly}")
    bed_phi = b.n * math.pi * b.radius**2 / (lx * b.height)
    if bed_phi > 0.85:
        raise ConfigError("bed.n", b.n, f"at most a packing fraction of 0.85 in the bed "
                          f"region (this is {bed_phi:.3f}): fewer or smaller bed disks, or "
                          f"a higher bed.height")


def _pair(c, key, allowed):
    """The config list at ``key`` as float64[2, 2], or :class:`ConfigError` naming it."""
    value = OmegaConf.to_container(OmegaConf.select(c, key))
    try:
        pair = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        pair = None
    if pair is None or pair.shape != (2, 2):
        raise ConfigError(key, value, allowed)
    return pair


def _validate_two_disks(c):
    """Two positions and two velocities; the disks apart, across a periodic side too."""
    position = _pair(c, "two_disks.positions", "two points [[x, y], [x, y]]")
    _pair(c, "two_disks.velocities", "two velocities [[vx, vy], [vx, vy]]")
    if c.disks.radius is None:
        raise ConfigError("disks.radius", None, "the radius of the two disks")
    box = np.array([float(x) for x in c.box.size])
    r = position[0] - position[1]
    if c.box.boundary == "periodic":
        r -= box * np.round(r / box)
    if np.hypot(*r) < 2.0 * c.disks.radius:
        raise ConfigError("two_disks.positions", position.tolist(),
                          f"two points [[x, y], [x, y]] at least 2 R = "
                          f"{2.0 * c.disks.radius:.6g} apart (the disks must not overlap)")


def validate(cfg: Any) -> None:
    """Check every value of a composed config; raise :class:`ConfigError` on the first bad one."""
    c = cfg if isinstance(cfg, DictConfig) else OmegaConf.structured(cfg)
    if c.scene not in SCENES:
        raise ConfigError("scene", c.scene, f"one of {', '.join(SCENES)}")
    _check_numbers(c)
    if len(c.box.size) != 2 or any(not (s > 0) for s in c.box.size):
        raise ConfigError("box.size", list(c.box.size), "two positive side lengths [Lx, Ly]")
    if c.box.boundary not in ("walls", "periodic"):
        raise ConfigError("box.boundary", c.box.boundary, "walls or periodic")
    d = c.disks
    if not 1 <= d.n <= MAX_DISKS:
        raise ConfigError("disks.n", d.n, f"from 1 to {MAX_DISKS} disks")
    if c.scene in FIXED_COUNT and d.n != FIXED_COUNT[c.scene]:
        raise ConfigError("disks.n", d.n, f"{FIXED_COUNT[c.scene]}: the {c.scene} scene has "
                          f"exactly that many disks")
    if d.radius is not None and d.packing_fraction is not None:
        raise ConfigError("disks.radius", d.radius,
                          "give disks.radius or disks.packing_fraction, not both")
    _positive(c, "disks.radius", d.radius)
    _resolvable(c, "disks.radius", d.radius)
    _within("disks.packing_fraction", d.packing_fraction, 1e-12, 0.9,
            "between 0 and 0.9 (hexagonal close packing is 0.9069)")
    if d.radius is None and d.packing_fraction is not None and c.scene not in FIXED_COUNT:
        area = float(c.box.size[0]) * float(c.box.size[1])
        _resolvable(c, "disks.packing_fraction",
                    math.sqrt(d.packing_fraction * area / (d.n * math.pi)), d.packing_fraction)
    _positive(c, "disks.mass", d.mass, allow_none=False)
    if d.speed is not None and d.temperature is not None:
        raise ConfigError("disks.speed", d.speed,
                          "give disks.speed or disks.temperature (set the other to null)")
    _positive(c, "disks.speed", d.speed, zero=True)
    _positive(c, "disks.temperature", d.temperature, zero=True)
    if d.placement not in ("random", "lattice", "melted", "auto"):
        raise ConfigError("disks.placement", d.placement, "random, lattice, melted or auto")
    if d.placement == "random" and c.scene in ("gas", "mixture", "cooling"):
        area = float(c.box.size[0]) * float(c.box.size[1])
        phi = (d.packing_fraction if d.radius is None
               else d.n * math.pi * d.radius**2 / area)
        if phi is not None and phi > RSA_JAMMING:
            raise ConfigError("disks.packing_fraction", round(phi, 4),
                              f"random placement reaches at most φ ≈ {RSA_JAMMING}; use "
                              f"disks.placement=melted or auto")
    _within("restitution.disk", c.restitution.disk, 0.0, 1.0, "between 0 and 1 (1 = elastic)")
    _within("restitution.wall", c.restitution.wall, 0.0, 1.0, "between 0 and 1 (1 = elastic)")
    _positive(c, "tc.time", c.tc.time, zero=True)
    _validate_gravity_and_walls(c)
    s = c.stop
    for key in ("collisions", "events", "time", "wall_seconds"):
        _positive(c, f"stop.{key}", s[key])
    for key in ("collisions", "events"):
        if s[key] is not None and s[key] > MAX_COUNT:
            raise ConfigError(f"stop.{key}", s[key], f"at most 2^62 = {MAX_COUNT}")
    _within("stop.energy_fraction", s.energy_fraction, 0.0, 1.0, "between 0 and 1")
    if s.at_rest is not None and not 0.0 < s.at_rest <= 1.0:
        raise ConfigError("stop.at_rest", s.at_rest, "a fraction in (0, 1]")
    if all(s[k] is None for k in ("collisions", "events", "time", "energy_fraction", "at_rest",
                                  "wall_seconds")):
        raise ConfigError("stop", None, "at least one of stop.collisions, stop.events, "
                          "stop.time, stop.energy_fraction, stop.at_rest, stop.wall_seconds")
    o = c.output
    if not o.file or "/" in o.file or o.file.startswith(".") or not o.file.strip():
        raise ConfigError("output.file", o.file, "a file name in the run folder, such as "
                          "run.h5 (no folders; not starting with a dot)")
    if o.every_collisions is not None and o.every_time is not None:
        raise ConfigError("output.every_collisions", o.every_collisions,
                          "give output.every_collisions or output.every_time, not both")
    _positive(c, "output.every_collisions", o.every_collisions)
    if o.every_collisions is not None and o.every_collisions > MAX_COUNT:
        raise ConfigError("output.every_collisions", o.every_collisions,
                          f"at most 2^62 = {MAX_COUNT}")
    _positive(c, "output.every_time", o.every_time)
    if o.every_time is not None and c.stop.time is not None \
            and math.ulp(float(c.stop.time)) > 1e-6 * o.every_time:
        raise ConfigError("output.every_time", o.every_time,
                          f"a cadence that float64 resolves up to stop.time = {c.stop.time}: "
                          f"above {1e6 * math.ulp(float(c.stop.time)):.3g}")
    rdf = c.observe.radial_distribution
    if rdf.bins is not None:
        if rdf.bins < 1:
            raise ConfigError("observe.radial_distribution.bins", rdf.bins, "at least 1 bin")
        if not rdf.r_max > 1.0:
            raise ConfigError("observe.radial_distribution.r_max", rdf.r_max,
                              "greater than 1 (r in units of the contact distance 2⟨R⟩)")
    _positive(c, "observe.clusters.gap", c.observe.clusters.gap, zero=True)
    cells = c.observe.local_fields.cells
    if cells is not None and cells < 1:
        raise ConfigError("observe.local_fields.cells", cells, "at least 1 cell along x")
    if c.scene in ("crater", "vibrated_bed"):
        _validate_bed(c)
    if c.scene == "vibrated_bed" and c.bed.settle_time is not None:
        raise ConfigError("bed.settle_time", c.bed.settle_time,
                          "null: the vibrated bed starts at rest where it is placed (only the "
                          "crater scene settles its bed first)")
    if c.scene == "crater":
        p, b = c.projectile, c.bed
        _positive(c, "bed.settle_time", b.settle_time)
        if b.settle_time is not None and not any(c.gravity):
            raise ConfigError("bed.settle_time", b.settle_time,
                              "null without gravity (nothing settles); set gravity=[0,-1]")
        if p is None:
            raise ConfigError("scene", c.scene, "the crater scene needs projectile and bed")
        _positive(c, "projectile.radius", p.radius, allow_none=False)
        _resolvable(c, "projectile.radius", p.radius)
        _positive(c, "projectile.speed", p.speed, zero=True, allow_none=False)
        _positive(c, "projectile.mass", p.mass)
        lx, ly = c.box.size
        x, y = p.position
        if not (p.radius <= x <= lx - p.radius and p.radius <= y <= ly - p.radius):
            raise ConfigError("projectile.position", list(p.position),
                              f"inside the box, at least projectile.radius={p.radius} from "
                              f"every wall")
        if y - p.radius < b.height and b.settle_time is None:
            raise ConfigError("projectile.position", list(p.position),
                              f"above the bed (bed.height={b.height}) by at least its radius")
    if c.scene == "mixture":
        m = c.mixture
        if m is None or len(m.masses) != len(m.fractions) or len(m.masses) < 1:
            raise ConfigError("mixture.masses", None if m is None else list(m.masses),
                              "one mass per entry of mixture.fractions")
        if any(not (x > 0) for x in m.masses):
            raise ConfigError("mixture.masses", list(m.masses), "positive masses")
        if any(not (x > 0) for x in m.fractions) or abs(sum(m.fractions) - 1.0) > 1e-9:
            raise ConfigError("mixture.fractions", list(m.fractions),
                              "positive fractions that sum to 1")
        counts = [math.floor(x * d.n) for x in m.fractions]
        if min(counts[1:], default=1) < 1:
            raise ConfigError("mixture.fractions", list(m.fractions),
                              f"fractions that give every species at least one of the "
                              f"disks.n={d.n} disks (a species gets floor(fraction × n))")
    if c.scene == "two_disks":
        _validate_two_disks(c)
    if c.scene == "scattering":
        sc = c.scattering
        _positive(c, "scattering.target_radius", sc.target_radius, allow_none=False)
        _resolvable(c, "scattering.target_radius", sc.target_radius)
        _positive(c, "scattering.target_mass", sc.target_mass, allow_none=False)
        if d.radius is None:
            raise ConfigError("disks.radius", None, "the scattering projectile needs a radius")
        _within("scattering.impact_parameter", sc.impact_parameter, 0.0,
                sc.target_radius + d.radius,
                f"between 0 and the contact distance {sc.target_radius + d.radius}")
