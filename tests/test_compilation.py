"""Each variant of a compiled function compiled under its own lock, once across processes
(sim.engine.compilation)."""

import json
import os
import subprocess
import sys
import textwrap

import pytest
from numba import njit, types

from sim.engine import compilation


def test_a_variant_not_held_is_compiled_under_a_lock_of_its_own(tmp_path, monkeypatch):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path))
    held = []
    real = compilation._held
    monkeypatch.setattr(compilation, "_held", lambda path: held.append(path) or real(path))
    add_one = njit(lambda x: x + 1)
    compilation.compile_once(add_one, (1.0,))
    assert add_one.signatures == [(types.float64,)] and len(held) == 1
    assert held[0].startswith(str(tmp_path)) and os.path.exists(held[0])
    compilation.compile_once(add_one, (2.5,))  # held already: no lock, nothing compiled
    assert len(held) == 1 and len(add_one.signatures) == 1
    compilation.compile_once(add_one, (1,))  # another variant: another lock
    assert add_one.signatures[-1] == (types.int64,)
    assert len(held) == 2 and held[0] != held[1]


def test_a_lock_that_cannot_be_made_is_passed_over(tmp_path):
    (tmp_path / "a_file").write_text("")
    entered = False
    with compilation._held(str(tmp_path / "a_file" / "x.lock")):
        entered = True
    assert entered


def test_the_cache_saves_its_entries_under_a_lock():
    from numba.core import caching

    assert caching.IndexDataCacheFile.save.__wrapped__ is not None


@pytest.mark.slow  # each process compiles the helpers, one of them the gas scene's loop
def test_processes_starting_together_on_a_cold_cache_compile_a_variant_once(tmp_path):
    script = textwrap.dedent("""
        import json
        from sim.engine import Boundary, Engine
        from sim.engine.loop import run_events
        from sim.pipeline.initial import hexagonal_lattice

        position = hexagonal_lattice(100, 0.01)
        Engine(position, [[1.0, 0.0]] * 100, 0.01, boundary=Boundary()).run(collisions=100)
        print(json.dumps(sum(run_events.stats.cache_misses.values())))
        """)
    environment = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    processes = [subprocess.Popen([sys.executable, "-c", script], env=environment,
                                  stdout=subprocess.PIPE, text=True) for _ in range(2)]
    compiled = [json.loads(p.communicate(timeout=1800)[0]) for p in processes]
    assert sorted(compiled) == [0, 1]
