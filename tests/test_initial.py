"""Initial states: placement without overlap, where asked, reproducibly; velocity laws."""

import freud
import numpy as np
import pytest
from scipy import stats

from sim.checks.audit import outside_box, overlapping_pairs
from sim.pipeline.initial import (
    PlacementError,
    fixed_speed,
    hexagonal_lattice,
    maxwellian,
    melted_lattice,
    radius_for_packing,
    random_sequential,
    remove_drift,
)


@pytest.mark.parametrize("periodic", [(False, False), (True, True)])
def test_random_placement_polydisperse_without_overlap(periodic):
    rng = np.random.default_rng(0)
    radius = rng.uniform(0.003, 0.009, 3000)
    position = random_sequential(radius, periodic=periodic, seed=1)
    assert overlapping_pairs(position, radius, periodic=periodic, tolerance=0.0)[0].size == 0
    assert outside_box(position, radius, periodic=periodic, tolerance=0.0).size == 0
    np.testing.assert_array_equal(position, random_sequential(radius, periodic=periodic, seed=1))
    assert not np.array_equal(position, random_sequential(radius, periodic=periodic, seed=2))


def test_random_placement_stays_in_its_region():
    radius = np.full(2000, 0.0045)
    position = random_sequential(radius, region=((0.0, 1.0), (0.0, 0.5)), seed=3)
    assert position[:, 1].max() <= 0.5 - 0.0045
    assert position[:, 1].min() >= 0.0045


def test_random_placement_error_reports_the_packing_reached():
    with pytest.raises(PlacementError, match=r"stopped at packing fraction 0\.[45]\d\d"):
        random_sequential(np.full(2000, np.sqrt(0.6 / (2000 * np.pi))), seed=4)


def test_lattice_in_a_region_with_jitter():
    radius = 0.0045
    position = hexagonal_lattice(4000, radius, region=((0.0, 1.0), (0.0, 0.5)), seed=5)
    assert overlapping_pairs(position, radius, tolerance=0.0)[0].size == 0
    assert position[:, 1].max() <= 0.5 - radius and position[:, 1].min() >= radius
    assert np.unique(np.round(position[:, 1], 6)).size > 100  # jittered, not bare rows


def global_bond_order(position, region):
    """|⟨ψ₆⟩| over the disks of a walled region ((x0, x1), (y0, y1)), from freud (the test's
    oracle), six nearest neighbours; the region is set in a box twice its size so that no
    neighbour is found across a wall."""
    (x0, x1), (y0, y1) = region
    box = freud.box.Box(Lx=2 * (x1 - x0), Ly=2 * (y1 - y0), is2D=True)
    points = np.column_stack([position[:, 0] - x1, position[:, 1] - y1, np.zeros(len(position))])
    hexatic = freud.order.Hexatic(k=6)
    hexatic.compute((box, points), neighbors={"num_neighbors": 6})
    return float(np.abs(hexatic.particle_order.mean()))


def test_melted_lattice_is_a_fluid_without_overlap():
    """The crater bed's packing (φ = 0.51 in the lower half of the box): the jittered lattice
    is a crystal (|ψ₆| ≈ 0.9); melted, its global order is a fluid's, within three times the
    1/√n of uncorrelated bond angles, and no disk overlaps another or a wall."""
    n, radius, region = 4000, 0.0045, ((0.0, 1.0), (0.0, 0.5))
    crystal = hexagonal_lattice(n, radius, region=region, seed=5)
    fluid = melted_lattice(n, radius, region=region, seed=5)
    assert global_bond_order(crystal, region) > 0.8
    assert global_bond_order(fluid, region) < 3.0 / np.sqrt(n)
    # disks may touch, to round-off, as they do at the melt's last collision (the engine's
    # own check of its input allows it: 1e-9 of the contact distance)
    assert overlapping_pairs(fluid, np.full(n, radius))[0].size == 0
    inner = radius * (1.0 - 1e-9)
    assert fluid[:, 1].max() <= 0.5 - inner and fluid.min() >= inner
    np.testing.assert_array_equal(fluid, melted_lattice(n, radius, region=region, seed=5))


def test_lattice_error_names_the_limit():
    with pytest.raises(PlacementError, match="0.9069"):
        hexagonal_lattice(1000, np.sqrt(0.93 / (1000 * np.pi)))


def test_fixed_speed_directions_are_uniform():
    v = fixed_speed(20_000, 2.5, seed=6)
    np.testing.assert_allclose(np.hypot(*v.T), 2.5, rtol=1e-15)
    angle = np.arctan2(v[:, 1], v[:, 0])
    assert stats.kstest(angle, stats.uniform(-np.pi, 2 * np.pi).cdf).pvalue > 1e-3


def test_maxwellian_components_and_zero_drift():
    mass = np.where(np.arange(20_000) % 2, 1.0, 4.0)
    v = remove_drift(maxwellian(mass, 0.7, seed=7), mass)
    assert np.abs((mass[:, None] * v).sum(axis=0)).max() < 1e-10
    for m in (1.0, 4.0):
        components = v[mass == m].ravel()
        assert stats.kstest(components, stats.norm(scale=np.sqrt(0.7 / m)).cdf).pvalue > 1e-3


#: arguments of the placement helpers that no scene can take: (call, the words of the refusal)
BAD_ARGUMENTS = {
    "lattice-no-disks": (lambda: hexagonal_lattice(0, 0.01), "hexagonal_lattice(n=0)"),
    "lattice-fractional-n": (lambda: hexagonal_lattice(2.5, 0.01), "hexagonal_lattice(n=2.5)"),
    "lattice-nan-radius": (lambda: hexagonal_lattice(10, np.nan), "entry 0 is nan"),
    "lattice-negative-radius": (lambda: hexagonal_lattice(10, -0.01), "radius=…"),
    "lattice-jitter-2": (lambda: hexagonal_lattice(10, 0.01, jitter=2.0), "jitter=2.0"),
    "speeds-of-no-disks": (lambda: fixed_speed(-1, 1.0), "fixed_speed(n=-1)"),
    "speeds-nan": (lambda: fixed_speed(3, np.nan), "fixed_speed(speed=nan)"),
    "random-nan-radius": (lambda: random_sequential([0.01, np.nan]), "entry 1 is nan"),
    "random-negative-radius": (lambda: random_sequential([0.01, -0.01]), "entry 1 is -0.01"),
    "maxwellian-negative-temperature": (lambda: maxwellian(np.ones(4), -1.0),
                                        "maxwellian(temperature=-1.0)"),
    "maxwellian-zero-mass": (lambda: maxwellian([1.0, 0.0], 1.0), "entry 1 is 0.0"),
    "packing-above-one": (lambda: radius_for_packing(10, 2.0),
                          "radius_for_packing(packing_fraction=2.0)"),
    "packing-complex": (lambda: radius_for_packing(10, 0.5j), "packing_fraction=0.5j"),
}


@pytest.mark.parametrize("case", sorted(BAD_ARGUMENTS))
def test_placement_helpers_refuse_bad_arguments_naming_them(case):
    call, words = BAD_ARGUMENTS[case]
    with pytest.raises(ValueError) as refusal:
        call()
    assert words in str(refusal.value) and "\n" not in str(refusal.value)
