"""What the small commands (``sim-movie``, ``sim-export``) share: usage errors as one line,
and :func:`run_command`, which turns their errors and signals into one line on stderr and an
exit status: 0 done, 2 bad input, 1 an output that could not be written, 128 + n after
signal n (SIGTERM ends a command as Ctrl-C does, so that it cleans up the same way)."""

import argparse
import signal
import sys


class BadInput(ValueError):
    """Input the command cannot take, said in one line: exit status 2."""


class CannotWrite(OSError):
    """An output that could not be written, nothing of it left behind: exit status 1."""


class Parser(argparse.ArgumentParser):
    """Usage errors as :class:`BadInput`: one line, not the usage and a message."""

    def error(self, message):
        raise BadInput(message)


def interrupt(signum, frame):
    """Signal handler: a KeyboardInterrupt carrying the signal's number."""
    raise KeyboardInterrupt(signum)


def _say(prog, message):
    print(f"{prog}: {' '.join(str(message).split())}", file=sys.stderr, flush=True)


def run_command(prog, body, bad_input=(), unwritten="nothing written"):
    """Run ``body()`` as the command ``prog``; returns its exit status. Exceptions of
    :class:`BadInput` or ``bad_input`` are status 2, :class:`CannotWrite` status 1, a signal
    128 + its number with a line saying ``unwritten``."""
    previous = signal.signal(signal.SIGTERM, interrupt)
    try:
        body()
    except (BadInput, *bad_input) as error:
        _say(prog, error)
        return 2
    except CannotWrite as error:
        _say(prog, error)
        return 1
    except KeyboardInterrupt as error:
        signum = error.args[0] if error.args else signal.SIGINT
        _say(prog, f"{'terminated' if signum == signal.SIGTERM else 'interrupted'}; "
                   f"{unwritten}")
        return 128 + signum
    finally:
        signal.signal(signal.SIGTERM, previous)
    return 0
