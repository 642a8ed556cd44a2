"""The engine of a validated config: its scene, restitution, walls and what it observes."""

from omegaconf import OmegaConf

from sim.engine.core import Engine
from sim.pipeline.config import ConfigError
from sim.pipeline.scenes import build_scene

#: rows of the compiled event log between drains (6 float64 each)
EVENT_LOG_ROWS = 1 << 16


def _walls(cfg):
    """The walls that are not plain hard walls, as :class:`sim.engine.core.Engine` takes them."""
    walls = {}
    for name, wall in OmegaConf.to_container(cfg.walls).items():
        if wall["temperature"] is not None or wall["speed"] or wall["amplitude"]:
            walls[name] = wall
    return walls


def build_engine(cfg):
    """Scene and engine for a validated config; bad values raise :class:`ConfigError`."""
    scene = build_scene(cfg)
    restitution = float(cfg.restitution.disk)
    observe = cfg.observe
    try:
        return Engine(scene.position, scene.velocity, scene.radius, scene.mass, scene.species,
                      boundary=scene.boundary, restitution=restitution,
                      wall_restitution=float(cfg.restitution.wall), tc=cfg.tc.time,
                      gravity=list(cfg.gravity), walls=_walls(cfg), seed=int(cfg.seed),
                      unwrap=observe.mean_squared_displacement,
                      pressure_tensor=observe.pressure_tensor,
                      event_log=EVENT_LOG_ROWS if observe.event_log else None)
    except ValueError as error:
        raise ConfigError("scene", cfg.scene, str(error)) from error
