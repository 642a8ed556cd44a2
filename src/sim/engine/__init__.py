"""The compiled core: the state of the disks, the event queue, the neighbour lists, the
kinematics of free flight and contact, and the event loop that ties them together
(:mod:`sim.engine.loop`); :class:`Engine` drives it from Python.

``Engine``, ``Boundary`` and the errors a run can end with are importable from here; they are
looked up on first use, so that the compiled modules can import one another without loading
the engine's Python side.
"""

_PUBLIC = {"Engine": "sim.engine.core", "Boundary": "sim.engine.inputs",
           "PhysicsBreakdown": "sim.engine.errors", "StalledError": "sim.engine.errors",
           "ClosedBoxError": "sim.engine.errors", "InelasticCollapseError": "sim.engine.errors"}

__all__ = sorted(_PUBLIC)


def __getattr__(name):
    if name not in _PUBLIC:
        raise AttributeError(f"module 'sim.engine' has no attribute {name!r}")
    from importlib import import_module

    return getattr(import_module(_PUBLIC[name]), name)
