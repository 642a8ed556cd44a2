"""Growing disks (sim.effects.growth): the growing contact and the shrinking shell against
bisection oracles, never an overlap from dilute to jammed, the packing-fraction stop to
round-off, the same bits however a run is cut, and growth 0 as no growth at all."""

import math

import numpy as np
import pytest
from hypothesis import assume, example, given
from hypothesis import strategies as st

from conftest import assert_no_overlap, gas
from sim.checks.audit import overlapping_pairs
from sim.engine import Engine
from sim.engine.kinematics import growing_contact_time, shrinking_shell_exit_time
from sim.engine.running import CLOSE_PACKING
from sim.pipeline.runner import build_engine
from variants import compose_scene

finite = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)
rate = st.floats(1e-3, 10.0)


def _first_root(g, horizon):
    """The first τ in [0, horizon] where the convex function g (g(0) > 0) reaches 0, by
    ternary search for its minimum and bisection before it; inf when g stays above 0.
    Returns (τ, the minimum of g), so that a grazing case can be told."""
    lo, hi = 0.0, horizon
    for _ in range(300):
        a, b = lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0
        if g(a) < g(b):
            hi = b
        else:
            lo = a
    bottom = 0.5 * (lo + hi)
    if g(bottom) > 0.0 and g(horizon) > 0.0:
        return math.inf, min(g(bottom), g(horizon))
    end = bottom if g(bottom) <= 0.0 else horizon
    lo, hi = 0.0, end
    for _ in range(300):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) > 0.0 else (lo, mid)
    return hi, g(bottom)


@given(finite, finite, finite, finite, st.floats(0.01, 5.0), rate)
@example(3.0, 0.0, 1.0, 0.0, 1.0, 0.5)  # receding, but slower than the contact grows
@example(3.0, 0.0, 0.0, 0.0, 1.0, 1.0)  # at rest: the growth alone closes the gap
@example(0.0, 3.0, 2.0, 0.0, 1.0, 0.1)  # passing by, caught as the disks grow
@example(2.0, 2.426014361448294, 2.0, -6.103515625e-05, 2.0, 2.0)  # grazing at τ ≈ 4·10⁴
def test_growing_contact_is_the_first_crossing(rx, ry, vx, vy, sigma, sigma_rate):
    """The root is the first τ with |r + v τ| = σ + ṡ τ (g(τ) = |r + v τ| − σ − ṡ τ is
    convex), found by bisection up to a horizon; never negative; none when g stays
    positive. A root beyond the horizon (a relative speed that barely beats the growth
    meets or grazes far away) is a zero of g to round-off."""
    assume(math.hypot(rx, ry) > sigma * (1.0 + 1e-9))
    tau = growing_contact_time(rx, ry, vx, vy, sigma, sigma_rate, math.inf)

    def g(t):
        return math.hypot(rx + vx * t, ry + vy * t) - sigma - sigma_rate * t

    scale = math.hypot(rx, ry) + sigma
    horizon = 1e3 * scale / min(sigma_rate, 1.0)
    oracle, lowest = _first_root(g, horizon)
    assert tau >= 0.0
    assume(abs(lowest) > 1e-9 * scale)  # grazing: either answer is right to round-off
    if math.isinf(oracle):
        assert math.isinf(tau) or (tau > horizon
                                   and abs(g(tau)) <= 1e-9 * (scale + sigma_rate * tau))
    else:
        assert tau == pytest.approx(oracle, rel=1e-7, abs=1e-9 * scale)


@given(finite, finite, finite, finite, st.floats(0.01, 5.0), rate,
       st.one_of(st.floats(0.0, 100.0), st.just(math.inf)))
def test_a_pair_the_growing_filter_drops_touches_no_sooner(rx, ry, vx, vy, sigma, sigma_rate,
                                                           horizon):
    """Given the time τ of an event found already, the filter drops only pairs whose
    contact comes no sooner (``growing_contact_time`` returns inf for them)."""
    exact = growing_contact_time(rx, ry, vx, vy, sigma, sigma_rate, math.inf)
    filtered = growing_contact_time(rx, ry, vx, vy, sigma, sigma_rate, horizon)
    if math.isinf(filtered):
        assert exact >= horizon * (1.0 - 1e-12)
    else:
        assert filtered == exact


def test_an_overlap_by_round_off_that_closes_touches_at_once():
    assert growing_contact_time(1.0 - 1e-15, 0.0, -1.0, 0.0, 1.0, 0.1, math.inf) == 0.0
    # separating faster than the contact grows, never to meet again
    assert math.isinf(growing_contact_time(1.0 - 1e-15, 0.0, 2.0, 0.0, 1.0, 0.1, math.inf))


@given(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), finite, finite, st.floats(0.0, 10.0))
def test_a_shrinking_shell_is_left_at_its_first_crossing(dx, dy, vx, vy, shrink):
    """The exit is the first τ with |d + v τ| = δ − rate τ (convex minus linear), found by
    bisection; at rate 0 it is the fixed shell's exit."""
    delta = 1.0
    tau = shrinking_shell_exit_time(dx, dy, vx, vy, delta, shrink)
    assert tau >= 0.0
    if vx * vx + vy * vy + shrink * shrink < 1e-280:  # slower counts as rest
        assert math.isinf(tau)
        return

    def g(t):  # room left in the shell, positive inside and concave
        return delta - shrink * t - math.hypot(dx + vx * t, dy + vy * t)

    lo, hi = 0.0, 1.0
    while g(hi) > 0.0:
        hi *= 2.0
    for _ in range(300):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid) > 0.0 else (lo, mid)
    assert tau == pytest.approx(hi, rel=1e-9, abs=1e-12)


def _compress(*overrides):
    """A small engine of the compress scene (its canonical variant)."""
    return build_engine(compose_scene("compress", "disks.n=200", *overrides))


@pytest.mark.parametrize("boundary", ["periodic", "walls"])
def test_growing_gas_never_overlaps(boundary):
    """From φ = 0.3 to jamming, periodic and walled: no two disks overlap and none leaves the
    box at any of the stops on the way, and the run ends jammed."""
    engine = _compress(f"box.boundary={boundary}", "growth.rate=1.0")
    reason = "time"
    while reason == "time":
        reason = engine.run(time=engine.time + 0.02, jamming=1e6, chunk_events=20_000)
        assert_no_overlap(engine)
    assert reason == "jamming"
    assert 0.78 < engine.packing_fraction() < 0.91


def test_growing_disks_whose_collisions_outrun_float64_have_jammed():
    """Without a pressure watch the compression runs on until its collisions come closer in
    time than float64 resolves: the disks have jammed (no StalledError), and no pair
    overlaps."""
    engine = _compress("growth.rate=1.0")
    assert engine.run(time=100.0) == "jamming"
    assert 0.8 < engine.packing_fraction() < 0.91
    assert_no_overlap(engine)


def test_the_packing_fraction_stop_reaches_its_target_to_round_off():
    engine = _compress("growth.rate=1.0")
    assert engine.run(packing_fraction=0.7) == "packing_fraction"
    t = engine.packing_fraction_time(0.7)
    assert engine.time <= t < engine.next_event_time()
    assert engine.packing_fraction(t) == pytest.approx(0.7, rel=4e-16)
    position = engine.positions(t)
    assert overlapping_pairs(position, engine.radii(t), engine.box, engine.periodic)[0].size == 0


def test_the_rescaling_holds_the_kinetic_energy():
    """Growth pumps energy in at every contact (about 10 % per collision per disk at this
    fast rate); rescaled every 0.2 collisions per disk, it stays within 5 % of the initial
    energy up to φ = 0.75."""
    engine = _compress("growth.rate=1.0", "growth.rescale_every=0.2")
    energies = []
    while engine.run(packing_fraction=0.75, time=engine.time + 0.01) == "time":
        energies.append(engine.kinetic_energy())
    assert len(energies) > 10
    assert np.max(np.abs(np.array(energies) / engine.initial_energy - 1.0)) < 0.05


def test_the_same_bits_however_the_run_is_cut_and_across_a_checkpoint():
    whole = _compress("growth.rate=1.0")
    whole.run(time=0.2)
    cut = _compress("growth.rate=1.0")
    cut.run(time=0.07, chunk_events=997)
    saved = cut.state_dict()
    resumed = _compress("growth.rate=1.0")
    resumed.load_state_dict({key: np.array(value) for key, value in saved.items()})
    resumed.run(time=0.2, chunk_events=3001)
    for engine in (cut, resumed):
        engine.run(time=0.2)
    for engine in (cut, resumed):
        assert engine.collisions == whole.collisions
        assert np.array_equal(engine.positions(), whole.positions())
        assert np.array_equal(engine.velocities(), whole.velocities())


def test_growth_zero_is_no_growth_to_the_bit():
    still = gas(300, 0.4, periodic=(True, True))
    zero = gas(300, 0.4, periodic=(True, True), growth_rate=0.0)
    assert zero.growth is None and zero.system_event is None
    for engine in (still, zero):
        engine.run(collisions=20_000)
    assert np.array_equal(still.positions(), zero.positions())
    assert np.array_equal(still.velocities(), zero.velocities())


@pytest.mark.parametrize(("keyword", "value", "allowed"), [
    ("growth_rate", -1.0, "a finite rate ≥ 0"),
    ("growth_rate", math.nan, "a finite rate ≥ 0"),
    ("growth_rate", math.inf, "a finite rate ≥ 0"),
    ("rescale_every", 0.0, "collisions per disk > 0"),
])
def test_bad_growth_is_refused_in_one_line(keyword, value, allowed):
    with pytest.raises(ValueError, match=allowed) as error:
        Engine(np.array([[0.25, 0.5], [0.75, 0.5]]), np.ones((2, 2)), 0.1, **{keyword: value})
    assert "\n" not in str(error.value)


def test_growth_of_disks_at_rest_is_refused():
    with pytest.raises(ValueError, match="disks at rest"):
        Engine(np.array([[0.25, 0.5], [0.75, 0.5]]), np.zeros((2, 2)), 0.1, growth_rate=0.1)


def test_growth_with_a_moving_wall_is_refused():
    with pytest.raises(ValueError, match="moving walls"):
        Engine(np.array([[0.25, 0.5], [0.75, 0.5]]), np.ones((2, 2)), 0.1, growth_rate=0.1,
               walls={"top": {"speed": -0.1}})


def test_a_packing_fraction_above_close_packing_is_refused_for_disks_of_one_size():
    engine = _compress("compress.radius_ratio=1")
    with pytest.raises(ValueError, match="π/√12"):
        engine.run(packing_fraction=0.5 * (CLOSE_PACKING + 1.0))
    mixture = _compress("growth.rate=1.0")  # two sizes: a target it cannot reach, jams first
    assert mixture.run(packing_fraction=0.5 * (CLOSE_PACKING + 1.0)) == "jamming"
    assert mixture.packing_fraction() < CLOSE_PACKING


#: the fastest and the slowest growth rates of figure 14 (sim.figures.jamming), 1/time
FASTEST, SLOWEST = 1.0, 0.01


@pytest.mark.slow
@pytest.mark.parametrize(("boundary", "ratio", "rate", "gravity"), [
    ("periodic", 1.4, FASTEST, False), ("periodic", 1.4, SLOWEST, False),
    ("walls", 1.4, FASTEST, False), ("walls", 1.4, SLOWEST, False),
    ("walls", 1.4, FASTEST, True), ("walls", 1.4, SLOWEST, True),
    ("periodic", 10.0, FASTEST, False), ("periodic", 10.0, SLOWEST, False),
    ("walls", 10.0, FASTEST, False), ("walls", 10.0, SLOWEST, False),
])
def test_no_overlap_from_dilute_to_jammed(boundary, ratio, rate, gravity):
    """The overlap audit at every one of 60 stops from φ = 0.3 to jamming (βP/ρ = 10⁶),
    periodic and walled, gravity on and off, size ratios 1:1.4 and 1:10, at the fastest and
    the slowest rates of figure 14."""
    engine = _compress(f"box.boundary={boundary}", f"compress.radius_ratio={ratio}",
                       f"growth.rate={rate}", "gravity=[0,-1]" if gravity else "gravity=[0,0]")
    end = (math.sqrt(0.92 / 0.3) - 1.0) / rate  # no packing of these disks is denser
    reason, stops = "time", 0
    while reason == "time":
        reason = engine.run(time=min(engine.time + end / 60.0, end), jamming=1e6)
        assert_no_overlap(engine)
        stops += 1
    assert reason == "jamming" and stops > 10
    assert engine.packing_fraction() > 0.75


@pytest.mark.slow
def test_a_compressed_placement_is_a_random_fluid_at_the_packing_asked():
    """``disks.placement=compressed`` at φ = 0.68, beyond random addition: the packing asked
    (the disks' own radii) without overlap, and a fluid's global order |Ψ₆| < 3/√N."""
    from sim.analysis.packing import global_bond_order
    from sim.pipeline.initial import compressed

    n, radius = 1000, 0.0147
    position = compressed(np.full(n, radius), periodic=(True, True), seed=3)
    assert overlapping_pairs(position, np.full(n, radius), (1.0, 1.0),
                             (True, True))[0].size == 0
    assert global_bond_order(position, (1.0, 1.0), (True, True)) < 3.0 / np.sqrt(n)


def test_a_dense_gas_starts_compressed_in_the_compress_scenes_loop():
    """``auto`` compresses a gas denser than φ = 0.6 (sim.pipeline.scenes.MELT_LIMIT); the
    preparation runs the compiled loop of the compress scene (a quick test that compiled
    another would fail), and the gas starts at its packing without overlap."""
    from sim.pipeline.scenes import preparation

    cfg = compose_scene("gas", "disks.packing_fraction=0.65", "box.boundary=periodic")
    assert "compressed by growing disks" in preparation(cfg)
    engine = build_engine(cfg)
    assert engine.packing_fraction() == pytest.approx(0.65, rel=1e-12)
    assert_no_overlap(engine)


def test_a_compressed_placement_above_close_packing_is_refused():
    from sim.pipeline.initial import PlacementError, compressed

    with pytest.raises(PlacementError, match="π/√12"):
        compressed(np.full(100, 0.055), periodic=(True, True))
