"""The equation of state at the published sizes (sim.checks.melting): the reference data as
published, and a short run of the study's state point (its long run is the validation row
``melting_small_n``)."""

import csv
import importlib.util
import json
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

from sim.checks.melting import loop_extrema, reference, state_point
from sim.pipeline.interruption import STOPS, Interruption, between_jobs
from sim.pipeline.run_cache import compose_config
from sim.pipeline.runner import run


def test_the_published_pressures_are_read_per_size_and_box():
    phi, pressure, error, aspect = reference(72, "1:1")
    assert aspect == 1.0 and phi[0] == 0.65 and pressure[0] == pytest.approx(6.901074)
    assert np.all(np.diff(pressure) > 0)  # N = 72 in its square box has no loop
    phi, pressure, error, aspect = reference(224, "1:1")
    assert np.any(np.diff(pressure) < 0)  # N = 224 in its square box has one
    assert reference(870, "29:30√3/2")[3] == pytest.approx(29 / (15 * np.sqrt(3)))
    with pytest.raises(ValueError, match="no published pressures"):
        reference(100, "1:1")


def test_the_loop_of_a_published_curve_and_none_where_it_is_monotone():
    """N = 224 in its square box: the maximum near φ = 0.692 and the minimum near 0.705
    (Li et al. 2022), with errors far below the grid's 0.002; N = 72 has none."""
    extrema = loop_extrema(*reference(224, "1:1")[:3])
    phi_max, phi_max_error, p_max, _ = extrema["max"]
    phi_min, phi_min_error, p_min, _ = extrema["min"]
    assert 0.691 < phi_max < 0.693 and 0.703 < phi_min < 0.708 and p_min < p_max
    assert phi_max_error < 5e-4 and phi_min_error < 1e-3
    assert loop_extrema(*reference(72, "1:1")[:3]) is None


def test_a_short_run_of_a_state_point_is_near_the_published_pressure():
    """N = 72 in its square box at φ = 0.65, 4000 collisions per disk: within 1 % of
    Li et al.'s value (the validation row runs it to an error of 0.002)."""
    phi, pressure, _, aspect = reference(72, "1:1")
    mean, error, _, per_disk = state_point(72, aspect, 0.65, collisions=4000, blocks=64)
    assert per_disk == pytest.approx(4100, rel=0.01)
    assert abs(mean - pressure[0]) < 0.01 * pressure[0] and error < 0.05


STUDY = Path(__file__).parents[1] / "experiments" / "melting" / "study.py"


def _study():
    """The study's module, its sibling modules (plan, tables, figures) importable."""
    if str(STUDY.parent) not in sys.path:
        sys.path.insert(0, str(STUDY.parent))
    spec = importlib.util.spec_from_file_location("melting_study", STUDY)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_study_resumes_a_cut_short_point_to_the_same_bits_and_runs_nothing_twice(
        tmp_path, monkeypatch, capsys):
    """make melting's smoke run (--quick: N = 72 at two φ): a point interrupted after its
    first chunk is resumed, not begun again, and ends on the bits of a study never
    interrupted; a second study with every point done runs nothing and rewrites no run."""
    study = _study()
    plan = sys.modules["plan"]
    first = plan.points(plan.QUICK, tmp_path / "cut")[0]
    with monkeypatch.context() as patch:  # a signal before the first chunk ends
        patch.setattr(Interruption, "requested", property(lambda self: True))
        patch.setattr(Interruption, "reason", property(lambda self: "interrupted"))
        run(compose_config(first.overrides(first.group.first)), first.folder)
    with h5py.File(first.folder / "run.h5") as f:
        assert f["observables/collisions/value"][-1] < first.group.first * first.group.n
    for out in ("cut", "whole"):
        assert study.main(["--quick", "--jobs", "1", "--out", str(tmp_path / out),
                           "--results", str(tmp_path / out / "results")]) == 0
    for point in plan.points(plan.QUICK, tmp_path / "cut"):
        whole = tmp_path / "whole" / point.folder.relative_to(tmp_path / "cut") / "run.h5"
        with h5py.File(point.folder / "run.h5") as a, h5py.File(whole) as b:
            for name in ("particles/disks/position/value", "observables/collision_virial/value"):
                assert np.array_equal(a[name][-1], b[name][-1])
    with open(tmp_path / "whole" / "results" / "melting.csv", encoding="utf-8") as file:
        rows = list(csv.DictReader(file))
    assert [r["phi"] for r in rows] == ["0.650", "0.700"]
    assert set(rows[0]) == {"n", "aspect", "phi", "start", "seed", "collisions_per_disk",
                            "bPd2", "err", "psi6"}
    published = reference(72, "1:1")[1]
    assert abs(float(rows[0]["bPd2"]) - published[0]) < 5 * float(rows[0]["err"]) + 0.01
    files = sorted((tmp_path / "whole" / "runs").glob("*/run.h5"))
    stamps = [f.stat().st_mtime_ns for f in files]
    capsys.readouterr()
    assert study.main(["--quick", "--jobs", "1", "--out", str(tmp_path / "whole"),
                       "--results", str(tmp_path / "whole" / "results")]) == 0
    assert "collisions per disk:" not in capsys.readouterr().out  # no run reported
    assert [f.stat().st_mtime_ns for f in files] == stamps
    capsys.readouterr()  # a clone with the results alone goes on from them: nothing to run
    assert study.main(["--quick", "--jobs", "1", "--out", str(tmp_path / "clone"),
                       "--results", str(tmp_path / "clone" / "results"), "--ledger",
                       str(tmp_path / "whole" / "results" / "melting.json")]) == 0
    assert "collisions per disk:" not in capsys.readouterr().out
    assert not list((tmp_path / "clone" / "runs").glob("*/run.h5"))
    with open(tmp_path / "clone" / "results" / "melting.csv", encoding="utf-8") as file:
        assert list(csv.DictReader(file)) == rows


def test_a_committed_record_of_older_rules_is_run_again_to_its_recorded_length(tmp_path):
    """adopt: a point with neither record nor run here takes the committed one; one made by
    an older analysis, its run file not here, is run again from its start to its length."""
    study = _study()
    plan = sys.modules["plan"]
    point = plan.points(plan.QUICK, tmp_path)[0]
    g = point.group
    older = {"group": g.name, "n": g.n, "box": g.box, "phi": point.phi, "start": g.start,
             "seed": 0,
             "analysis": study.ANALYSIS - 1, "collisions_per_disk": 3 * g.first,
             "cpu_seconds": 5.0, "status": "done"}
    ledger = tmp_path / "melting.json"
    ledger.write_text(json.dumps({"points": [older]}))
    study.adopt([point], ledger)
    assert json.loads((point.folder / "point.json").read_text())["cpu_seconds"] == 5.0
    assert study._pending([point]) == [(point, 3 * g.first)]


def test_an_adopted_point_whose_rerun_was_cut_short_goes_on_to_its_recorded_length(
        tmp_path, monkeypatch):
    """_pending: a point whose committed record is done but whose run here (made again for
    what the record lacks) was stopped by a signal resumes to the record's length; once
    that run is whole, the point is judged by it and not resumed to that length again."""
    study = _study()
    plan = sys.modules["plan"]
    point = plan.points(plan.QUICK, tmp_path)[0]
    g = point.group
    done = {"group": g.name, "n": g.n, "box": g.box, "phi": point.phi, "start": g.start,
            "seed": 0,
            "analysis": study.ANALYSIS, "collisions_per_disk": g.first, "cpu_seconds": 5.0,
            "err": 0.0, "converged": True, "drift": 0.0, "blocks": 100, "cut": 0,
            "bPd2": 1.0, "status": "done"}
    ledger = tmp_path / "melting.json"
    ledger.write_text(json.dumps({"points": [done]}))
    study.adopt([point], ledger)
    with monkeypatch.context() as patch:  # a signal before the first chunk ends
        patch.setattr(Interruption, "requested", property(lambda self: True))
        patch.setattr(Interruption, "reason", property(lambda self: "interrupted"))
        run(compose_config(point.overrides(g.first)), point.folder)
    assert study._pending([point]) == [(point, g.first)]
    assert study.advance(point, g.first)["collisions_per_disk"] == g.first
    (again, length), = study._pending([point])  # the quick point asks for more, not again
    assert again == point and length > g.first


def test_a_point_runs_on_to_the_length_its_error_asks_for_and_stops_where_it_should():
    """next_length: none for a point that meets its target (and agrees with the runs of its
    state point from other starts), has reached its longest run or failed; else its
    error's ask (with the margin), within the growth's bounds, whole blocks."""
    study = _study()
    plan = sys.modules["plan"]
    group = plan.Group("g", 72, "1:1", (0.65,), "compressed", 100, 10_000, 100_000, 0.01)
    point = plan.Point(group, 0.65, Path("unused"))
    record = {"collisions_per_disk": 10_000, "err": 0.01, "converged": True, "drift": 0.5,
              "blocks": 100, "cut": 0}
    assert study.status(point, record) == "done" and study.next_length(point, record) is None
    slightly = dict(record, err=0.0105)  # asks 1.3 × 1.1025: the growth's least, 1.5
    assert study.next_length(point, slightly) == 15_000
    far = dict(record, err=0.05)  # asks 32 times: the growth's most, 4
    assert study.next_length(point, far) == 40_000
    unknown = dict(record, err=float("nan"), converged=False)
    assert study.next_length(point, unknown) == 40_000
    drifting = dict(record, drift=4.0)
    assert study.status(point, drifting) == "running"
    assert study.status(point, dict(record, cut=11)) == "done"  # 11 of 111 blocks cut
    assert study.status(point, dict(record, cut=12)) == "running"  # more than a tenth
    few = dict(record, blocks=40, cut=60, err=0.001)  # asks 6000 cut + 64 blocks of 100
    assert study.status(point, few) == "running" and study.next_length(point, few) == 15_000
    fewer = dict(few, collisions_per_disk=2_000)  # 1200 cut + 6400: more than 1.5 times
    assert study.next_length(point, fewer) == 7_600
    longest = dict(far, collisions_per_disk=100_000)
    assert study.status(point, longest) == "longest"
    assert study.next_length(point, longest) is None
    record = dict(record, bPd2=9.0)  # beside a run of the same point from another start
    assert study.status(point, record, [{"bPd2": 9.0 + 2.9 * 0.01 * 2**0.5, "err": 0.01}]) \
        == "done"
    apart = [{"bPd2": 9.0 + 3.1 * 0.01 * 2**0.5, "err": 0.01}]
    assert study.status(point, record, apart) == "running"
    assert study.next_length(point, record, apart) == 15_000
    failed = {"collisions_per_disk": 5_000, "failed": "a run to its collisions"}
    assert study.status(point, failed) == "failed" and study.next_length(point, failed) is None


def test_the_runs_of_one_state_point_from_other_starts_or_seeds_are_its_twins():
    """plan.points and plan.twins: a point per φ and seed; its twins are the points at the
    same N, box and φ from another start or with another seed, and no others; replicas (the
    same start, other seeds) share the group's target as √(replicas) times each run's."""
    _study()
    plan = sys.modules["plan"]
    todo = plan.points(plan.PLAN, Path("unused"))
    by_folder = {p.folder.name: p for p in todo}
    first, second = by_folder["224-square-0.720"], by_folder["224-square-replicas-0.720-seed1"]
    assert plan.twins(first, todo) == [second] and plan.twins(second, todo) == [first]
    assert plan.twins(by_folder["224-square-0.712"], todo) == []
    assert by_folder["224-square-0.712"].target == 0.003
    assert first.target == second.target == pytest.approx(0.003 * 2**0.5)
    melted = by_folder["16384-square-melted-0.704"]
    assert plan.twins(by_folder["16384-square-0.704"], todo) == [melted]
    assert by_folder["16384-square-0.704"].target == melted.target == 0.003
    compressed = [by_folder[f"16384-square-replicas-0.716-seed{s}"] for s in (1, 2, 3, 4)]
    assert {p.replicas for p in [by_folder["16384-square-0.716"], *compressed]} == {5}
    assert by_folder["16384-square-melted-0.716"].replicas == 1
    assert "seed=4" in compressed[3].overrides(1000) and "seed=0" in first.overrides(1000)


def test_replicas_combine_to_their_weighted_mean():
    """tables.estimates: the runs of one N, box, φ and start with different seeds give
    Σ p/σ² / Σ 1/σ² ± S (Σ 1/σ²)^(−1/2), S the Particle Data Group's scale factor when they
    scatter more than their errors say, done only when each replica of the plan is; a run
    alone is itself."""
    _study()
    tables = sys.modules["tables"]
    run = {"n": 224, "box": "1:1", "phi": 0.72, "start": "compressed", "replicas": 2}
    records = [dict(run, seed=0, bPd2=9.0, err=0.003, status="done"),
               dict(run, seed=1, bPd2=9.1, err=0.004, status="running"),
               dict(run, phi=0.712, seed=0, bPd2=8.7, err=0.01, status="done", replicas=1)]
    both, alone = tables.estimates(records)
    w = np.array([1 / 0.003**2, 1 / 0.004**2])
    assert both["seeds"] == [0, 1] and both["status"] == "running"
    assert both["bPd2"] == pytest.approx((9.0 * w[0] + 9.1 * w[1]) / w.sum())
    chi2 = w @ (np.array([9.0, 9.1]) - both["bPd2"]) ** 2  # 0.1² / 0.005² = 400: scaled
    assert both["scale"] == pytest.approx(chi2**0.5) == pytest.approx(20.0)
    assert both["err"] == pytest.approx(0.0024 * 20.0)  # 0.003 · 0.004 / 0.005, widened
    close = tables.estimates([records[0], dict(records[1], bPd2=9.001)])[0]
    assert close["scale"] == 1.0 and close["err"] == pytest.approx(0.0024)
    assert (alone["bPd2"], alone["err"], alone["status"]) == (8.7, 0.01, "done")
    unknown = tables.estimates([records[0], dict(records[1], err=float("nan"))])[0]
    assert np.isnan(unknown["bPd2"]) and np.isnan(unknown["err"])
    first, = tables.estimates(records[:1])  # its replica not begun: not done
    assert first["status"] == "running" and first["bPd2"] == 9.0
    both = tables.estimates([records[0], dict(records[1], status="longest")])[0]
    assert both["status"] == "longest"


def _seed_and_replica(tmp_path, first_record, later_record):
    """The study, the points of the plan under ``tmp_path``, and N = 128² at φ = 0.716 from
    the compressed fluid with seed 0 and seed 1, their records written."""
    study = _study()
    plan = sys.modules["plan"]
    todo = plan.points(plan.PLAN, tmp_path)
    by_folder = {p.folder.name: p for p in todo}
    first = by_folder["16384-square-0.716"]
    later = by_folder["16384-square-replicas-0.716-seed1"]
    for point, record in ((first, first_record), (later, later_record)):
        point.folder.mkdir(parents=True)
        (point.folder / "point.json").write_text(json.dumps(record))
    return study, todo, first, later


def test_a_replica_still_on_its_way_does_not_undo_a_run_done(tmp_path):
    """study._others: a replica begun later, its blocks still too few, counts against no run
    of its state point, however far its pressure; once it meets its own target and
    disagrees, the run done runs on."""
    done = {"collisions_per_disk": 1_200_000, "bPd2": 9.16, "err": 0.0043, "converged": True,
            "drift": 0.0, "blocks": 1190, "cut": 9}
    early = dict(done, collisions_per_disk=80_000, bPd2=9.12, err=0.005, blocks=42, cut=38)
    study, todo, first, later = _seed_and_replica(tmp_path, done, early)
    assert study._others(first, todo) == []
    assert study.status(first, done, study._others(first, todo)) == "done"
    finished = dict(early, blocks=400, cut=10)  # met its own target, 8 combined errors off
    (later.folder / "point.json").write_text(json.dumps(finished))
    assert study._others(first, todo) == [finished]
    assert study.status(first, done, study._others(first, todo)) == "running"


@pytest.mark.parametrize("shortest_first, expected", [(False, [2, 0, 1]), (True, [1, 0, 2])])
def test_rounds_are_handed_out_the_longest_or_the_shortest_first(monkeypatch, shortest_first,
                                                                 expected):
    """study._run_here in the order of study.urgency: the costliest round (disks times
    collisions per disk) first, or with shortest_first the cheapest."""
    study = _study()
    plan = sys.modules["plan"]
    points = {p.folder.name: p for p in plan.points(plan.PLAN, Path("unused"))}
    rounds = [(points["72-square-0.650"], 2_000_000), (points["224-square-0.670"], 300_000),
              (points["16384-square-0.698"], 80_000)]  # 1.44e8, 6.72e7, 1.31e9 collisions
    done = []
    monkeypatch.setattr(study, "_pending", lambda todo: [r for r in rounds if r not in done])
    monkeypatch.setattr(study, "advance", lambda point, length: done.append((point, length)))
    monkeypatch.setattr(study, "_report", lambda *args: None)
    study._run_here([], study.urgency(shortest_first))
    assert done == [rounds[k] for k in expected]


def test_replicas_that_scatter_more_than_their_errors_run_on(tmp_path):
    """study.status and next_length with the replicas' scale factor: two runs of one state
    point and start, each within its own target, 2.7 combined errors apart, have not sampled
    what their errors claim (S ≈ 2.7) and both run on; close together, both are done."""
    long = {"start": "compressed", "seed": 0, "collisions_per_disk": 1_200_000,
            "bPd2": 9.1619, "err": 0.0043, "converged": True, "drift": 0.0, "blocks": 1190,
            "cut": 9}
    short = dict(long, seed=1, collisions_per_disk=240_000, bPd2=9.1419, err=0.0061,
                 blocks=235, cut=5)
    study, todo, first, later = _seed_and_replica(tmp_path, long, short)
    assert study._scale(first, long, study._others(first, todo)) == pytest.approx(2.68, abs=0.01)
    for point, record in ((first, long), (later, short)):
        others = study._others(point, todo)
        assert study.status(point, record, others) == "running"
        assert study.next_length(point, record, others) > record["collisions_per_disk"]
    close = dict(short, bPd2=9.1600)
    (later.folder / "point.json").write_text(json.dumps(close))
    assert study.status(first, long, study._others(first, todo)) == "done"
    assert study.status(later, close, study._others(later, todo)) == "done"


def test_a_stop_that_reaches_a_worker_of_the_pool_between_runs_stops_its_next_run(
        monkeypatch):
    """Ctrl-C reaches every process of the study's group. A worker of the pool starts with
    SIGINT and SIGTERM blocked (held back while the study starts it); one that came during
    its start-up, or while it waits for work, is taken as a request that its next run stop
    at its first chunk, and raises nothing (no traceback from a worker not running)."""
    import signal

    monkeypatch.setattr(Interruption, "early", None)
    monkeypatch.setattr(Interruption, "last_signal", None)
    handlers = {number: signal.getsignal(number) for number in STOPS}
    held = signal.pthread_sigmask(signal.SIG_BLOCK, STOPS)  # as a worker starts
    try:
        signal.raise_signal(signal.SIGINT)  # during its start-up: pending, not delivered
        assert Interruption.early is None
        between_jobs(Interruption.take_early)  # the pool's initializer
        assert Interruption.early == signal.SIGINT
        assert not signal.pthread_sigmask(signal.SIG_BLOCK, ()) & STOPS
        signal.raise_signal(signal.SIGTERM)  # while it waits for work
        assert Interruption.early == signal.SIGTERM
        with Interruption() as interruption:  # its next run stops at its first chunk
            assert interruption.requested
    finally:  # a signal still pending is dropped, not raised into the test session
        for number in STOPS:
            signal.signal(number, signal.SIG_IGN)
        signal.pthread_sigmask(signal.SIG_SETMASK, held)
        for number, handler in handlers.items():
            signal.signal(number, handler)


def test_a_clone_keeps_the_coexistence_snapshot_it_cannot_draw(tmp_path):
    """With no run file of N = 128² here, the ψ₆ figure of the ledger's folder is kept as it
    is (its snapshot needs a run file; its g₆ traces could not have changed), not redrawn
    with an empty panel; with no such figure, one is drawn."""
    _study()
    figures = sys.modules["figures"]
    records = [{"n": figures.TRACED, "phi": 0.708, "start": "compressed", "seed": 0,
                "trace": {"r": [1.0, 2.0], "g6": [0.9, 0.5]}}]
    kept = tmp_path / "ledger" / "melting_psi6.png"
    kept.parent.mkdir()
    kept.write_bytes(b"the committed figure")
    results = tmp_path / "results"
    results.mkdir()
    figures.draw_bond_order(records, [], tmp_path / "out", results, kept_in=kept.parent)
    assert (results / "melting_psi6.png").read_bytes() == b"the committed figure"
    kept.unlink()
    figures.draw_bond_order(records, [], tmp_path / "out", results, kept_in=kept.parent)
    assert (results / "melting_psi6.png").read_bytes()[:4] == b"\x89PNG"
