"""The compiled variants of the event loop that the quick suite may use, compiled once per run.

numba compiles :func:`sim.engine.loop.run_events` anew for every combination of argument
types: every effect on or off (:class:`sim.effects.Effects`), mass, species and shell radius
shared or per disk, list capacities shared or per disk. Each combination costs about 20 s of
compilation and almost nothing to run, so the quick suite keeps to a canonical set:
:data:`CANONICAL`, the variants that the shipped scenes compile (but crater_gravity's crater
under gravity, :data:`SLOW_SCENARIOS`), and one with every observer on. Before the tests
start, ``conftest.py`` compiles them into the numba cache in as many processes as there are
workers (``python tests/variants.py NAME ...``), and every quick test fails that compiles a
variant outside the set, naming it (:func:`describe`).

Budget: a new effect or interaction adds at most one canonical variant (its scene); a test
that needs another combination is ``slow``.

The canonical variants in :class:`sim.engine.Engine` terms (the box's walls or periodic
sides, the values of the effects and of the disks do not change the variant; N does only
through the look-ahead of states larger than the caches, from
:data:`sim.engine.sizing.LOOKAHEAD_MIN_DISKS` disks on, which a test may switch on for fewer;
every disk alike means one mass, one species and one radius):

================  ==============================================================================
gas               no effect, every disk alike
mixture           no effect, masses and species per disk (radii may differ too)
cooling           ``restitution`` < 1 and ``tc`` > 0; every disk alike
driven            ``restitution`` < 1 and a thermal wall (``walls={...: {"temperature": T}}``)
vibrated_bed      ``restitution``, ``wall_restitution`` < 1, ``tc``, ``gravity`` and a moving or
                  vibrating wall
crater            ``restitution``, ``wall_restitution``, ``tc``; masses and species per disk and
                  one disk far larger than the rest (list capacities per disk)
settling_bed      ``restitution``, ``wall_restitution``, ``tc`` and ``gravity``, every disk alike
rough_cooling     ``restitution``, ``tangential_restitution`` (rough, no friction) and ``tc``
observers         ``unwrap``, ``pressure_tensor`` and ``event_log``, every disk alike
compress          ``growth`` (and its system event, the rescaling); radii and species per disk
square_well       a stepped pair potential (``potential_steps``), every disk alike; its
                  shoulder twin too
gas_lookahead     gas, looking ahead (the crater's variant looking ahead is ``slow``)
================  ==============================================================================
"""

import json
import sys
from pathlib import Path

from hydra import compose, initialize_config_dir

from sim.pipeline.config import register
from sim.pipeline.overrides import CONF_DIR

register()
SCENARIOS = sorted(p.stem for p in Path(CONF_DIR, "scenario").glob("*.yaml"))

#: overrides that make a scene small enough for a quick test (same compiled variant)
SHRINK = {"gas": ["disks.n=300"], "mixture": ["disks.n=300"], "cooling": ["disks.n=300"],
          "square_well": ["disks.n=300"], "square_shoulder": ["disks.n=300"],
          "compress": ["disks.n=300"],
          "driven": ["disks.n=300"], "vibrated_bed": ["bed.n=100"],
          "crater": ["bed.n=400", "projectile.radius=0.02"],
          "crater_gravity": ["bed.n=300", "bed.radius=0.012", "bed.settle_time=0.5"]}

#: every recorder of the loop on (unwrapped positions, pressure tensor, event log), as config
#: overrides and as Engine keywords: a test of any of them shares the loop of the others
RECORDERS = ("observe.mean_squared_displacement=true", "observe.pressure_tensor=true",
             "observe.event_log=true")
RECORDER_KEYWORDS = {"unwrap": True, "pressure_tensor": True, "event_log": 1000}
#: the recorders on a periodic gas
OBSERVERS = ("box.boundary=periodic", *RECORDERS)
#: a thermal top wall that disks moving along y = 0.5 never reach: with it, inelastic disks
#: without the TC model run the driven scene's loop, and nothing else changes
UNREACHED_THERMAL_WALL = {"top": {"temperature": 1.0}}

#: shipped scenes whose runs are slow: crater_gravity settles its bed (a canonical variant,
#: ``settling_bed``) and then compiles the crater under gravity, for what crater and
#: vibrated_bed check quickly
SLOW_SCENARIOS = ("crater_gravity",)
#: name → (scene, overrides) of the variants the quick suite compiles: the shipped scenes
#: but :data:`SLOW_SCENARIOS` (single_disk, two_disks and scattering compile one of these;
#: the tests that run every scene check it), crater_gravity's bed settling (inelastic disks
#: alike under gravity with the TC model: disks at rest on a still floor) and a gas with every
#: recorder on
CANONICAL = {**{scene: (scene,) for scene in ("gas", "mixture", "compress", "driven",
                                               "vibrated_bed", "crater", "rough_cooling",
                                               "cooling")},
             "settling_bed": ("gas", "gravity=[0,-1]", "restitution.disk=0.9",
                              "restitution.wall=0.9", "tc.time=1e-4"),
             "square_well": ("square_well",),
             "observers": ("gas", *OBSERVERS),
             "gas_lookahead": ("gas",)}
#: the canonical variants that look ahead (``Engine.lookahead``), whatever their N
LOOKAHEAD = ("gas_lookahead",)


def compose_scene(name, *overrides):
    """The config of the shipped scene ``name``, made small (:data:`SHRINK`), with
    ``overrides``; the progress bar off."""
    with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
        return compose("config", overrides=[f"scenario={name}", *SHRINK.get(name, []),
                                            "output.progress=false", *overrides])


def compiled():
    """{text: signature} of ``run_events`` as this process has compiled or loaded it."""
    loop = sys.modules.get("sim.engine.loop")
    return {} if loop is None else {str(s): s for s in loop.run_events.signatures}


def cached():
    """{text: signature} of ``run_events`` in the numba cache: what every process of the
    session compiled, subprocesses of ``python -m sim`` included. (numba keeps them in one
    index per function, keyed by (signature, target, code hash).)"""
    from sim.engine.loop import run_events

    return {str(key[0]): key[0] for key in run_events._cache._cache_file._load_index()}


def describe(signature):
    """A signature of ``run_events`` in words: the effects on, and what is per disk."""
    from numba import types

    def named(group):
        return dict(zip(group.fields, group.types, strict=True))

    disks, neighbours, effects = (named(signature[k]) for k in (0, 2, 4))
    ahead = "" if signature[7] == types.none else "; looking ahead"
    pair = "" if signature[5] == types.none else f"; pair interaction {signature[5]}"
    per_disk = [name for name in ("delta", "mass", "species")
                if isinstance(disks[name], types.Array)]
    if isinstance(neighbours["nb_cap"], types.Array):
        per_disk.append("list capacity")
    on = [name for name, kind in effects.items() if kind != types.none and name != "seed"]
    return (f"effects: {', '.join(on) or 'none'}; per disk: {', '.join(per_disk) or 'none'}"
            f"{ahead}{pair}; types: {signature}")


def warm(names):
    """Compile the canonical variants ``names`` (into the numba cache); {name: [signature]}."""
    from sim.pipeline.runner import build_engine

    made = {}
    for name in names:
        before = compiled().keys()
        scene, *overrides = CANONICAL[name]
        engine = build_engine(compose_scene(scene, *overrides))
        engine.lookahead = name in LOOKAHEAD
        engine.run(contacts=200)
        made[name] = sorted(compiled().keys() - before)
    return made


def shares(names, processes):
    """``names`` dealt into ``processes`` lists of about equal length (one variant each). The
    order of :data:`CANONICAL` balances two processes (compress, whose disks grow, and
    square_well are the slowest variants; the seconds of each process from an empty cache are
    in ``docs/performance-history.md``, the quick suite's compilation)."""
    return [names[k::processes] for k in range(min(processes, len(names)))]


def scenario_params():
    """:data:`SCENARIOS` as pytest parameters, those of :data:`SLOW_SCENARIOS` marked slow."""
    import pytest

    return [pytest.param(name, marks=pytest.mark.slow) if name in SLOW_SCENARIOS else name
            for name in SCENARIOS]


if __name__ == "__main__":
    print(json.dumps(warm(sys.argv[1:])))
