"""The quick suite's canonical compiled variants (``variants.py``) and the guard of
``conftest.py`` that fails a quick test compiling another."""

import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

import variants
from conftest import gas

TESTS = Path(__file__).parent


def test_a_variant_is_named_by_its_effects_and_what_is_per_disk():
    from sim.engine.loop import run_events

    gas(50, 0.2, periodic=(True, True))  # the gas scene's variant
    gas(50, 0.2, periodic=(True, True), **variants.RECORDER_KEYWORDS)
    named = {variants.describe(s).split("; types")[0] for s in run_events.signatures}
    assert "effects: none; per disk: none" in named
    assert "effects: images, virial_tensor, event_log; per disk: none" in named


def test_the_warm_up_shares_its_compilation_evenly():
    shares = variants.shares(list(variants.CANONICAL), 2)
    assert sorted(name for share in shares for name in share) == sorted(variants.CANONICAL)
    assert max(map(len, shares)) - min(map(len, shares)) <= 1
    assert variants.shares(["gas"], 4) == [["gas"]]


@pytest.mark.slow  # it compiles a variant outside the canonical set, as it must
def test_a_quick_test_that_compiles_another_variant_fails_naming_it(tmp_path):
    for name in ("conftest.py", "variants.py"):
        shutil.copy(TESTS / name, tmp_path)
    (tmp_path / "test_exotic.py").write_text(textwrap.dedent("""
        from conftest import gas


        def test_gravity_alone():
            gas(20, 0.1, gravity=[0.0, -1.0]).run(collisions=10)
        """))
    done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                           "-m", "not slow", "test_exotic.py"], cwd=tmp_path,
                          capture_output=True, text=True, timeout=1800)
    assert done.returncode == 1, done.stdout[-3000:]
    assert "1 passed, 1 error" in done.stdout
    assert "outside the canonical set" in done.stdout
    assert "effects: gravity; per disk: none" in done.stdout
