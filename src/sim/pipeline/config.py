"""The typed configuration of a scene: the schema (:mod:`sim.pipeline.schema`) registered in
Hydra's ConfigStore, and the range checks that types cannot express.

Hydra rejects unknown keys and wrong types when it composes the config; :func:`validate`
then checks every value against what is allowed and raises :class:`ConfigError` naming the
key, the value and the allowed range; each effect checks its own keys
(:func:`sim.effects.check_config`). ``conf/config.yaml`` holds the defaults with a comment
on every key; ``conf/scenario/*.yaml`` are the scenarios. The scenes they name, and the
checks of each scene's own keys, are :data:`sim.pipeline.scenes.SCENES`.
"""

import math
from dataclasses import fields
from typing import Any

from hydra.core.config_store import ConfigStore
from omegaconf import DictConfig, OmegaConf

from sim.effects import check_config
from sim.effects.values import (
    LARGEST,
    MAX_DISKS,
    MAX_SEED,
    SMALLEST,
    ConfigError,
    positive,
    resolvable,
    within,
)
from sim.engine.inputs import MAX_COUNT
from sim.engine.running import CLOSE_PACKING
from sim.pipeline.config_reference import leaves
from sim.pipeline.initial import RSA_JAMMING
from sim.pipeline.scenes import PLACEMENTS, SCENES
from sim.pipeline.schema import SimConfig, StopConfig, leaf_fields, plain_type

#: the stop conditions of a scene (``stop:``), in the order of conf/config.yaml
STOP_KEYS = tuple(f.name for f in fields(StopConfig))


def register():
    """Put the schema in Hydra's ConfigStore as ``sim_schema`` (conf/config.yaml extends it)."""
    ConfigStore.instance().store(name="sim_schema", node=SimConfig)


def integer_keys():
    """Dotted keys of the schema typed int (``disks.n``, ``stop.collisions``, …)."""
    return [key for key, f in leaf_fields() if plain_type(f.type) is int]


def flat(cfg):
    """{dotted key: value} of every leaf of a config, interpolations resolved (lists stay
    whole)."""
    return leaves(OmegaConf.to_container(cfg, resolve=True))


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


def _check_keys(c):
    """Refuse a key the schema does not have (Hydra lets ``+key=`` and ``++key=`` add one):
    every leaf is a key of the schema, a section of it left out (``projectile: null``), or
    lies under a key whose value is a mapping (walls)."""
    known = [key for key, _ in leaf_fields()]
    for key in flat(c):
        if key not in known and not any(key.startswith(k + ".") or k.startswith(key + ".")
                                        for k in known):
            raise ConfigError(key, OmegaConf.select(c, key), "a key of the config, as "
                              "python -m sim --help lists them (+ and ++ add no new keys)")


def one_size(c):
    """Whether every disk of the scene has one radius: the gases, and the compress scene with
    a radius ratio of 1 or one kind of disk."""
    if c.scene == "compress":
        k = c.compress
        return k.radius_ratio == 1.0 or k.large_fraction in (0.0, 1.0)
    return SCENES[c.scene].gas_like


def validate(cfg: Any) -> None:
    """Check every value of a composed config; raise :class:`ConfigError` on the first bad one."""
    c = cfg if isinstance(cfg, DictConfig) else OmegaConf.structured(cfg)
    _check_keys(c)
    if c.scene not in SCENES:
        raise ConfigError("scene", c.scene, f"one of {', '.join(SCENES)}")
    scene = SCENES[c.scene]
    _check_numbers(c)
    if len(c.box.size) != 2 or any(not (s > 0) for s in c.box.size):
        raise ConfigError("box.size", list(c.box.size), "two positive side lengths [Lx, Ly]")
    if c.box.boundary not in ("walls", "periodic"):
        raise ConfigError("box.boundary", c.box.boundary, "walls or periodic")
    d = c.disks
    if not 1 <= d.n <= MAX_DISKS:
        raise ConfigError("disks.n", d.n, f"from 1 to {MAX_DISKS} disks")
    if scene.fixed_count is not None and d.n != scene.fixed_count:
        raise ConfigError("disks.n", d.n, f"{scene.fixed_count}: the {c.scene} scene has "
                          f"exactly that many disks")
    if d.radius is not None and d.packing_fraction is not None:
        raise ConfigError("disks.radius", d.radius,
                          "give disks.radius or disks.packing_fraction, not both")
    positive("disks.radius", d.radius)
    resolvable(c, "disks.radius", d.radius)
    within("disks.packing_fraction", d.packing_fraction, 1e-12, 0.9,
           "between 0 and 0.9 (hexagonal close packing is 0.9069)")
    if d.radius is None and d.packing_fraction is not None and scene.fixed_count is None:
        area = float(c.box.size[0]) * float(c.box.size[1])
        resolvable(c, "disks.packing_fraction",
                   math.sqrt(d.packing_fraction * area / (d.n * math.pi)), d.packing_fraction)
    positive("disks.mass", d.mass, allow_none=False)
    if d.speed is not None and d.temperature is not None:
        raise ConfigError("disks.speed", d.speed,
                          "give disks.speed or disks.temperature (set the other to null)")
    if d.speed is None and d.temperature is None and scene.gas_like:
        raise ConfigError("disks.speed", None, "a speed, or a temperature in "
                          "disks.temperature: one of the two (both are null)")
    positive("disks.speed", d.speed, zero=True)
    positive("disks.temperature", d.temperature, zero=True)
    if d.placement not in PLACEMENTS and d.placement != "auto":
        raise ConfigError("disks.placement", d.placement, ", ".join(PLACEMENTS) + " or auto")
    if d.placement == "random" and scene.gas_like:
        area = float(c.box.size[0]) * float(c.box.size[1])
        phi = (d.packing_fraction if d.radius is None
               else d.n * math.pi * d.radius**2 / area)
        if phi is not None and phi > RSA_JAMMING:
            raise ConfigError("disks.packing_fraction", round(phi, 4),
                              f"random placement reaches at most φ ≈ {RSA_JAMMING}; use "
                              f"disks.placement=melted or auto")
    check_config(c)  # every effect's keys
    s = c.stop
    for key in ("collisions", "contacts", "time", "wall_seconds"):
        positive(f"stop.{key}", s[key])
    for key in ("collisions", "contacts"):
        if s[key] is not None and s[key] > MAX_COUNT:
            raise ConfigError(f"stop.{key}", s[key], f"at most 2^62 = {MAX_COUNT}")
    within("stop.energy_fraction", s.energy_fraction, 0.0, 1.0, "between 0 and 1")
    if s.at_rest is not None and not 0.0 < s.at_rest <= 1.0:
        raise ConfigError("stop.at_rest", s.at_rest, "a fraction in (0, 1]")
    if s.packing_fraction is not None and not 0.0 < s.packing_fraction < 1.0:
        raise ConfigError("stop.packing_fraction", s.packing_fraction,
                          "a packing fraction in (0, 1) (with growth.rate > 0)")
    if s.packing_fraction is not None and s.packing_fraction > CLOSE_PACKING and one_size(c):
        raise ConfigError("stop.packing_fraction", s.packing_fraction,
                          f"at most π/√12 = {CLOSE_PACKING:.4f}, the densest packing of disks of "
                          f"one size")
    if s.packing_fraction is not None and c.growth.rate == 0.0:
        raise ConfigError("stop.packing_fraction", s.packing_fraction,
                          "null with growth.rate = 0: disks that do not grow keep their "
                          "packing fraction (set growth.rate > 0)")
    if s.jamming is not None and not 1.0 < s.jamming < math.inf:
        raise ConfigError("stop.jamming", s.jamming, "a finite reduced pressure βP/ρ > 1")
    if all(s[k] is None for k in STOP_KEYS):
        raise ConfigError("stop", None, "at least one of "
                          + ", ".join(f"stop.{k}" for k in STOP_KEYS))
    o = c.output
    if not o.file or "/" in o.file or o.file.startswith(".") or not o.file.strip():
        raise ConfigError("output.file", o.file, "a file name in the run folder, such as "
                          "run.h5 (no folders; not starting with a dot)")
    if o.every_collisions is not None and o.every_time is not None:
        raise ConfigError("output.every_collisions", o.every_collisions,
                          "give output.every_collisions or output.every_time, not both")
    positive("output.every_collisions", o.every_collisions)
    if o.every_collisions is not None and o.every_collisions > MAX_COUNT:
        raise ConfigError("output.every_collisions", o.every_collisions,
                          f"at most 2^62 = {MAX_COUNT}")
    positive("output.every_time", o.every_time)
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
    positive("observe.clusters.gap", c.observe.clusters.gap, zero=True)
    cells = c.observe.local_fields.cells
    if cells is not None and cells < 1:
        raise ConfigError("observe.local_fields.cells", cells, "at least 1 cell along x")
    if any(c[section] is None for section in scene.sections):
        raise ConfigError("scene", c.scene, f"the {c.scene} scene needs its "
                          f"{' and '.join(scene.sections)} section"
                          f"{'s' if len(scene.sections) > 1 else ''}")
    scene.check(c)
