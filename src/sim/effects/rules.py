"""Compiled rules that depend on whether an effect is on.

An effect the scene does not use reaches the compiled loop as None. Each place where an
effect acts is a *rule*: a function whose first argument is the effect's value, written twice
— the rule with the effect and the rule without it — and joined by :func:`effect_rule`. numba
picks one of the two by the type of the first argument while it compiles, and inlines it, so
the loop of a scene without the effect holds none of its code. This works wherever the value
comes from — an argument, or a field of the :class:`sim.effects.Effects` tuple the loop takes
— where ``if value is None`` inside compiled code would only be pruned for arguments.
"""

import functools
import inspect

from numba import types
from numba.extending import overload


def effect_rule(absent):
    """Decorator: the decorated function is the rule when its first argument (the effect's
    value) is given, ``absent`` (same signature) the rule when it is None. Returns the rule
    that chooses between them, in compiled code as in Python."""

    def join(present):
        @functools.wraps(present)
        def rule(value, *rest):
            return (absent if value is None else present)(value, *rest)

        def choose(value, *rest):
            return absent if value is types.none else present

        choose.__signature__ = inspect.signature(present)  # numba checks it against the rules'
        overload(rule, inline="always")(choose)
        return rule

    return join
