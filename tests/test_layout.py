"""The layout: the engine and the effects stand below the pipeline, and every old import path
(the flat package, the run helpers once in sim.figures) still leads to its module, with a
DeprecationWarning, and ``python -m`` on an old path runs the new module."""

import importlib
import pkgutil
import subprocess
import sys
import warnings

import sim.effects
import sim.engine
from sim.moved import MOVED

#: what the engine and the effects must not load: the config machinery and the layers above
ABOVE = ("omegaconf", "hydra", "sim.pipeline", "sim.storage", "sim.analysis", "sim.checks",
         "sim.figures")


def test_the_engine_and_the_effects_load_nothing_above_them():
    modules = [m.name for package in (sim.engine, sim.effects)
               for m in pkgutil.iter_modules(package.__path__, package.__name__ + ".")]
    code = ("import sys\n" + "".join(f"import {m}\n" for m in modules)
            + f"print(sorted(k for k in sys.modules if k.startswith({ABOVE!r})))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert len(modules) > 20 and out.stdout.strip() == "[]", out.stdout


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
