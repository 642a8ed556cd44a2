"""One word, one meaning: a *contact* is a disk touching a disk (a *collision*) or a wall (a
*wall contact*); an *event* is what the loop applies, a contact or a neighbour-shell exit
(:mod:`sim.engine.codes`). The names these words replaced in 0.1.0 are gone; a run file of
0.1.0, whose config still holds the old stop key (null) and whose checkpoints name the
staleness stamps as collision counts, resumes to the same bits, and one of an older sim is
refused in one line."""

import h5py
import numpy as np
import pytest
import yaml

from sim.analysis.datasets import open_run
from sim.engine import Engine
from sim.engine.checkpoint import RENAMED_ARRAYS
from sim.pipeline import runner
from sim.pipeline.config import ConfigError, register
from sim.pipeline.initial import fixed_speed, radius_for_packing, random_sequential
from sim.pipeline.overrides import compose_overrides
from sim.pipeline.resume import resume
from sim.storage.inspect import summary

register()


@pytest.fixture(scope="module")
def gas():
    n = 200
    radius = radius_for_packing(n, 0.3)
    engine = Engine(random_sequential(np.full(n, radius), seed=1), fixed_speed(n, 1.0, seed=2),
                    radius)
    engine.run(contacts=3000)
    return engine


def test_contacts_are_collisions_and_wall_contacts_and_events_are_more(gas):
    assert gas.wall_contacts > 0 and gas.collisions > 0
    assert gas.contacts == gas.collisions + gas.wall_contacts == 3000
    assert gas.events > gas.contacts  # shell exits are events, not contacts
    assert gas.contacts_by_disk().sum() == 2 * gas.collisions + gas.wall_contacts


@pytest.mark.parametrize("old", ["steps", "wall_collisions", "collisions_by_disk"])
def test_the_names_before_the_renaming_are_gone(gas, old):
    assert not hasattr(gas, old)


@pytest.mark.parametrize("stop", ["contacts", "collisions", "events"])
def test_each_count_stops_a_run_exactly(stop):
    n = 100
    radius = radius_for_packing(n, 0.4)
    engine = Engine(random_sequential(np.full(n, radius), seed=3), fixed_speed(n, 1.0, seed=4),
                    radius)
    target = getattr(engine, stop) + 1234
    assert engine.run(**{stop: target}, chunk_events=500) == stop
    assert getattr(engine, stop) == target


def _stored_stop(path, **stop):
    """Set keys of the stop section of the config stored in the run file at ``path``."""
    with h5py.File(path, "r+") as f:
        parameters = f["parameters"].attrs
        config = yaml.safe_load(str(parameters["config"]))
        config["stop"].update(stop)
        parameters["config"] = yaml.safe_dump(config)


def _checkpoints_of_0_1_0(path):
    """Lay out the checkpoints of the run file at ``path`` as sim 0.1.0 did: the staleness
    stamps under their old names, and no counted stamps or system-event slot."""
    with h5py.File(path, "r+") as f:
        for slot in f["checkpoint"].values():
            for old, new in RENAMED_ARRAYS.items():
                slot.move(new, old)
            for name in ("disks/counted", "disks/system_time"):
                del slot[name]


def test_a_run_file_of_version_0_1_0_resumes_to_the_same_bits(tmp_path):
    overrides = ["scenario=single_disk", "output.progress=false"]
    whole = runner.run(compose_overrides([*overrides, "stop.contacts=300"]), tmp_path / "whole")
    path = runner.run(compose_overrides([*overrides, "stop.contacts=200"]), tmp_path / "part")
    _stored_stop(path, events=None)  # 0.1.0 stored the renamed key, null
    _checkpoints_of_0_1_0(path)
    resume(path, ["stop.contacts=300"])
    with open_run(path) as resumed, open_run(whole) as ds:
        np.testing.assert_array_equal(resumed["position"].values[-1], ds["position"].values[-1])
        assert int(resumed["wall_contacts"].values[-1]) == 300
    assert summary(path)["stop_reason"] == "contacts"


def test_a_run_file_of_an_older_sim_is_refused_in_one_line(tmp_path):
    path = runner.run(compose_overrides(["scenario=single_disk", "stop.contacts=50",
                                         "output.progress=false"]), tmp_path)
    _stored_stop(path, events=50, contacts=None)
    with pytest.raises(ConfigError, match=r"stop.events=50, the name before 0.1.0"):
        resume(path, ["stop.contacts=80"])
