"""The layout: every old import path (the flat package, the run helpers once in sim.figures)
still leads to its module, with a DeprecationWarning, and ``python -m`` on an old path runs the
new module."""

import importlib
import subprocess
import sys

import pytest

from sim.moved import MOVED


@pytest.mark.parametrize("old", sorted(MOVED))
def test_old_path_gives_the_module_with_a_warning(old):
    sys.modules.pop(old, None)
    with pytest.warns(DeprecationWarning, match=MOVED[old]):
        module = importlib.import_module(old)
    assert module is importlib.import_module(MOVED[old])


@pytest.mark.parametrize("old, command", [("sim.inspect", "sim-inspect"),
                                          ("sim.movie", "sim-movie")])
def test_old_command_path_runs(old, command):
    out = subprocess.run([sys.executable, "-m", old, "--help"], capture_output=True, text=True,
                         check=True)
    assert out.stdout.startswith(f"usage: {command}")
