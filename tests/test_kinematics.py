"""Contact-time roots: exact cases, never negative, and no cancellation for grazing pairs."""

import math

import pytest
from hypothesis import example, given
from hypothesis import strategies as st

from sim.engine.kinematics import (
    may_touch_before,
    pair_contact_time,
    shell_exit_time,
    wall_contact_time,
)

finite = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)


@pytest.mark.parametrize(
    ("r", "v", "sigma", "expected"),
    [
        ((3.0, 0.0), (-1.0, 0.0), 1.0, 2.0),  # head-on: gap 2 closed at speed 1
        ((0.0, 5.0), (0.0, -2.0), 1.0, 2.0),
        ((3.0, 0.0), (1.0, 0.0), 1.0, math.inf),  # receding
        ((3.0, 2.0), (-1.0, 0.0), 1.0, math.inf),  # misses: impact parameter 2 > σ
        ((3.0, 0.5), (-1.0, 0.0), 1.0, 3.0 - math.sqrt(0.75)),  # oblique
    ],
)
def test_pair_contact_time_exact_cases(r, v, sigma, expected):
    assert pair_contact_time(*r, *v, sigma) == pytest.approx(expected, rel=1e-15)


def test_grazing_contact_far_away_keeps_its_precision():
    # impact parameter b = 1 - e at unit contact distance, starting 1000 away along x:
    # contact after 1000 - sqrt(1 - b²), 1 - b² = e (2 - e) formed without cancellation
    e = 2.0**-30
    b = 1.0 - e
    tau = pair_contact_time(1000.0, b, -1.0, 0.0, 1.0)
    assert tau == pytest.approx(1000.0 - math.sqrt(e * (2.0 - e)), rel=1e-15)


def test_round_off_overlap_collides_at_once():
    assert pair_contact_time(1.0 - 1e-15, 0.0, -1.0, 0.0, 1.0) == 0.0


@given(finite, finite, finite, finite, st.floats(0.01, 5.0))
def test_pair_contact_time_is_never_negative_and_solves_contact(rx, ry, vx, vy, sigma):
    tau = pair_contact_time(rx, ry, vx, vy, sigma)
    assert tau >= 0.0
    if math.isfinite(tau) and rx * rx + ry * ry >= sigma * sigma:
        distance = math.hypot(rx + vx * tau, ry + vy * tau)
        assert distance == pytest.approx(sigma, rel=1e-9, abs=1e-9)


@given(finite, finite, finite, finite, st.floats(0.01, 5.0),
       st.one_of(st.floats(0.0, 100.0), st.just(math.inf)))
@example(1.0, 0.0, -2.092393952918845e-46, 0.0, 1.0, 2.2250738585e-313)  # -2bτ underflows
def test_a_pair_the_filter_drops_touches_no_sooner(rx, ry, vx, vy, sigma, tau):
    """may_touch_before drops only pairs whose contact time is not below τ (to round-off),
    and with τ = ∞ it keeps every pair that ever touches."""
    tau_contact = pair_contact_time(rx, ry, vx, vy, sigma)
    if not may_touch_before(rx, ry, vx, vy, sigma, tau):
        assert tau_contact >= tau * (1.0 - 1e-12)
    if math.isinf(tau):
        assert may_touch_before(rx, ry, vx, vy, sigma, tau) or math.isinf(tau_contact)


def test_the_filter_drops_a_far_pair_and_keeps_an_overlap():
    # head-on, gap 2 closed at speed 1: contact at τ = 2, bound c / (-2b) = 8 / 6
    assert may_touch_before(3.0, 0.0, -1.0, 0.0, 1.0, 2.5)
    assert not may_touch_before(3.0, 0.0, -1.0, 0.0, 1.0, 1.0)
    assert may_touch_before(1.0 - 1e-15, 0.0, -1.0, 0.0, 1.0, 0.0)


@given(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), finite, finite)
def test_shell_exit_lands_on_the_shell(dx, dy, vx, vy):
    delta = 1.0
    tau = shell_exit_time(dx, dy, vx, vy, delta)
    assert tau >= 0.0
    if vx * vx + vy * vy > 1e-280:  # slower counts as rest
        assert math.hypot(dx + vx * tau, dy + vy * tau) == pytest.approx(delta, rel=1e-12)


def test_wall_contact_time_sides():
    assert wall_contact_time(0.5, -1.0, 0.1, 1.0) == (pytest.approx(0.4), 0)
    assert wall_contact_time(0.5, 2.0, 0.1, 1.0) == (pytest.approx(0.2), 1)
    assert wall_contact_time(0.5, 0.0, 0.1, 1.0)[0] == math.inf
    # already touching and moving outwards: at once, never in the past
    assert wall_contact_time(0.1 - 1e-17, -1.0, 0.1, 1.0)[0] == 0.0
