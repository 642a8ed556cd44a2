"""Hostile cases: what a careless, unlucky or malicious user does to ``python -m sim``.

Every case asserts the documented outcome (``sim/pipeline/cli.py``: exit status 0, 1, 2, 3, 130
or 143), that stderr is one line naming the key, path or cause and never a traceback, that a
refusal (exit 2) leaves nothing behind anywhere under the test's folder (hidden files and
empty folders included) and that every file there before the case is unchanged (sha256).

Refusals run in the process: those made before Hydra starts through the command line's entry
function (``sim.pipeline.cli.main``), those of a scene or a run file through the runner
(``sim.pipeline.runner.run`` and ``resume``), with one refusal end to end. What only a process
shows (signals, kills, locks, concurrent starts, sweeps, Hydra's run folders) runs as real
subprocesses, each with a generous hang guard (``timeout=``). No assertion depends on elapsed
time.
"""

import hashlib
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from sim.pipeline import runner
from sim.pipeline.config import ConfigError
from sim.pipeline.run_cache import compose_config
from sim.pipeline.sweep_stop import descendants
from sim.storage.inspect import summary

PY = sys.executable
HANG_GUARD = 300  # seconds; a guard against hangs, never a measure of speed
QUIET = "output.progress=false"

#: a run that would go on for hours: it is stopped by a signal or a kill
FOREVER = ["disks.n=2000", "stop.collisions=100000000", "output.every_collisions=20000"]
#: a tiny run whose file the resume and folder cases start from
SMALL = ["disks.n=200", "stop.collisions=2000"]


# ---------------------------------------------------------------------------------------
# helpers


def tree(root):
    """{relative path: sha256 of a file, "dir", or "not a regular file"} of everything under
    ``root``, hidden entries included."""
    root = Path(root)
    out = {}
    for folder, dirs, files in os.walk(root):
        for name in dirs:
            out[str((Path(folder) / name).relative_to(root)) + "/"] = "dir"
        for name in files:
            path = Path(folder) / name
            if not path.is_file():  # a named pipe: reading it would wait for a writer
                out[str(path.relative_to(root))] = "not a regular file"
                continue
            digest = hashlib.sha256()
            with open(path, "rb") as handle:
                for block in iter(lambda: handle.read(1 << 20), b""):
                    digest.update(block)
            out[str(path.relative_to(root))] = digest.hexdigest()
    return out


def lines_of(text):
    return [line for line in (text or "").splitlines() if line.strip()]


@dataclass
class Result:
    code: object
    out: str
    err: str


def check(result, status, names=(), before=None, after=None, nothing_new=False,
          any_of=()):
    """Every problem of ``result`` against the expectations, as one assertion: exit status,
    one stderr line naming each of ``names`` (and one of ``any_of``), no traceback; with
    ``before``/``after`` trees, files unchanged and (``nothing_new``) no new entry."""
    problems = []
    err_lines = lines_of(result.err)
    if result.code != status:
        problems.append(f"exit status {result.code!r}, expected {status}")
    if "Traceback" in (result.err or ""):
        problems.append("stderr has a Traceback")
    if status == 0:
        if len(err_lines) > 1:
            problems.append(f"stderr has {len(err_lines)} lines, expected at most one")
    elif len(err_lines) != 1:
        problems.append(f"stderr has {len(err_lines)} lines, expected exactly one")
    line = err_lines[0] if err_lines else ""
    for name in names:
        if name not in line:
            problems.append(f"stderr line does not name {name!r}")
    if any_of and not any(name in line for name in any_of):
        problems.append(f"stderr line names none of {list(any_of)}")
    if before is not None and after is not None:
        changed = sorted(p for p, digest in before.items() if after.get(p) != digest)
        if changed:
            problems.append(f"files changed or removed: {changed}")
        if nothing_new:
            new = sorted(set(after) - set(before))
            if new:
                problems.append(f"left behind: {new}")
    assert not problems, ("; ".join(problems) + f"\n--- exit {result.code!r}\n--- stderr:\n"
                          f"{(result.err or '')[-3000:]}\n--- stdout:\n"
                          f"{(result.out or '')[-1500:]}")


def sim(*args, cwd, timeout=HANG_GUARD, **options):
    """``python -m sim`` as a subprocess (progress bar off), to completion."""
    done = subprocess.run([PY, "-m", "sim", QUIET, *args], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout, **options)
    return Result(done.returncode, done.stdout, done.stderr)


def start(*args, cwd, **options):
    return subprocess.Popen([PY, "-m", "sim", QUIET, *args], cwd=cwd, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, **options)


def finish(process):
    out, err = process.communicate(timeout=HANG_GUARD)
    return Result(process.returncode, out, err)


def wait_for(path, process, poll=0.01):
    """Wait until ``path`` exists or ``process`` has ended (hang guard: HANG_GUARD)."""
    deadline = time.monotonic() + HANG_GUARD
    while not Path(path).exists() and process.poll() is None:
        if time.monotonic() > deadline:
            process.kill()
            pytest.fail(f"{path} did not appear within the hang guard")
        time.sleep(poll)
    return Path(path).exists()


def hidden_leftovers(root):
    return sorted(str(p.relative_to(root)) for p in Path(root).rglob(".*"))


def stop_reason(path):
    return summary(path, verify=False)["stop_reason"]


def stored(path):
    with h5py.File(path, "r") as f:
        attrs = f["parameters"].attrs
        return (yaml.safe_load(str(attrs["config"])),
                yaml.safe_load(str(attrs["resumes"])) if "resumes" in attrs else None)


class HydraReached(Exception):
    """The in-process entry point got as far as Hydra: the case was not refused before."""


@pytest.fixture
def entry(monkeypatch, capsys, tmp_path):
    """``sim.pipeline.cli.main()`` in this process, in ``tmp_path``, stopped (HydraReached) if it
    gets as far as Hydra; returns a function of the command line giving a :class:`Result`."""
    import sim.pipeline.cli as main_module
    import sim.pipeline.cli_exits as exits_module

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(exits_module, "MADE_FOLDERS", [])
    monkeypatch.setattr(main_module, "INTERRUPTED", [])
    monkeypatch.setattr(exits_module, "STOPPED_BY", [signal.SIGINT])
    monkeypatch.setattr(sys, "unraisablehook", sys.unraisablehook)
    monkeypatch.setattr(runner.Interruption, "at_second_signal", None)

    def reached():
        raise HydraReached

    monkeypatch.setattr(main_module, "hydra_main", reached)
    previous = signal.getsignal(signal.SIGTERM)

    def call(*args):
        monkeypatch.setattr(sys, "argv", ["sim", QUIET, *args])
        capsys.readouterr()
        try:
            main_module.main()
            code = 0
        except SystemExit as stop:
            code = 0 if stop.code is None else stop.code
        except HydraReached:
            code = "not refused before Hydra started"
        finally:
            signal.signal(signal.SIGTERM, previous)
        out, err = capsys.readouterr()
        return Result(code, out, err)

    return call


@pytest.fixture(scope="module")
def small_run(tmp_path_factory):
    """A complete run file of :data:`SMALL` (200 disks, 2000 collisions)."""
    folder = tmp_path_factory.mktemp("small")
    result = sim(*SMALL, f"hydra.run.dir={folder / 'run'}", cwd=folder)
    assert result.code == 0, result.err
    return folder / "run" / "run.h5"


def copy_run(small_run, tmp_path, name="prev"):
    """The small run's folder copied to ``tmp_path/name``; returns its run file."""
    folder = tmp_path / name
    folder.mkdir()
    shutil.copy2(small_run, folder / "run.h5")
    return folder / "run.h5"


# ---------------------------------------------------------------------------------------
# bad input, refused before Hydra starts: exit 2, one line naming the key, nothing written

BAD_INPUT = {
    # integer keys
    "collisions-2.5": ("stop.collisions=2.5", "stop.collisions"),
    "collisions-abc": ("stop.collisions=abc", "stop.collisions"),
    "collisions-0": ("stop.collisions=0", "stop.collisions"),
    "collisions-1e400": ("stop.collisions=1e400", "stop.collisions"),
    "collisions-above-2^62": ("stop.collisions=99999999999999999999", "stop.collisions"),
    "n-of-5000-digits": ("disks.n=" + "9" * 5000, "disks.n"),
    "n-unreadable": ("disks.n=[1,", "disks.n"),
    "n-0": ("disks.n=0", "disks.n"),
    "n--5": ("disks.n=-5", "disks.n"),
    "n-1e30": ("disks.n=1e30", "disks.n"),
    "n-2^31": ("disks.n=2147483648", "disks.n"),
    "bed.n-0-gas": ("bed.n=0", "bed.n"),
    "bed.n-0-crater": ("scenario=crater bed.n=0", "bed.n"),
    # non-finite and absurd numbers
    "tc.time-nan": ("tc.time=nan", "tc.time"),
    "tc-a-value": ("tc=nan", "tc"),
    "speed-1e200": ("disks.speed=1e200", "disks.speed"),
    "speed-1e-300": ("disks.speed=1e-300", "disks.speed"),
    "speed-nan": ("disks.speed=nan", "disks.speed"),
    "mass-inf": ("disks.mass=inf", "disks.mass"),
    "temperature--1": ("disks.temperature=-1", "disks.temperature"),
    "temperature--1-speed-null": ("disks.speed=null disks.temperature=-1",
                                  "disks.temperature"),
    "box-1e-300": ("box.size=[1e-300,1]", "box.size"),
    "box-inf": ("box.size=[1,inf]", "box.size"),
    "box-one-side": ("box.size=[1]", "box.size"),
    "box-null-side": ("box.size=[1,null]", "box.size"),
    "gravity-nan": ("gravity=[0,nan]", "gravity"),
    "wall-T-inf": ("walls.left.temperature=inf", "walls.left.temperature"),
    "wall-T-nan": ("walls.left.temperature=nan", "walls.left.temperature"),
    "wall-T--1": ("walls.left.temperature=-1", "walls.left.temperature"),
    "wall-speed-inf": ("walls.top.speed=inf", "walls.top.speed"),
    "restitution-nan": ("restitution.disk=nan", "restitution.disk"),
    "restitution-1.5": ("restitution.disk=1.5", "restitution.disk"),
    "packing-0.95": ("disks.packing_fraction=0.95", "disks.packing_fraction"),
    "every_time-0": ("output.every_time=0", "output.every_time"),
    "wall_seconds-nan": ("stop.wall_seconds=nan", "stop.wall_seconds"),
    "stop.time-inf": ("stop.time=inf", "stop.time"),
    # seeds
    "seed--1": ("seed=-1", "seed"),
    "seed-1e23": ("seed=100000000000000000000000", "seed"),
    "seed-1.5": ("seed=1.5", "seed"),
    # keys the schema does not have, added with + or ++
    "plus-unknown-key": ("+disks.extra=5", "disks.extra"),
    "plusplus-unknown-key": ("++foo=5", "foo"),
    # scenes
    "two_disks-n-5": ("scenario=two_disks disks.n=5", "disks.n"),
    "mixture-empty-species": ("scenario=mixture disks.n=3 mixture.masses=[1,2,3,4,5] "
                              "mixture.fractions=[0.2,0.2,0.2,0.2,0.2]", "mixture.fractions"),
    "mixture-zero-fraction": ("scenario=mixture mixture.fractions=[0.5,0]",
                              "mixture.fractions"),
    "mixture-section-in-gas": ("mixture.fractions=[0.5,0]", "mixture.fractions"),
    "scenario-nosuch": ("scenario=nosuch", "nosuch"),
    "output.file-outside": ("output.file=../escape.h5", "output.file"),
    "two_disks-one-velocity": ("scenario=two_disks two_disks.velocities=[[1,0]]",
                               "two_disks.velocities"),
    "misspelt-disks.nn": ("disks.nn=3", "disks.nn"),
    "sweep-item-abc": ("stop.collisions=2e6,abc -m", "abc"),
    "sweep-item-nan": ("restitution.disk=0.5,nan -m", "restitution.disk"),
    "unbalanced-bracket": ("seed=1)", "seed=1)"),
    "neither-speed-nor-temperature": ("disks.speed=null disks.temperature=null", "disks.speed"),
    "sweep-job-folder-outside-the-sweep": ("seed=0,1 hydra.sweep.subdir=../out${hydra.job.num} -m",
                                           "hydra.sweep.subdir"),
    "no-workers": ("seed=0,1 hydra.launcher.n_jobs=0 -m", "hydra.launcher.n_jobs"),
    "delete-a-key": ("~seed", "~seed"),
    "delete-a-stop-key": ("~stop.collisions", "stop.collisions=…"),
    "sweep-jobs-in-one-folder": ("seed=0,1 hydra.sweep.subdir=same -m", "hydra.sweep.subdir"),
    "sweep-jobs-in-one-folder-by-a-key": ("seed=0,1 disks.n=50,60 hydra.sweep.subdir=n${seed} -m",
                                          "hydra.sweep.subdir"),
    # resources
    "memory-1e9-disks": ("disks.n=1000000000", "disks.n"),
    "memory-1e9-disks-run.dir": ("disks.n=1000000000 hydra.run.dir=X/run", "disks.n"),
    "memory-local-cells": ("observe.local_fields.cells=1000000", "observe.local_fields.cells"),
    "memory-rdf-bins": ("observe.radial_distribution.bins=10000000000",
                        "observe.radial_distribution.bins"),
    "disk-full-every-collision": ("disks.n=2000 stop.collisions=100000000 "
                                  "output.every_collisions=1", "output.every_collisions"),
    # values each scene's or effect's own check refuses
    "n-abc": ("disks.n=abc", "disks.n"),
    "radius-and-packing": ("disks.radius=0.01", "disks.packing_fraction"),
    "random-placement-too-dense": ("disks.placement=random disks.packing_fraction=0.7",
                                   "disks.packing_fraction"),
    "projectile-radius-negative": ("scenario=crater projectile.radius=-0.01",
                                   "projectile.radius"),
    "at_rest-0": ("stop.at_rest=0", "stop.at_rest"),
    "projectile-section-in-gas": ("scenario=gas projectile.radius=0.1", "projectile"),
    "rdf-bins-0": ("observe.radial_distribution.bins=0", "observe.radial_distribution.bins"),
    "cluster-gap-negative": ("observe.clusters.gap=-1", "observe.clusters.gap"),
    "local-cells-0": ("observe.local_fields.cells=0", "observe.local_fields.cells"),
    "gravity-three-numbers": ("gravity=[0,-1,0]", "gravity"),
    "gravity-periodic": ("gravity=[0,-1] box.boundary=periodic", "gravity"),
    "amplitude-without-frequency": ("walls.bottom.amplitude=0.01", "walls.bottom.frequency"),
    "moving-wall-periodic": ("walls.top.speed=-0.1 box.boundary=periodic", "box.boundary"),
    "wall-that-is-not": ("walls.middle.speed=1", "walls.middle"),
    "settle-without-gravity": ("scenario=crater bed.settle_time=1", "bed.settle_time"),
    "projectile-outside": ("scenario=crater projectile.position=[2,0.9]",
                           "projectile.position"),
    "two-disks-overlapping": ("scenario=two_disks two_disks.positions=[[0.5,0.5],[0.51,0.5]]",
                              "two_disks.positions"),
    "fractions-above-1": ("scenario=mixture mixture.fractions=[0.7,0.7]", "mixture.fractions"),
    "no-stop-condition": ("stop.collisions=null stop.time=null stop.energy_fraction=null",
                          "stop.collisions"),
    "two-snapshot-cadences": ("output.every_collisions=100 output.every_time=0.1",
                              "output.every_time"),
    # rough disks
    "tangential-restitution-1.5": ("restitution.tangential=1.5", "restitution.tangential"),
    "friction-of-smooth-disks": ("friction.mu=0.3", "restitution.tangential"),
    "friction-negative": ("friction.mu=-1", "friction.mu"),
    "inertia-factor-0": ("disks.inertia_factor=0", "disks.inertia_factor"),
    "rotational-temperature--1": ("disks.rotational_temperature=-1",
                                  "disks.rotational_temperature"),
    "rotational-temperature-inf": ("disks.rotational_temperature=inf",
                                   "disks.rotational_temperature"),
    "rough-walls-periodic": ("box.boundary=periodic restitution.wall_tangential=0.5",
                             "restitution.wall_tangential"),
    "rough-pressure-tensor": ("restitution.tangential=0.5 observe.pressure_tensor=true",
                              "observe.pressure_tensor"),
    # growing disks
    "growth-rate--1": ("growth.rate=-1", "growth.rate"),
    "growth-rate-nan": ("growth.rate=nan", "growth.rate"),
    "growth-rate-inf": ("growth.rate=inf", "growth.rate"),
    "rescale-every-0": ("growth.rate=0.1 growth.rescale_every=0", "growth.rescale_every"),
    "packing-stop-without-growth": ("stop.packing_fraction=0.5", "stop.packing_fraction"),
    "packing-stop-above-close-packing": ("growth.rate=0.1 stop.packing_fraction=0.95",
                                         "stop.packing_fraction"),
    "growth-with-a-piston": ("growth.rate=0.1 walls.top.speed=-0.1", "growth.rate"),
    "growth-with-a-vibrating-wall": ("growth.rate=0.1 walls.bottom.amplitude=0.01 "
                                     "walls.bottom.frequency=10", "growth.rate"),
    "growth-of-rough-disks": ("growth.rate=0.1 restitution.tangential=0.5", "growth.rate"),
    "compress-without-growth": ("scenario=compress growth.rate=0", "growth.rate"),
    # stepped potentials
    "step-inside-the-core": ("potential.steps=[0.9] potential.energies=[-1]",
                             "potential.steps"),
    "steps-not-increasing": ("potential.steps=[1.5,1.2] potential.energies=[-1,1]",
                             "potential.steps"),
    "step-energy-nan": ("potential.steps=[1.5] potential.energies=[nan]", "potential.energies"),
    "step-energy-inf": ("potential.steps=[1.5] potential.energies=[-inf]",
                        "potential.energies"),
    "step-without-its-energy": ("potential.steps=[1.5,2] potential.energies=[-1]",
                                "potential.energies"),
    "steps-of-growing-disks": ("scenario=compress potential.steps=[1.5] "
                               "potential.energies=[-1]", "potential.steps"),
    "compress-ratio-below-1": ("scenario=compress compress.radius_ratio=0.5",
                               "compress.radius_ratio"),
    "jamming-pressure-1": ("stop.jamming=1", "stop.jamming"),
    "placement-unknown": ("disks.placement=squeezed", "disks.placement"),
    # words that are no override: a value cut at a space the shell split, a bare word
    "path-with-a-space-unquoted": ("hydra.run.dir=my runs/x", "quoted"),
    "a-bare-word": ("gas", "KEY=VALUE"),
    # flags Hydra's parser refuses, in one line instead of its usage text
    "flag-unknown": ("--no-such-flag", "--no-such-flag"),
    "flag-short-unknown": ("-x disks.n=10", "-x"),
    "flag-abbreviated": ("--multi seed=0,1", "--multi"),
    "flag-without-its-value": ("--cfg", "--cfg"),
    "flag-value-not-a-choice": ("--cfg=everything", "--cfg"),
    "flags-that-exclude-each-other": ("--cfg job seed=0,1 -m", "--cfg"),
    "flag-shell-completion": ("--shell-completion", "--shell-completion"),
    "flag-experimental-rerun": ("--experimental-rerun config.pickle", "--experimental-rerun"),
    "flag-config-name": ("-cn nosuch", "--config-name"),
    "flag-config-path": ("-cp /tmp", "--config-path"),
    "flag-config-dir": ("--config-dir /nonexistent", "--config-dir"),
    "hydra-mode": ("hydra.mode=MULTIRUN disks.n=100,120", "hydra.mode"),
    "flag-resolve-without-cfg": ("--resolve", "--resolve"),
    "flag-package": ("--cfg job -p nope", "--package"),
}


@pytest.mark.parametrize("case", list(BAD_INPUT), ids=list(BAD_INPUT))
def test_bad_input_is_refused_with_one_line_and_nothing_written(case, entry, tmp_path):
    command, key = BAD_INPUT[case]
    args = command.split()
    if "-m" in args:  # the sweep flag last, as the README writes it
        args = [a for a in args if a != "-m"] + [f"hydra.sweep.dir={tmp_path}/S", "-m"]
    (tmp_path / "keep.txt").write_text("a file that was here before")
    before = tree(tmp_path)
    result = entry(*args)
    check(result, 2, [key], before, tree(tmp_path), nothing_new=True)


def test_job_folders_named_by_a_swept_key_are_accepted(entry, tmp_path):
    result = entry("seed=0,1", "hydra.sweep.subdir=seed_${seed}", f"hydra.sweep.dir={tmp_path}/S",
                   "-m")
    assert result.code == "not refused before Hydra started", result.err


@pytest.mark.parametrize("flags", ["--cfg job", "--info", "--hydra-help", "--cfg all seed=3"])
def test_flags_that_only_print_make_no_run_folder(flags, entry, tmp_path):
    """``--cfg job`` and the like reach Hydra, which prints and runs nothing: no folder is
    made for a run."""
    result = entry(*flags.split())
    assert result.code == "not refused before Hydra started", result
    assert tree(tmp_path) == {}


def test_cfg_job_of_a_resume_shows_the_config_it_runs(small_run, entry, tmp_path):
    """``resume=FILE --cfg job`` prints the run file's config with the overrides, not the
    default config Hydra would compose, and makes nothing."""
    path = copy_run(small_run, tmp_path)
    before = tree(tmp_path)
    result = entry(f"resume={path}", "stop.collisions=5000", "--cfg", "job")
    assert result.code == 0, result.err
    shown = yaml.safe_load(result.out)
    assert shown["disks"]["n"] == 200 and shown["stop"]["collisions"] == 5000
    assert tree(tmp_path) == before


def test_a_misspelt_key_is_quoted_with_the_value_given(entry, tmp_path):
    """``disks.nn=3``: the message quotes what was typed (3), not ``None``."""
    result = entry("disks.nn=3")
    check(result, 2, ["disks.nn"])
    assert "None" not in lines_of(result.err)[0], result.err


def test_a_wrong_type_in_a_scenario_file_of_ones_own_is_named_by_its_key(entry, tmp_path):
    """A scenario file on Hydra's search path with ``stop.collisions: 1.5e3``: one line
    naming the key and the value, not "no such scenario"."""
    scenes = tmp_path / "mine" / "scenario"
    scenes.mkdir(parents=True)
    (scenes / "bad.yaml").write_text("# @package _global_\nscene: gas\nstop:\n"
                                     "  collisions: 1.5e3\n")
    result = entry(f"hydra.searchpath=[file://{tmp_path / 'mine'}]", "scenario=bad")
    check(result, 2, ["stop.collisions", "1500"])
    assert "no such scenario" not in result.err


# ---------------------------------------------------------------------------------------
# numbers that look wrong but are fine: they run


RUNS = {
    "collisions-2e4": (["stop.collisions=2e4", "disks.n=200"], 200),
    "n-1e3": (["disks.n=1e3", "stop.collisions=2000"], 1000),
    "seed-2^63-1": (["seed=9223372036854775807", "disks.n=200", "stop.collisions=2000"], 200),
}


@pytest.mark.parametrize("case", list(RUNS), ids=list(RUNS))
def test_numbers_written_as_floats_and_the_largest_seed_run(case, tmp_path):
    args, n = RUNS[case]
    result = sim(*args, "hydra.run.dir=run", cwd=tmp_path)
    check(result, 0)
    info = summary(tmp_path / "run" / "run.h5")
    assert info["stop_reason"] in ("collisions", "wall_seconds")
    if n is not None:
        assert info["n"] == n
    if case.startswith("collisions"):
        assert info["collisions"] == 20_000
    if case.startswith("seed"):
        assert info["seed"] == 2**63 - 1
    assert not hidden_leftovers(tmp_path)


# ---------------------------------------------------------------------------------------
# runs that cannot be made (stop conditions that can never hold, what only the built scene
# shows): refused (exit 2) before anything is written; and a scene at rest that ends by itself

NEVER = {
    "single-disk-collisions": ("scenario=single_disk stop.collisions=10 stop.contacts=null",
                               "stop.collisions"),
    "parallel-pair-collisions": ("scenario=two_disks two_disks.velocities=[[0,1],[0,1]] "
                                 "stop.collisions=10", "stop.collisions"),
    "elastic-energy_fraction": ("disks.n=200 stop.collisions=null stop.energy_fraction=0.5",
                                "stop.energy_fraction"),
    "periodic-single-disk-contacts": ("scenario=single_disk box.boundary=periodic "
                                    "stop.contacts=100", "stop.contacts"),
    "elastic-energy_fraction-gravity": ("disks.n=50 gravity=[0,-1] stop.collisions=null "
                                        "stop.energy_fraction=0.5", "stop.energy_fraction"),
    "elastic-energy_fraction-thermal-wall": ("disks.n=50 walls.top.temperature=2 "
                                             "stop.collisions=null stop.energy_fraction=0.5",
                                             "stop.energy_fraction"),
    "periodic-overlap-across-the-side": ("scenario=two_disks box.boundary=periodic "
                                         "disks.radius=0.13 "
                                         "two_disks.positions=[[0.05,0.5],[0.95,0.5]]",
                                         "two_disks.positions"),
    "rdf-r_max-beyond-half-box": ("observe.radial_distribution.bins=50 "
                                  "observe.radial_distribution.r_max=100",
                                  "observe.radial_distribution.r_max"),
    "step-beyond-half-the-box": ("scenario=square_well box.boundary=periodic "
                                 "walls.left.temperature=null walls.right.temperature=null "
                                 "walls.bottom.temperature=null walls.top.temperature=null "
                                 "potential.steps=[60]",
                                 "potential.steps"),
    # a time reached only after more collisions than the engine counts (ran on for ever)
    "time-beyond-2^62-collisions": ("disks.n=100 stop.collisions=null stop.time=1e50",
                                    "stop.time"),
    "time-beyond-2^62-collisions-sparse": ("disks.n=100 stop.collisions=null stop.time=1e50 "
                                           "output.every_time=1e49", "stop.time"),
    "time-beyond-2^62-events-of-a-driven-gas": ("scenario=driven disks.n=200 stop.collisions=null "
                                                "stop.time=1e50", "stop.time"),
    "settling-for-ever": ("scenario=crater_gravity bed.n=300 bed.settle_time=1e6",
                          "bed.settle_time"),
    "time-beyond-2^62-events-under-gravity": ("disks.n=100 gravity=[0,-1] restitution.disk=0.9 "
                                              "restitution.wall=0.9 tc.time=1e-4 "
                                              "stop.collisions=null stop.time=1e50", "stop.time"),
}


#: cases whose scene compiles a variant of the loop outside the quick suite's (variants.py)
EXOTIC = ("elastic-energy_fraction-gravity", "elastic-energy_fraction-thermal-wall")


@pytest.mark.parametrize("case", [pytest.param(case, marks=pytest.mark.slow) if case in EXOTIC
                                  else case for case in NEVER], ids=list(NEVER))
def test_a_run_that_cannot_be_made_is_refused_before_anything_is_written(case, tmp_path):
    """In the process: the runner builds the scene and weighs its stop conditions before it
    writes anything, and raises the ConfigError the command line prints as its one line."""
    from sim.pipeline.config import ConfigError
    command, key = NEVER[case]
    folder = tmp_path / "run"
    folder.mkdir()
    with pytest.raises(ConfigError) as refused:
        runner.run(compose_config([*command.split(), QUIET]), folder)
    assert key in str(refused.value)
    assert not list(folder.iterdir())


def test_a_stop_condition_that_can_never_hold_is_refused_end_to_end(tmp_path):
    """The same refusal through ``python -m sim``: exit 2, one line, nothing left."""
    before = tree(tmp_path)
    result = sim("scenario=single_disk", "stop.collisions=10", "stop.contacts=null",
                 "hydra.run.dir=X", cwd=tmp_path)
    check(result, 2, ["stop.collisions"], before, tree(tmp_path), nothing_new=True)


def test_disks_at_rest_end_by_themselves(tmp_path):
    result = sim("disks.n=200", "disks.speed=0", "output.every_collisions=null",
                 "output.every_time=0.1", "stop.collisions=1000", "hydra.run.dir=run",
                 cwd=tmp_path)
    check(result, 0)
    assert summary(tmp_path / "run" / "run.h5")["stop_reason"] == "no_events"
    assert not hidden_leftovers(tmp_path)


# ---------------------------------------------------------------------------------------
# resume= of things that are not a resumable run file


def _foreign(path):
    with h5py.File(path, "w") as f:
        f["x"] = np.arange(3)


def _garbage_config(path):
    with h5py.File(path, "r+") as f:
        f["parameters"].attrs["config"] = "{{{: not yaml ]\n  - at all"


def _edited_n(path):
    with h5py.File(path, "r+") as f:
        config = yaml.safe_load(str(f["parameters"].attrs["config"]))
        config["disks"]["n"] = 100
        f["parameters"].attrs["config"] = yaml.safe_dump(config)


def _no_checkpoint(path):
    """A run file stripped of /checkpoint, as a killed run of an old version leaves it:
    resuming it could only start it again over its snapshots."""
    with h5py.File(path, "r+") as f:
        del f["checkpoint"]
        f["parameters"].attrs["stop_reason"] = "running"


def _write(path, data):
    if isinstance(data, str):
        path.write_text(data)
    else:
        path.write_bytes(data)
    return path


def _then(action, path):
    action(path)
    return path


BAD_RESUME = {
    "missing": lambda folder, good: folder / "missing.h5",
    "folder": lambda folder, good: good.parent,
    "empty": lambda folder, good: _write(folder / "empty.h5", b""),
    "text": lambda folder, good: _write(folder / "text.h5", "hello\n"),
    "truncated": lambda folder, good: _write(folder / "cut.h5",
                                             good.read_bytes()[: good.stat().st_size // 2]),
    "foreign-hdf5": lambda folder, good: _then(_foreign, folder / "foreign.h5"),
    "garbage-config": lambda folder, good: _then(_garbage_config, good),
    "named-pipe": lambda folder, good: _then(os.mkfifo, folder / "pipe.h5"),  # hung
    "proc-file": lambda folder, good: Path("/proc/self/mem"),  # exit 1: no lock file in /proc
}

#: run files that open but cannot be continued
UNRESUMABLE = {"no-checkpoint": lambda folder, good: _then(_no_checkpoint, good)}


@pytest.mark.parametrize("case", [*BAD_RESUME, *UNRESUMABLE])
def test_resume_of_what_is_not_a_run_file_is_refused(case, entry, small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    target = (BAD_RESUME | UNRESUMABLE)[case](tmp_path, good)
    before = tree(tmp_path)
    result = entry(f"resume={target}")
    check(result, 2, ["resume"], before, tree(tmp_path), nothing_new=True)


# ---------------------------------------------------------------------------------------
# sim.storage.inspect of what is not a run file: exit 2, one line naming the path


@pytest.mark.parametrize("case", list(BAD_RESUME), ids=list(BAD_RESUME))
def test_inspect_of_what_is_not_a_run_file_is_one_line(case, small_run, tmp_path, capsys):
    from sim.storage import inspect

    good = copy_run(small_run, tmp_path)
    target = BAD_RESUME[case](tmp_path, good)
    before = tree(tmp_path)
    capsys.readouterr()
    code = inspect.main([str(target)])
    out, err = capsys.readouterr()
    check(Result(code, out, err), 2, [target.name], before, tree(tmp_path), nothing_new=True)


def test_a_named_pipe_as_the_run_file_of_a_new_run_is_refused(entry, tmp_path):
    """A run folder whose run.h5 is a named pipe: refused, not a wait for a writer."""
    (tmp_path / "X").mkdir()
    os.mkfifo(tmp_path / "X" / "run.h5")
    before = tree(tmp_path)
    with pytest.raises(ConfigError, match="not a regular file"):
        runner.run(compose_config([*SMALL, QUIET]), tmp_path / "X")
    assert tree(tmp_path) == before


@pytest.mark.parametrize("extra", [[], ["stop.collisions=4000"]], ids=["plain", "longer"])
def test_resume_of_a_run_file_whose_config_was_edited_is_refused(extra, small_run, tmp_path):
    """The stored config says disks.n=100, the checkpoint holds 200 disks: the file no longer
    describes itself, and resuming must not write into it."""
    good = copy_run(small_run, tmp_path)
    _edited_n(good)
    before = tree(tmp_path)
    with pytest.raises(ConfigError) as refused:
        runner.resume(good, extra)
    assert "resume" in str(refused.value) or "disks.n" in str(refused.value)
    assert tree(tmp_path) == before  # nothing changed, nothing new


@pytest.mark.parametrize("key, value, names", [("seed", 7, "velocities"),
                                                ("disks.mass", 2.0, "masses")])
def test_resume_of_a_file_whose_config_makes_another_first_snapshot_is_refused(
        key, value, names, small_run, tmp_path):
    """A seed or a mass edited in the stored config: sizes agree, but the config no longer
    makes the file's first snapshot, and the run would go on with other bits."""
    good = copy_run(small_run, tmp_path)
    with h5py.File(good, "r+") as f:
        config = yaml.safe_load(str(f["parameters"].attrs["config"]))
        section, _, name = key.rpartition(".")
        (config[section] if section else config)[name] = value
        f["parameters"].attrs["config"] = yaml.safe_dump(config)
    before = tree(tmp_path)
    with pytest.raises(ConfigError, match=f"resume.*first snapshot.*{names}"):
        runner.resume(good, ["stop.collisions=4000"])
    assert tree(tmp_path) == before


def test_resume_into_another_run_folder_is_refused(entry, small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    before = tree(tmp_path)
    result = entry(f"resume={good}", f"hydra.run.dir={tmp_path / 'X'}")
    check(result, 2, ["hydra.run.dir", "resume"], before, tree(tmp_path), nothing_new=True)
    result = entry(f"resume={good}", f"hydra.run.dir={good.parent}")  # its own folder
    assert result.code == "not refused before Hydra started"


def test_resume_may_not_change_the_scene(entry, small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    before = tree(tmp_path)
    result = entry(f"resume={good}", "disks.n=10")
    check(result, 2, ["disks.n"], before, tree(tmp_path), nothing_new=True)


def test_resume_as_a_sweep_is_refused(entry, small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    before = tree(tmp_path)
    result = entry(f"resume={good}", f"hydra.sweep.dir={tmp_path}/S", "-m")
    check(result, 2, ["resume"], before, tree(tmp_path), nothing_new=True)


def test_resume_to_fewer_collisions_than_done_is_refused(small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    before = tree(tmp_path)
    with pytest.raises(ConfigError, match="stop.collisions"):
        runner.resume(good, ["stop.collisions=1000"])
    assert tree(tmp_path) == before  # nothing changed, nothing new


@pytest.mark.parametrize("harmless", ["output.progress=true", "stop.wall_seconds=100"])
def test_resume_of_a_complete_run_with_a_harmless_override_says_complete(harmless, small_run,
                                                                        tmp_path, caplog):
    """A chained batch job resumes with a new budget: a complete run stays as it is."""
    good = copy_run(small_run, tmp_path)
    before = tree(tmp_path)
    with caplog.at_level("INFO"):
        assert runner.resume(good, [harmless]) == good
    assert tree(tmp_path) == before  # nothing changed, nothing new
    assert "is complete" in caplog.text


def test_resume_to_more_collisions_continues_a_complete_run(small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    done = summary(good)["collisions"]
    result = sim(f"resume={good}", "stop.collisions=4000", cwd=tmp_path)
    check(result, 0)
    info = summary(good)
    assert info["collisions"] == 4000 > done and info["stop_reason"] == "collisions"
    assert info["damaged"] == []
    config, resumes = stored(good)
    assert config["stop"]["collisions"] == 4000
    assert resumes and any("stop.collisions=4000" in entry_["overrides"] for entry_ in resumes)
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["prev", "run.h5"]  # no leftovers


@pytest.mark.parametrize("key", ["seed", "scene"])
def test_a_stored_config_is_read_as_data_never_resolved(key, entry, small_run, tmp_path,
                                                        monkeypatch):
    """An interpolation put into a stored config is not resolved on resume: the key holds
    its text, which the schema refuses (an integer seed) or the file contradicts (a scene
    that is no scene)."""
    good = copy_run(small_run, tmp_path)
    with h5py.File(good, "r+") as f:
        config = yaml.safe_load(str(f["parameters"].attrs["config"]))
        config[key] = "${oc.env:MY_VALUE}"
        f["parameters"].attrs["config"] = yaml.safe_dump(config)
    monkeypatch.setenv("MY_VALUE", {"seed": "7", "scene": "gas"}[key])
    before = tree(tmp_path)
    result = entry(f"resume={good}", "stop.collisions=4000")
    check(result, 2, ["resume", "${oc.env:MY_VALUE}"], before, tree(tmp_path),
          nothing_new=True)


def test_resume_falls_back_when_the_latest_checkpoint_slot_is_gone(small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    with h5py.File(good, "r+") as f:
        del f["checkpoint"][str(f["checkpoint"].attrs["latest"])]
        f["parameters"].attrs["stop_reason"] = "interrupted"
    with pytest.warns(RuntimeWarning, match="is damaged; resuming from slot"), \
            pytest.warns(RuntimeWarning, match="snapshots written after it"):
        runner.resume(good)
    assert summary(good)["stop_reason"] == "collisions" and summary(good)["damaged"] == []


def test_resume_may_repeat_a_stored_value(small_run, tmp_path):
    """``disks.n=200`` on a file of 200 disks changes nothing: not refused."""
    good = copy_run(small_run, tmp_path)
    runner.resume(good, ["stop.collisions=3000", "disks.n=200", "seed=0"])
    assert summary(good)["collisions"] == 3000
    with pytest.raises(ConfigError, match="disks.n.*unchanged on resume"):
        runner.resume(good, ["stop.collisions=4000", "disks.n=300"])


def test_a_stored_value_of_the_wrong_type_is_one_plain_line(entry, small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    with h5py.File(good, "r+") as f:
        config = yaml.safe_load(str(f["parameters"].attrs["config"]))
        config["disks"]["n"] = "two hundred"
        f["parameters"].attrs["config"] = yaml.safe_dump(config)
    result = entry(f"resume={good}", "stop.collisions=4000")
    check(result, 2, ["resume", "two hundred", "disks.n"])
    assert "object_type" not in result.err and "reference_type" not in result.err


def test_a_run_folder_whose_run_file_has_no_checkpoint_is_named_as_a_folder(small_run,
                                                                            tmp_path):
    good = copy_run(small_run, tmp_path)
    _no_checkpoint(good)
    with pytest.raises(ConfigError) as refused:
        runner.run(compose_config([*SMALL, QUIET]), good.parent, folder_key="hydra.run.dir")
    assert refused.value.key == "hydra.run.dir" and refused.value.value == str(good.parent)


def test_resume_after_a_kill_says_which_snapshots_it_computes_again(small_run, tmp_path):
    """A run killed between checkpoints: its file points at the first checkpoint while later
    frames were flushed. Resume says how many it drops and ends with the frames of the run
    never killed."""
    good = copy_run(small_run, tmp_path)
    with h5py.File(small_run, "r") as f:
        whole = f["particles/disks/position/value"][()]
    with h5py.File(good, "r+") as f:
        first = min(f["checkpoint"], key=lambda slot: f["checkpoint"][slot].attrs["snapshots"])
        f["checkpoint"].attrs["latest"] = first
        f["parameters"].attrs["stop_reason"] = "running"
    with pytest.warns(RuntimeWarning, match=rf"the {len(whole) - 1} snapshots written after "
                                            rf"it, to t = .*, are dropped; the run goes on "
                                            rf"from the checkpoint"):
        runner.resume(good)
    with h5py.File(good, "r") as f:
        np.testing.assert_array_equal(f["particles/disks/position/value"][()], whole)
    assert summary(good)["stop_reason"] == "collisions"


# ---------------------------------------------------------------------------------------
# folders and files, never lost


@pytest.fixture(scope="module")
def live_run(tmp_path_factory):
    """A run that would go on for hours, its run file published; SIGINT ends it at the
    module's end (or in :func:`test_a_live_run_ends_on_sigint_with_its_file_whole`)."""
    folder = tmp_path_factory.mktemp("live")
    process = start(*FOREVER, f"hydra.run.dir={folder / 'X'}", cwd=folder)
    appeared = wait_for(folder / "X" / "run.h5", process)
    if not appeared:
        result = finish(process)
        pytest.fail(f"the long run ended before its file appeared: {result}")
    yield process, folder
    if process.poll() is None:
        process.kill()
        process.communicate(timeout=HANG_GUARD)


def test_a_second_run_into_a_live_runs_folder_is_refused(live_run):
    process, folder = live_run
    before = set(tree(folder))
    result = sim(*FOREVER, f"hydra.run.dir={folder / 'X'}", cwd=folder)
    check(result, 2, ["hydra.run.dir", str(process.pid)])
    assert process.poll() is None, "the first run died"
    assert not set(tree(folder)) - before


def test_inspect_of_a_live_run_file_is_one_line(live_run):
    process, folder = live_run
    done = subprocess.run([PY, "-m", "sim.storage.inspect", str(folder / "X" / "run.h5")],
                          cwd=folder, capture_output=True, text=True, timeout=HANG_GUARD)
    check(Result(done.returncode, done.stdout, done.stderr), 2, ["run.h5"])


def test_inspect_names_the_run_writing_a_file_whatever_hdf5_locks(small_run, tmp_path,
                                                                   capsys):
    """sim's own lock, which ``HDF5_USE_FILE_LOCKING=FALSE`` leaves in place, says a run is
    writing the file: one line naming the process, exit 2."""
    from sim.pipeline.run_folder import RunLock
    from sim.storage import inspect

    good = copy_run(small_run, tmp_path)
    with RunLock(good):
        capsys.readouterr()
        code = inspect.main([str(good)])
    out, err = capsys.readouterr()
    check(Result(code, out, err), 2, [str(os.getpid()), "being written"])
    assert inspect.main([str(good)]) == 0  # the run over: read as ever


def test_resume_of_a_live_run_file_is_refused(live_run):
    process, folder = live_run
    before = set(tree(folder))
    result = sim(f"resume={folder / 'X' / 'run.h5'}", cwd=folder)
    check(result, 2, ["resume"])
    assert process.poll() is None, "the first run died"
    assert not set(tree(folder)) - before


#: a process that holds a run file open for writing, as a resume does, until it is killed
HOLDING = "import h5py, sys, time; f = h5py.File(sys.argv[1], 'r+'); print('open', flush=True); \
time.sleep(600)"


def _alias(path, how, folder):
    """Another name of the run file ``path`` in ``folder``: a hard or a symbolic link."""
    folder.mkdir()
    alias = folder / "alias.h5"
    if how == "hard link":
        os.link(path, alias)
    else:
        alias.symlink_to(path)
    return alias


@pytest.mark.parametrize("how", ["hard link", "symbolic link"])
def test_a_run_file_in_use_is_refused_under_every_name(how, small_run, tmp_path):
    """Resumed under one name, a run file is refused under another: a symbolic link leads to
    the same lock file, a hard link meets HDF5's lock of the file another process has open."""
    from sim.pipeline.run_folder import RunLock

    good = copy_run(small_run, tmp_path)
    alias = _alias(good, how, tmp_path / "other")
    for using, asked in ((good, alias), (alias, good)):
        if how == "hard link":
            holder = subprocess.Popen([PY, "-c", HOLDING, str(using)], stdout=subprocess.PIPE,
                                      stderr=subprocess.PIPE, text=True)
            assert holder.stdout.readline().strip() == "open", finish(holder)
            try:
                before = tree(tmp_path)
                with pytest.raises(ConfigError, match="resume"):
                    runner.resume(asked, ["stop.collisions=4000"])
                assert tree(tmp_path) == before
            finally:
                holder.kill()
                finish(holder)
        else:
            before = tree(tmp_path)
            with RunLock(using), pytest.raises(ConfigError,
                                               match="resume.*no other run is using"):
                runner.resume(asked, ["stop.collisions=4000"])
            assert tree(tmp_path) == before


#: Resumes of a run file in use under another name, and of a new run's file through a hard
#: link made while it runs, in a process where HDF5 does not lock files: one line per case
WITHOUT_HDF5_LOCKS = """
import os, sys
from pathlib import Path
from sim.pipeline import runner, writing
from sim.pipeline.config import ConfigError
from sim.pipeline.run_cache import compose_config
from sim.pipeline.run_folder import HDF5_LOCKS_FILES, RunLock

def refused(path):
    try:
        runner.resume(path, ["stop.collisions=4000"])
        return "resumed"
    except ConfigError as error:
        return "refused" if "no other run is using" in str(error) else str(error)

print("HDF5 locks files:", HDF5_LOCKS_FILES)
good, hard, soft, fresh = map(Path, sys.argv[1:])
for using, asked in ((good, hard), (hard, good), (good, soft), (soft, good)):
    with RunLock(using):
        print(using.name, asked.name, refused(asked))
advance = writing.advance

def resume_through_a_link(engine, cfg, writer, *args):
    os.link(writer.path, fresh.parent / "alias.h5")
    print("live run", refused(fresh.parent / "alias.h5"))
    return advance(engine, cfg, writer, *args)

writing.advance = resume_through_a_link
runner.run(compose_config(["disks.n=200", "stop.collisions=2000"]), fresh)
"""


def test_without_hdf5_locks_a_run_file_is_still_refused_under_every_name(small_run, tmp_path):
    """``HDF5_USE_FILE_LOCKING=FALSE`` (usual on Lustre and NFS) leaves the file to sim's own
    lock of it: resumed, or written by a new run, under one name, refused under another."""
    good = copy_run(small_run, tmp_path)
    hard = _alias(good, "hard link", tmp_path / "h")
    soft = _alias(good, "symbolic link", tmp_path / "s")
    before = tree(tmp_path)
    done = subprocess.run([PY, "-c", WITHOUT_HDF5_LOCKS, str(good), str(hard), str(soft),
                           str(tmp_path / "fresh")], capture_output=True, text=True,
                          timeout=HANG_GUARD, env={**os.environ, "HDF5_USE_FILE_LOCKING": "FALSE"})
    assert done.returncode == 0, done.stderr[-3000:]
    assert done.stdout.splitlines() == [
        "HDF5 locks files: False", "run.h5 alias.h5 refused", "alias.h5 run.h5 refused",
        "run.h5 alias.h5 refused", "alias.h5 run.h5 refused", "live run refused"]
    assert tree(tmp_path / "prev") == {k.partition("/")[2]: v for k, v in before.items()
                                       if k.startswith("prev/") and k != "prev/"}
    assert summary(tmp_path / "fresh" / "run.h5")["stop_reason"] == "collisions"


def test_a_live_run_ends_on_sigint_with_its_file_whole(live_run):
    process, folder = live_run
    assert process.poll() is None, "the long run ended by itself"
    process.send_signal(signal.SIGINT)
    result = finish(process)
    check(result, 130, ["resume="])
    info = summary(folder / "X" / "run.h5")
    assert info["stop_reason"] == "interrupted" and info["damaged"] == []
    assert info["snapshots"] >= 1
    assert not hidden_leftovers(folder)


@pytest.mark.slow  # beside the quick suite's runs of the same path
def test_four_runs_started_together_get_four_folders(tmp_path):
    processes = [start(*SMALL, f"seed={k}", cwd=tmp_path) for k in range(4)]
    results = [finish(p) for p in processes]
    for result in results:
        check(result, 0)
    files = sorted(tmp_path.glob("outputs/runs/*/*/run.h5"))
    assert len(files) == 4 and len({f.parent for f in files}) == 4
    assert sorted(summary(f)["seed"] for f in files) == [0, 1, 2, 3]
    assert not hidden_leftovers(tmp_path)


def test_the_same_command_twice_at_once_into_one_folder(tmp_path):
    """Both start together; whichever gets the folder runs, the other is refused (exit 2,
    naming hydra.run.dir) or finds the run complete (exit 0): one intact run file."""
    args = ["disks.n=2000", "stop.collisions=200000", "output.every_collisions=20000",
            "hydra.run.dir=X"]
    results = [finish(p) for p in [start(*args, cwd=tmp_path) for _ in range(2)]]
    codes = sorted(r.code for r in results)
    assert codes in ([0, 0], [0, 2]), [(r.code, r.err[-500:]) for r in results]
    for result in results:
        check(result, result.code, ["hydra.run.dir"] if result.code == 2 else [])
    assert summary(tmp_path / "X" / "run.h5")["stop_reason"] == "collisions"
    assert not hidden_leftovers(tmp_path)


def test_a_complete_run_asked_for_again_is_left_as_it_is(small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    before = tree(tmp_path)
    result = sim(*SMALL, f"hydra.run.dir={good.parent}", cwd=tmp_path)
    check(result, 0, [], before, tree(tmp_path), nothing_new=True)
    assert "is complete" in result.out


def test_another_config_into_a_complete_runs_folder_is_refused(small_run, tmp_path):
    good = copy_run(small_run, tmp_path)
    before = tree(tmp_path)
    result = sim("disks.n=300", "stop.collisions=2000", f"hydra.run.dir={good.parent}",
                 cwd=tmp_path)
    check(result, 2, ["disks.n", "200", "300"], before, tree(tmp_path), nothing_new=True)


#: inelastic contacts under the TC model, and elastic ones: canonical variants (variants.py)
SWEEP = ["disks.n=100", "stop.collisions=1000", "tc.time=1e-6", "restitution.disk=0.9,1.0"]


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    """The sweep :data:`SWEEP`, run once for the module."""
    folder = tmp_path_factory.mktemp("sweep")
    result = sim(*SWEEP, "hydra.sweep.dir=S", "-m", cwd=folder)
    assert result.code == 0, result.err[-2000:]
    return folder / "S"


def finished_sweep(swept, folder):
    """The finished sweep :data:`SWEEP` copied to ``folder/S``."""
    return shutil.copytree(swept, folder / "S")


def test_another_sweep_into_a_sweep_folder_is_refused_before_any_job(swept, tmp_path):
    finished_sweep(swept, tmp_path)
    before = tree(tmp_path)
    result = sim("disks.n=100", "stop.collisions=1000", "restitution.disk=0.8,0.7",
                 "hydra.sweep.dir=S", "-m", cwd=tmp_path)
    check(result, 2, ["hydra.sweep.dir", "restitution.disk"], before, tree(tmp_path),
          nothing_new=True)


def test_the_same_sweep_again_changes_nothing_and_reads_back_labelled(swept):
    """Run again into the sweep's own folder (a copy of the folder would differ in the paths
    Hydra records): it finds every job complete and writes nothing."""
    from sim.analysis.datasets import open_sweep

    folder = swept.parent
    before = tree(folder)
    result = sim(*SWEEP, "hydra.sweep.dir=S", "-m", cwd=folder)
    check(result, 0, [], before, tree(folder), nothing_new=True)
    assert result.out.count("is complete") == 2
    sweep = open_sweep(swept)
    labels = sweep["restitution_disk"].values.tolist()
    assert labels == [0.9, 1.0]
    for value in labels:
        config = yaml.safe_load(str(sweep["config"].sel(restitution_disk=value).item()))
        assert config["restitution"]["disk"] == value
    recorded = sorted(stored(p)[0]["restitution"]["disk"] for p in swept.glob("*/run.h5"))
    assert recorded == labels


def test_a_flag_hydra_refuses_leaves_no_run_folder(tmp_path):
    result = sim("--no-such-flag", cwd=tmp_path, timeout=HANG_GUARD)
    assert result.code == 2 and "--no-such-flag" in result.err
    assert tree(tmp_path) == {}


@pytest.mark.slow  # beside the quick suite's runs of the same path
def test_a_sweep_into_the_default_sweep_folder_runs_with_the_flag_first(tmp_path):
    """No hydra.sweep.dir, and the flag first as Hydra's documents write it (``-m`` last, as
    the README writes it, in the sweeps above)."""
    result = sim("--multirun", *SWEEP, cwd=tmp_path)
    check(result, 0)
    files = sorted(tmp_path.glob("outputs/multirun/*/*/*/run.h5"))
    assert len(files) == 2


def test_a_run_folder_holding_a_foreign_run_h5_is_refused(tmp_path):
    (tmp_path / "F").mkdir()
    (tmp_path / "F" / "run.h5").write_text("my notes, not a run file\n")
    before = tree(tmp_path)
    result = sim(*SMALL, "hydra.run.dir=F", cwd=tmp_path)
    check(result, 2, ["hydra.run.dir"], before, tree(tmp_path), nothing_new=True)


def test_a_stale_lock_and_part_file_of_a_dead_run_do_not_block_the_folder(tmp_path):
    folder = tmp_path / "L"
    folder.mkdir()
    (folder / ".run.h5.lock").write_text("999999")
    (folder / ".run.h5.part").write_bytes(b"half a header")
    result = sim(*SMALL, f"hydra.run.dir={folder}", cwd=tmp_path)
    check(result, 0)
    assert stop_reason(folder / "run.h5") == "collisions"
    assert not hidden_leftovers(tmp_path)


def test_a_run_folder_that_is_a_file_is_one_line_exit_1(tmp_path):
    (tmp_path / "afile").write_text("not a folder")
    before = tree(tmp_path)
    result = sim(*SMALL, "hydra.run.dir=afile", cwd=tmp_path)
    check(result, 1, ["afile"], before, tree(tmp_path), nothing_new=True)


def test_a_run_folder_that_cannot_be_written_is_one_line_exit_1(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        if os.access(locked, os.W_OK):  # root: permissions do not bind; /proc refuses all
            target = "/proc/x/run"
        else:
            target = str(locked / "run")
        before = tree(tmp_path)
        result = sim(*SMALL, f"hydra.run.dir={target}", cwd=tmp_path)
        check(result, 1, [target], before, tree(tmp_path), nothing_new=True)
    finally:
        locked.chmod(0o755)


def _file_size_limit():
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    import resource
    resource.setrlimit(resource.RLIMIT_FSIZE, (64 << 10, 64 << 10))


def test_a_file_size_limit_at_the_first_write_is_one_line_exit_1(tmp_path):
    result = finish(start("disks.n=2000", "stop.collisions=100000", "hydra.run.dir=F",
                          cwd=tmp_path, preexec_fn=_file_size_limit))
    assert not (tmp_path / "F" / "run.h5").exists()
    assert not (tmp_path / "F" / ".run.h5.part").exists()
    assert not hidden_leftovers(tmp_path)
    check(result, 1, ["run.h5"])


#: moments of a SIGKILL: early in start-up, when the run folder, the part file and the run
#: file appear, and in the run; the quick suite takes one of each phase
KILL_MOMENTS = [pytest.param("5ms", marks=pytest.mark.slow),
                pytest.param("50ms", marks=pytest.mark.slow), "folder-appears",
                "part-appears", pytest.param("file-appears", marks=pytest.mark.slow),
                "file+0.3s"]


@pytest.mark.parametrize("moment", KILL_MOMENTS)
def test_sigkill_at_any_moment_leaves_a_readable_file_or_none(moment, tmp_path):
    folder = tmp_path / "X"
    process = start(*FOREVER, f"hydra.run.dir={folder}", cwd=tmp_path)
    try:
        if moment.endswith("ms"):
            time.sleep(float(moment[:-2]) / 1000)
        else:
            target = {"folder-appears": folder, "part-appears": folder / ".run.h5.part",
                      "file-appears": folder / "run.h5", "file+0.3s": folder / "run.h5"}
            wait_for(target[moment], process, poll=0.001)
            if moment == "file+0.3s":
                time.sleep(0.3)
    finally:
        process.kill()
        result = finish(process)
    assert result.code == -signal.SIGKILL, result.err[-2000:]
    path = folder / "run.h5"
    if path.exists():
        info = summary(path)  # reads, or raises
        assert info["stop_reason"] == "running" and info["damaged"] == []
        with h5py.File(path, "r") as f:  # published with its first checkpoint complete
            assert "latest" in f["checkpoint"].attrs
        again = sim(f"resume={path}", f"stop.collisions={info['collisions'] + 40000}",
                    cwd=tmp_path)
    else:  # nothing published: the folder takes the run again
        again = sim("disks.n=2000", "stop.collisions=40000", f"hydra.run.dir={folder}",
                    cwd=tmp_path)
    check(again, 0)
    assert stop_reason(path) == "collisions"
    assert not hidden_leftovers(tmp_path)


# ---------------------------------------------------------------------------------------
# every run ends


def test_a_wall_clock_budget_ends_a_run_that_snapshots_every_collision(tmp_path):
    result = sim("disks.n=200", "output.every_collisions=1", "stop.wall_seconds=1",
                 "hydra.run.dir=run", cwd=tmp_path)
    check(result, 0)
    assert summary(tmp_path / "run" / "run.h5", verify=False)["stop_reason"] == "wall_seconds"


@pytest.mark.slow  # beside the quick suite's runs of the same path
def test_sigterm_ends_a_run_resumably_and_resume_finishes_it(tmp_path):
    process = start(*FOREVER, "hydra.run.dir=X", cwd=tmp_path)
    try:
        assert wait_for(tmp_path / "X" / "run.h5", process), finish(process).err[-2000:]
        time.sleep(0.3)
    finally:
        process.send_signal(signal.SIGTERM)
        result = finish(process)
    check(result, 143, ["resume="])
    assert "resume=" in lines_of(result.err)[-1]
    path = tmp_path / "X" / "run.h5"
    info = summary(path)
    assert info["stop_reason"] == "terminated" and info["damaged"] == []
    again = sim(f"resume={path}", f"stop.collisions={info['collisions'] + 40000}",
                cwd=tmp_path)
    check(again, 0)
    assert stop_reason(path) == "collisions"
    assert not hidden_leftovers(tmp_path)


def still_running(pids):
    """Those of ``pids`` that run (neither ended nor zombies)."""
    running = []
    for pid in pids:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()[0]
        except OSError:  # ended
            continue
        if state != "Z":
            running.append(pid)
    return running


@pytest.mark.parametrize("to, how, seeds", [  # quick: the workers; the group is quick below
    ("the workers", signal.SIGTERM, "0,1"),
    pytest.param("the process group", signal.SIGINT, "0,1", marks=pytest.mark.slow),
    pytest.param("the command", signal.SIGTERM, "0,1,2", marks=pytest.mark.slow)])
def test_a_signal_stops_a_sweep_whole(to, how, seeds, tmp_path):
    """However a signal reaches a sweep (a scheduler signals the workers, Ctrl-C the process
    group, kill the command): every running job ends with its final snapshot and checkpoint,
    a job not begun runs nothing, and the command exits 128 + the signal's number, its
    workers gone and no stop file left."""
    process = start(*FOREVER, f"seed={seeds}", "hydra.sweep.dir=S", "-m", cwd=tmp_path,
                    start_new_session=True)
    try:
        for job in ("0", "1"):
            assert wait_for(tmp_path / "S" / job / "run.h5", process), finish(process).err
    finally:
        workers = descendants(process.pid)
        if to == "the process group":
            os.killpg(process.pid, how)
        for pid in workers if to == "the workers" else [process.pid] * (to == "the command"):
            try:
                os.kill(pid, how)
            except ProcessLookupError:
                pass
        result = finish(process)
    reason = "terminated" if how == signal.SIGTERM else "interrupted"
    check(result, 128 + how, [reason, "hydra.sweep.dir=S"])
    assert {stop_reason(tmp_path / "S" / job / "run.h5") for job in "01"} == {reason}
    summary_ = yaml.safe_load((tmp_path / "S" / "sweep_summary.yaml").read_text())
    assert summary_["stopped"] == len(seeds.split(",")) and summary_["failed"] == 0
    assert not (tmp_path / "S" / "2" / "run.h5").exists()  # begun after the stop: nothing
    assert not (tmp_path / "S" / ".sweep-stop").exists()
    assert not still_running(workers)


#: a ``sitecustomize`` for a sweep's processes: the first joblib worker that imports the
#: module named by $SIGNAL_AT sends SIGINT to the process group, as Ctrl-C would, once; the
#: moment is set by the program, not by a clock
SIGNAL_AT_IMPORT = """
import importlib.abc, os, signal, sys


class AtImport(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name == os.environ["SIGNAL_AT"]:
            sys.meta_path.remove(self)
            try:
                os.close(os.open(os.environ["SIGNAL_TOKEN"], os.O_CREAT | os.O_EXCL))
            except FileExistsError:
                return None
            os.killpg(os.getpgid(0), signal.SIGINT)
        return None


if "--process-name" in sys.argv:  # loky's worker, not the sweep or a resource tracker
    sys.meta_path.insert(0, AtImport())
"""


@pytest.mark.parametrize("moment", ["joblib", pytest.param("hydra", marks=pytest.mark.slow)])
def test_ctrl_c_as_a_sweep_worker_starts_stops_the_sweep_in_one_line(moment, tmp_path):
    """Ctrl-C while a worker starts (importing joblib, before it can take signals; importing
    hydra, as it reads its first job): no worker dies of it, no traceback, exit 130, no job
    run, no stop file left."""
    site = tmp_path / "site"
    site.mkdir()
    (site / "sitecustomize.py").write_text(SIGNAL_AT_IMPORT)
    environment = {**os.environ, "SIGNAL_AT": moment, "SIGNAL_TOKEN": str(tmp_path / "token"),
                   "PYTHONPATH": os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")])}
    result = sim(*FOREVER, "seed=0,1", "hydra.sweep.dir=S", "-m", cwd=tmp_path,
                 env=environment, start_new_session=True,
                 preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert (tmp_path / "token").exists()  # the signal was sent
    check(result, 130, ["interrupted", "hydra.sweep.dir=S"])
    assert not list((tmp_path / "S").glob("*/run.h5"))
    assert not (tmp_path / "S" / ".sweep-stop").exists()


def test_ctrl_c_while_a_worker_waits_between_jobs_ends_only_the_running_job(tmp_path):
    """Ctrl-C to the process group when one worker has finished its jobs and another still
    runs one: the idle worker ignores it (joblib's pool stays whole), the running job ends
    with its final snapshot and checkpoint, exit 130."""
    process = start("disks.n=2000", "output.every_collisions=20000",
                    "stop.collisions=2000,100000000,2000", "hydra.sweep.dir=S", "-m",
                    cwd=tmp_path, start_new_session=True,
                    preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    statuses = [tmp_path / "S" / job / "job_status.yaml" for job in "02"]
    try:
        for path in [*statuses, tmp_path / "S" / "1" / "run.h5"]:
            assert wait_for(path, process), finish(process).err[-2000:]
    finally:
        os.killpg(process.pid, signal.SIGINT)
        result = finish(process)
    check(result, 130, ["interrupted", "hydra.sweep.dir=S"])
    assert stop_reason(tmp_path / "S" / "1" / "run.h5") == "interrupted"
    assert [stop_reason(tmp_path / "S" / job / "run.h5") for job in "02"] == ["collisions"] * 2


def test_a_worker_killed_outright_stops_its_sweep_in_one_line(tmp_path):
    """kill -9 (the OOM killer) of a sweep's worker breaks joblib's pool, which kills the
    others: one line naming the sweep folder to run again, exit 1, every run file whole."""
    process = start(*FOREVER, "seed=0,1", "hydra.sweep.dir=S", "-m", cwd=tmp_path,
                    start_new_session=True)
    try:
        for job in "01":
            assert wait_for(tmp_path / "S" / job / "run.h5", process), finish(process).err
    finally:
        workers = [pid for pid in descendants(process.pid)
                   if b"popen_loky" in Path(f"/proc/{pid}/cmdline").read_bytes()]
        os.kill(workers[0], signal.SIGKILL)
        result = finish(process)
    check(result, 1, ["worker", "SIGKILL", "hydra.sweep.dir=S"])
    for job in "01":
        assert summary(tmp_path / "S" / job / "run.h5")["damaged"] == []


def test_a_sweep_killed_outright_leaves_no_worker_computing(tmp_path):
    """SIGKILL to a sweep's process (the OOM killer, kill -9): its workers end their jobs as
    at SIGTERM, with final snapshot and checkpoint, and exit instead of computing for no
    one."""
    process = start(*FOREVER, "seed=0,1", "hydra.sweep.dir=S", "-m", cwd=tmp_path,
                    start_new_session=True)
    try:
        for job in "01":
            assert wait_for(tmp_path / "S" / job / "run.h5", process), finish(process).err
    finally:
        workers = descendants(process.pid)
        process.kill()
        finish(process)
    deadline = time.monotonic() + HANG_GUARD
    while still_running(workers):
        assert time.monotonic() < deadline, "the workers of a killed sweep still run"
        time.sleep(0.05)
    assert {stop_reason(tmp_path / "S" / job / "run.h5") for job in "01"} == {"terminated"}


#: ``python -m sim`` that sends itself SIGINT at a moment of its start-up, the first argument:
#: as the import of that module begins (a finder put first on sys.meta_path), or, for
#: "locked", once the run folder is made and its lock taken, before the run file. The moment
#: is set by the program, not by a clock, so that a loaded machine cannot move it.
SELF_INTERRUPTED = """
import importlib.abc, os, runpy, signal, sys
moment = sys.argv.pop(1)
# Ctrl-C as at a terminal, also where the tests were started with SIGINT ignored (a
# background job of a script), which Python would otherwise keep ignoring
signal.signal(signal.SIGINT, signal.default_int_handler)


def interrupt():
    os.kill(os.getpid(), signal.SIGINT)


class AtImport(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name == moment:
            sys.meta_path.remove(self)
            interrupt()
        return None


if moment == "locked":
    import sim.pipeline.run_folder
    take = sim.pipeline.run_folder.RunLock.__enter__

    def taken(lock):
        take(lock)
        interrupt()
        return lock

    sim.pipeline.run_folder.RunLock.__enter__ = taken
else:
    sys.meta_path.insert(0, AtImport())
sys.argv = ["sim", *sys.argv[1:]]
runpy.run_module("sim", run_name="__main__")
"""

#: while the modules the command line needs are imported, and once its run folder is locked
STARTUP_MOMENTS = ["hydra", "numba", "h5py", "sim.engine.core", "locked"]


@pytest.mark.parametrize("moment", STARTUP_MOMENTS)
def test_sigint_during_start_up_is_one_line_exit_130_and_leaves_nothing(moment, tmp_path):
    done = subprocess.run([PY, "-c", SELF_INTERRUPTED, moment, QUIET, *SMALL, "hydra.run.dir=X"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=HANG_GUARD)
    result = Result(done.returncode, done.stdout, done.stderr)
    check(result, 130, [])
    files = [p for p in tmp_path.rglob("*") if not p.is_dir()]
    assert not files, files
    assert not (tmp_path / "X").exists() or not any((tmp_path / "X").iterdir())


def test_two_quick_sigints_still_leave_a_readable_resumable_file(tmp_path):
    """Ctrl-C pressed twice: the second acts at once (mid-chunk or mid-write); the file
    that is left must still read, and resume must continue it."""
    process = start(*FOREVER, "hydra.run.dir=X", cwd=tmp_path)
    try:
        assert wait_for(tmp_path / "X" / "run.h5", process), finish(process).err[-2000:]
        time.sleep(0.3)
        process.send_signal(signal.SIGINT)
        time.sleep(0.02)
    finally:
        if process.poll() is None:
            process.send_signal(signal.SIGINT)
        result = finish(process)
    path = tmp_path / "X" / "run.h5"
    info = summary(path)
    assert info["damaged"] == []
    again = sim(f"resume={path}", f"stop.collisions={info['collisions'] + 40000}",
                cwd=tmp_path)
    check(again, 0)
    assert stop_reason(path) == "collisions"
    assert not hidden_leftovers(tmp_path)
    check(result, 130, [])  # last: the file matters most


def test_inelastic_collapse_is_exit_3_with_the_state_kept(tmp_path):
    # the driven scene's thermal walls do not stop a dense lattice at ξ = 0.2 collapsing
    result = sim("scenario=driven", "disks.n=300", "restitution.disk=0.2",
                 "disks.packing_fraction=0.6", "disks.placement=lattice",
                 "stop.collisions=2000000", "output.every_collisions=100000",
                 "hydra.run.dir=run", cwd=tmp_path)
    check(result, 3, ["inelastic collapse"])
    info = summary(tmp_path / "run" / "run.h5")
    assert info["stop_reason"] == "inelastic_collapse" and info["damaged"] == []
    assert not hidden_leftovers(tmp_path)


def test_a_jammed_piston_is_exit_3_with_the_state_kept(tmp_path):
    # inelastic under gravity with the TC model: the vibrated bed's compiled variant
    result = sim("disks.n=50", "disks.packing_fraction=0.05", "walls.top.speed=-0.5",
                 "gravity=[0,-1]", "restitution.disk=0.9", "restitution.wall=0.9",
                 "tc.time=1e-6", "stop.collisions=null", "stop.wall_seconds=3600",
                 "output.every_collisions=100000", "hydra.run.dir=run", cwd=tmp_path)
    check(result, 3, ["jammed"])
    info = summary(tmp_path / "run" / "run.h5")
    assert info["stop_reason"] == "closed_box" and info["damaged"] == []
    assert not hidden_leftovers(tmp_path)


# ---------------------------------------------------------------------------------------
# the Python API


def _engine_case(name):
    position = [[0.2, 0.2], [0.5, 0.5], [0.8, 0.8]]
    velocity = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.5]]
    if name == "overlap":
        position[2] = [0.52, 0.5]
    elif name == "outside":
        position[2] = [0.99, 0.5]
    elif name == "nan-velocity":
        velocity[2] = [float("nan"), 0.0]
    elif name == "nan-position":
        position[2] = [float("nan"), 0.5]
    elif name == "inf-velocity":
        velocity[2] = [0.0, float("inf")]
    return position, velocity


@pytest.mark.parametrize("name", ["overlap", "outside", "nan-velocity", "nan-position",
                                  "inf-velocity"])
def test_the_engine_refuses_a_bad_disk_naming_it(name):
    from sim.engine import Engine

    position, velocity = _engine_case(name)
    with pytest.raises(ValueError) as error:
        Engine(position, velocity, 0.05)
    message = str(error.value)
    assert re.search(r"\bdisk 2\b", message), message
    if name == "overlap":
        assert re.search(r"\bdisk 1\b", message), message


def test_the_engine_refuses_a_bad_mass_or_radius_naming_the_disk():
    from sim.engine import Engine

    position, velocity = _engine_case("none")
    for options in ({"mass": [1.0, float("inf"), 1.0]}, {"mass": [1.0, -1.0, 1.0]}):
        with pytest.raises(ValueError, match=r"\bdisk 1\b"):
            Engine(position, velocity, 0.05, **options)
    with pytest.raises(ValueError, match=r"\bdisk 1\b"):
        Engine(position, velocity, [0.05, float("nan"), 0.05])
