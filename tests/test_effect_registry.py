"""One list of effects (sim.effects.EFFECTS): every effect module is in it, and every entry
has its module with the protocol (KEYWORDS, check_config, engine_arguments, loop_values), its
fields of the loop's Effects, its config keys (exactly those it reads, all in
conf/config.yaml), its validation and its cost rows."""

import ast
import importlib.util
import inspect
import re
from pathlib import Path

import numpy as np
import pytest
from omegaconf import OmegaConf
from omegaconf.errors import ConfigAttributeError, ConfigKeyError

import sim.effects
from sim.checks.validation import STUDIES
from sim.effects import EFFECTS, Effects, engine_keywords
from sim.engine import Engine
from sim.pipeline.config import flat
from sim.pipeline.overrides import CONF_DIR
from variants import compose_scene

EFFECT_MODULES = sorted(p.stem for p in Path(sim.effects.__file__).parent.glob("*.py")
                        if p.stem not in ("__init__", "rules", "values"))  # helpers
TESTS = Path(__file__).parent
PROTOCOL = ("check_config", "engine_arguments", "loop_values")

#: every effect on, so that each reads all of its keys (the pressure tensor aside: it is
#: refused with rough disks, and its switch is read either way)
EVERY_EFFECT_ON = ("restitution.disk=0.9", "restitution.wall=0.9", "tc.time=1e-6",
                   "gravity=[0,-1]", "walls.bottom.amplitude=0.01", "walls.bottom.frequency=10",
                   "walls.left.temperature=1", "observe.mean_squared_displacement=true",
                   "observe.event_log=true",
                   "restitution.tangential=0.5", "restitution.wall_tangential=0.5",
                   "friction.mu=0.3", "friction.wall_mu=0.3", "disks.inertia_factor=0.4",
                   "disks.rotational_temperature=1", "potential.steps=[1.5]",
                   "potential.energies=[-1]")

#: sections of conf/config.yaml that the pipeline owns and effects may read too
PIPELINE_SECTIONS = {"seed", "box", "observe", "disks"}


def _cost_rows():
    spec = importlib.util.spec_from_file_location(
        "effects_cost", TESTS.parent / "benchmarks" / "effects_cost.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.EFFECTS


def _config_keys():
    """Dotted keys of conf/config.yaml (lists whole), Hydra's own aside."""
    cfg = OmegaConf.load(Path(CONF_DIR) / "config.yaml")
    for key in ("defaults", "hydra"):
        cfg.pop(key)
    return set(flat(cfg))


def _only(cfg, keys):
    """The config with only ``keys``, in struct mode: reading any other key fails."""
    sub = OmegaConf.create({})
    for key in keys:
        OmegaConf.update(sub, key, OmegaConf.select(cfg, key))
    OmegaConf.set_struct(sub, True)
    return sub


def test_every_effect_module_is_registered_once():
    assert sorted(effect.name for effect in EFFECTS) == EFFECT_MODULES


def test_the_loop_takes_every_field_of_every_effect_once():
    fields = [field for effect in EFFECTS for field in effect.fields]
    assert len(fields) == len(set(fields))
    assert Effects._fields == tuple(fields)


@pytest.mark.parametrize("effect", EFFECTS, ids=lambda e: e.name)
def test_effect_has_module_protocol_config_validation_and_cost(effect):
    module = effect.module
    assert module.__doc__, f"sim.effects.{effect.name} says what the effect is"
    for name in PROTOCOL:
        assert callable(getattr(module, name, None)), f"sim.effects.{effect.name}.{name}"
        assert getattr(module, name).__doc__, f"sim.effects.{effect.name}.{name} docstring"
    assert isinstance(module.KEYWORDS, dict)
    assert all(isinstance(meaning, str) and meaning for _, meaning in module.KEYWORDS.values())
    assert set(effect.config) <= _config_keys(), set(effect.config) - _config_keys()
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


@pytest.mark.parametrize("effect", EFFECTS, ids=lambda e: e.name)
def test_effect_reads_exactly_its_config_keys(effect):
    """check_config and engine_arguments work on the effect's keys alone, and each of them
    is needed."""
    cfg = compose_scene("gas", *EVERY_EFFECT_ON)
    module = effect.module
    module.check_config(_only(cfg, effect.config))
    assert module.engine_arguments(_only(cfg, effect.config)) == module.engine_arguments(cfg)
    for key in effect.config:
        sub = _only(cfg, [other for other in effect.config if other != key])
        with pytest.raises((ConfigAttributeError, ConfigKeyError)):
            module.check_config(sub)
            module.engine_arguments(sub)


def test_every_key_of_an_effect_section_belongs_to_an_effect():
    """conf/config.yaml has no key in an effect's section that no effect reads."""
    declared = {key for effect in EFFECTS for key in effect.config}
    sections = {key.split(".")[0] for key in declared} - PIPELINE_SECTIONS
    in_sections = {key for key in _config_keys() if key.split(".")[0] in sections}
    assert in_sections == {key for key in declared if key.split(".")[0] in sections}


def test_engine_arguments_are_engine_keywords():
    cfg = compose_scene("gas")
    for effect in EFFECTS:
        assert set(effect.module.engine_arguments(cfg)) <= set(effect.module.KEYWORDS)


def test_loop_values_fill_exactly_the_effects_fields():
    keywords = {keyword: default for keyword, (default, _) in engine_keywords().items()}
    context = {"n": 2, "n_species": 1, "box": np.ones(2), "periodic": np.zeros(2, dtype=bool),
               "radius": np.full(2, 0.1), "mass": np.ones(2), "initial_energy": 1.0}
    for effect in EFFECTS:
        values = effect.module.loop_values(keywords, context)
        # and an effect's system event (sim.effects docstring), none with these defaults
        assert values.pop("system_event", None) is None, effect.name
        assert values.pop("pair_interaction", None) is None, effect.name
        assert tuple(values) == effect.fields, effect.name
        context.update(values)


def test_engine_documents_every_keyword_it_takes():
    documented = set()
    for names in re.findall(r"^    (\w+(?:, \w+)*) :", Engine.__doc__, flags=re.MULTILINE):
        documented.update(names.split(", "))
    parameters = inspect.signature(Engine).parameters
    own = {name for name, p in parameters.items() if p.kind != p.VAR_KEYWORD}
    assert documented == own | set(engine_keywords())
    assert not own & set(engine_keywords())


def test_engine_refuses_an_unknown_keyword():
    with pytest.raises(TypeError, match="unexpected keyword arguments \\['restitutoin'\\]"):
        Engine([[0.5, 0.5]], [[1.0, 0.0]], 0.1, restitutoin=0.9)
