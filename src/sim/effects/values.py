"""What a config value may be: :class:`ConfigError`, the limits of the engine's numbers, and
the checks that :func:`sim.pipeline.config.validate`, the effects' (:mod:`sim.effects`) and
the scenes' own checks (:mod:`sim.pipeline.scenes`) share. A leaf below the effects and the
pipeline: it reads a config (an OmegaConf DictConfig or any object with the same attributes)
without importing OmegaConf, so that the engine and the effects load without it."""

import numpy as np

from sim.engine.inputs import RESOLUTION_LIMIT, SCALE_LIMIT

#: Every dimensional number of a scene (a length, speed, mass, time, temperature or
#: acceleration) is 0 or of a magnitude in [SMALLEST, LARGEST], the engine's own range
#: (:data:`sim.engine.inputs.SCALE_LIMIT`): squares and products stay inside float64's.
SMALLEST, LARGEST = 1.0 / SCALE_LIMIT, SCALE_LIMIT

#: Smallest disk radius, as a fraction of the box's longer side (the engine's
#: :data:`sim.engine.inputs.RESOLUTION_LIMIT`, against the far edge of the disks, which the box
#: side bounds): float64 positions resolve 2⁻⁵² of the side, and smaller disks' contacts
#: drown in round-off.
SMALLEST_RADIUS = RESOLUTION_LIMIT

#: Largest seed: the compiled generator of thermal walls keys its draws with an int64.
MAX_SEED = 2**63 - 1
#: Largest number of disks: the engine numbers them with int32.
MAX_DISKS = 2**31 - 1


class ConfigError(ValueError):
    """A config value outside what is allowed."""

    def __init__(self, key, value, allowed):
        self.key, self.value, self.allowed = key, value, allowed
        super().__init__(f"{key}={value!r} is not allowed: {allowed}")

    def __reduce__(self):  # survives the trip back from a sweep's worker process
        return type(self), (self.key, self.value, self.allowed)


def positive(key, value, allow_none=True, zero=False):
    """Refuse a ``value`` that is not > 0 (≥ 0 with ``zero``), or None unless allowed."""
    if value is None:
        if allow_none:
            return
        raise ConfigError(key, value, "a number is required")
    if not (value > 0 or (zero and value == 0)):
        raise ConfigError(key, value, "must be ≥ 0" if zero else "must be > 0")


def within(key, value, low, high, text):
    """Refuse a ``value`` outside [low, high] (None passes); ``text`` says what is allowed."""
    if value is not None and not low <= value <= high:
        raise ConfigError(key, value, text)


def resolvable(c, key, radius, value=None):
    """Refuse a disk radius that float64 positions in this box cannot resolve."""
    side = max(float(x) for x in c.box.size)
    if radius is not None and radius < SMALLEST_RADIUS * side:
        raise ConfigError(key, radius if value is None else value,
                          f"disks of radius at least 2^-40 of the box's longer "
                          f"side ({SMALLEST_RADIUS * side:.3g} here; this gives "
                          f"{radius:.3g}): float64 positions resolve 2^-52 of the side")


def select(c, key):
    """The config value at the dotted ``key`` (``"box.size"``)."""
    for name in key.split("."):
        c = getattr(c, name)
    return c


def plain(value):
    """A config value as plain Python: lists and mappings of a DictConfig (or of a plain
    config) as lists and dicts, for messages and arrays."""
    if isinstance(value, str) or not hasattr(value, "__iter__"):
        return value
    if hasattr(value, "keys"):
        return {k: plain(value[k]) for k in value.keys()}
    return [plain(v) for v in value]


def walled(c, name):
    """Refuse a thermal or moving wall ``walls.<name>`` in a periodic box."""
    if c.box.boundary == "periodic":
        raise ConfigError(f"walls.{name}", plain(c.walls[name]),
                          "thermal or moving walls need box.boundary=walls")


def pair(c, key, allowed):
    """The config list at ``key`` as float64[2, 2], or :class:`ConfigError` naming it."""
    value = plain(select(c, key))
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        array = None
    if array is None or array.shape != (2, 2):
        raise ConfigError(key, value, allowed)
    return array
