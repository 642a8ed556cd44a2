"""One registry of scenes: every scene in :data:`sim.pipeline.scenes.SCENES` has its scenario
file, its schema sections, its builder, preparation, checks and disk count, and composes and
builds; no scenario file names a scene the registry lacks."""

from pathlib import Path

import numpy as np
import pytest
import yaml
from omegaconf import OmegaConf

from sim.pipeline import resources
from sim.pipeline.cli import CONF_DIR
from sim.pipeline.config import ConfigError, validate
from sim.pipeline.config_reference import scene_sections
from sim.pipeline.scenes import BUILDERS, PREPARATIONS, SCENES, SceneSpec, build_scene, preparation
from variants import compose_scene

SCENARIO_DIR = Path(CONF_DIR, "scenario")
#: scenario file name → the scene it names
SCENARIO_SCENES = {path.stem: yaml.safe_load(path.read_text())["scene"]
                   for path in sorted(SCENARIO_DIR.glob("*.yaml"))}


def test_every_scenario_file_names_a_registered_scene():
    unknown = {stem: scene for stem, scene in SCENARIO_SCENES.items() if scene not in SCENES}
    assert not unknown, f"scenario files naming scenes outside the registry: {unknown}"


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_scene_has_its_scenario_file(name):
    path = SCENARIO_DIR / f"{name}.yaml"
    assert path.exists(), f"no {path}"
    assert SCENARIO_SCENES[name] == name, f"{path} names the scene {SCENARIO_SCENES[name]!r}"


def test_builders_and_preparations_are_those_of_the_registry():
    assert list(BUILDERS) == list(SCENES) == list(PREPARATIONS)
    for name, scene in SCENES.items():
        assert scene.name == name
        assert BUILDERS[name] is scene.builder and PREPARATIONS[name] is scene.preparation
        assert callable(scene.check)
        assert callable(scene.disk_count) and callable(scene.packing_fraction)


def test_a_scene_without_its_disk_count_is_refused():
    with pytest.raises(TypeError, match="disk_count"):
        SceneSpec("nosuch", SCENES["gas"].builder)


def test_a_stored_scene_outside_the_registry_counts_disks_n():
    """A stored config is not validated: its scene may be unknown to the registry."""
    cfg = compose_scene("crater", "scene=nosuch")
    assert resources.disk_count(cfg) == (cfg.disks.n, "disks.n")


def test_the_schema_sections_are_those_the_scenes_need():
    claimed = {section for scene in SCENES.values() for section in scene.sections}
    assert claimed == set(scene_sections())


def test_an_unregistered_scene_is_refused_with_every_registered_one_named():
    with pytest.raises(ConfigError) as refused:
        validate(compose_scene("gas", "scene=nosuch"))
    assert refused.value.key == "scene"
    assert all(name in refused.value.allowed for name in SCENES)


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_scene_composes_validates_and_builds(name):
    cfg = compose_scene(name)
    validate(cfg)
    assert cfg.scene == name
    assert preparation(cfg)
    built = build_scene(cfg)
    n = built.radius.size
    assert built.position.shape == built.velocity.shape == (n, 2)
    assert built.mass.shape == built.species.shape == (n,) and n >= 1
    assert np.isfinite(built.position).all() and np.isfinite(built.velocity).all()
    scene = SCENES[name]
    if scene.fixed_count is not None:
        assert n == scene.fixed_count
    if scene.gas_like:
        assert n == cfg.disks.n
    count, key = scene.disk_count(cfg)
    assert count == n and resources.disk_count(cfg) == (count, key)
    assert 0.0 < scene.packing_fraction(cfg, n) <= 0.9
    if scene.fixed_count is None:  # the key sets the count
        more = compose_scene(name, f"{key}={OmegaConf.select(cfg, key) + 1}")
        assert scene.disk_count(more) == (n + 1, key)


@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_scene_is_validated_by_its_own_entry(name):
    """The registry's checks are the ones validate applies: its sections are required, its
    disk count is held, and a gas refuses a random placement past jamming."""
    scene = SCENES[name]
    for section in scene.sections:
        with pytest.raises(ConfigError, match=section) as refused:
            validate(compose_scene(name, f"{section}=null"))
        assert refused.value.key == "scene"
    if scene.fixed_count is not None:
        with pytest.raises(ConfigError) as refused:
            validate(compose_scene(name, f"disks.n={scene.fixed_count + 1}"))
        assert refused.value.key == "disks.n"
    if scene.gas_like:
        with pytest.raises(ConfigError) as refused:
            validate(compose_scene(name, "disks.placement=random", "disks.radius=null",
                                   "disks.packing_fraction=0.6"))
        assert refused.value.key == "disks.packing_fraction"

