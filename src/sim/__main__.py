"""``python -m sim`` and the ``sim`` command: the command line of :mod:`sim.pipeline.cli`, imported
inside a guard, so that Ctrl-C or SIGTERM while the engine and Hydra load ends with one line.
``-h``/``--help`` prints the reference of every scenario and key
(:mod:`sim.pipeline.config_reference`) without loading either; ``--hydra-help`` is Hydra's."""

import os  # os and sys are loaded with the interpreter: importing them costs nothing
import sys

from sim.pipeline.leaving import caused_by_a_signal, leave

#: the signal that arrived while the command line was loading (2: SIGINT, 15: SIGTERM)
_ARRIVED = [2]
#: the flags that print the reference of every scenario and key
HELP = ("-h", "--help")


def _stop(signum, frame):
    _ARRIVED.append(signum)
    raise KeyboardInterrupt


def _help():
    """Print the reference of every scenario and key (:mod:`sim.pipeline.config_reference`)."""
    from sim.pipeline.config_reference import text

    try:
        print(text(), flush=True)
    except BrokenPipeError:  # a reader that stopped early (| head): the rest is not wanted
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())


def main():
    try:
        import signal

        signal.signal(signal.SIGTERM, _stop)
        if any(arg in HELP for arg in sys.argv[1:]):
            return _help()
        from sim.pipeline.cli import main as command_line
    except BaseException as error:
        if not caused_by_a_signal(error):
            raise
        how = "terminated" if _ARRIVED[-1] == 15 else "interrupted"
        leave(f"sim: {how} while starting; nothing was written", 128 + _ARRIVED[-1])
    try:
        command_line()
    finally:  # the command is over: a late Ctrl-C must not break the exit with a traceback
        signal.signal(signal.SIGINT, signal.SIG_IGN)


if __name__ == "__main__":
    main()
