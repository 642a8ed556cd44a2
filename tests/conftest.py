"""Shared, seeded state factories, the overlap audit every dynamics test ends with, the
validation table the slow studies fill, and the compiled variants of the quick suite
(``variants.py``): compiled before the tests start, and none other compiled by a quick test."""

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

import variants
from sim.checks.audit import outside_box, overlapping_pairs
from sim.checks.rows import table
from sim.engine import Boundary, Engine
from sim.engine.box import nearest_images
from sim.pipeline.initial import (
    fixed_speed,
    hexagonal_lattice,
    radius_for_packing,
    random_sequential,
)

#: Tests never depend on the clock: no example has a deadline (the first example of a test
#: compiles numba code, and a loaded machine runs anything slowly). The quick suite draws
#: few examples where each builds and runs an engine (:func:`engine_examples`); ``make
#: validate`` loads the profile ``validate`` (``--hypothesis-profile=validate``) and draws
#: them all.
QUICK_EXAMPLES = 8
settings.register_profile("quick", deadline=None)
settings.register_profile("validate", deadline=None, max_examples=200)
settings.load_profile("quick")


def engine_examples(full):
    """Hypothesis settings of a test whose examples build and run an engine: ``full``
    examples under the profile ``validate``, at most :data:`QUICK_EXAMPLES` otherwise."""
    validating = settings.default.max_examples == settings.get_profile("validate").max_examples
    return settings(max_examples=full if validating else min(full, QUICK_EXAMPLES))


def gas(n, phi, periodic=(False, False), seed=0, speed=1.0, **engine_options):
    """An engine with n equal disks at packing fraction phi in the unit box, equal speeds."""
    radius = radius_for_packing(n, phi)
    if phi <= 0.4:
        position = random_sequential(np.full(n, radius), periodic=periodic, seed=seed)
    else:
        position = hexagonal_lattice(n, radius, periodic=periodic, seed=seed)
    velocity = fixed_speed(n, speed, seed=seed + 1)
    return Engine(position, velocity, radius, boundary=Boundary(periodic=periodic),
                  **engine_options)


def distances(engine):
    """Every distance between two disks float64[n, n] at the engine's current time, through
    the nearest periodic image (user order)."""
    position = engine.positions()
    r = nearest_images(position[:, None, :] - position[None, :, :], engine.box, engine.periodic)
    return np.hypot(r[..., 0], r[..., 1])


def assert_no_overlap(engine, tolerance=1e-9):
    """Independent all-pairs audit (k-d tree) at the engine's current time."""
    position = engine.positions()
    pairs, overlap = overlapping_pairs(position, engine.radii(), engine.box, engine.periodic,
                                       tolerance)
    assert pairs.size == 0, f"overlapping pairs {pairs[:5].tolist()}, overlaps {overlap[:5]}"
    escaped = outside_box(position, engine.radii(), engine.box, engine.periodic, tolerance,
                          engine.wall_positions())
    assert escaped.size == 0, f"disks outside the box: {escaped[:5].tolist()}"


@pytest.fixture
def make_gas():
    return gas


VALIDATION_TABLE = Path("outputs") / "validation" / "table.md"
_validation_rows = []


@pytest.fixture
def validation_rows():
    """Rows of the validation table (sim.checks.validation.Check), collected over the session."""
    return _validation_rows


def pytest_terminal_summary(terminalreporter):
    """Say what compiling the canonical variants took; write and show the validation table
    when validation studies ran."""
    warm = terminalreporter.config.stash.get(WARM_KEY, None)
    if warm is not None:
        terminalreporter.write_line("canonical variants of the event loop: {} compiled or "
                                    "loaded in {} processes in {:.0f} s".format(*warm))
    outside = terminalreporter.config.stash.get(OUTSIDE_KEY, [])
    if outside:
        terminalreporter.write_sep("=", "variants compiled outside the canonical set "
                                        "(tests/variants.py), by a subprocess or a test", red=True)
        for line in outside:
            terminalreporter.write_line(line)
    if not _validation_rows:
        return
    VALIDATION_TABLE.parent.mkdir(parents=True, exist_ok=True)
    text = table(_validation_rows)
    VALIDATION_TABLE.write_text(text)
    terminalreporter.write_sep("=", f"validation table ({VALIDATION_TABLE})")
    terminalreporter.write(text)


# ---------------------------------------------------------------------------------------
# the compiled variants of the quick suite (variants.py)


#: the signatures of the canonical variants (text); how many, in how many processes, seconds
CANONICAL_KEY = pytest.StashKey[set]()
WARM_KEY = pytest.StashKey[tuple]()
#: the signatures in the numba cache once the canonical ones are; those that came after,
#: outside the canonical set
CACHED_KEY = pytest.StashKey[set]()
OUTSIDE_KEY = pytest.StashKey[list]()


def pytest_sessionstart(session):
    """Before the workers start (pytest-xdist starts them after this hook): compile the
    canonical variants into the numba cache, in as many processes as there are workers, so
    that no two workers compile one variant and none waits on another's compilation. With a
    warm cache this takes seconds (each process loads them)."""
    config = session.config
    if hasattr(config, "workerinput"):
        config.stash[CANONICAL_KEY] = set(json.loads(config.workerinput["canonical"]))
        return
    if config.option.collectonly:
        config.stash[CANONICAL_KEY] = set()
        return
    processes = max(1, int(getattr(config.option, "numprocesses", None) or 1))
    started = time.perf_counter()
    warming = [subprocess.Popen([sys.executable, str(Path(variants.__file__)), *names],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
               for names in variants.shares(list(variants.CANONICAL), processes)]
    made = {}
    for process in warming:
        out, err = process.communicate()
        if process.returncode != 0:
            raise pytest.UsageError(f"compiling the canonical variants failed:\n{err}")
        made.update(json.loads(out))
    config.stash[CANONICAL_KEY] = {s for signatures in made.values() for s in signatures}
    config.stash[WARM_KEY] = (len(config.stash[CANONICAL_KEY]), len(warming),
                              time.perf_counter() - started)
    config.stash[CACHED_KEY] = set(variants.cached())


def pytest_sessionfinish(session):
    """The quick suite's subprocesses (``python -m sim``, sweeps) compile out of the tests'
    sight: a variant that entered the numba cache during the session and is not canonical
    fails the session, named in the summary."""
    config = session.config
    if (hasattr(config, "workerinput") or CACHED_KEY not in config.stash
            or config.option.markexpr != "not slow"):
        return
    cached = variants.cached()
    outside = cached.keys() - config.stash[CACHED_KEY] - config.stash[CANONICAL_KEY]
    if outside:
        config.stash[OUTSIDE_KEY] = sorted(variants.describe(cached[s]) for s in outside)
        session.exitstatus = pytest.ExitCode.TESTS_FAILED


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node):
    """pytest-xdist: hand each worker the canonical signatures."""
    node.workerinput["canonical"] = json.dumps(sorted(node.config.stash[CANONICAL_KEY]))


#: variants outside the canonical set that this process has compiled and that were reported
#: (or compiled by a slow test, which may)
_SEEN_OUTSIDE = set()


@pytest.fixture(autouse=True)
def compiles_only_canonical_variants(request):
    """A quick test may use only the canonical variants of the event loop: the first test
    after which this process holds another (compiled by the test or by a fixture it uses)
    fails, naming it. A slow test may compile any."""
    yield
    compiled = variants.compiled()
    outside = compiled.keys() - request.config.stash[CANONICAL_KEY] - _SEEN_OUTSIDE
    _SEEN_OUTSIDE.update(outside)
    if not outside or request.node.get_closest_marker("slow"):
        return
    pytest.fail("compiled a variant of run_events outside the canonical set "
                "(tests/variants.py); use a canonical scene or mark the test slow:\n"
                + "\n".join(variants.describe(compiled[s]) for s in sorted(outside)),
                pytrace=False)
