"""One list of effects (sim.effects.EFFECTS): every effect module is in it, and every entry
has its module, its fields of the loop's Effects, its config keys, its validation and its
cost rows."""

import ast
import importlib
import importlib.util
from pathlib import Path

import pytest
from omegaconf import OmegaConf

import sim.effects
from sim.checks.validation import STUDIES
from sim.effects import EFFECTS, Effects
from test_pipeline import compose_scene

EFFECT_MODULES = sorted(p.stem for p in Path(sim.effects.__file__).parent.glob("*.py")
                        if p.stem not in ("__init__", "rules"))
TESTS = Path(__file__).parent


def _cost_rows():
    spec = importlib.util.spec_from_file_location(
        "effects_cost", TESTS.parent / "benchmarks" / "effects_cost.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.EFFECTS


def test_every_effect_module_is_registered_once():
    assert sorted(effect.name for effect in EFFECTS) == EFFECT_MODULES


def test_the_loop_takes_every_field_of_every_effect_once():
    fields = [field for effect in EFFECTS for field in effect.fields]
    assert len(fields) == len(set(fields))
    assert Effects._fields == tuple(fields)


@pytest.mark.parametrize("effect", EFFECTS, ids=lambda e: e.name)
def test_effect_has_module_config_validation_and_cost(effect):
    module = importlib.import_module(f"sim.effects.{effect.name}")
    assert module.__doc__, f"sim.effects.{effect.name} says what the effect is"
    cfg = compose_scene("gas")
    for key in effect.config:
        assert OmegaConf.select(cfg, key, default="missing") != "missing", key
    assert effect.validation
    for check in effect.validation:
        if "::" in check:
            file, name = check.split("::")
            tree = ast.parse((TESTS / file).read_text())
            assert name in {node.name for node in tree.body
                            if isinstance(node, ast.FunctionDef)}, check
        else:
            assert check in STUDIES, check
    rows = _cost_rows()
    assert effect.cost and all(row in rows for row in effect.cost), effect.cost
