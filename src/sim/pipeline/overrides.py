"""The command line's overrides: integers written as ``2e6`` made whole, a sweep expanded into
its jobs, configs composed from the package's ``conf/``, and the value of one key read or
replaced."""

import functools
import itertools
import math
import re
from collections import OrderedDict

from hydra import compose, initialize_config_dir
from hydra.core.override_parser.overrides_parser import OverridesParser
from omegaconf import OmegaConf

from sim.pipeline.cli_exits import fail, first_line
from sim.pipeline.config import integer_keys
from sim.pipeline.schema import CONF_DIR

INTEGER_KEYS = frozenset(integer_keys())
SWEEP_FLAGS = ("-m", "--multirun")


_FLOAT = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")


def whole_numbers(args):
    """The command line with numbers written as ``2e6`` or ``1000.0`` given to integer keys
    (``stop.collisions=2e6``) written as integers; a sweep's comma list item by item."""
    out = []
    for arg in args:
        key, equals, value = arg.partition("=")
        if equals and key.lstrip("+~") in INTEGER_KEYS:
            items = [_integer(item.strip()) if _FLOAT.fullmatch(item.strip()) else item
                     for item in value.split(",")]
            arg = f"{key}={','.join(items)}"
        out.append(arg)
    return out


def _integer(text):
    value = float(text)
    if math.isfinite(value) and value == int(value) and not re.fullmatch(r"[+-]?\d+", text):
        return str(int(value))
    return text


def hydra_arguments(args):
    """The command line read by Hydra's own parser (an ``argparse`` namespace: its flags, and
    ``overrides``). A flag it does not know, abbreviated or missing its value is one line,
    exit 2, where argparse would print Hydra's usage text; so are Hydra's flags that choose
    other configs or replay a job, and ``hydra.mode`` (the sweep flag sets it)."""
    from hydra._internal.utils import get_args_parser  # the parser ``hydra.main`` reads with

    parser = get_args_parser()
    parser.allow_abbrev = False  # --multi would be a sweep to Hydra, not to the checks here

    def refuse(message):
        fail(f"{message}: python -m sim takes KEY=VALUE overrides, -m (or --multirun) for a "
             f"sweep, --help, and Hydra's flags (--hydra-help lists them)")

    parser.error = refuse
    known = parser.parse_intermixed_args(args)  # overrides before, between or after flags
    commands = [flag for flag, given in (("--run", known.run), ("--multirun", known.multirun),
                                         ("--cfg", known.cfg), ("--info", known.info),
                                         ("--shell-completion", known.shell_completion))
                if given]
    if len(commands) > 1:  # Hydra's own check, a ValueError traceback there
        refuse(f"{' and '.join(commands)} together; only one of them may be given")
    if known.resolve and not known.cfg:  # Hydra's own check, a ValueError traceback there
        refuse("--resolve without --cfg; it resolves what --cfg prints")
    for flag, given in (("--package", known.package),
                        ("--config-path", known.config_path),
                        ("--config-name", known.config_name),
                        ("--config-dir", known.config_dir),
                        ("--experimental-rerun", known.experimental_rerun),
                        ("--shell-completion", known.shell_completion)):
        if given:
            fail(f"{flag} is not taken by python -m sim: its configs are the package's conf/, "
                 f"a scene is chosen with scenario=NAME and a run continued with "
                 f"resume=RUN_FILE")
    if any(item.partition("=")[0].lstrip("+~") == "hydra.mode" for item in known.overrides):
        fail("hydra.mode is not set on the command line: -m (or --multirun) makes a sweep")
    return known


def prints_only(args):
    """Whether the command line asks Hydra to print something (``--cfg``, ``--info``,
    ``--hydra-help``) instead of running."""
    known = hydra_arguments(args)
    return bool(known.cfg or known.info or known.hydra_help)


def combinations(args):
    """Every job the command line asks for, as lists of overrides, in the order and numbering
    of Hydra's basic sweeper (a repeated key: the last one counts)."""
    overrides = hydra_arguments(args).overrides
    try:
        parsed = OverridesParser.create().parse_overrides(overrides)
    except Exception as error:
        fail(_unreadable(overrides, error))
    choices = OrderedDict()
    for o in parsed:
        key = o.get_key_element()
        if o.is_sweep_override():
            choices[key] = [f"{key}={v}" for v in o.sweep_string_iterator()]
        else:
            choices[key] = [f"{key}={o.get_value_element_as_str()}"]
    return [list(c) for c in itertools.product(*choices.values())]


def _unreadable(overrides, error):
    """The first of ``overrides`` that Hydra's grammar cannot read, in one line naming its key
    (a long value cut short), and why."""
    parser = OverridesParser.create()
    for override in overrides:
        try:
            parser.parse_override(override)
        except Exception as failure:
            key, equals, value = override.partition("=")
            shown = value if len(value) <= 40 else f"{value[:20]}… ({len(value)} characters)"
            reason = str(failure).strip().splitlines()[0] if str(failure).strip() else ""
            if "Exceeds the limit" in reason:  # Python's cap on the digits of an int
                return f"{key}={shown} is not allowed: a number, not one of {len(value)} digits"
            if not equals:  # a word cut from the value before it by a space
                at = overrides.index(override)
                before = f" after {overrides[at - 1]}" if at else ""
                return (f"{override!r}{before} is not allowed: an override is KEY=VALUE; a "
                        f"value with spaces is quoted whole, 'KEY=a value' (the shell splits "
                        f"it at the space)")
            return (f"{key}={shown} is not allowed: a value Hydra's override grammar reads "
                    f"({reason or first_line(failure)}); quote one with brackets, commas or "
                    f"spaces as text, '{key}=\"…\"', or write a list [a,b] or a sweep a,b")
    return first_line(error)


def compose_overrides(combination, hydra_config=False):
    """The config of ``combination`` (with Hydra's own node when ``hydra_config``)."""
    with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
        return compose("config", overrides=list(combination), return_hydra_config=hydra_config)


def hydra_settings(args):
    """The config composed with Hydra's own node, from the command line's ``hydra…``
    overrides (its folders, launcher, subdir); read-only, composed once per process for the
    same overrides (each composition takes about 0.2 s of a run's start)."""
    return _hydra_settings(tuple(a for a in args if a.lstrip("+~").startswith("hydra")))


@functools.cache
def _hydra_settings(hydra_overrides):
    settings = compose_overrides(hydra_overrides, hydra_config=True)
    OmegaConf.set_readonly(settings, True)
    return settings


def task_overrides(combination):
    """``combination`` without its ``hydra…`` overrides."""
    return [c for c in combination if not c.lstrip("+~").startswith("hydra")]


def value_of(args, key):
    """The value the command line gives ``key`` (the last, as Hydra takes it), unquoted by
    Hydra's own grammar, or None."""
    items = [a for a in args if a.partition("=")[0] == key]
    if not items:
        return None
    value = OverridesParser.create().parse_override(items[-1]).value()
    return None if value is None else str(value)


def _quoted(text):
    """``text`` as a value of Hydra's override grammar."""
    if re.fullmatch(r"[\w./:+-]+", text):
        return text
    return "'" + text.replace("'", "\\'") + "'"


def flags_last(args):
    """The command line with its overrides first and its flags after them, in their order:
    Hydra's parser takes the overrides as one run of words at the start, which a flag between
    or before them would cut (``-m seed=0,1``, ``--cfg job seed=3``)."""
    overrides = hydra_arguments(args).overrides
    flags = list(args)
    for item in overrides:
        flags.remove(item)
    return [*overrides, *flags]


def with_value(args, key, value):
    """The command line with ``key=value`` in place of what it gave ``key``, first (Hydra
    takes overrides before its flags, such as -m)."""
    return [f"{key}={_quoted(str(value))}", *(a for a in args if a.partition("=")[0] != key)]
