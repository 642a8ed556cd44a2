"""Import paths of the flat layout before 0.1.0, and of the run cache and crater runs once in
:mod:`sim.figures`, kept for one release: ``import sim.runner`` still gives
:mod:`sim.pipeline.runner`, with a DeprecationWarning, and ``python -m sim.inspect`` still runs
:mod:`sim.storage.inspect`."""

import sys
import warnings

#: old module → its home now
MOVED = {
    "sim.event_loop": "sim.engine.loop", "sim.event_queue": "sim.engine.queue",
    "sim.neighbours": "sim.engine.neighbours", "sim.state": "sim.engine.state",
    "sim.kinematics": "sim.engine.kinematics", "sim.flight": "sim.engine.flight",
    "sim.collision_rules": "sim.engine.contact", "sim.parameters": "sim.engine.parameters",
    "sim.prefetch": "sim.engine.prefetch", "sim.gravity": "sim.effects.gravity",
    "sim.walls": "sim.effects.walls", "sim.recorders": "sim.effects.event_log",
    "sim.config": "sim.pipeline.config", "sim.scenes": "sim.pipeline.scenes",
    "sim.initial": "sim.pipeline.initial", "sim.runner": "sim.pipeline.runner",
    "sim.cli": "sim.pipeline.cli", "sim.callbacks": "sim.pipeline.callbacks",
    "sim.run_folder": "sim.pipeline.run_folder", "sim.resources": "sim.pipeline.resources",
    "sim.stop_conditions": "sim.pipeline.stop_conditions",
    "sim.command": "sim.pipeline.command", "sim.h5md": "sim.storage.h5md",
    "sim.inspect": "sim.storage.inspect", "sim.export": "sim.storage.export",
    "sim.observers": "sim.analysis.observers", "sim.theory": "sim.analysis.theory",
    "sim.crater": "sim.analysis.crater", "sim.validation": "sim.checks.validation",
    "sim.reference": "sim.checks.reference", "sim.audit": "sim.checks.audit",
    "sim.movie": "sim.figures.movie", "sim.figures.runs": "sim.pipeline.run_cache",
    "sim.figures.crater_runs": "sim.analysis.crater",
}


class MovedModules:
    """A finder for the old paths: importing one gives the module at its new path (the same
    module object, so classes and state are shared); running one with ``python -m`` runs the
    new module's code."""

    @classmethod
    def find_spec(cls, name, path=None, target=None):
        if name not in MOVED:
            return None
        from importlib.machinery import ModuleSpec

        return ModuleSpec(name, cls(MOVED[name]))

    def __init__(self, new):
        self.new = new

    def create_module(self, spec):
        from importlib import import_module

        if spec.name != "__main__":
            warnings.warn(f"{spec.name} is now {self.new}; the old path goes in the next "
                          f"release", DeprecationWarning, stacklevel=2)
        return import_module(self.new)

    def exec_module(self, module):
        pass

    def get_code(self, name):
        """For ``python -m``: the code of the new module, or of its ``__main__`` if it is a
        package."""
        from importlib.util import find_spec

        spec = find_spec(self.new)
        if spec.submodule_search_locations is not None:
            spec = find_spec(f"{self.new}.__main__")
        return spec.loader.get_code(spec.name)


def install():
    if not any(finder is MovedModules for finder in sys.meta_path):
        sys.meta_path.append(MovedModules)
