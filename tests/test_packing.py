"""The structure of packings (sim.analysis.packing): ψ₆ against freud, contacts and rattlers
against hand-made packings and an all-pairs count, and the backbone of a jammed packing."""

import freud
import numpy as np
import pytest

from sim.analysis.packing import (
    backbone,
    bond_order,
    contact_number,
    contact_numbers,
    contacts,
    global_bond_order,
    orientational_correlation,
)
from sim.engine.box import nearest_images
from sim.pipeline.initial import hexagonal_lattice, random_sequential
from sim.pipeline.runner import build_engine
from variants import compose_scene


def _freud_order(position, box):
    """ψ₆ of every disk by freud: Voronoi neighbours, unweighted Hexatic(k=6)."""
    system = (freud.box.Box(*box, is2D=True),
              np.column_stack([position - 0.5 * np.asarray(box), np.zeros(len(position))]))
    voronoi = freud.locality.Voronoi()
    voronoi.compute(system)
    hexatic = freud.order.Hexatic(k=6)
    hexatic.compute(system, neighbors=voronoi.nlist)
    return hexatic.particle_order


@pytest.mark.parametrize("kind", ["fluid", "crystal"])
def test_bond_order_agrees_with_freud(kind):
    box = (1.0, 1.0)
    rng = np.random.default_rng(3)
    if kind == "fluid":
        position = random_sequential(np.full(400, 0.012), periodic=(True, True), seed=4)
    else:  # a hexagonal lattice, jittered, in a box it fits
        position = hexagonal_lattice(400, 0.02, periodic=(True, True), seed=4)
        position = (position + rng.normal(0.0, 0.002, position.shape)) % 1.0
    psi = bond_order(position, box, (True, True))
    oracle = _freud_order(position, box)
    # freud works in float32; and where four centres lie almost on one circle (a Voronoi
    # face of length ~0) the two triangulations may take different neighbours: a few disks
    agree = np.abs(psi - oracle) < 1e-4
    assert agree.mean() >= 0.99
    assert abs(abs(psi.mean()) - abs(oracle.mean())) < 1e-3
    order = global_bond_order(position, box, (True, True))
    assert (order > 0.5) if kind == "crystal" else (order < 3.0 / np.sqrt(400))


def test_orientational_correlation_agrees_with_freud():
    """g₆(r) of a jittered crystal against freud's CorrelationFunction of the same ψ₆ on the
    same frame (freud sums in float32: agreement to 1e-5)."""
    box = (1.0, 1.0)
    rng = np.random.default_rng(7)
    position = (hexagonal_lattice(400, 0.02, periodic=(True, True), seed=4)
                + rng.normal(0.0, 0.003, (400, 2))) % 1.0
    psi = bond_order(position, box, (True, True))
    r, g6 = orientational_correlation(position, psi, box, (True, True), 20, 0.4)
    system = (freud.box.Box(*box, is2D=True),
              np.column_stack([position - 0.5, np.zeros(len(position))]))
    oracle = freud.density.CorrelationFunction(bins=20, r_max=0.4)
    oracle.compute(system, values=psi, neighbors={"r_max": 0.4, "exclude_ii": True})
    filled = np.isfinite(g6)
    assert filled.sum() >= 15 and np.allclose(r, oracle.bin_centers)
    assert np.allclose(g6[filled], oracle.correlation[filled], atol=1e-5)


def test_contacts_are_the_pairs_closer_than_the_tolerance():
    rng = np.random.default_rng(5)
    radius = rng.uniform(0.01, 0.02, 300)
    position = random_sequential(radius, periodic=(True, True), seed=6)
    box, periodic = np.ones(2), (True, True)
    r = nearest_images(position[:, None] - position[None], box, periodic)
    gap = np.hypot(r[..., 0], r[..., 1]) - radius[:, None] - radius[None]
    for tolerance in (1e-3, 0.05, 0.2):
        close = np.argwhere(np.triu(gap < tolerance * 2.0 * radius.mean(), 1))
        found = contacts(position, radius, box, periodic, tolerance)
        assert sorted(map(tuple, found.tolist())) == sorted(map(tuple, close.tolist()))


def test_rattlers_are_removed_until_every_disk_left_is_held():
    # a chain 0-1-2-3 held by nothing; four disks 4..7 each touching the three others, and 8
    # touching two of them; 9 touching none
    pairs = np.array([[0, 1], [1, 2], [2, 3],
                      [4, 5], [4, 6], [4, 7], [5, 6], [5, 7], [6, 7], [8, 4], [8, 5]])
    assert backbone(pairs, 10).tolist() == [False] * 4 + [True] * 4 + [False, False]
    # without 6-7, 6 and 7 have two contacts each; then 4 and 5 are left with two: none is held
    assert not backbone(np.delete(pairs, 8, axis=0), 10).any()


def test_a_crystal_at_contact_has_six_contacts_and_no_rattler():
    n = 16 * 14  # a hexagonal lattice that fits the box exactly: every disk touches six
    lx = 1.0
    radius = lx / 32.0
    ly = 14 * np.sqrt(3.0) * radius
    x = np.arange(16) * 2.0 * radius
    rows = [np.column_stack([x + (radius if k % 2 else 0.0),
                             np.full(16, k * np.sqrt(3.0) * radius)]) for k in range(14)]
    position = np.vstack(rows) + 0.25 * radius
    z, rattlers, count = contact_number(position, np.full(n, radius), (lx, ly), (True, True),
                                        1e-9)
    assert z == pytest.approx(6.0) and rattlers == 0.0 and count == 3 * n


def test_a_jammed_packing_is_isostatic_on_its_plateau():
    """An LS packing of the compress scene at βP/ρ = 10⁹: its contacts lie at gaps of about
    10⁻⁸ σ, the next neighbours' at 10⁻³ σ and beyond, and between the two (10⁻⁷ to 10⁻⁴) the
    backbone's z is flat and near the isostatic 4 of frictionless disks (4 − 2/N_b in a
    periodic box)."""
    engine = build_engine(compose_scene("compress", "disks.n=300", "growth.rate=0.1"))
    assert engine.run(jamming=1e9) == "jamming"
    tolerances = np.logspace(-7, -4, 4)
    z, rattlers = contact_numbers(engine.positions(), engine.radii(), engine.box,
                                  engine.periodic, tolerances)
    assert np.ptp(z) < 0.05
    assert 3.9 < z.mean() < 4.05
    assert 0.0 <= rattlers.mean() < 0.15


def test_bond_order_of_a_frame_at_coexistence_agrees_with_freud_disk_by_disk(tmp_path):
    """The last frame of the melting scene as shipped (N = 870 at φ = 0.70, inside the
    liquid–hexatic coexistence) after 20 collisions per disk: sim's and freud's Voronoi
    neighbours are the same for nearly every disk, and where they are, ψ₆ agrees to freud's
    float32 round-off; the ψ₆ the observer wrote is that of the frame's positions, and g₆(r)
    agrees with freud's on the same frame."""
    from sim.analysis.datasets import open_run
    from sim.analysis.packing import voronoi_neighbours
    from sim.pipeline.runner import run

    cfg = compose_scene("melting", "stop.collisions=17400", "output.every_collisions=8700")
    with open_run(run(cfg, tmp_path)) as data:
        last = data.isel(time=-1)
        position, stored = last["position"].values, last["bond_order"].values
        box = tuple(data.attrs["box"])
    psi = bond_order(position, box, (True, True))
    assert np.array_equal(stored[:, 0] + 1j * stored[:, 1], psi)
    n = len(position)
    ours = [set() for _ in range(n)]
    for i, j in voronoi_neighbours(position, box, (True, True)):
        ours[i].add(j)
        ours[j].add(i)
    system = (freud.box.Box(*box, is2D=True),
              np.column_stack([position - 0.5 * np.asarray(box), np.zeros(n)]))
    voronoi = freud.locality.Voronoi()
    voronoi.compute(system)
    theirs = [set() for _ in range(n)]
    for i, j in voronoi.nlist[:]:
        theirs[i].add(j)
    same = np.array([a == b for a, b in zip(ours, theirs, strict=True)])
    assert same.mean() >= 0.99
    oracle = _freud_order(position, box)
    assert np.max(np.abs(psi - oracle)[same]) < 1e-5
    diameter = 2.0 * float(data["radius"][0])
    r, g6 = orientational_correlation(position, psi, box, (True, True), 24, 6 * diameter)
    correlation = freud.density.CorrelationFunction(bins=24, r_max=6 * diameter)
    correlation.compute(system, values=psi, neighbors={"r_max": 6 * diameter,
                                                       "exclude_ii": True})
    filled = np.isfinite(g6)
    assert filled.sum() >= 20 and np.allclose(g6[filled], correlation.correlation[filled],
                                               atol=1e-5)
