"""How the command line leaves: at once with one line (:func:`leave`), and whether an error
came of a signal (:func:`caused_by_a_signal`). A leaf that loads nothing but ``os`` and
``sys``, so that ``python -m sim`` (:mod:`sim.__main__`) has it before the engine and Hydra
load."""

import os
import sys


def caused_by_a_signal(error):
    """Whether a KeyboardInterrupt is ``error`` or its cause (Python wraps one raised while
    a class is being made, e.g. in ``__set_name__``)."""
    while error is not None:
        if isinstance(error, KeyboardInterrupt):
            return True
        error = error.__cause__ or error.__context__
    return False


def leave(message, status):
    """Print ``message`` and end the process with ``status`` at once. After a Ctrl-C that
    landed in code run by ``exec`` (dataclasses make their methods so), CPython would end
    an orderly exit by killing itself with SIGINT instead; nothing is left to clean up."""
    print(message, file=sys.stderr, flush=True)
    sys.stdout.flush()
    os._exit(status)
