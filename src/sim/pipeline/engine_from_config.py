"""The engine of a validated config: its scene, and the keywords of every effect
(:func:`sim.effects.engine_arguments`)."""

from sim.effects import check_scene, engine_arguments
from sim.engine.core import Engine
from sim.pipeline.config import ConfigError
from sim.pipeline.scenes import build_scene


def build_engine(cfg):
    """Scene and engine for a validated config; bad values raise :class:`ConfigError`."""
    scene = build_scene(cfg)
    check_scene(cfg, scene)
    try:
        return Engine(scene.position, scene.velocity, scene.radius, scene.mass, scene.species,
                      boundary=scene.boundary, **engine_arguments(cfg))
    except ValueError as error:
        raise ConfigError("scene", cfg.scene, str(error)) from error
