"""What the engine refuses and where it stops: checked input, cells that cannot overflow, the
stall guard, errors of physics as one family, the piston guard after every chunk, and chunks
sized for a wall-clock budget."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import assert_no_overlap, gas
from sim.effects import loop_values
from sim.engine import (
    Boundary,
    ClosedBoxError,
    Engine,
    InelasticCollapseError,
    PhysicsBreakdown,
    StalledError,
)
from sim.engine.overlap import first_overlap
from sim.engine.running import TIMED_FIRST_CHUNK
from sim.engine.sizing import cell_limit, grid_cells
from sim.pipeline.initial import (
    fixed_speed,
    hexagonal_lattice,
    radius_for_packing,
    random_sequential,
)
from variants import RECORDER_KEYWORDS, UNREACHED_THERMAL_WALL


def refused(match, *args, **options):
    """The one-line ValueError that ``Engine(*args, **options)`` raises, matching ``match``."""
    with pytest.raises(ValueError, match=match) as caught:
        Engine(*args, **options)
    assert "\n" not in str(caught.value)
    return str(caught.value)


# -- 1. the input is checked ----------------------------------------------------------------
def brute_first_overlap(position, radius, box, periodic, tolerance=1e-9):
    """The definition of :func:`sim.engine.overlap.first_overlap`, pair by pair."""
    for i in range(len(radius)):
        r = position[i] - position[:i]
        r -= np.where(periodic, box * np.round(r / box), 0.0)
        distance = np.hypot(r[:, 0], r[:, 1])
        bad = np.flatnonzero(distance < (radius[i] + radius[:i]) * (1.0 - tolerance))
        if bad.size:
            return i, int(bad[0])
    return None


@settings(max_examples=60, deadline=None)
@given(n=st.integers(2, 80), seed=st.integers(0, 10_000), periodic=st.booleans(),
       spread=st.sampled_from([1.0, 3.0, 30.0]), size=st.floats(0.005, 0.3))
def test_first_overlap_is_the_first_disk_that_overlaps_one_before_it(n, seed, periodic, spread,
                                                                     size):
    """Against all pairs, for radii spread over up to a factor 30 (several grid levels), and
    disks so large that a periodic axis has only a few cells."""
    rng = np.random.default_rng(seed)
    radius = size * spread ** rng.uniform(-1.0, 0.0, n)
    box = np.array([1.0, 0.7])
    position = rng.uniform(0.0, 1.0, (n, 2)) * box
    if not periodic:
        position = np.clip(position, radius[:, None], box - radius[:, None])
    found = first_overlap(position, radius, box, (periodic, periodic))
    expected = brute_first_overlap(position, radius, box, (periodic, periodic))
    assert (found if found is None else found[:2]) == expected


def test_overlapping_disks_are_refused_naming_the_first():
    n = 30
    radius = np.full(n, 0.02)
    position = random_sequential(radius, seed=5)
    position[17] = position[3] + [0.03, 0.0]  # 0.03 < 0.04 from disk 3
    position[25] = position[4]
    message = refused(r"^disk 17 at \[.*\] overlaps disk 3 \(distance 0\.03 < contact "
                      r"distance 0\.04\)", position, np.zeros((n, 2)), radius)
    assert "may touch" in message
    # across the side of a periodic box, also when an axis has three cells
    refused("disk 1 at .* overlaps disk 0", [[0.05, 0.5], [0.95, 0.5]], np.zeros((2, 2)), 0.13,
            boundary=Boundary(periodic=(True, True)))
    refused("disk 1 at .* overlaps disk 0", [[0.005, 0.5], [0.99, 0.5]], np.zeros((2, 2)), 0.01,
            boundary=Boundary(periodic=(True, True)))
    # a large disk over small ones given before it
    small = hexagonal_lattice(200, 0.01, seed=2)
    position = np.vstack([small, [[0.5, 0.5]]])
    radius = np.append(np.full(200, 0.01), 0.1)
    refused("disk 200 at .* overlaps disk", position, np.zeros((201, 2)), radius)
    # disks placed exactly in contact stay accepted
    r = 0.02
    row = [[r + 2 * r * k, 0.5] for k in range(10)]
    assert Engine(row, np.zeros((10, 2)), r).n == 10


def test_bad_values_are_refused_naming_the_disk_or_parameter():
    position = hexagonal_lattice(10, 0.02, seed=1)
    velocity = np.zeros((10, 2))
    p = position.copy()
    p[4, 1] = np.nan
    refused(r"disk 4 has position \[.*nan\]", p, velocity, 0.02)
    v = velocity.copy()
    v[6, 0] = np.inf
    refused(r"disk 6 has velocity \[inf", position, v, 0.02)
    for bad in (0.0, -0.02, np.nan, np.inf):
        radius = np.full(10, 0.02)
        radius[2] = bad
        refused(r"disk 2 has radius .*: a radius must be finite and > 0", position, velocity,
                radius)
        mass = np.ones(10)
        mass[7] = bad
        refused(r"disk 7 has mass .*: a mass must be finite and > 0", position, velocity, 0.02,
                mass)
    p = position.copy()
    p[3] = [0.01, 0.5]
    refused(r"disk 3 at \[0\.01, 0\.5\] with radius 0\.02 pokes through a wall", p, velocity,
            0.02)
    # a disk as wide as the box touches both walls for ever
    refused(r"disk 0 of radius 0\.5 does not fit between the walls 1 apart along x",
            [[0.5, 0.5]], [[0.0, 0.0]], 0.5)
    refused(r"disk 1 of radius 0\.3 does not fit between the walls 0\.5 apart along y",
            [[0.5, 0.25], [0.4, 0.25]], [[0.0, 0.0]] * 2, [0.01, 0.3],
            boundary=Boundary(size=(1.0, 0.5)))
    for size in ((1.0, np.nan), (0.0, 1.0), (1.0, np.inf)):
        refused(r"Boundary\(size=\(.*\)\) is not allowed: two finite sides \(Lx, Ly\) > 0",
                position, velocity, 0.02, boundary=Boundary(size=size))

    def wall(**spec):
        return {"walls": {"left": {"temperature": 1.0}, "top": spec}}

    for t_wall in (np.inf, np.nan, 0.0, -1.0):
        refused(r"top wall: temperature .* must be finite and > 0", position, velocity, 0.02,
                **wall(temperature=t_wall))
    for spec in ({"speed": np.nan}, {"speed": np.inf}, {"amplitude": -0.1, "frequency": 1.0},
                 {"amplitude": 0.1, "frequency": np.inf}, {"amplitude": np.nan}):
        refused(r"^Engine\(walls=.* top wall: (speed|amplitude|frequency) .* must be finite",
                position, velocity, 0.02, **wall(**spec))
    refused(r"top wall: unknown keys \['temprature'\]", position, velocity, 0.02,
            **wall(temprature=1.0))
    for g in ([0.0, np.nan], [np.inf, 0.0]):
        refused(r"^Engine\(gravity=\[.*\]\) is not allowed: two finite numbers", position,
                velocity, 0.02, gravity=g)
    for tc in (np.nan, np.inf, -1e-8):
        refused(r"^Engine\(tc=.*\) is not allowed: the TC-model time t_c, finite and ≥ 0",
                position, velocity, 0.02, restitution=0.9, tc=tc)
    for xi in (np.nan, 1.5, -0.1):
        refused(r"^Engine\(restitution=.*\) is not allowed: .* in \[0, 1\]", position,
                velocity, 0.02, restitution=xi)
        refused(r"^Engine\(wall_restitution=.*\) is not allowed: a number in \[0, 1\]",
                position, velocity, 0.02, wall_restitution=xi)
    for seed in (-1, 2**63, 1.5, "7"):
        refused(r"^Engine\(seed=.*\) is not allowed: a whole number from 0 to 2\^63 - 1",
                position, velocity, 0.02, seed=seed)
    assert Engine(position, velocity, 0.02, seed=2**63 - 1).seed == 2**63 - 1


def test_the_engine_refuses_what_is_not_real_numbers_naming_the_argument():
    position, velocity = [[0.3, 0.5], [0.7, 0.5]], [[1.0, 0.0], [-1.0, 0.0]]
    refused(r"Engine\(position=…\) is not allowed: real numbers", [[0.3 + 1j, 0.5], [0.7, 0.5]],
            velocity, 0.01)
    refused(r"Engine\(radius='0.01'\) is not allowed", position, velocity, "0.01")
    refused(r"Engine\(velocity=…\)", position, [[1.0], [-1.0, 0.0]], 0.01)
    refused(r"Engine\(species=…\) is not allowed: whole numbers", position, velocity, 0.01,
            species=[0.5, 1])
    refused(r"^Engine\(restitution=…\) is not allowed: one number or a symmetric 2 × 2 matrix",
            position, velocity, 0.01, species=[0, 1], restitution=np.full((3, 3), 0.9))
    refused(r"^Engine\(radius=…\) is not allowed: one number, or one per disk \(2 numbers\)",
            position, velocity, [0.01, 0.01, 0.01])
    refused(r"^Engine\(mass=…\) is not allowed: one number, or one per disk",
            position, velocity, 0.01, [[1.0, 1.0]])
    refused(r"^Engine\(species=…\) is not allowed: whole numbers from 0 to 1023", position,
            velocity, 0.01, species=[0, 10**6])
    refused(r"^Engine\(boundary=\(1\.0, 1\.0\)\) is not allowed: a sim\.engine\.Boundary",
            position, velocity, 0.01, boundary=(1.0, 1.0))


#: Engine keywords that size its shells and lists, and boundaries, that no engine can take:
#: (keywords, the words of the refusal); each raised before any work, without a warning
BAD_ENGINE_OPTIONS = {
    "shell-nan": ({"shell": np.nan}, "Engine(shell=nan) is not allowed: a finite shell"),
    "shell-inf": ({"shell": np.inf}, "Engine(shell=inf)"),
    "shell-1e300": ({"shell": 1e300}, "Engine(shell=1e+300) is not allowed: at most 101 = 1 + L/R"),
    "shell-text": ({"shell": "2"}, "Engine(shell='2')"),
    "shell-bool": ({"shell": True}, "Engine(shell=True)"),
    "shell-1": ({"shell": 1.0}, "Engine(shell=1.0)"),
    "shell-below-1": ({"shell": 0.5}, "Engine(shell=0.5)"),
    "lead-nan": ({"shell_lead": np.nan}, "Engine(shell_lead=nan) is not allowed: a lead"),
    "lead-text": ({"shell_lead": "x"}, "Engine(shell_lead='x')"),
    "lead-1": ({"shell_lead": 1.0}, "Engine(shell_lead=1.0)"),
    "lead-negative": ({"shell_lead": -0.1}, "Engine(shell_lead=-0.1)"),
    "capacity-nan": ({"list_capacity": np.nan}, "Engine(list_capacity=nan) is not allowed: "
                                                "a whole number from 1 to 2"),
    "capacity-1e300": ({"list_capacity": 1e300}, "Engine(list_capacity=1e+300)"),
    "capacity-negative": ({"list_capacity": -3}, "Engine(list_capacity=-3)"),
    "capacity-0": ({"list_capacity": 0}, "Engine(list_capacity=0)"),
    "capacity-fractional": ({"list_capacity": 2.5}, "Engine(list_capacity=2.5)"),
    "capacity-text": ({"list_capacity": "8"}, "Engine(list_capacity='8')"),
    "capacity-beyond-n": ({"list_capacity": 3}, "Engine(list_capacity=3)"),
    "periodic-text": ({"boundary": Boundary(periodic="yes")}, "Boundary(periodic='yes') is "
                                                                 "not allowed: True or False"),
    "periodic-three": ({"boundary": Boundary(periodic=(True, True, False))},
                       "Boundary(periodic=(True, True, False))"),
    "periodic-numbers": ({"boundary": Boundary(periodic=(1, 1))}, "Boundary(periodic=(1, 1))"),
    "size-number": ({"boundary": Boundary(size=2.0)}, "Boundary(size=2.0)"),
}


@pytest.mark.parametrize("case", sorted(BAD_ENGINE_OPTIONS))
def test_the_engine_refuses_bad_sizing_options_naming_them(case):
    keywords, words = BAD_ENGINE_OPTIONS[case]
    message = refused("^Engine|^Boundary", [[0.3, 0.5], [0.7, 0.5]], [[1.0, 0.0], [-1.0, 0.0]],
                      0.01, **keywords)
    assert words in message


def test_the_engine_takes_sizing_options_as_documented():
    """Whole floats and numpy numbers; one flag for both periodic axes."""
    position, velocity = [[0.3, 0.5], [0.7, 0.5]], [[1.0, 0.0], [-1.0, 0.0]]
    engine = Engine(position, velocity, 0.01, shell=np.float32(1.5), shell_lead=0,
                    list_capacity=2.0, boundary=Boundary(periodic=True))
    assert engine.periodic.tolist() == [True, True]
    assert engine.disks.nb_cap.tolist() == [2, 2] and engine.geometry[5] == 0.0


PERIODIC = Boundary(periodic=True)
TWO_SPECIES = {"species": [0, 1]}

#: the effects' Engine keywords (each effect's KEYWORDS) that no engine can take: (keywords,
#: the words of the refusal, which names the keyword); ``species`` and ``boundary`` set the
#: scene. Each is refused before any work, in the format of sim.engine.inputs.refused.
BAD_EFFECT_KEYWORDS = {
    # restitution
    "restitution-nan": ({"restitution": np.nan},
                        "Engine(restitution=nan) is not allowed: one number or a symmetric "
                        "1 × 1 matrix"),
    "restitution-text": ({"restitution": "0.9"}, "Engine(restitution='0.9')"),
    "restitution-bool": ({"restitution": True}, "Engine(restitution=True)"),
    "restitution-shape": ({"restitution": [0.9, 0.9], **TWO_SPECIES},
                          "Engine(restitution=[0.9, 0.9]) is not allowed: one number or a "
                          "symmetric 2 × 2 matrix"),
    "restitution-asymmetric": ({"restitution": [[0.9, 0.8], [0.7, 0.9]], **TWO_SPECIES},
                               "Engine(restitution=[[0.9, 0.8], [0.7, 0.9]]) is not allowed: "
                               "a symmetric 2 × 2 matrix"),
    "wall_restitution-text": ({"wall_restitution": "0.5"},
                              "Engine(wall_restitution='0.5') is not allowed: a number in "
                              "[0, 1]"),
    "wall_restitution-bool": ({"wall_restitution": False}, "Engine(wall_restitution=False)"),
    "wall_restitution-list": ({"wall_restitution": [0.5] * 4}, "Engine(wall_restitution=…)"),
    "collapse_interval-nan": ({"collapse_interval": np.nan},
                              "Engine(collapse_interval=nan) is not allowed: a finite time > 0"),
    "collapse_interval-inf": ({"collapse_interval": np.inf}, "Engine(collapse_interval=inf)"),
    "collapse_interval-0": ({"collapse_interval": 0.0}, "Engine(collapse_interval=0.0)"),
    "collapse_interval-negative": ({"collapse_interval": -1e-6},
                                   "Engine(collapse_interval=-1e-06)"),
    "collapse_interval-text": ({"collapse_interval": "1e-6"},
                               "Engine(collapse_interval='1e-6')"),
    "collapse_streak-nan": ({"collapse_streak": np.nan},
                            "Engine(collapse_streak=nan) is not allowed: a whole number from 0 "
                            "to 2^62"),
    "collapse_streak-1e300": ({"collapse_streak": 1e300}, "Engine(collapse_streak=1e+300)"),
    "collapse_streak-negative": ({"collapse_streak": -1}, "Engine(collapse_streak=-1)"),
    "collapse_streak-fractional": ({"collapse_streak": 2.5}, "Engine(collapse_streak=2.5)"),
    "collapse_streak-bool": ({"collapse_streak": True}, "Engine(collapse_streak=True)"),
    "collapse_streak-text": ({"collapse_streak": "10"}, "Engine(collapse_streak='10')"),
    # tc
    "tc-text": ({"tc": "1e-4", "restitution": 0.9}, "Engine(tc='1e-4') is not allowed: the "
                                                    "TC-model time t_c, finite and ≥ 0"),
    "tc-bool": ({"tc": True, "restitution": 0.9}, "Engine(tc=True)"),
    "tc-complex": ({"tc": 1j}, "Engine(tc=1j)"),
    # gravity
    "gravity-text": ({"gravity": ["0", "-1"]}, "Engine(gravity=['0', '-1']) is not allowed: "
                                               "two finite numbers [gx, gy]"),
    "gravity-column": ({"gravity": [[0.0], [-1.0]]}, "Engine(gravity=[[0.0], [-1.0]])"),
    "gravity-three": ({"gravity": [0.0, -1.0, 0.0]}, "Engine(gravity=[0.0, -1.0, 0.0])"),
    "gravity-number": ({"gravity": -1.0}, "Engine(gravity=-1.0)"),
    "gravity-bools": ({"gravity": [False, True]}, "Engine(gravity=[False, True])"),
    "gravity-periodic": ({"gravity": [0.0, -1.0], "boundary": PERIODIC},
                         "Engine(gravity=[0.0, -1.0]) is not allowed: no component along a "
                         "periodic axis"),
    # walls
    "walls-text": ({"walls": "top"}, "Engine(walls='top') is not allowed: None or a mapping "
                                     "of wall names"),
    "walls-list": ({"walls": [("top", {"speed": 0.1})]}, "Engine(walls=…) is not allowed"),
    "walls-unknown-wall": ({"walls": {"roof": {"speed": 0.1}}},
                           "Engine(walls={'roof': {'speed': 0.1}}) is not allowed: unknown "
                           "wall 'roof'"),
    "walls-spec-number": ({"walls": {"top": 1.0}}, "Engine(walls={'top': 1.0}) is not allowed: "
                                                   "top wall: None or a mapping"),
    "walls-unknown-key": ({"walls": {"top": {"temprature": 1.0}}},
                          "is not allowed: top wall: unknown keys ['temprature']"),
    "walls-temperature-nan": ({"walls": {"top": {"temperature": np.nan}}},
                              "Engine(walls={'top': {'temperature': nan}}) is not allowed: top "
                              "wall: temperature nan must be finite and > 0"),
    "walls-temperature-text": ({"walls": {"top": {"temperature": "1"}}},
                               "top wall: temperature '1' must be finite and > 0"),
    "walls-temperature-bool": ({"walls": {"top": {"temperature": True}}},
                               "top wall: temperature True must be finite and > 0"),
    "walls-speed-text": ({"walls": {"top": {"speed": "0.1"}}},
                         "top wall: speed '0.1' must be finite"),
    "walls-speed-none": ({"walls": {"top": {"speed": None}}}, "top wall: speed None must be"),
    "walls-frequency-list": ({"walls": {"top": {"amplitude": 0.01, "frequency": [1.0, 2.0]}}},
                             "top wall: frequency [1.0, 2.0] must be finite and ≥ 0"),
    "walls-amplitude-without-frequency": ({"walls": {"top": {"amplitude": 0.01}}},
                                          "top wall: an angular frequency > 0 for a wall "
                                          "with an amplitude"),
    "walls-periodic": ({"walls": {"top": {"speed": 0.1}}, "boundary": PERIODIC},
                       "Engine(walls={'top': {'speed': 0.1}}) is not allowed: top wall is "
                       "given on a periodic axis"),
    # thermal walls: the seed
    "seed-nan": ({"seed": np.nan}, "Engine(seed=nan) is not allowed: a whole number from 0 "
                                   "to 2^63 - 1"),
    "seed-1e300": ({"seed": 1e300}, "Engine(seed=1e+300)"),
    "seed-bool": ({"seed": True}, "Engine(seed=True)"),
    "seed-text": ({"seed": "7"}, "Engine(seed='7')"),
    "seed-negative": ({"seed": -1}, "Engine(seed=-1)"),
    "seed-nan-spins": ({"seed": np.nan, "rotational_temperature": 1.0}, "Engine(seed=nan)"),
    # recorders
    "unwrap-text": ({"unwrap": "yes"}, "Engine(unwrap='yes') is not allowed: True or False"),
    "unwrap-1": ({"unwrap": 1}, "Engine(unwrap=1)"),
    "unwrap-none": ({"unwrap": None}, "Engine(unwrap=None)"),
    "pressure_tensor-text": ({"pressure_tensor": "no"},
                             "Engine(pressure_tensor='no') is not allowed: True or False"),
    "pressure_tensor-0": ({"pressure_tensor": 0}, "Engine(pressure_tensor=0)"),
    "pressure_tensor-text-rough": ({"pressure_tensor": "no", "tangential_restitution": 0.5},
                                   "Engine(pressure_tensor='no') is not allowed: True or False"),
    "event_log-nan": ({"event_log": np.nan}, "Engine(event_log=nan) is not allowed: a whole "
                                             "number from 1 to 16777216"),
    "event_log-1e300": ({"event_log": 1e300}, "Engine(event_log=1e+300)"),
    "event_log-bool": ({"event_log": True}, "Engine(event_log=True)"),
    "event_log-0": ({"event_log": 0}, "Engine(event_log=0)"),
    "event_log-negative": ({"event_log": -5}, "Engine(event_log=-5)"),
    "event_log-fractional": ({"event_log": 2.5}, "Engine(event_log=2.5)"),
    "event_log-text": ({"event_log": "1000"}, "Engine(event_log='1000')"),
    # rotation
    "tangential_restitution-nan": ({"tangential_restitution": np.nan},
                                   "Engine(tangential_restitution=nan) is not allowed: one "
                                   "number or a symmetric 1 × 1 matrix"),
    "tangential_restitution-1.5": ({"tangential_restitution": 1.5},
                                   "Engine(tangential_restitution=1.5)"),
    "tangential_restitution-text": ({"tangential_restitution": "0.5"},
                                    "Engine(tangential_restitution='0.5')"),
    "tangential_restitution-shape": ({"tangential_restitution": [0.5, 0.5, 0.5]},
                                     "Engine(tangential_restitution=[0.5, 0.5, 0.5])"),
    "tangential_restitution-asymmetric": ({"tangential_restitution": [[0.5, 0.1], [0.2, 0.5]],
                                           **TWO_SPECIES},
                                          "Engine(tangential_restitution=[[0.5, 0.1], [0.2, "
                                          "0.5]]) is not allowed: a symmetric 2 × 2 matrix"),
    "wall_tangential_restitution-three": ({"wall_tangential_restitution": [0.5] * 3},
                                          "Engine(wall_tangential_restitution=[0.5, 0.5, 0.5]) "
                                          "is not allowed: one number for every wall or four"),
    "wall_tangential_restitution-nan": ({"wall_tangential_restitution": np.nan},
                                        "Engine(wall_tangential_restitution=nan)"),
    "wall_tangential_restitution-bool": ({"wall_tangential_restitution": True},
                                         "Engine(wall_tangential_restitution=True)"),
    "friction-nan": ({"friction": np.nan, "tangential_restitution": 0.5},
                     "Engine(friction=nan) is not allowed: one number or a symmetric 1 × 1 "
                     "matrix (a row and a column per species) of finite values ≥ 0"),
    "friction-inf": ({"friction": np.inf, "tangential_restitution": 0.5},
                     "Engine(friction=inf)"),
    "friction-negative": ({"friction": -0.1, "tangential_restitution": 0.5},
                          "Engine(friction=-0.1)"),
    "friction-text": ({"friction": "0.1", "tangential_restitution": 0.5},
                      "Engine(friction='0.1')"),
    "friction-smooth": ({"friction": 0.3}, "Engine(friction=0.3) is not allowed: None with "
                                           "smooth contacts"),
    "wall_friction-nan": ({"wall_friction": np.nan, "wall_tangential_restitution": 0.5},
                          "Engine(wall_friction=nan) is not allowed: one number for every wall"),
    "wall_friction-shape": ({"wall_friction": [[0.1, 0.1], [0.1, 0.1]],
                             "wall_tangential_restitution": 0.5},
                            "Engine(wall_friction=[[0.1, 0.1], [0.1, 0.1]])"),
    "wall_friction-periodic": ({"wall_friction": 0.1, "tangential_restitution": 0.5,
                                "wall_tangential_restitution": 0.5, "boundary": PERIODIC},
                               "Engine(wall_friction=0.1) is not allowed: None: a periodic box "
                               "has no walls"),
    "inertia_factor-0": ({"inertia_factor": 0.0}, "Engine(inertia_factor=0.0) is not allowed: "
                                                  "q = I/(m a²) in (0, 1]"),
    "inertia_factor-nan": ({"inertia_factor": np.nan}, "Engine(inertia_factor=nan)"),
    "inertia_factor-text": ({"inertia_factor": "0.5"}, "Engine(inertia_factor='0.5')"),
    "inertia_factor-bool": ({"inertia_factor": True}, "Engine(inertia_factor=True)"),
    "spin-nan": ({"spin": np.nan}, "Engine(spin=nan) is not allowed: one finite number or "
                                   "n = 2 of them"),
    "spin-shape": ({"spin": [1.0, 2.0, 3.0]}, "Engine(spin=[1.0, 2.0, 3.0])"),
    "spin-text": ({"spin": "1"}, "Engine(spin='1')"),
    "spin-and-temperature": ({"spin": [1.0, 2.0], "rotational_temperature": 1.0},
                             "Engine(rotational_temperature=1.0) is not allowed: 0 when "
                             "``spin`` is given"),
    "rotational_temperature-nan": ({"rotational_temperature": np.nan},
                                   "Engine(rotational_temperature=nan) is not allowed: a "
                                   "finite temperature ≥ 0"),
    "rotational_temperature-inf": ({"rotational_temperature": np.inf},
                                   "Engine(rotational_temperature=inf)"),
    "rotational_temperature-text": ({"rotational_temperature": "1"},
                                    "Engine(rotational_temperature='1')"),
}


@pytest.mark.parametrize("case", sorted(BAD_EFFECT_KEYWORDS))
def test_the_engine_refuses_bad_effect_keywords_naming_them(case):
    """Every effect keyword is checked as the command line checks its config key: a
    ValueError of one line naming the keyword, its value and what is allowed."""
    keywords, words = BAD_EFFECT_KEYWORDS[case]
    keywords = dict(keywords)
    scene = {"species": keywords.pop("species", None),
             "boundary": keywords.pop("boundary", Boundary())}
    message = refused("^Engine", [[0.3, 0.5], [0.7, 0.5]], [[1.0, 0.0], [-1.0, 0.0]], 0.01,
                      **scene, **keywords)
    assert words in message


def test_the_engine_refuses_a_system_event_of_no_registered_kind():
    message = refused("^Engine", [[0.3, 0.5], [0.7, 0.5]], [[1.0, 0.0], [-1.0, 0.0]], 0.01,
                      system_event=(1.0, 2.0))
    assert "Engine(system_event=…) is not allowed: None, or a value of a kind registered " \
           "with sim.engine.system.handler (a tuple is none)" == message


def test_the_effect_keywords_take_numpy_numbers_and_whole_floats():
    """What the table above refuses is all: numpy booleans and numbers, whole floats, tuples."""
    scene = {"n": 2, "n_species": 2, "box": np.ones(2), "periodic": np.zeros(2, dtype=bool),
             "radius": np.full(2, 0.01), "mass": np.ones(2), "initial_energy": 1.0}
    values, _ = loop_values({
        "unwrap": np.True_, "pressure_tensor": np.False_, "event_log": np.int64(100),
        "seed": 7.0, "collapse_streak": np.int32(5), "collapse_interval": np.float32(1e-3),
        "restitution": ((0.9, 0.8), (0.8, 0.9)), "wall_restitution": np.float64(0.5),
        "tc": 0, "gravity": (0, -1), "inertia_factor": 1, "spin": np.int64(2),
        "walls": {"top": {"temperature": np.float32(2.0), "speed": 0}, "left": None,
                  "right": {"amplitude": 0.01, "frequency": np.int64(3)}}}, scene)
    assert values["images"].shape == (2, 2) and values["virial_tensor"] is None
    assert values["event_log"][0].shape == (100, 6) and values["seed"] == 7
    assert values["collapse"] == (np.float32(1e-3), 5) and values["tc"] is None
    assert values["restitution"].tolist() == [[0.9, 0.8], [0.8, 0.9]]
    assert values["gravity"].tolist() == [0.0, -1.0] and values["spin"].tolist() == [2.0, 2.0]
    assert values["wall_temperature"][3] == 2.0 and values["wall_motion"][1].tolist() == [
        0.0, 0.01, 3.0]


#: arguments of Engine.run that no run can take: (keywords, the words of the refusal)
BAD_RUN_ARGUMENTS = {
    "collisions-negative": ({"collisions": -5}, "collisions=-5"),
    "collisions-fractional": ({"collisions": 2.7}, "collisions=2.7"),
    "collisions-1e30": ({"collisions": 1e30}, "collisions=1e+30"),
    "collisions-beyond-int64": ({"collisions": 2**63}, "collisions="),
    "contacts-text": ({"contacts": "10"}, "contacts='10'"),
    "events-bool": ({"events": True}, "events=True"),
    "time-negative": ({"time": -1.0}, "time=-1.0"),
    "time-nan": ({"time": np.nan}, "time=nan"),
    "time-inf": ({"time": np.inf}, "time=inf"),
    "time-complex": ({"time": 1 + 2j}, "time=(1+2j)"),
    "energy_fraction-2": ({"energy_fraction": 2.0}, "energy_fraction=2.0"),
    "energy_fraction-negative": ({"energy_fraction": -1}, "energy_fraction=-1"),
    "energy_fraction-nan": ({"energy_fraction": np.nan}, "energy_fraction=nan"),
    "wall_seconds-nan": ({"wall_seconds": np.nan}, "wall_seconds=nan"),
    "wall_seconds-negative": ({"wall_seconds": -1}, "wall_seconds=-1"),
    "chunk_events-0": ({"collisions": 1000, "chunk_events": 0}, "chunk_events=0"),
    "chunk_events-negative": ({"collisions": 1000, "chunk_events": -3}, "chunk_events=-3"),
    "until-not-callable": ({"until": 5}, "until=5"),
    "nothing": ({}, "at least one stop condition"),
}


@pytest.mark.parametrize("case", sorted(BAD_RUN_ARGUMENTS))
def test_run_refuses_what_no_run_can_take_naming_the_argument(case):
    """Engine.run checks its arguments as the command line checks ``stop``: a ValueError of
    one line naming the argument and what is allowed, before any event."""
    keywords, words = BAD_RUN_ARGUMENTS[case]
    engine = gas(50, 0.2, seed=3)
    with pytest.raises(ValueError) as refusal:
        engine.run(**keywords)
    message = str(refusal.value)
    assert words in message and "\n" not in message
    assert engine.events == 0 and engine.time == 0.0


#: stop conditions an elastic gas can never meet, alone: (keywords, the words of the refusal)
UNREACHABLE_RUNS = {
    "energy_fraction": ({"energy_fraction": 0.5},
                        "run(energy_fraction=0.5) is not allowed: a fraction this engine can "
                        "reach: no contact of it dissipates energy"),
    "energy_fraction-0": ({"energy_fraction": 0}, "run(energy_fraction=0)"),
    "time-1e300": ({"time": 1e300}, "run(time=1e+300) is not allowed: a time this engine can "
                                    "reach: the kinetic energy never changes"),
    "time-1e20": ({"time": 1e20}, "run(time=1e+20)"),
    "both": ({"time": 1e300, "energy_fraction": 0.5},
             "run(time=1e+300, energy_fraction=0.5) is not allowed: none can hold"),
}


@pytest.mark.parametrize("case", sorted(UNREACHABLE_RUNS))
def test_run_refuses_conditions_an_elastic_gas_never_meets(case):
    """As the command line refuses such a ``stop``: no contact of elastic disks and walls
    dissipates energy, and a gas whose kinetic energy never changes has an event at least
    every 2 δ √(M/2E), so 2^62 events reach no further than ~1e17 here."""
    keywords, words = UNREACHABLE_RUNS[case]
    engine = gas(50, 0.2, seed=3)
    with pytest.raises(ValueError) as refusal:
        engine.run(**keywords)
    message = str(refusal.value)
    assert words in message and "another stop condition" in message and "\n" not in message
    assert engine.events == 0 and engine.time == 0.0


def test_run_takes_a_condition_another_one_or_dissipation_can_end():
    """Not refused: another condition that ends the run, a fraction met already (1: at
    once), an energy that inelastic disks dissipate, a time within reach."""
    engine = gas(50, 0.2, seed=3)
    assert engine.run(energy_fraction=0.5, collisions=100) == "collisions"
    assert engine.run(time=1e300, events=engine.events + 100) == "events"
    assert engine.run(energy_fraction=1.0) == "energy_fraction"
    assert engine.run(time=engine.time + 0.1) == "time"
    cooling = gas(50, 0.2, seed=3, restitution=0.5, tc=1e-6)
    assert cooling.run(energy_fraction=0.5) == "energy_fraction"


def test_an_elastic_gas_has_an_event_within_the_bound_of_its_latest_time():
    """The premise of the refusal of a time beyond reach: a dilute gas (where events are
    furthest apart), event by event, never waits longer than 2 δ √(M/2E) between two."""
    engine = gas(50, 0.01, (True, False), seed=8)
    latest, _ = engine.latest_time()
    gap = latest / 2**62
    before = engine.time
    for _ in range(3000):
        assert engine.run(events=engine.events + 1) == "events"
        assert engine.time - before <= gap
        before = engine.time


def test_run_refuses_collisions_of_disks_that_never_touch():
    """One disk in a box, or two that keep their axis apart, never collide: run(collisions=…)
    alone is refused (it ran for ever), as the command line refuses stop.collisions."""
    lone = Engine([[0.5, 0.5]], [[1.0, 0.0]], 0.01)
    with pytest.raises(ValueError, match=r"^run\(collisions=10\) is not allowed: a count these "
                                         r"disks reach: one disk has no other"):
        lone.run(collisions=10)
    assert lone.run(collisions=10, events=100) == "events"
    apart = Engine([[0.2, 0.3], [0.2, 0.7]], [[0.0, 1.0], [0.0, 1.0]], 0.01,
                   boundary=Boundary(periodic=True))
    with pytest.raises(ValueError, match=r"^run\(contacts=5, collisions=5\) is not allowed: "
                                         r"none can hold"):
        apart.run(collisions=5, contacts=5)


def test_a_bed_under_gravity_has_an_event_within_the_bound_of_its_latest_time():
    """The premise of the refusal of a time beyond reach under gravity, whatever the energy
    does: disks settling inelastically on a floor never wait longer than (2 + 2√2) √(δ/g)
    between two events; and a time beyond it is refused."""
    engine = gas(50, 0.05, seed=8, gravity=[0.0, -1.0], restitution=0.9,
                 wall_restitution=0.9, tc=1e-4)
    latest, reason = engine.latest_time()
    assert "under gravity" in reason
    gap = (latest - engine.time) / (2**62 - engine.events)
    before = engine.time
    for _ in range(3000):
        assert engine.run(events=engine.events + 1) == "events"
        assert engine.time - before <= gap
        before = engine.time
    with pytest.raises(ValueError, match=r"^run\(time=1e\+300\) is not allowed: a time this "
                                         r"engine can reach: under gravity"):
        engine.run(time=1e300)
    driven = gas(50, 0.05, seed=8, restitution=0.9, walls={"bottom": {"temperature": 1.0}})
    with pytest.raises(ValueError, match=r"^run\(time=1e\+50\) is not allowed: a time this "
                                         r"engine can reach: its thermal walls"):
        driven.run(time=1e50)


def test_run_takes_whole_floats_and_numpy_numbers():
    engine = gas(50, 0.2, seed=3)
    assert engine.run(collisions=1e3) == "collisions" and engine.collisions == 1000
    assert engine.run(collisions=np.int64(1500), chunk_events=np.int32(100)) == "collisions"
    assert engine.run(time=np.float32(engine.time + 0.5)) == "time"


# -- 2. sizing that cannot overflow -----------------------------------------------------------
def test_cell_count_is_capped_whatever_the_scale():
    for box, width, n in (((1.0, 1.0), 1e-40, 100), ((1e30, 1e30), 1e-3, 100),
                          ((1e300, 1.0), 1e-300, 10), ((1.0, 1.0), 0.1, 100)):
        cells = grid_cells(np.array(box), width, cell_limit(n))
        assert 1 <= cells[0] * cells[1] <= cell_limit(n)
        assert np.all(np.array(box) / cells >= width)
    assert grid_cells(np.array([1.0, 1.0]), 0.1, cell_limit(100)).tolist() == [10, 10]


def scaled_cluster(radius, box, speed=1.0, mass=1.0, n=400, **options):
    """n disks of ``radius`` on a lattice at φ = 0.5 in the corner (0, 0) of ``box``."""
    unit = radius_for_packing(n, 0.5)
    position = hexagonal_lattice(n, unit, seed=1) * (radius / unit)
    return Engine(position, fixed_speed(n, speed, seed=2), radius, mass,
                  boundary=Boundary(size=box), **options)


@pytest.mark.parametrize("radius, side, speed, mass", [
    (1e-40, 1.0, 1.0, 1.0), (1e-3, 1e30, 1.0, 1.0), (1e-52, 1e-50, 1.0, 1.0),
    (0.014, 1.0, 1e-50, 1.0), (0.014, 1.0, 1e50, 1e-50), (0.014, 1.0, 1.0, 1e50)])
def test_extreme_but_finite_scales_run_clean(radius, side, speed, mass):
    """Tiny disks in a large box get a few wide cells, and each scene runs thousands of
    collisions without overlap, its energy kept (the bound on events spent is far above the
    ~2e5 that the slowest, a cluster spreading into its box, spends)."""
    engine = scaled_cluster(radius, (side, side), speed, mass)
    assert engine.grid[0] * engine.grid[1] <= cell_limit(engine.n)
    energy = engine.kinetic_energy()
    assert engine.run(collisions=3000, until=lambda e: e.events > 10**6) == "collisions"
    assert engine.kinetic_energy() == pytest.approx(energy, rel=1e-12)
    assert_no_overlap(engine)


def test_disks_slow_against_their_box_do_not_hang_the_queue():
    """Predictions 1e50 time units ahead fit the queue, also when every first prediction is
    made before the first event (no contact at t = 0)."""
    n = 100
    radius = radius_for_packing(n, 0.2)
    engine = Engine(random_sequential(np.full(n, radius), seed=3), fixed_speed(n, 1e-50, seed=4),
                    radius)
    assert engine.run(contacts=2000) == "contacts"
    assert 1e48 < engine.time < 1e52
    assert_no_overlap(engine)


@pytest.mark.parametrize("scene, match", [
    ({"velocity": 1e200}, "the speed of disk 0 is 1e.200: it must lie in"),
    ({"velocity": 1e-70}, "the speed of disk 0 is 1e-70"),
    ({"mass": 1e200}, "the mass of disk 0 is 1e.200"),
    ({"side": 1e300}, "the box side along x is 1e.300"),
    ({"gravity": [0.0, -1e200]}, r"√\(\|g\| L\).* is 1e\+100"),
    ({"walls": {"left": {"temperature": 1e300}}}, r"√\(T_w / m\) of the left wall"),
    ({"walls": {"top": {"amplitude": 0.01, "frequency": 1e100}}}, "A ω of the top wall"),
    ({"radius": 1e-40}, "radius of disk 0 is 1e-40, less than 2..-40 of the far edge"),
    ({"radius": 1e-3, "side": 1e30, "periodic": True}, "far edge of the disks .1e.30"),
])
def test_scenes_float64_cannot_hold_are_refused_naming_the_parameter(scene, match):
    side = scene.get("side", 1.0)
    speed = scene.get("velocity", 1.0)
    refused(match, [[0.5, 0.5], [0.7, 0.5]], [[speed, 0.0], [0.0, 0.0]],
            scene.get("radius", 0.05), scene.get("mass", 1.0),
            boundary=Boundary(size=(side, side), periodic=(scene.get("periodic", False),) * 2),
            gravity=scene.get("gravity"), walls=scene.get("walls"))


# -- 3. the stall guard -----------------------------------------------------------------------
def touching_ring(n=20, radius=0.01, periodic_y=True, **options):
    """n disks touching all round a periodic box 2 n R wide; the first moves along the row."""
    x = radius + 2.0 * radius * np.arange(n)
    velocity = np.zeros((n, 2))
    velocity[0, 0] = 1.0
    return Engine(np.stack([x, np.full(n, 0.5)], axis=1), velocity, radius,
                  boundary=Boundary(size=(2 * n * radius, 1.0), periodic=(True, periodic_y)),
                  **options)


@pytest.mark.parametrize("options", [{}, {"restitution": 0.5, "tc": 1e-6}])
@pytest.mark.parametrize("chunk_events", [200_000, 100])
def test_a_chain_creeping_round_a_periodic_box_is_a_stall(options, chunk_events):
    """Momentum runs round the ring through contacts a few ulps apart in time: caught within
    the guard's 16 N + 1000 events, also when they span many chunks."""
    engine = touching_ring(**options)
    with pytest.raises(StalledError, match="TC model") as caught:
        engine.run(contacts=10**7, chunk_events=chunk_events)
    assert "\n" not in str(caught.value)
    assert engine.events <= 16 * engine.n + 1001
    assert engine.time < 1e-12


def test_an_inelastic_chain_without_tc_collapses():
    """The ring of the test above, inelastic and without the TC model, with walls along y
    that it never reaches (every contact normal along x): collapse, not a stall."""
    engine = touching_ring(restitution=0.5, periodic_y=False, walls=UNREACHED_THERMAL_WALL)
    with pytest.raises(InelasticCollapseError, match="TC model"):
        engine.run(contacts=10**7)
    assert engine.wall_contacts == 0


def test_stall_interval_follows_the_fastest_speed_the_scene_sets():
    """stall_dt = 2⁻⁴⁴ D / v: D the far edge of the disks (1 here), v the initial rms speed,
    √(|g| L), |U| + A ω or √(T_w/m), whichever is fastest. Restitution and t_c set no speed;
    each scene carries those of the shipped scene with its effect (the settling crater bed,
    the vibrated bed, the driven gas), whose compiled loops the quick tests share."""
    def stall_dt(velocity=(0.3, 0.4), **options):
        return Engine([[0.95, 0.5]], [velocity], 0.05, **options).stall_dt

    inelastic = {"restitution": 0.9, "wall_restitution": 0.9, "tc": 1e-4}
    assert stall_dt() == 2.0**-44 / 0.5
    assert stall_dt(velocity=(0.0, 0.0)) == 2.0**-44
    assert stall_dt(gravity=[0.0, -4.0], **inelastic) == 2.0**-44 / 2.0
    # a moving wall faster than √(|g| L) = 1
    assert stall_dt(walls={"top": {"speed": -3.0}}, gravity=[0.0, -1.0],
                    **inelastic) == 2.0**-44 / 3.0
    assert stall_dt(walls={"top": {"amplitude": 0.01, "frequency": 500.0}},
                    gravity=[0.0, -1.0], **inelastic) == pytest.approx(2.0**-44 / 5.0,
                                                                        rel=1e-15)
    assert stall_dt(walls={"top": {"temperature": 16.0}}, restitution=0.9) == 2.0**-44 / 4.0
    # disks in a corner of a huge box: the ulps of their coordinates, not of the box side
    assert stall_dt(boundary=Boundary(size=(1e30, 1e30))) == 2.0**-44 / 0.5


# -- 4. errors of physics are one family ------------------------------------------------------
def test_errors_of_physics_share_a_base_and_name_their_stop_reason():
    reasons = {StalledError: "stalled", InelasticCollapseError: "inelastic_collapse",
               ClosedBoxError: "closed_box"}
    for kind, reason in reasons.items():
        assert issubclass(kind, PhysicsBreakdown) and issubclass(kind, RuntimeError)
        assert kind.stop_reason == reason
    position = np.array([[0.4, 0.5], [0.5, 0.5], [0.6, 0.5]])
    velocity = [[1.0, 0.0], [0.0, 0.0], [-0.7, 0.0]]
    with pytest.raises(PhysicsBreakdown) as caught:
        Engine(position, velocity, 0.01, restitution=0.05,
               walls=UNREACHED_THERMAL_WALL).run(collisions=10**6)
    assert caught.value.stop_reason == "inelastic_collapse"
    assert "\n" not in str(caught.value) and "tc.time" in str(caught.value)
    # a piston in the vibrated bed's effects (ξ, ξ_w, t_c, gravity: its compiled loop)
    lone = Engine([[0.5, 0.5]], [[0.0, 0.0]], 0.05, walls={"right": {"speed": -0.1}},
                  gravity=[0.0, -1.0], restitution=0.9, wall_restitution=0.9, tc=1e-4)
    with pytest.raises(PhysicsBreakdown) as caught:
        lone.run(time=10.0)
    assert caught.value.stop_reason == "closed_box"
    assert "\n" not in str(caught.value) and "stop.time" in str(caught.value)


# -- 5. the piston guard runs after every chunk -----------------------------------------------
def test_a_jammed_piston_is_caught_when_the_caller_stops_every_few_collisions():
    """Snapshots every 200 collisions end every call before its chunk: the guard still runs
    after each, and the jam is reported before the walls close. The gas has the vibrated
    bed's effects (ξ, ξ_w, t_c, gravity: its compiled loop); as the piston squeezes it, its
    contacts come within t_c of each other, turn elastic, and the energy diverges."""
    n = 50
    radius = radius_for_packing(n, 0.05)
    engine = Engine(random_sequential(np.full(n, radius), seed=1), fixed_speed(n, 1.0, seed=2),
                    radius, walls={"right": {"speed": -0.2}}, gravity=[0.0, -1.0],
                    restitution=0.9, wall_restitution=0.9, tc=1e-4)
    with pytest.raises(ClosedBoxError, match="jammed"):
        for _ in range(100_000):
            engine.run(collisions=engine.collisions + 200)
    assert engine.time < engine.closing_time


# -- 6. chunks sized for the wall-clock budget ------------------------------------------------
def test_an_exhausted_budget_returns_after_one_small_chunk():
    engine = gas(2000, 0.5, seed=7)
    assert engine.run(wall_seconds=0.0, collisions=10**12) == "wall_seconds"
    assert 0 < engine.events <= TIMED_FIRST_CHUNK


def test_chunks_sized_by_the_clock_change_no_bits():
    """One call, a budget that sizes chunks from the measured rate, and many short calls all
    end in the same state."""
    engines = [gas(500, 0.5, (True, False), seed=29, restitution=0.9, tc=1e-6) for _ in range(3)]
    engines[0].run(collisions=60_000)
    engines[1].run(collisions=60_000, wall_seconds=1e9)
    while engines[2].collisions < 60_000:
        engines[2].run(collisions=min(engines[2].collisions + 7_000, 60_000), wall_seconds=1e9,
                       chunk_events=5_000)
    for engine in engines[1:]:
        np.testing.assert_array_equal(engine.positions(), engines[0].positions())
        np.testing.assert_array_equal(engine.velocities(), engines[0].velocities())
        assert engine.time == engines[0].time


# -- a checkpoint of another scene ------------------------------------------------------------
def test_a_checkpoint_of_another_scene_is_refused_before_anything_changes():
    """What resume loads must be this scene's: other disk counts, or arrays this engine does
    not keep, are refused, and the engine's own state is left as it was."""
    engine = gas(100, 0.3, seed=1)
    engine.run(collisions=500)
    before = {key: np.array(value) for key, value in engine.state_dict().items()}
    larger = gas(120, 0.3, seed=1)
    with pytest.raises(ValueError, match="disks/table has shape"):
        engine.load_state_dict(larger.state_dict())
    recording = gas(100, 0.3, seed=1, **RECORDER_KEYWORDS)
    with pytest.raises(ValueError, match=r"unknown \['disks/images', 'virial_tensor'\]"):
        engine.load_state_dict(recording.state_dict())
    for key, value in engine.state_dict().items():
        np.testing.assert_array_equal(value, before[key], err_msg=key)
