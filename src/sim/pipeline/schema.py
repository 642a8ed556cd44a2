"""The schema of a scene's config: one dataclass per section of ``conf/config.yaml``.

It stands apart from the checks (:mod:`sim.pipeline.config`, which need the scenes and so the
engine) so that the reference of the keys (:mod:`sim.pipeline.config_reference`, ``python -m
sim --help``) reads it without loading the compiled engine.
"""

import typing
from dataclasses import dataclass, field, fields, is_dataclass
from pathlib import Path
from typing import Optional

from omegaconf import MISSING

#: the YAML of the scenes, shipped in the package (``conf/`` at the top of a clone links here)
CONF_DIR = str(Path(__file__).resolve().parents[1] / "conf")


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
    inertia_factor: float = 0.5
    rotational_temperature: float = 0.0


@dataclass
class RestitutionConfig:
    disk: float = 1.0
    wall: float = 1.0
    tangential: float = -1.0
    wall_tangential: float = -1.0


@dataclass
class FrictionConfig:
    mu: Optional[float] = None
    wall_mu: Optional[float] = None


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
class GrowthConfig:
    rate: float = 0.0
    rescale_every: float = 1.0


@dataclass
class PotentialConfig:
    steps: list = field(default_factory=list)
    energies: list = field(default_factory=list)


@dataclass
class StopConfig:
    collisions: Optional[int] = None
    contacts: Optional[int] = None
    time: Optional[float] = None
    energy_fraction: Optional[float] = None
    packing_fraction: Optional[float] = None
    jamming: Optional[float] = None
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
    bond_order: bool = False
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
class CompressConfig:
    radius_ratio: float = 1.4
    large_fraction: float = 0.5


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
    friction: FrictionConfig = field(default_factory=FrictionConfig)
    gravity: list = field(default_factory=lambda: [0.0, 0.0])
    walls: WallsConfig = field(default_factory=WallsConfig)
    growth: GrowthConfig = field(default_factory=GrowthConfig)
    potential: PotentialConfig = field(default_factory=PotentialConfig)
    stop: StopConfig = field(default_factory=StopConfig)
    output: OutputConfig = field(default_factory=OutputConfig)
    observe: ObserveConfig = field(default_factory=ObserveConfig)
    projectile: Optional[ProjectileConfig] = None
    bed: Optional[BedConfig] = None
    mixture: Optional[MixtureConfig] = None
    compress: Optional[CompressConfig] = None
    scattering: Optional[ScatteringConfig] = None
    two_disks: Optional[TwoDisksConfig] = None
    resume: Optional[str] = None




def plain_type(annotation):
    """The type a field holds when it holds a value: ``float`` of ``Optional[float]``."""
    inner = [a for a in typing.get_args(annotation) if a is not type(None)]
    return inner[0] if inner else annotation


def leaf_fields(node=SimConfig, prefix=""):
    """(dotted key, dataclass field) of every leaf of the schema, sections (also optional
    ones, such as ``projectile``) walked into."""
    for f in fields(node):
        section = plain_type(f.type)
        if is_dataclass(section):
            yield from leaf_fields(section, f"{prefix}{f.name}.")
        else:
            yield prefix + f.name, f
