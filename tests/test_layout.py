"""The layout: no import circle among sim's modules, the engine and the effects below the
pipeline, and no long positional argument lists."""

import ast
import pkgutil
import subprocess
import sys
from pathlib import Path

import sim
import sim.effects
import sim.engine

SOURCE = Path(sim.__file__).parent

#: the most positional arguments a function of sim takes: more go in a named group
#: (sim.engine.groups) or a tuple of what belongs together
MOST_POSITIONAL = 12

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


def imports_among_modules():
    """sim's modules and, for each, the modules of sim it imports anywhere in its source (a
    name imported from a module counts as that module, or as the submodule of that name)."""
    modules = {}
    for path in SOURCE.rglob("*.py"):
        parts = ("sim", *path.relative_to(SOURCE).with_suffix("").parts)
        modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    graph = {name: set() for name in modules}
    for name, path in modules.items():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                graph[name] |= {a.name for a in node.names if a.name in modules}
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                for alias in node.names:
                    full = f"{node.module}.{alias.name}"
                    target = full if full in modules else node.module
                    if target in modules:
                        graph[name].add(target)
    return graph


def test_no_module_of_sim_imports_itself_back():
    graph = imports_among_modules()
    circles = []
    for start in graph:  # a path from a module back to itself, by depth-first search
        stack, seen = [(start, (start,))], set()
        while stack:
            name, path = stack.pop()
            for imported in graph[name]:
                if imported == start:
                    circles.append(" → ".join((*path, start)))
                elif imported not in seen:
                    seen.add(imported)
                    stack.append((imported, (*path, imported)))
    assert len(graph) > 100 and not circles, circles


def test_no_function_takes_more_than_twelve_positional_arguments():
    long_lists = []
    for path in SOURCE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                count = len(node.args.posonlyargs) + len(node.args.args)
                if count > MOST_POSITIONAL:
                    long_lists.append(f"{path.relative_to(SOURCE)}: {node.name} takes {count}")
    assert not long_lists, long_lists
