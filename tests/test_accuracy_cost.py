"""The accuracy–cost study (experiments/accuracy_cost/study.py), quick settings: every knob
writes its numbers and figure, and the numbers behave as the physics says."""

import importlib.util
from pathlib import Path

import numpy as np
import xarray as xr

STUDY = Path(__file__).parents[1] / "experiments" / "accuracy_cost" / "study.py"


def load_study():
    spec = importlib.util.spec_from_file_location("accuracy_cost_study", STUDY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_quick_study_writes_every_knob_and_behaves(tmp_path):
    study = load_study()
    study.main(["--quick", "--out", str(tmp_path)])
    for name in study.KNOBS:
        assert (tmp_path / f"{name}.nc").exists() and (tmp_path / f"{name}.png").exists()
    assert (tmp_path / "pareto.png").exists() and (tmp_path / "summary.md").exists()
    knob = {name: xr.open_dataset(tmp_path / f"{name}.nc") for name in study.KNOBS}
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
    # TC: far too short a t_c still collapses, 10⁻³ mean free times does not
    tc = knob["tc_time"]
    assert tc["collapsed"].sel(setting=1e-9) == 1 and tc["collapsed"].sel(setting=1e-3) == 0
    # snapshots cost time and bytes: more of them, bigger file and longer run
    s = knob["snapshot_cadence"]
    assert s["file_bytes"][0] > s["file_bytes"][-1] and s["seconds"][0] > s["seconds"][-1]
    assert s.attrs["seconds_per_snapshot"] > 0 and s.attrs["bytes_per_snapshot"] > 0
    # the crater at rest is its own reference
    assert knob["crater_stop"]["error"][-1] == 0.0
