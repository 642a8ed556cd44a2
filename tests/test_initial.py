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


def test_random_placement_error_names_radius_and_reports_the_packing_reached():
    with pytest.raises(PlacementError, match=r"^random_sequential\(radius=…\) is not allowed: "
                                             r".*stopped at packing fraction 0\.[45]\d\d"):
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


def test_lattice_error_names_radius_and_the_limit():
    with pytest.raises(PlacementError, match=r"^hexagonal_lattice\(radius=.*\) is not allowed: "
                                             r".*0\.9069"):
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


#: ten small radii, for the placement refusals below
R = np.full(10, 0.01)

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
    # boxes, regions and periodic flags that gave NaN positions or disks outside the box
    "random-box-nan": (lambda: random_sequential(R, box=(np.nan, 1)),
                       "random_sequential(box=(nan, 1))"),
    "random-box-inf": (lambda: random_sequential(R, box=(np.inf, 1)), "box=(inf, 1)"),
    "random-box-negative": (lambda: random_sequential(R, box=(-1, 1)), "box=(-1, 1)"),
    "random-box-three-sides": (lambda: random_sequential(R, box=(1, 1, 1)), "box=(1, 1, 1)"),
    "random-box-number": (lambda: random_sequential(R, box=1.0), "box=1.0"),
    "random-region-outside": (lambda: random_sequential(R, region=((-5, 5), (0, 1))),
                              "region=((-5, 5), (0, 1))"),
    "random-region-inverted": (lambda: random_sequential(R, region=((0.8, 0.2), (0, 1))),
                               "region=((0.8, 0.2), (0, 1))"),
    "random-region-nan": (lambda: random_sequential(R, region=((0, np.nan), (0, 1))),
                          "region=((0, nan), (0, 1))"),
    "random-region-shape": (lambda: random_sequential(R, region=(0, 1)), "region=(0, 1)"),
    "random-disk-wider-than-box": (lambda: random_sequential(np.full(1, 0.6)),
                                   "a diameter 1.2 does not fit"),
    "random-disk-wider-than-region": (
        lambda: random_sequential(R, region=((0, 1), (0, 0.015))), "its side 0.015 along y"),
    "random-periodic-text": (lambda: random_sequential(R, periodic="yes"), "periodic='yes'"),
    "random-periodic-numbers": (lambda: random_sequential(R, periodic=(1, 0)),
                                "periodic=(1, 0)"),
    "random-periodic-three": (lambda: random_sequential(R, periodic=(True,) * 3),
                              "periodic=(True, True, True)"),
    "lattice-box-nan": (lambda: hexagonal_lattice(10, 0.01, box=(np.nan, 1)),
                        "hexagonal_lattice(box=(nan, 1))"),
    "lattice-box-inf": (lambda: hexagonal_lattice(10, 0.01, box=(np.inf, np.inf)),
                        "box=(inf, inf)"),
    "lattice-box-negative": (lambda: hexagonal_lattice(10, 0.01, box=(-1, -1)),
                             "hexagonal_lattice(box=(-1, -1))"),
    "lattice-region-inverted": (lambda: hexagonal_lattice(10, 0.01, region=((0, 1), (1, 0))),
                                "region=((0, 1), (1, 0))"),
    "lattice-periodic-text": (lambda: hexagonal_lattice(10, 0.01, periodic="no"),
                              "periodic='no'"),
    "lattice-radii-not-n": (lambda: hexagonal_lattice(10, [0.01, 0.02]), "one for each"),
    "melt-box-nan": (lambda: melted_lattice(10, 0.01, box=(np.nan, 1)),
                     "melted_lattice(box=(nan, 1))"),
    # arrays of the wrong shape
    "random-no-radii": (lambda: random_sequential([]), "random_sequential(radius=…)"),
    "random-radii-2d": (lambda: random_sequential(np.full((2, 2), 0.01)), "1-D array"),
    "maxwellian-masses-2d": (lambda: maxwellian([[1, 2], [3, 4]], 1),
                             "maxwellian(mass=…) is not allowed: a mass, or a 1-D array"),
    "maxwellian-no-masses": (lambda: maxwellian([], 1), "maxwellian(mass=…)"),
    "drift-zero-mass": (lambda: remove_drift(np.ones((2, 2)), 0.0), "entry 0 is 0.0"),
    "drift-masses-sum-zero": (lambda: remove_drift(np.ones((2, 2)), [1.0, -1.0]),
                              "entry 1 is -1.0"),
    "drift-nan-velocity": (lambda: remove_drift([[1.0, np.nan], [0.0, 0.0]], 1.0),
                           "remove_drift(velocity=…) is not allowed: entry 1 is nan"),
    "drift-velocity-shape": (lambda: remove_drift([1.0, 2.0], 1.0), "an array (n, 2)"),
    "drift-masses-not-n": (lambda: remove_drift(np.ones((3, 2)), [1.0, 2.0]),
                           "one for each of the n = 3"),
    "drift-text": (lambda: remove_drift("fast", 1.0), "remove_drift(velocity='fast')"),
    # seeds: whole numbers from 0 to 2^64 - 1, as numpy takes them
    "random-seed-negative": (lambda: random_sequential(R, seed=-1),
                             "random_sequential(seed=-1) is not allowed: a whole number from "
                             "0 to 2^64 - 1"),
    "random-seed-fractional": (lambda: random_sequential(R, seed=1.5), "seed=1.5"),
    "random-seed-too-large": (lambda: random_sequential(R, seed=2**64), "seed=1844"),
    "speed-seed-negative": (lambda: fixed_speed(3, 1.0, seed=-3), "fixed_speed(seed=-3)"),
    "lattice-seed-text": (lambda: hexagonal_lattice(10, 0.01, seed="x"),
                          "hexagonal_lattice(seed='x')"),
    "maxwellian-seed-none": (lambda: maxwellian(1.0, 1.0, seed=None), "seed=None"),
    "melt-seed-negative": (lambda: melted_lattice(10, 0.01, seed=-1),
                           "melted_lattice(seed=-1)"),
    # attempts and melts: refused, not a jam or a run that never ends
    "random-attempts-nan": (lambda: random_sequential(R, max_attempts=np.nan),
                            "max_attempts=nan"),
    "random-attempts-huge": (lambda: random_sequential(R, max_attempts=1e300),
                             "max_attempts=1e+300"),
    "random-attempts-zero": (lambda: random_sequential(R, max_attempts=0),
                             "random_sequential(max_attempts=0) is not allowed: a whole number "
                             "from 1 to"),
    "random-attempts-negative": (lambda: random_sequential(R, max_attempts=-1),
                                 "max_attempts=-1"),
    "melt-nan": (lambda: melted_lattice(10, 0.01, collisions_per_disk=np.nan),
                 "melted_lattice(collisions_per_disk=nan)"),
    "melt-inf": (lambda: melted_lattice(10, 0.01, collisions_per_disk=np.inf),
                 "collisions_per_disk=inf"),
    "melt-negative": (lambda: melted_lattice(10, 0.01, collisions_per_disk=-1),
                      "melted_lattice(collisions_per_disk=-1)"),
    "melt-for-ever": (lambda: melted_lattice(10, 0.01, collisions_per_disk=1e12),
                      "collisions_per_disk=1000000000000.0) is not allowed: a number of "
                      "collisions per disk from 0 to 10000"),
}

#: the refusals that are :class:`PlacementError` (disks that do not fit, which a scene's
#: packing is refused for); every other is a plain ValueError naming an argument
DO_NOT_FIT = {"random-disk-wider-than-box", "random-disk-wider-than-region"}


@pytest.mark.parametrize("case", sorted(BAD_ARGUMENTS))
def test_placement_helpers_refuse_bad_arguments_naming_them(case):
    call, words = BAD_ARGUMENTS[case]
    with pytest.raises(ValueError) as refusal:
        call()
    assert words in str(refusal.value) and "\n" not in str(refusal.value)
    assert isinstance(refusal.value, PlacementError) == (case in DO_NOT_FIT)


def test_placement_helpers_take_what_their_docstrings_allow():
    """One flag for both axes, whole floats and numpy numbers, the largest seed, lists, and a
    single disk to melt (nothing to collide with: it stays on its site)."""
    np.testing.assert_array_equal(random_sequential(R, periodic=True, seed=np.int64(3)),
                                  random_sequential(R, periodic=(True, True), seed=3))
    np.testing.assert_array_equal(hexagonal_lattice(10, 0.01, periodic=np.bool_(False)),
                                  hexagonal_lattice(10, 0.01))
    assert random_sequential(R, seed=2**64 - 1, max_attempts=1e3).shape == (10, 2)
    np.testing.assert_array_equal(fixed_speed(3, 1.0, seed=5.0), fixed_speed(3, 1.0, seed=5))
    assert maxwellian(2.0, 1.0).shape == (1, 2)
    np.testing.assert_array_equal(remove_drift([[1.0, 2.0], [3.0, 4.0]], [1.0, 1.0]),
                                  [[-1.0, -1.0], [1.0, 1.0]])
    position = random_sequential(R, box=(2.0, 0.5), region=((1.0, 2.0), (0.0, 0.5)), seed=1)
    assert position[:, 0].min() >= 1.01 and position[:, 1].max() <= 0.49
    np.testing.assert_array_equal(melted_lattice(1, 0.1, seed=4),
                                  hexagonal_lattice(1, 0.1, seed=4))
    assert melted_lattice(1, 0.1, collisions_per_disk=1e4).shape == (1, 2)
