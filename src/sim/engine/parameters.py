"""Per-disk parameters that a scene may give every disk alike.

Mass, species and neighbour-shell radius are per-disk arrays in the engine's state, but most
scenes give every disk the same value. The compiled loop then takes the number instead of the
array (:func:`common_value`), reads it through :func:`per_disk`, and numba compiles a variant
that never loads the array: a scene pays for polydispersity only when it has some.

Arrays that only some scenes need (a pair interaction's reaches, states and event names) are
None in the others, and the compiled code reads and writes them through
:func:`optional_entry` and :func:`set_optional_entry`, which compile to nothing for None.
"""

import numpy as np
from numba import types
from numba.extending import overload


def per_disk(values, i):
    """The value of a per-disk parameter for disk i inside compiled code: ``values[i]`` for an
    array, ``values`` itself for a number shared by every disk.

    A scene whose disks share a mass (or a shell radius, or a species) passes the number, and
    the compiled loop never loads the array: numba compiles the variant for the type it gets.
    """
    return values[i] if isinstance(values, np.ndarray) else values


@overload(per_disk, inline="always")
def _per_disk(values, i):
    if isinstance(values, types.Array):
        return lambda values, i: values[i]
    return lambda values, i: values


def optional_entry(values, k, default):
    """``values[k]``, or ``default`` when ``values`` is None (an array the scene does not
    need); inside compiled code numba picks one by the type."""
    return default if values is None else values[k]


@overload(optional_entry, inline="always")
def _optional_entry(values, k, default):
    if values is types.none:
        return lambda values, k, default: default
    return lambda values, k, default: values[k]


def set_optional_entry(values, k, value):
    """``values[k] = value``, unless ``values`` is None (an array the scene does not need)."""
    if values is not None:
        values[k] = value


@overload(set_optional_entry, inline="always")
def _set_optional_entry(values, k, value):
    if values is types.none:
        return lambda values, k, value: None

    def set_entry(values, k, value):
        values[k] = value
    return set_entry


def common_value(values):
    """The value every entry of the per-disk array ``values`` shares, as a Python number, or
    None when they differ. The engine passes that number to the compiled loop instead of the
    array (see :func:`per_disk`)."""
    if values.size and np.all(values == values.flat[0]):
        return values.flat[0].item()
    return None
