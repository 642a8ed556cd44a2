"""The accuracy–cost study (experiments/accuracy_cost/study.py), quick settings: every knob
writes its numbers and figure, and the numbers behave as the physics says.

The knob of the TC time runs inelastic disks between walls with and without the TC model,
compiled loops of their own (tests/variants.py): it, and the study's warm-up of that loop,
run only in ``make validate``. Wall-clock seconds are what the study measures, but never
what a test asserts."""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

STUDY = Path(__file__).parents[1] / "experiments" / "accuracy_cost" / "study.py"
#: the knobs whose loops are the quick suite's
QUICK_KNOBS = ("n_disks", "collisions", "sampling_interval", "equilibration", "crater_dx",
               "crater_stop", "snapshot_cadence")


def load_study():
    spec = importlib.util.spec_from_file_location("accuracy_cost_study", STUDY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run_study(study, out, knobs):
    """The study's knobs ``knobs`` at quick settings into ``out``: each writes its numbers
    and figure; {knob: Dataset}."""
    study.main(["--quick", "--out", str(out), "--knobs", *knobs])
    for name in knobs:
        assert (out / f"{name}.nc").exists() and (out / f"{name}.png").exists()
    assert (out / "pareto.png").exists() and (out / "summary.md").exists()
    datasets = {name: xr.load_dataset(out / f"{name}.nc") for name in knobs}
    for name, ds in datasets.items():
        # every setting has its cost beside its error (its value is the clock's, not checked)
        assert ds["seconds"].sizes["setting"] == ds["setting"].size, name
        assert np.all(np.isfinite(ds["seconds"])), name
    return datasets


def test_quick_study_writes_every_knob_and_behaves(tmp_path, monkeypatch):
    study = load_study()
    assert set(QUICK_KNOBS) == set(study.KNOBS) - {"tc_time"}
    # the warm-up only keeps compilation out of the first setting's seconds, and loads the
    # TC knob's loop too
    monkeypatch.setattr(study, "warm_up", lambda: None)
    knob = run_study(study, tmp_path, QUICK_KNOBS)
    # finite size: every N agrees with Kolafa–Rottner within its 2σ bar plus 0.2 %, and the
    # bar falls as 1/√N (×4 from 64 to 1024 disks); at 64 disks the 2σ bar (about 1 %) hides
    # the finite-size shift, so which of two errors is larger is chance
    n = knob["n_disks"]
    assert np.all(n["error"] < n["error_bar"] + 0.002)
    assert n["error_bar"][0] > 2.5 * n["error_bar"][-1]
    # the statistical error bar of Z falls with the collisions sampled, roughly as 1/√C, once
    # it is estimated from 10 blocks or more (blocks of 10 collisions per disk: C ≥ 100; the
    # scatter of 2 or 5 block means says little about their spread)
    c = knob["collisions"].where(knob["collisions"]["setting"] >= 100, drop=True)
    assert c["setting"].size >= 3
    slope = np.polyfit(np.log(c["setting"]), np.log(c["error_bar"]), 1)[0]
    assert -0.8 < slope < -0.3
    # equal speeds relax: kurtosis 1 (error 0.5) at the start, near 2 after 8 per disk
    e = knob["equilibration"]
    assert e["error"][0] == 0.5 and e["error"][-1] < 0.05
    # snapshots cost bytes: more of them, a bigger file, by a fixed size each (the seconds
    # they cost are measured, and not asserted: they are the clock's)
    s = knob["snapshot_cadence"]
    assert np.all(np.diff(s["snapshots"]) < 0) and np.all(np.diff(s["file_bytes"]) < 0)
    assert s.attrs["bytes_per_snapshot"] > 0
    assert np.isfinite(s.attrs["seconds_per_snapshot"])
    # the crater at rest is its own reference
    assert knob["crater_stop"]["error"][-1] == 0.0


@pytest.mark.slow  # inelastic disks between walls with and without TC: no quick variant
def test_quick_study_of_the_tc_time_behaves(tmp_path):
    """TC: far too short a t_c still collapses, 10⁻³ mean free times does not."""
    tc = run_study(load_study(), tmp_path, ("tc_time",))["tc_time"]
    assert tc["collapsed"].sel(setting=1e-9) == 1 and tc["collapsed"].sel(setting=1e-3) == 0
