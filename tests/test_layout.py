"""The layout: every old import path (the flat package, the run helpers once in sim.figures)
still leads to its module, with a DeprecationWarning, and ``python -m`` on an old path runs the
new module."""

import importlib
import subprocess
import sys
import warnings

from sim.moved import MOVED


def test_every_old_path_gives_the_module_with_a_warning():
    wrong = []
    for old, new in sorted(MOVED.items()):
        sys.modules.pop(old, None)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            module = importlib.import_module(old)
        warned = [w for w in caught if issubclass(w.category, DeprecationWarning)
                  and new in str(w.message)]
        if module is not importlib.import_module(new) or not warned:
            wrong.append(old)
    assert not wrong, f"old paths that do not lead to their module with a warning: {wrong}"


def test_an_old_command_path_runs():
    out = subprocess.run([sys.executable, "-m", "sim.inspect", "--help"], capture_output=True,
                         text=True, check=True)
    assert out.stdout.startswith("usage: sim-inspect")
