"""Two disks against closed-form results (docs/physics.md, "Two-body collisions")."""

import math

import numpy as np
import pytest

from sim.engine import Boundary, Engine

# (m1, m2, b/a, ξ): projectile m1 moving along +x at speed v, target m2 at rest
CASES = [
    (1.0, 1.0, 0.0, 1.0),
    (1.0, 4.0, 0.0, 1.0),
    (4.0, 1.0, 0.0, 0.5),
    (1.0, 1.0, 0.5, 1.0),
    (1.0, 3.0, 0.8, 1.0),
    (2.0, 1.0, 0.3, 0.7),
    (1e-6, 1.0, 0.6, 1.0),
    (1.0, 1e6, 0.9, 0.9),
    (1.0, 1.0, 0.999999, 1.0),
]


def collide(m1, m2, b_over_a, xi, v=2.0, r1=0.01, r2=0.03):
    """Disks 0 and 1 after their one collision. Disks of unequal masses are two species (as in
    the scattering scene). Inelastic pairs have the TC model on, which acts on no first
    contact; unequal ones also ξ_w = ξ (no wall is reached) and a large disk at rest in a
    corner (nothing reaches it): the compiled variants of the cooling and crater scenes."""
    a = r1 + r2
    position = [[0.3, 0.5 + b_over_a * a], [0.6, 0.5]]
    velocity, radius, mass = [[v, 0.0], [0.0, 0.0]], [r1, r2], [m1, m2]
    options = {"tc": 1e-9} if xi < 1.0 else {}
    if m1 != m2 and xi < 1.0:
        position.append([0.15, 0.15])
        velocity.append([0.0, 0.0])
        radius.append(0.1)
        mass.append(1.0)
        options["wall_restitution"] = xi
    species = np.arange(len(mass)) if m1 != m2 else None
    engine = Engine(position, velocity, radius, mass=mass, species=species, restitution=xi,
                    boundary=Boundary(size=(1.0, 1.0)), **options)
    engine.run(collisions=1)
    assert engine.collisions == 1 and engine.wall_contacts == 0
    return engine, a


@pytest.mark.parametrize(("m1", "m2", "b_over_a", "xi"), CASES)
def test_impulse_and_energy_loss(m1, m2, b_over_a, xi):
    v = 2.0
    engine, _ = collide(m1, m2, b_over_a, xi, v)
    cos_alpha = math.sqrt(1.0 - b_over_a**2)
    mu = m1 * m2 / (m1 + m2)
    impulse = (1.0 + xi) * mu * v * cos_alpha
    recoil = engine.velocities()[1]
    # grazing contacts are ill-conditioned: a round-off δ in the contact point changes
    # cos α by about δ/cos α, hence the tolerance 1e-12/cos²α
    assert np.hypot(*recoil) == pytest.approx(impulse / m2, rel=1e-12 / cos_alpha**2)
    # the target recoils along the line of centres, at angle α below the x axis
    assert math.atan2(-recoil[1], recoil[0]) == pytest.approx(math.asin(b_over_a),
                                                              abs=1e-12 / cos_alpha)
    assert engine.dissipated_energy == pytest.approx(
        0.5 * (1.0 - xi**2) * mu * (v * cos_alpha) ** 2, rel=1e-12, abs=1e-300)
    p = engine.momentum()
    assert p[0] == pytest.approx(m1 * v, rel=1e-12)
    assert p[1] == pytest.approx(0.0, abs=1e-12 * m1 * v)


@pytest.mark.parametrize(("m1", "m2", "b_over_a", "xi"), [c for c in CASES if c[3] == 1.0])
def test_elastic_scattering_angles(m1, m2, b_over_a, xi):
    """b = a cos(χ/2); tan θ1 = sin χ / (m1/m2 + cos χ); θ2 = (π − χ)/2."""
    engine, _ = collide(m1, m2, b_over_a, xi)
    chi = 2.0 * math.acos(b_over_a)
    theta1 = math.atan2(math.sin(chi), m1 / m2 + math.cos(chi))
    v1 = engine.velocities()[0]
    if np.hypot(*v1) > 1e-9:
        assert math.atan2(v1[1], v1[0]) == pytest.approx(theta1, abs=1e-10)
    v2 = engine.velocities()[1]
    assert math.atan2(-v2[1], v2[0]) == pytest.approx(0.5 * (math.pi - chi), abs=1e-10)


@pytest.mark.parametrize(("m1", "m2", "xi"), [(1.0, 1.0, 1.0), (1.0, 3.0, 0.6), (5.0, 1.0, 0.2)])
def test_head_on(m1, m2, xi):
    v = 2.0
    engine, _ = collide(m1, m2, 0.0, xi, v)
    assert engine.velocities()[0, 0] == pytest.approx((m1 - xi * m2) / (m1 + m2) * v, abs=1e-14)
    assert engine.velocities()[1, 0] == pytest.approx((1 + xi) * m1 / (m1 + m2) * v, rel=1e-14)
    assert engine.velocities()[:2, 1] == pytest.approx([0.0, 0.0], abs=1e-15)
