"""The contact rules of rough disks (sim.effects.rotation; docs/rough-disks.md) against their
conservation laws and closed forms, and the two-temperature theory of their cooling
(sim.analysis.theory) against the average of the same rules over Maxwellian pairs."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from sim.analysis import theory
from sim.effects.rotation import (
    SMOOTH,
    maxwellian_spins,
    moment_of_inertia,
    rotational_energy,
    rotational_temperature,
    rough_contact,
    rough_parameters,
    rough_wall,
    tc_roughness,
    translational_temperature,
)
from sim.engine.contact import collide_disks
from sim.engine.kinematics import DISK_COLUMNS, RADIUS, VX, VY, X, Y


@njit(cache=True)
def contact(disks, spin, m_i, m_j, xi, q, beta, friction):
    """Disks 0 and 1 in contact: the smooth normal impulse, then the tangential one, as the
    event loop would chain them. Returns (normal loss, tangential loss)."""
    rx = disks[0, X] - disks[1, X]
    ry = disks[0, Y] - disks[1, Y]
    r = math.sqrt(rx * rx + ry * ry)
    lost_n, virial = collide_disks(0, 1, rx, ry, xi, disks, m_i, m_j, None)
    lost_t = rough_contact(0, 1, rx / r, ry / r, virial / r, disks, spin, m_i, m_j, q, beta,
                           friction)
    return lost_n, lost_t


@njit(cache=True)
def wall_contact(wall, normal_impulse, disks, spin, m, q, beta, friction):
    return rough_wall(0, wall, normal_impulse, disks, spin, m, q, beta, friction)


@njit(cache=True)
def compiled_tc_roughness(tc, beta, t, t_last_i, t_last_j):
    return tc_roughness(tc, beta, t, t_last_i, t_last_j)


def pair(angle, a_i, a_j, v_i, v_j):
    """Disks 0 (radius a_i) and 1 (radius a_j) touching, n = (cos, sin)(angle) from 1 to 0."""
    disks = np.zeros((2, DISK_COLUMNS))
    disks[1, X:Y + 1] = (0.3, -0.2)
    disks[0, X:Y + 1] = disks[1, X:Y + 1] + (a_i + a_j) * np.array([math.cos(angle),
                                                                   math.sin(angle)])
    disks[:, RADIUS] = a_i, a_j
    disks[0, VX:VY + 1] = v_i
    disks[1, VX:VY + 1] = v_j
    return disks


def totals(disks, spin, m, q):
    """Σ m v, Σ (m r × v + I ω), Σ (m v²/2 + I ω²/2), and the magnitudes of the terms of
    the angular momentum (its scale for a relative tolerance)."""
    inertia = moment_of_inertia(q, m, disks[:, RADIUS])
    x, y, vx, vy = disks[:, X], disks[:, Y], disks[:, VX], disks[:, VY]
    orbital = m * (x * vy - y * vx)
    return (np.array([np.sum(m * vx), np.sum(m * vy)]),
            np.sum(orbital) + np.sum(inertia * spin),
            np.sum(0.5 * m * (vx**2 + vy**2) + 0.5 * inertia * spin**2),
            np.sum(np.abs(m * x * vy)) + np.sum(np.abs(m * y * vx)) + np.sum(np.abs(inertia
                                                                                    * spin)))


speed = st.floats(-3.0, 3.0)
contacts = st.fixed_dictionaries({
    "angle": st.floats(0.0, 2.0 * math.pi),
    "a": st.tuples(st.floats(0.01, 0.3), st.floats(0.01, 0.3)),
    "m": st.tuples(st.floats(1e-2, 1e2), st.floats(1e-2, 1e2)),
    "v": st.tuples(speed, speed, speed, speed),
    "spin": st.tuples(st.floats(-50.0, 50.0), st.floats(-50.0, 50.0)),
    "xi": st.floats(0.0, 1.0),
    "q": st.floats(0.05, 1.0),
    "beta": st.floats(-1.0, 1.0),
    "friction": st.none() | st.floats(0.0, 2.0),
})


def run(c, **change):
    c = {**c, **change}
    disks = pair(c["angle"], *c["a"], c["v"][:2], c["v"][2:])
    spin = np.array(c["spin"], dtype=float)
    m = np.array(c["m"])
    before = totals(disks, spin, m, c["q"])
    lost = contact(disks, spin, m[0], m[1], c["xi"], c["q"], c["beta"], c["friction"])
    return disks, spin, m, before, totals(disks, spin, m, c["q"]), lost


@settings(deadline=None, max_examples=300, derandomize=True)
@given(contacts)
def test_momentum_and_angular_momentum_conserved(c):
    _, _, _, (p0, l0, e0, scale0), (p1, l1, e1, scale1), lost = run(c)
    p_scale = sum(m * (abs(c["v"][2 * k]) + abs(c["v"][2 * k + 1])) for k, m in enumerate(c["m"]))
    assert np.all(np.abs(p1 - p0) <= 1e-12 * p_scale)
    assert abs(l1 - l0) <= 1e-12 * max(scale0, scale1)
    # and the energy lost is the energy the disks no longer have
    assert e0 - e1 == pytest.approx(sum(lost), rel=1e-9, abs=1e-12 * e0)


@settings(deadline=None, max_examples=200, derandomize=True)
@given(contacts, st.sampled_from([-1.0, 1.0]))
def test_energy_conserved_when_elastic_and_smooth_or_perfectly_rough(c, beta):
    _, _, _, (_, _, e0, _), (_, _, e1, _), lost = run(c, xi=1.0, beta=beta, friction=None)
    assert e1 == pytest.approx(e0, rel=1e-12)
    assert abs(lost[1]) <= 1e-12 * e0


@settings(deadline=None, max_examples=200, derandomize=True)
@given(contacts)
def test_energy_lost_is_the_closed_form(c):
    """(1 − ξ²) μ g_n²/2 + (1 − β²) m_t g_t²/2, m_t = q μ/(1 + q), constant β."""
    disks = pair(c["angle"], *c["a"], c["v"][:2], c["v"][2:])
    n = np.array([math.cos(c["angle"]), math.sin(c["angle"])])
    t = np.array([-n[1], n[0]])
    g = disks[0, VX:VY + 1] - disks[1, VX:VY + 1]
    g_n = g @ n
    g_t = g @ t - c["a"][0] * c["spin"][0] - c["a"][1] * c["spin"][1]
    m_i, m_j = c["m"]
    mu = m_i * m_j / (m_i + m_j)
    m_t = c["q"] * mu / (1.0 + c["q"])
    _, _, _, (_, _, e0, _), (_, _, e1, _), lost = run(c, friction=None)
    if g_n >= 0.0:  # separating: nothing happens in the normal direction
        return
    expected = 0.5 * (1 - c["xi"] ** 2) * mu * g_n**2 + 0.5 * (1 - c["beta"] ** 2) * m_t * g_t**2
    assert sum(lost) == pytest.approx(expected, rel=1e-10, abs=1e-13 * e0)
    assert e0 - e1 == pytest.approx(expected, rel=1e-9, abs=1e-12 * e0)


@pytest.mark.parametrize("q", [0.5, 1.0, 0.4])
@pytest.mark.parametrize("wall", [0, 1, 2, 3])
def test_spinning_disk_hits_a_wall_head_on(wall, q):
    """β = 1, wall of the box: with t = ẑ × n, u = v·t the tangential velocity and s = a ω,
    g_t = u − s, P_t = −2 m_t g_t, m_t = q m/(1 + q) give
    u' = ((1 − q) u + 2 q s)/(1 + q), s' = (2 u − (1 − q) s)/(1 + q)
    (a ring, q = 1, exchanges them: u' = s, s' = u)."""
    m, a, omega, u, v_n = 2.0, 0.1, 7.0, 0.4, 1.5
    axis, sign = wall >> 1, 1.0 - 2.0 * (wall & 1)
    t_other = sign * (1.0 - 2.0 * axis)  # t's component along the other axis
    disks = np.zeros((1, DISK_COLUMNS))
    disks[0, RADIUS] = a
    disks[0, VX + axis] = -sign * v_n  # head-on into the wall
    disks[0, VX + 1 - axis] = t_other * u
    spin = np.array([omega])
    s = a * omega
    lost = wall_contact(wall, 2.0 * m * v_n, disks, spin, m, q, 1.0, None)
    assert t_other * disks[0, VX + 1 - axis] == pytest.approx(((1 - q) * u + 2 * q * s) / (1 + q),
                                                             rel=1e-13)
    assert a * spin[0] == pytest.approx((2 * u - (1 - q) * s) / (1 + q), rel=1e-13)
    assert disks[0, VX + axis] == -sign * v_n  # the normal velocity is the wall rule's business
    assert abs(lost) <= 1e-13 * m * (u * u + q * s * s)
    energy = 0.5 * m * disks[0, VX + 1 - axis] ** 2 + 0.5 * q * m * a * a * spin[0] ** 2
    assert energy == pytest.approx(0.5 * m * u * u + 0.5 * q * m * s * s, rel=1e-13)


@pytest.mark.parametrize(("beta", "friction"), [(0.7, None), (-0.3, None), (0.9, 0.05),
                                              (0.9, 2.0)])
@pytest.mark.parametrize("wall", [0, 1, 2, 3])
def test_wall_contact_conserves_angular_momentum_about_the_contact_point(wall, beta, friction):
    """The wall pushes at the contact point r − a n, so m a (n × v) + I ω is conserved."""
    m, a, q = 1.5, 0.2, 0.5
    axis, sign = wall >> 1, 1.0 - 2.0 * (wall & 1)
    n = np.zeros(2)
    n[axis] = sign
    disks = np.zeros((1, DISK_COLUMNS))
    disks[0, RADIUS] = a
    disks[0, VX:VY + 1] = -0.8 * n + (0.35, -0.6) * (1.0 - np.abs(n))
    spin = np.array([-3.0])

    def angular_momentum():
        return m * a * (n[0] * disks[0, VY] - n[1] * disks[0, VX]) + q * m * a * a * spin[0]

    before = angular_momentum()
    wall_contact(wall, 1.6 * m * 0.8, disks, spin, m, q, beta, friction)
    assert spin[0] != -3.0
    assert angular_momentum() == pytest.approx(before, rel=1e-14, abs=1e-15)


def test_a_ring_exchanges_spin_and_sliding_velocity_at_the_floor():
    """q = 1, β = 1 at the floor (wall 2: n = +y, t = −x): v_x' = −a ω, a ω' = −v_x."""
    disks = np.zeros((1, DISK_COLUMNS))
    disks[0, RADIUS] = 0.5
    disks[0, VX:VY + 1] = 0.3, -1.0
    spin = np.array([2.0])
    wall_contact(2, 2.0, disks, spin, 1.0, 1.0, 1.0, None)
    assert disks[0, VX] == pytest.approx(-1.0, rel=1e-15)
    assert 0.5 * spin[0] == pytest.approx(-0.3, rel=1e-15)


@pytest.mark.parametrize(("xi", "beta0", "friction", "q"),
                         [(0.9, 0.4, 0.3, 0.5), (0.6, 1.0, 0.1, 1.0), (1.0, 0.0, 0.5, 0.4)])
def test_walton_branches_meet_at_the_critical_angle(xi, beta0, friction, q):
    """Disk 1 at rest, disk 0 comes in at angle θ to −n (g_t/|g_n| = tan θ): it sticks with
    β₀ while tan θ < μ_f (1 + ξ)(1 + 1/q)/(1 + β₀), and slides above with the effective
    β = −1 + μ_f (1 + ξ)(1 + 1/q)/tan θ (masses and radii drop out)."""
    m_i, m_j, a_i, a_j = 1.0, 3.0, 0.05, 0.08
    critical = friction * (1 + xi) * (1 + 1 / q) / (1 + beta0)

    def effective_beta(tan_theta):
        theta = math.atan(tan_theta)
        disks = pair(0.0, a_i, a_j, (-math.cos(theta), math.sin(theta)), (0.0, 0.0))
        spin = np.zeros(2)
        g_t = disks[0, VY]  # n = x̂, t = ŷ
        contact(disks, spin, m_i, m_j, xi, q, beta0, friction)
        return -(disks[0, VY] - disks[1, VY] - a_i * spin[0] - a_j * spin[1]) / g_t, disks, spin

    for tan_theta in (0.3 * critical, 0.9 * critical):
        assert effective_beta(tan_theta)[0] == pytest.approx(beta0, rel=1e-12, abs=1e-14)
    for tan_theta in (1.1 * critical, 3.0 * critical):
        assert effective_beta(tan_theta)[0] == pytest.approx(
            -1 + friction * (1 + xi) * (1 + 1 / q) / tan_theta, rel=1e-12, abs=1e-14)
    below = effective_beta(critical * (1 - 1e-9))
    above = effective_beta(critical * (1 + 1e-9))
    assert above[0] == pytest.approx(below[0], abs=1e-8)
    np.testing.assert_allclose(above[1][:, VX:VY + 1], below[1][:, VX:VY + 1], atol=1e-8)
    np.testing.assert_allclose(above[2] * (a_i, a_j), below[2] * (a_i, a_j), atol=1e-8)


@settings(deadline=None, max_examples=100, derandomize=True)
@given(contacts)
def test_smooth_contact_leaves_spins_and_tangential_motion_alone(c):
    """β = −1 without friction is the smooth contact, bit for bit."""
    disks, spin, *_ = run(c, beta=SMOOTH, friction=None)
    smooth = pair(c["angle"], *c["a"], c["v"][:2], c["v"][2:])
    collide_disks(0, 1, *(smooth[0, X:Y + 1] - smooth[1, X:Y + 1]), c["xi"], smooth, *c["m"], None)
    assert np.array_equal(disks, smooth)
    assert np.array_equal(spin, c["spin"])
    wall = smooth.copy()[:1]
    wall_spin = spin[:1].copy()
    wall_contact(2, 1.0, wall, wall_spin, c["m"][0], c["q"], SMOOTH, None)
    assert np.array_equal(wall, smooth[:1])
    assert np.array_equal(wall_spin, spin[:1])


def test_tc_contacts_are_smooth():
    assert compiled_tc_roughness(0.1, 0.5, 1.0, 0.95, 0.0) == SMOOTH
    assert compiled_tc_roughness(0.1, 0.5, 1.0, 0.5, 0.99) == SMOOTH
    assert compiled_tc_roughness(0.1, 0.5, 1.0, 0.5, 0.5) == 0.5
    assert compiled_tc_roughness(None, 0.5, 1.0, 0.95, 0.95) == 0.5
    assert tc_roughness(0.1, 0.5, 1.0, 0.95, 0.0) == SMOOTH


def test_parameters_are_checked():
    assert rough_parameters(1, None, 0.5) == (1.0, None, 0.5)
    for bad in [(1.5, None, 0.5), (0.0, -0.1, 0.5), (0.0, None, 0.0), (0.0, math.inf, 0.5)]:
        with pytest.raises(ValueError):
            rough_parameters(*bad)


def test_temperatures_of_maxwellian_spins():
    rng = np.random.default_rng(3)
    n, m, a, q = 200_000, 2.0, 0.01, 0.5
    inertia = np.full(n, moment_of_inertia(q, m, a))
    spin = maxwellian_spins(rng, 0.7, inertia)
    # ⟨I ω²⟩ = T with relative standard error √(2/n) = 0.3 %
    assert rotational_temperature(spin, inertia) == pytest.approx(0.7, rel=0.015)
    assert rotational_energy(spin, inertia) == pytest.approx(
        0.5 * n * rotational_temperature(spin, inertia), rel=1e-12)
    assert translational_temperature([[3.0, 4.0], [0.0, 0.0]], m) == 12.5


@njit(cache=True)
def collisional_averages(normals, angles, xi, beta, q, t_tr, t_rot):
    """⟨ΔE_tr⟩ and ⟨ΔE_rot⟩ per collision of equal disks (m = 1, a = 1/2) drawn from
    Maxwellians at T_tr and T_rot (``normals`` float64[samples, 6] standard normal numbers,
    ``angles`` float64[samples] the directions of n), each pair weighted by its collision rate
    w = |g_n| Θ(−g_n), with their standard errors √(Σ w² (x − x̄)²)/Σ w."""
    samples = angles.size
    m, a = 1.0, 0.5
    inertia = q * m * a * a
    disks = np.zeros((2, DISK_COLUMNS))
    disks[:, RADIUS] = a
    spin = np.zeros(2)
    w = np.zeros(samples)
    d_tr = np.zeros(samples)
    d_rot = np.zeros(samples)
    for k in range(samples):
        for d in range(2):
            disks[d, VX] = normals[k, 3 * d] * math.sqrt(t_tr / m)
            disks[d, VY] = normals[k, 3 * d + 1] * math.sqrt(t_tr / m)
            spin[d] = normals[k, 3 * d + 2] * math.sqrt(t_rot / inertia)
        nx, ny = math.cos(angles[k]), math.sin(angles[k])
        e_tr = 0.5 * m * np.sum(disks[:, VX:VY + 1] ** 2)
        e_rot = 0.5 * inertia * np.sum(spin**2)
        _, p_n = collide_disks(0, 1, nx, ny, xi, disks, m, m, None)  # |r| = 1: virial = P_n
        if p_n == 0.0:  # separating pairs do not collide
            continue
        w[k] = p_n
        rough_contact(0, 1, nx, ny, p_n, disks, spin, m, m, q, beta, None)
        d_tr[k] = 0.5 * m * np.sum(disks[:, VX:VY + 1] ** 2) - e_tr
        d_rot[k] = 0.5 * inertia * np.sum(spin**2) - e_rot
    total = np.sum(w)
    mean_tr = np.sum(w * d_tr) / total
    mean_rot = np.sum(w * d_rot) / total
    error_tr = math.sqrt(np.sum((w * (d_tr - mean_tr)) ** 2)) / total
    error_rot = math.sqrt(np.sum((w * (d_rot - mean_rot)) ** 2)) / total
    return mean_tr, mean_rot, error_tr, error_rot


@pytest.mark.parametrize(("xi", "beta", "q", "t_rot"),
                         [(0.9, 0.5, 0.5, 0.4), (0.8, -0.5, 0.5, 2.0), (1.0, 0.3, 1.0, 1.0)])
def test_cooling_coefficients_are_the_maxwellian_average_of_the_contact_rule(xi, beta, q, t_rot):
    """dT_tr/dt = −ν (A T_tr − B T_rot), dT_rot/dt = 2ν (B T_tr − C T_rot) with ν the
    collision frequency: per collision ⟨ΔE_tr⟩ = −2 (A T_tr − B T_rot) and
    ⟨ΔE_rot⟩ = 2 (B T_tr − C T_rot) (E_tr = T_tr, E_rot = T_rot/2 per disk, two disks per
    collision)."""
    t_tr = 1.0
    a_coef, b_coef, c_coef = theory.rough_disk_cooling_coefficients(xi, beta, q)
    rng = np.random.default_rng(11)
    samples = 400_000
    mean_tr, mean_rot, error_tr, error_rot = collisional_averages(
        rng.normal(size=(samples, 6)), rng.uniform(0.0, 2.0 * math.pi, samples), xi, beta, q,
        t_tr, t_rot)
    assert mean_tr == pytest.approx(-2 * (a_coef * t_tr - b_coef * t_rot), abs=5 * error_tr)
    assert mean_rot == pytest.approx(2 * (b_coef * t_tr - c_coef * t_rot), abs=5 * error_rot)


@pytest.mark.parametrize("q", [0.1, 0.4, 0.5, 1.0])
def test_perfectly_rough_elastic_disks_reach_equipartition(q):
    assert theory.rough_disk_temperature_ratio(1.0, 1.0, q) == pytest.approx(1.0, rel=1e-14)
    assert theory.rough_disk_cooling_rate(1.0, 1.0, q) == pytest.approx(0.0, abs=1e-15)


def test_smooth_limits():
    """β = −1: spin decouples, r = 0 and the cooling rate is the smooth (1 − ξ²)/2; at ξ = 1
    r → 0 continuously as β → −1, at ξ < 1 it diverges like q (1 − ξ²)/(2η²)."""
    assert theory.rough_disk_temperature_ratio(0.9, -1.0, 0.5) == 0.0
    assert theory.rough_disk_cooling_rate(0.9, -1.0, 0.5) == pytest.approx(0.5 * (1 - 0.81))
    assert theory.rough_disk_temperature_ratio(1.0, -1.0 + 1e-6, 0.5) < 1e-6
    eta = 0.5 * 1e-6 / 3.0
    assert theory.rough_disk_temperature_ratio(0.9, -1.0 + 1e-6, 0.5) == pytest.approx(
        0.5 * 0.19 / (2 * eta**2), rel=1e-3)
    nu0 = 3.0
    t0 = 4.0 / ((1 - 0.81) * nu0)  # Haff's t₀ of smooth disks
    assert theory.rough_disk_haff_temperature(t0, 2.0, nu0, 0.9, -1.0, 0.5) == pytest.approx(0.5)


@pytest.mark.parametrize(("xi", "beta"), [(0.9, 0.5), (0.9, 0.0), (0.8, -0.5), (0.5, 0.9)])
def test_temperature_ratio_is_where_the_cooling_equations_settle(xi, beta):
    """Integrate dT_tr/dτ = −(A T_tr − B T_rot), dT_rot/dτ = 2(B T_tr − C T_rot) (τ counts
    collisions; ν ∝ √T_tr only rescales time) from equipartition, and from no spin."""
    a_coef, b_coef, c_coef = theory.rough_disk_cooling_coefficients(xi, beta, 0.5)
    expected = theory.rough_disk_temperature_ratio(xi, beta, 0.5)
    for start in (1.0, 0.0):
        t_tr, t_rot, step = 1.0, start, 1e-2
        for _ in range(100_000):
            t_tr, t_rot = (t_tr - step * (a_coef * t_tr - b_coef * t_rot),
                           t_rot + 2 * step * (b_coef * t_tr - c_coef * t_rot))
            t_tr, t_rot = 1.0, t_rot / t_tr  # only the ratio matters
        assert t_rot == pytest.approx(expected, rel=1e-9)
