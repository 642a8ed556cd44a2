"""One word, one meaning: a *contact* is a disk touching a disk (a *collision*) or a wall (a
*wall contact*); an *event* is what the loop applies, a contact or a neighbour-shell exit
(:mod:`sim.engine.codes`). The names these words replaced still work for one release, with a
warning, and run files written before the renaming still open and resume."""

import h5py
import numpy as np
import pytest
import yaml

from sim.analysis.datasets import open_run
from sim.engine import Engine
from sim.pipeline import runner
from sim.pipeline.config import register, renamed_keys
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


@pytest.mark.parametrize("old, new", [("steps", "events"), ("wall_collisions", "wall_contacts")])
def test_old_engine_names_warn_and_read_the_new(gas, old, new):
    with pytest.warns(DeprecationWarning, match=f"Engine.{old} is now Engine.{new}"):
        assert getattr(gas, old) == getattr(gas, new)


def test_collisions_by_disk_is_contacts_by_disk(gas):
    with pytest.warns(DeprecationWarning, match="contacts_by_disk"):
        np.testing.assert_array_equal(gas.collisions_by_disk(), gas.contacts_by_disk())


@pytest.mark.parametrize("stop", ["contacts", "collisions", "events"])
def test_each_count_stops_a_run_exactly(stop):
    n = 100
    radius = radius_for_packing(n, 0.4)
    engine = Engine(random_sequential(np.full(n, radius), seed=3), fixed_speed(n, 1.0, seed=4),
                    radius)
    target = getattr(engine, stop) + 1234
    assert engine.run(**{stop: target}, chunk_events=500) == stop
    assert getattr(engine, stop) == target


def test_the_old_stop_key_warns_and_sets_the_new():
    with pytest.warns(FutureWarning, match=r"stop.events=70 is now called stop.contacts=70"):
        cfg = compose_overrides(["scenario=single_disk", "stop.events=70"])
    assert (cfg.stop.contacts, cfg.stop.events) == (70, None)


def _as_written_before_the_renaming(path):
    """Give the run file at ``path`` the names a run file had before the renaming."""
    with h5py.File(path, "r+") as f:
        f["observables"].move("wall_contacts", "wall_collisions")
        parameters = f["parameters"].attrs
        config = yaml.safe_load(str(parameters["config"]))
        config["stop"]["events"] = config["stop"].pop("contacts")
        parameters["config"] = yaml.safe_dump(config)
        parameters["stop_reason"] = "events"


def test_a_run_file_from_before_the_renaming_opens_and_resumes(tmp_path):
    cfg = compose_overrides(["scenario=single_disk", "stop.contacts=200",
                             "output.progress=false"])
    path = runner.run(cfg, tmp_path)
    with open_run(path) as ds:
        written = ds["wall_contacts"].values.copy()
    _as_written_before_the_renaming(path)
    with open_run(path) as ds:
        np.testing.assert_array_equal(ds["wall_contacts"].values, written)
    assert resume(path) == path  # complete as it was: nothing to do, nothing written
    assert summary(path)["stop_reason"] == "events"
    resume(path, ["stop.contacts=300"])
    with h5py.File(path, "r") as f:
        assert "wall_contacts" in f["observables"] and "wall_collisions" not in f["observables"]
        assert f["observables/wall_contacts/value"][-1] == 300
        config = yaml.safe_load(str(f["parameters"].attrs["config"]))
    assert (config["stop"]["contacts"], config["stop"]["events"]) == (300, None)
    assert summary(path)["stop_reason"] == "contacts"


def test_renamed_keys_leave_a_config_with_new_names_alone():
    cfg = compose_overrides(["scenario=single_disk"])
    before = cfg.copy()
    assert renamed_keys(cfg) == before
