"""The pipeline: every scenario composes and runs, the run file has the H5MD layout, resume
continues to the same bits, sweeps run. Bad values and their one-line refusals are
``test_hostile.py``'s."""

import math
import subprocess
import sys

import h5py
import numpy as np
import pytest
import yaml

from sim.analysis.datasets import open_run, open_sweep
from sim.pipeline import runner
from sim.pipeline.config import ConfigError
from sim.pipeline.overrides import value_of
from sim.storage.errors import RunFileError
from sim.storage.h5md import RunWriter
from sim.storage.inspect import summary
from variants import OBSERVERS, compose_scene, scenario_params


@pytest.mark.parametrize("name", scenario_params())
def test_every_scenario_runs_and_writes_h5md(name, tmp_path):
    cfg = compose_scene(name, "stop.collisions=300", "stop.contacts=1000",
                        "output.every_collisions=null", "output.every_time=2.0")
    path = runner.run(cfg, tmp_path)
    with h5py.File(path, "r") as f:
        assert list(f["h5md"].attrs["version"]) == [1, 1]
        assert f["h5md/creator"].attrs["name"] == "sim"
        box = f["particles/disks/box"]
        assert box.attrs["dimension"] == 2 and box["edges"].shape == (2,)
        n = f["particles/disks/radius"].shape[0]
        for element in ("position", "velocity"):
            g = f[f"particles/disks/{element}"]
            frames = g["step"].shape[0]
            assert frames >= 2 and g["time"].shape == (frames,)
            assert g["value"].shape == (frames, n, 2)
        for name_ in ("kinetic_energy", "kinetic_energy_by_species", "collisions",
                      "wall_contacts", "dissipated_energy", "collision_virial"):
            assert f[f"observables/{name_}/value"].shape[0] == frames
        assert f["parameters"].attrs["stop_reason"] in ("collisions", "contacts", "time",
                                                        "energy_fraction", "no_events")
        assert "scene: " + cfg.scene in f["parameters"].attrs["config"]
        observables = {name_: f[f"observables/{name_}/value"][()] for name_ in
                       ("kinetic_energy", "potential_energy", "dissipated_energy", "wall_work")}
        rotational = (f["observables/rotational_energy/value"][()]
                      if "rotational_energy" in f["observables"] else 0.0)
    info = summary(path)
    assert info["n"] == n and info["snapshots"] == frames
    if cfg.growth.rate > 0.0:  # growth pumps energy in and its rescaling takes it out
        assert info["energy_drift"] is None
        return
    # kinetic (translational and rotational) + potential + dissipated − work of the walls
    # stays what it was
    balance = (observables["kinetic_energy"] + rotational + observables["potential_energy"]
               + observables["dissipated_energy"] - observables["wall_work"])
    scale = max(observables["kinetic_energy"].max(), abs(observables["wall_work"]).max())
    np.testing.assert_allclose(balance, balance[0], rtol=0, atol=1e-10 * scale)
    assert info["energy_drift"] <= 1e-10


def interrupted_at_the_fourth_snapshot(cfg, folder, monkeypatch, checkpoint_every_snapshot):
    """Run ``cfg`` into ``folder`` until a KeyboardInterrupt at its fourth snapshot; with
    ``checkpoint_every_snapshot`` false only the first snapshot checkpoints and nothing is
    flushed before the interrupt. Returns the run file."""
    original = RunWriter.snapshot
    calls = {"n": 0}

    def interrupted(self, engine, time=None, checkpoint=False):
        if not checkpoint_every_snapshot:
            self.checkpoint_seconds = self.flush_seconds = 1e9
        original(self, engine, time, checkpoint or checkpoint_every_snapshot)
        calls["n"] += 1
        if calls["n"] == 4:
            raise KeyboardInterrupt

    folder.mkdir()
    monkeypatch.setattr(RunWriter, "snapshot", interrupted)
    with pytest.raises(KeyboardInterrupt):
        runner.run(cfg, folder)
    monkeypatch.setattr(RunWriter, "snapshot", original)
    return folder / "run.h5"


#: scenes resumed in the tests: a cooling gas, a gas driven by thermal walls (the walls'
#: random numbers), and a periodic gas that logs every contact and observes unwrapped
#: displacements and the pressure tensor
RESUMED = {
    "gas": ("gas", "restitution.disk=0.9", "tc.time=1e-7"),
    "driven": ("driven",),
    "observers": ("gas", *OBSERVERS, "observe.velocity_autocorrelation=true"),
}
RESUMED_KEYS = ("particles/disks/position/value", "particles/disks/velocity/value",
                "particles/disks/position/time", "observables/collisions/value",
                "observables/dissipated_energy/value", "observables/wall_work/value")
OBSERVER_KEYS = ("events/contacts", "observables/mean_squared_displacement/value",
               "observables/collision_virial_tensor/value")


@pytest.mark.parametrize("scene", sorted(RESUMED))
def test_resume_continues_to_the_same_bits(scene, tmp_path, monkeypatch):
    cfg = compose_scene(*RESUMED[scene], "stop.collisions=6000", "output.every_collisions=1000")
    (tmp_path / "whole").mkdir()
    whole = runner.run(cfg, tmp_path / "whole")
    cut = interrupted_at_the_fourth_snapshot(cfg, tmp_path / "cut", monkeypatch, True)
    assert summary(cut)["snapshots"] == 4
    runner.resume(cut)
    with h5py.File(whole, "r") as a, h5py.File(cut, "r") as b:
        for key in RESUMED_KEYS + (OBSERVER_KEYS if scene == "observers" else ()):
            np.testing.assert_array_equal(a[key][()], b[key][()], err_msg=key)
        assert b["parameters"].attrs["stop_reason"] == "collisions"


@pytest.mark.parametrize("scene", sorted(RESUMED))
def test_frames_buffered_after_a_checkpoint_are_cut_and_made_again(scene, tmp_path,
                                                                   monkeypatch):
    cfg = compose_scene(*RESUMED[scene], "stop.collisions=6000", "output.every_collisions=1000")
    (tmp_path / "whole").mkdir()
    whole = runner.run(cfg, tmp_path / "whole")
    cut = interrupted_at_the_fourth_snapshot(cfg, tmp_path / "cut", monkeypatch, False)
    with h5py.File(cut, "r") as f:  # the error path wrote the buffered frames
        assert f["particles/disks/position/value"].shape[0] == 4
        assert f["checkpoint"][f["checkpoint"].attrs["latest"]].attrs["snapshots"] == 1
    with pytest.warns(RuntimeWarning, match="the 3 snapshots written after it"):
        runner.resume(cut)
    with h5py.File(whole, "r") as a, h5py.File(cut, "r") as b:
        for key in ("particles/disks/position/value", "observables/collisions/value",
                    *(OBSERVER_KEYS if scene == "observers" else ())):
            np.testing.assert_array_equal(a[key][()], b[key][()], err_msg=key)


def run_cli(*args, cwd):
    return subprocess.run([sys.executable, "-m", "sim", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=600)


def test_the_sweep_command_writes_two_run_files(tmp_path):
    # the command of the README, shrunk by overrides placed before its -m
    result = run_cli("scenario=crater", "projectile.radius=0.01,0.02", "bed.n=300",
                     "stop.collisions=2000", f"hydra.sweep.dir={tmp_path}/sweep", "-m",
                     cwd=tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]
    files = sorted(tmp_path.rglob("run.h5"))
    assert len(files) == 2
    radii = sorted(float(h5py.File(f, "r")["particles/disks/radius"][-1]) for f in files)
    assert radii == [0.01, 0.02]
    sweep = open_sweep(tmp_path / "sweep")
    assert sweep["projectile_radius"].values.tolist() == [0.01, 0.02]
    assert sweep["position"].dims == ("projectile_radius", "snapshot", "disk", "axis")
    np.testing.assert_array_equal(sweep["radius"].isel(disk=-1), [0.01, 0.02])
    assert (sweep["collisions"].max("snapshot") > 0).all()
    configs = [yaml.safe_load(c) for c in sweep["config"].values]
    assert [c["projectile"]["radius"] for c in configs] == [0.01, 0.02]


def test_snapshots_in_time_lie_on_their_grid_and_end_once(tmp_path):
    """Snapshot times are k Δt, not sums of Δt: a hundred steps of 0.4 end at stop.time = 40
    with one snapshot there, none a round-off before it."""
    path = runner.run(compose_scene("gas", "stop.collisions=null", "stop.time=40",
                                    "output.every_collisions=null", "output.every_time=0.4",
                                    "disks.n=50", "disks.speed=0.01"), tmp_path)
    with open_run(path) as ds:
        time = ds["time"].values
    np.testing.assert_array_equal(time, np.arange(101) * 0.4)


def test_inspect_names_the_boundary_and_the_observables(tmp_path):
    path = runner.run(compose_scene("gas", "stop.collisions=500", "walls.bottom.temperature=2",
                                    "restitution.disk=0.9", "observe.clusters.gap=0.1"),
                      tmp_path)
    info = summary(path)
    assert info["boundary"] == ["walls", "walls"]
    assert info["walls"] == "bottom thermal at T = 2"
    assert {"clusters", "kinetic_energy", "collisions"} <= set(info["observables"])


@pytest.mark.parametrize("form", [[], ["--json"]])
def test_inspect_into_a_pipe_its_reader_closed_is_quiet(form, tmp_path):
    """``sim-inspect run.h5 | head -1``: the reader gone, the rest is dropped without a
    traceback. The read end is closed before the command has imported what it needs."""
    path = runner.run(compose_scene("gas", "stop.collisions=500"), tmp_path)
    with subprocess.Popen([sys.executable, "-m", "sim.storage.inspect", str(path), *form],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) as process:
        process.stdout.close()
        err = process.stderr.read()
        assert process.wait(timeout=300) == 0 and err == ""


def test_open_sweep_pads_shorter_runs_and_keeps_counters_integer(tmp_path):
    for k, collisions in enumerate((1500, 3000)):
        overrides = [f"stop.collisions={collisions}"]
        runner.run(compose_scene("gas", *overrides, "output.every_collisions=500"),
                   tmp_path / "sweep" / str(k), overrides=overrides)
    sweep = open_sweep(tmp_path / "sweep")
    assert sweep.attrs["swept"] == ["stop_collisions"]
    collisions = sweep["collisions"]
    assert collisions.dtype.kind == "i"
    np.testing.assert_array_equal(collisions.sel(stop_collisions=1500)[-3:], [-1, -1, -1])
    assert collisions.sel(stop_collisions=3000).values[-1] == 3000
    assert np.isnan(sweep["kinetic_energy"].sel(stop_collisions=1500)[-1])


def test_at_rest_stops_once_every_species_has_lost_its_energy(tmp_path):
    path = runner.run(compose_scene("crater", "stop.energy_fraction=null", "stop.at_rest=0.3",
                                    "stop.collisions=10000000"), tmp_path)
    with open_run(path) as ds:
        assert ds.attrs["stop_reason"] == "at_rest"
        by_species = ds["kinetic_energy_by_species"].values
        initial = ds["kinetic_energy"].values[0]
        assert np.all(by_species[-1] < 0.3 * initial)
        assert np.any(by_species[-2] >= 0.3 * initial)  # and not a snapshot later


def test_open_run_is_lazy_and_labelled(tmp_path):
    path = runner.run(compose_scene("mixture", "stop.collisions=3000",
                                    "output.every_collisions=500"), tmp_path)
    with open_run(path) as ds:
        assert ds.attrs["scene"] == "mixture"
        assert dict(ds.sizes) == {"time": 7, "disk": 300, "axis": 2, "species": 2}
        assert not ds["position"].variable._in_memory
        first = ds["position"].isel(time=0).values
        with h5py.File(path, "r") as f:
            np.testing.assert_array_equal(first, f["particles/disks/position/value"][0])
        by_species = ds["kinetic_energy_by_species"].sum("species")
        np.testing.assert_allclose(by_species, ds["kinetic_energy"], rtol=1e-12)
        assert set(np.unique(ds["mass"].values)) == {1.0, 4.0}


def test_a_failing_job_is_reported_and_the_others_finish(tmp_path, monkeypatch):
    import sim.pipeline.scenes

    def crater_that_fails_for_big_projectiles(cfg):
        if cfg.projectile.radius > 0.015:
            raise RuntimeError("this projectile breaks the scene")
        return original(cfg)

    original = sim.pipeline.scenes.BUILDERS["crater"]
    monkeypatch.setitem(sim.pipeline.scenes.BUILDERS, "crater",
                        crater_that_fails_for_big_projectiles)
    from sim.pipeline import cli as entry

    monkeypatch.setattr(sys, "argv", [
        "sim", "scenario=crater", "projectile.radius=0.01,0.02", "bed.n=300",
        "stop.collisions=2000", "output.progress=false", f"hydra.sweep.dir={tmp_path}",
        "hydra/launcher=basic", "-m"])
    with pytest.raises(SystemExit) as exit_:
        entry.main()
    assert exit_.value.code == 1
    summary_ = yaml.safe_load((tmp_path / "sweep_summary.yaml").read_text())
    assert (summary_["completed"], summary_["failed"]) == (1, 1)
    failed = [job for job in summary_["details"] if job["status"] == "FAILED"]
    assert "this projectile breaks the scene" in failed[0]["error"]
    assert (tmp_path / "0" / "run.h5").exists()


def test_inspect_and_open_run_reject_foreign_truncated_and_corrupt_files(tmp_path):
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = 1
    text = tmp_path / "text.h5"
    text.write_text("hello")
    good = runner.run(compose_scene("gas", "disks.n=200", "stop.collisions=2000"), tmp_path)
    truncated = tmp_path / "truncated.h5"
    truncated.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    corrupt = tmp_path / "corrupt.h5"
    data = bytearray(good.read_bytes())
    data[200:4000] = bytes(3800)  # the superblock survives, the root group's metadata not
    corrupt.write_bytes(bytes(data))
    for reader in (summary, open_run):
        with pytest.raises(RunFileError, match="not an H5MD run file"):
            reader(foreign)
        for broken in (text, truncated):
            with pytest.raises(RunFileError, match="not a readable HDF5"):
                reader(broken)
        with pytest.raises(RunFileError, match=str(corrupt)):
            reader(corrupt)


def test_config_error_names_key_value_and_allowed():
    error = ConfigError("restitution.disk", 1.5, "between 0 and 1")
    assert str(error) == "restitution.disk=1.5 is not allowed: between 0 and 1"


def test_a_sweep_runs_through_submitit(tmp_path):
    """The launcher a cluster uses (submitit; hydra/launcher=cluster on SLURM), run here with
    its local executor."""
    result = run_cli("scenario=crater", "projectile.radius=0.01,0.02", "bed.n=300",
                     "stop.collisions=2000", "hydra/launcher=submitit_local",
                     "hydra.launcher.timeout_min=10", f"hydra.sweep.dir={tmp_path}/sweep", "-m",
                     cwd=tmp_path)
    assert result.returncode == 0, result.stderr[-2000:]
    summary_ = yaml.safe_load((tmp_path / "sweep" / "sweep_summary.yaml").read_text())
    assert (summary_["completed"], summary_["failed"]) == (2, 0)
    assert len(list((tmp_path / "sweep").rglob("run.h5"))) == 2


def test_the_cluster_launcher_config_composes_to_slurm():
    from hydra import compose, initialize_config_dir

    from sim.pipeline.overrides import CONF_DIR

    with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
        cfg = compose("config", overrides=["hydra/launcher=cluster"], return_hydra_config=True)
    launcher = cfg.hydra.launcher
    assert launcher._target_.endswith("SlurmLauncher")
    assert (launcher.cpus_per_task, launcher.array_parallelism) == (1, 200)


def test_a_slurm_sweep_asks_for_what_its_runs_need(monkeypatch):
    """sim.pipeline.cluster: each job's memory from the largest run's estimate and a margin,
    its time limit twice the longest run at the assumed rate and the start's minutes, unless
    the command line gives them; a partition the cluster lacks, or a time beyond its
    partition's limit, named in one line. SLURM's times read in minutes."""
    from sim.pipeline import cluster
    from sim.pipeline.resources import estimate

    monkeypatch.setattr(cluster, "partitions", lambda: ({"short": 60.0, "long": None}, "short"))
    args = ["scenario=gas", "disks.n=1000,100000", "stop.collisions=6e8",
            "hydra/launcher=cluster", "-m"]
    assert cluster.slurm_launcher(args)
    configs = [compose_scene("gas", f"disks.n={n}", "stop.collisions=600000000")
               for n in (1000, 100000)]
    asked, line = cluster.job_resources(args, configs)
    largest = max(estimate(cfg)["memory"][0] for cfg in configs)
    memory = math.ceil(cluster.MEMORY_MARGIN * largest / 2**30)
    minutes = math.ceil(cluster.START_MINUTES + 2 * 6e8 / cluster.ASSUMED_RATE / 60)
    assert value_of(asked, "hydra.launcher.mem_gb") == str(memory)
    assert value_of(asked, "hydra.launcher.timeout_min") == str(minutes) == "25"
    assert f"{memory} GB and {minutes} min (estimated), partition the default" in line
    given = cluster.job_resources([*args[:-1], "hydra.launcher.mem_gb=7",
                                   "hydra.launcher.timeout_min=30", "-m"], configs)[0]
    assert value_of(given, "hydra.launcher.mem_gb") == "7"
    assert value_of(given, "hydra.launcher.timeout_min") == "30"
    with pytest.raises(ConfigError, match="at most the 60 minutes of partition short"):
        cluster.job_resources([*args[:-1], "hydra.launcher.timeout_min=61", "-m"], configs)
    long = cluster.job_resources([*args[:-1], "hydra.launcher.partition=long",
                                  "hydra.launcher.timeout_min=100000", "-m"], configs)[0]
    assert value_of(long, "hydra.launcher.timeout_min") == "100000"  # no limit there
    with pytest.raises(ConfigError, match="hydra.launcher.partition='gpu'.*: long, short"):
        cluster.job_resources([*args[:-1], "hydra.launcher.partition=gpu", "-m"], configs)
    unbounded = [compose_scene("crater", "stop.collisions=null")]  # to its energy fraction
    asked, line = cluster.job_resources(["scenario=crater", "hydra/launcher=cluster",
                                         "hydra.launcher.partition=long", "-m"], unbounded)
    assert value_of(asked, "hydra.launcher.timeout_min") is None and "240 min" in line
    assert not cluster.slurm_launcher(["scenario=gas", "-m"])
    assert cluster.minutes("30") == 30 and cluster.minutes("1:30") == 1.5
    assert cluster.minutes("2:00:00") == 120 and cluster.minutes("1-00:00:00") == 1440
    assert cluster.minutes("1-2") == 1560 and cluster.minutes("infinite") is None


def test_a_signal_another_thread_received_stops_the_run_at_its_next_chunk():
    """The kernel may give SIGTERM to any thread (a BLAS thread of numpy: SLURM's scancel on a
    busy machine); the main thread, which holds the GIL through the compiled chunks, learns of
    it when it asks between chunks, not at SIGKILL. A thread of C code (sleeping 5 s unless a
    signal wakes it) takes the signal; the calls of ``held`` keep the GIL, as the event loop
    does."""
    import ctypes
    import signal

    from sim.pipeline.interruption import Interruption

    libc, held = ctypes.CDLL(None), ctypes.PyDLL(None)
    thread = ctypes.c_ulong()
    assert libc.pthread_create(ctypes.byref(thread), None, libc.sleep, ctypes.c_void_p(5)) == 0
    with Interruption() as interruption:
        assert not interruption.requested
        held.pthread_kill(thread, signal.SIGTERM)
        held.pthread_join(thread, None)  # its handler has run in that thread
        assert interruption.requested and interruption.reason == "terminated"


def test_a_job_on_slurm_is_stopped_alone_and_the_schedulers_words_come_in_one_line(
        monkeypatch):
    """sim.pipeline.cluster in a job (its SLURM id from the environment): a signal before the
    run begins is kept for it (submitit would pass SIGTERM over), the stop recorded with its
    signal; the sweep's line names the time limit when SLURM's warning or SLURM itself says
    so; sbatch's refusal in one line naming the setting it speaks of."""
    import signal

    from omegaconf import OmegaConf

    from sim.pipeline import cluster
    from sim.pipeline.interruption import Interruption

    monkeypatch.setenv("SLURM_ARRAY_JOB_ID", "41")
    monkeypatch.setenv("SLURM_ARRAY_TASK_ID", "3")
    monkeypatch.setenv("SUBMITIT_EXECUTOR", "slurm")
    assert cluster.slurm_job(OmegaConf.create({"_target_": "x.SlurmLauncher"}))
    assert not cluster.slurm_job(OmegaConf.create({"_target_": "x.JoblibLauncher"}))
    handlers = {n: signal.getsignal(n) for n in (signal.SIGTERM, signal.SIGUSR2)}
    try:
        cluster.take_signals()
        assert not Interruption().requested
        signal.raise_signal(signal.SIGUSR2)  # the time limit's warning while it starts
        assert Interruption().requested and Interruption().reason == "terminated"
    finally:
        for number, handler in handlers.items():
            signal.signal(number, handler)
        Interruption.early = Interruption.time_limit_warning = None
        Interruption.at_second_signal = None
    stopped = cluster.stopped_job(signal.SIGTERM, "terminated")
    assert stopped == {"stopped": "terminated", "signal": "SIGTERM", "slurm_job": "41_3"}
    jobs = [{"job": 0, **stopped}, {"job": 1, "signal": "SIGUSR2", "slurm_job": "41_4"}]
    monkeypatch.setattr(cluster, "scheduler_states", lambda ids: {})
    line = cluster.report_stopped(jobs, "sweep", 5)
    assert "jobs 0, 1" in line and "time limit hydra.launcher.timeout_min=5" in line
    monkeypatch.setattr(cluster, "scheduler_states", lambda ids: {"41_3": "CANCELLED"})
    assert "cancelled (scancel" in cluster.report_stopped(jobs[:1], "sweep", 5)
    monkeypatch.setattr(cluster, "scheduler_states", lambda ids: {"41_3": "TIMEOUT"})
    assert "time limit" in cluster.report_stopped(jobs[:1], "sweep", 5)
    launcher = OmegaConf.create({"partition": "nosuch", "mem_gb": 900})
    partition = ("sbatch: error: invalid partition specified: nosuch\n"
                 "sbatch: error: Batch job submission failed: Invalid partition name specified")
    assert cluster.refused(partition)
    assert cluster.scheduler_error(partition, "sweep", launcher) == (
        "sim: SLURM refused the jobs (hydra.launcher.partition=nosuch): invalid partition "
        "specified: nosuch; Invalid partition name specified")
    memory = ("sbatch: error: Memory specification can not be satisfied\n"
              "sbatch: error: Batch job submission failed: Requested node configuration is "
              "not available")
    assert "(hydra.launcher.mem_gb=900): Memory specification" in cluster.scheduler_error(
        memory, "sweep", launcher)
    lost = cluster.scheduler_error("Job 41_3 (task: 0) with path x\nhas not produced any "
                                   "output (state: CANCELLED)", "sweep", launcher)
    assert lost.startswith("sim: a job of the sweep ended without a result (Job 41_3")


def test_the_wall_budget_does_not_count_compiling_the_loop(tmp_path, monkeypatch):
    """A budget of a microsecond, as if compiling the loop had taken 10⁶ s more: the
    compilation is not counted, and the run ends by its other stop condition."""
    from sim.engine import running

    real = running.compile_once
    monkeypatch.setattr(running, "compile_once", lambda function, arguments:
                        real(function, arguments) + 1e6)
    cfg = compose_scene("gas", "stop.collisions=3000", "stop.wall_seconds=1e-6")
    assert summary(runner.run(cfg, tmp_path))["stop_reason"] == "collisions"
    monkeypatch.setattr(running, "compile_once", real)
    (tmp_path / "counted").mkdir()  # the same budget without the credit is spent at once
    assert summary(runner.run(cfg, tmp_path / "counted"))["stop_reason"] == "wall_seconds"
