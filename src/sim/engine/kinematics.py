"""Free flight and contact times: every root the engine solves lives here.

Disks fly in straight lines between events, so a disk stored at position ``r`` at its own
time ``t_disk`` is at ``r + v (t - t_disk)`` at time ``t`` (lazy update). Contact times are
roots of quadratics ``a τ² + 2 b τ + c = 0``, taken in the cancellation-free form
(Press et al., *Numerical Recipes*, §5.6): the root is never formed as a small difference of
large numbers, and it is never negative, so no event is ever predicted in the past.

Units: lengths in box units, times in the scene's time unit; all functions take float64
scalars and return float64 scalars (``inf`` when there is no contact).

The per-disk state the event loop reads for every neighbour lives in one row of
``disks: float64[n, DISK_COLUMNS]`` (array of structs): predicting disk i touches one 64-byte
cache line per neighbour instead of one line in each of four arrays.
"""

import math

from numba import njit

INF = math.inf
#: Squared speeds below this (deep in the subnormal range of float64 once multiplied by a
#: length) count as rest: a disk that slow never reaches its shell.
TINY_SPEED_SQUARED = 1e-280

# columns of the disk table ``disks: float64[n, DISK_COLUMNS]``
X = 0  # position at the disk's own time (x, y)
Y = 1
VX = 2  # velocity (vx, vy)
VY = 3
T_OWN = 4  # the disk's own time (relative clock), at which (x, y) holds
RADIUS = 5
CX = 6  # centre of its neighbour shell (x, y)
CY = 7
DISK_COLUMNS = 8


@njit(cache=True, inline="always")
def minimum_image(dx, length, periodic):
    """Nearest periodic image of a separation ``dx`` along an axis of ``length``.

    Requires ``|dx| < 1.5 length``: stored positions are wrapped into the box and a disk
    never flies further than its shell (δ < L/8) before it is stored again. The engine sizes
    shells so that two disks in each other's lists are less than L/2 apart in the image in
    which they can touch (R_1 + R_2 + 4 δ ≤ L/2), which is then the nearest one.
    """
    if periodic:
        if dx > 0.5 * length:
            return dx - length
        if dx < -0.5 * length:
            return dx + length
    return dx


@njit(cache=True, inline="always")
def wrap(x, length, periodic):
    """Fold a coordinate back into ``[0, length)`` on a periodic axis."""
    if periodic:
        if x >= length:
            x -= length
            if x >= length:
                x = x % length
        elif x < 0.0:
            x += length
            if x < 0.0 or x >= length:
                x = x % length
    return x


@njit(cache=True, inline="always", error_model="numpy")
def pair_contact_time(rx, ry, vx, vy, sigma):
    """Time until two disks at separation ``r = r_i - r_j`` with relative velocity
    ``v = v_i - v_j`` reach contact distance ``sigma``.

    Solves |r + v τ| = σ. With b = r·v, c = |r|² - σ², a = |v|², the first root is
    τ = c / (-b + sqrt(D)) — cancellation free for approaching disks (b < 0) — and the
    discriminant is formed as D = a σ² - (r × v)², equal to b² - a c but without subtracting
    the large |r|²|v|² from itself, so grazing contacts far away keep their precision.
    Disks already overlapping by round-off while approaching (c < 0, b < 0) collide at
    once: τ = 0 rather than a negative time, so they never tunnel through each other.

    Branch-free: the root is always computed and discarded (→ inf) when the disks recede
    (b ≥ 0) or miss (D ≤ 0). Whether a pair approaches is a coin flip to the branch
    predictor; the neighbour loop asks :func:`may_touch_before` first, and only pairs that
    pass it pay for the root.
    """
    b = rx * vx + ry * vy
    c = rx * rx + ry * ry - sigma * sigma
    a = vx * vx + vy * vy
    cross = rx * vy - ry * vx
    discriminant = a * sigma * sigma - cross * cross
    tau = max(c / (-b + math.sqrt(max(discriminant, 0.0))), 0.0)
    return tau if (b < 0.0) & (discriminant > 0.0) else INF


@njit(cache=True, inline="always")
def pair_exit_time(rx, ry, vx, vy, distance):
    """Time until two disks that are closer than ``distance`` (their pair's state says so,
    whatever round-off says of |r|) are at that distance again, moving apart: the larger root
    of |r + v τ|² = distance² (b = r·v, c = |r|² − distance², a = |v|²), (s − b)/a for b ≤ 0
    and −c/(b + s) for b > 0 with s = √(b² − a c) (no cancellation); at once (0) for a pair
    found beyond it by round-off and moving apart; ∞ for a pair at rest."""
    a = vx * vx + vy * vy
    if a == 0.0:
        return INF
    b = rx * vx + ry * vy
    c = rx * rx + ry * ry - distance * distance
    s = math.sqrt(max(b * b - a * c, 0.0))
    if b <= 0.0:
        return (s - b) / a
    return max(-c / (b + s), 0.0)


@njit(cache=True, inline="always")
def may_touch_before(rx, ry, vx, vy, sigma, tau):
    """Whether two disks (separation ``r``, relative velocity ``v``, contact distance σ) may
    touch sooner than τ; when not, :func:`pair_contact_time` is at least τ.

    With b = r·v and c = |r|² - σ² (as there), an approaching pair apart (b < 0 < c) has
    D = b² - a c ≤ b², hence τ_contact = c / (-b + sqrt(D)) ≥ c / (-2 b): it cannot touch
    before τ when c > -2 b τ. The test c ≤ -2 b τ is false as well for receding pairs apart
    (b ≥ 0 < c; also b = 0 with τ = ∞, where -2 b τ is NaN) and true for touching or
    overlapping approaching ones, which collide at once, even when -2 b τ underflows to zero
    (a pair at contact approaching at 1e-46 with τ = 1e-313, found by hypothesis). The filter
    of Smallenburg's code (Eur. Phys. J. E 45, 22 (2022)): no square root or division for
    most neighbours.
    """
    b = rx * vx + ry * vy
    c = rx * rx + ry * ry - sigma * sigma
    return c <= -2.0 * b * tau


@njit(cache=True, inline="always", error_model="numpy")
def shell_exit_time(dx, dy, vx, vy, delta):
    """Time until a disk at displacement ``d`` from its shell centre, moving with ``v``, is at
    distance ``delta`` from that centre: the larger root of |d + v τ|² = δ².

    With b = d·v, c = |d|² - δ² ≤ 0 the roots have opposite signs; the positive one is
    (-b + s)/a for b ≤ 0 and -c/(b + s) for b > 0, s = sqrt(b² - a c). A disk found outside
    its shell by round-off (c > 0) leaves at once (τ = 0).

    Both root forms are computed and one is selected, without a branch on the sign of b,
    which the branch predictor cannot guess.
    """
    a = vx * vx + vy * vy
    if a < TINY_SPEED_SQUARED:
        return INF
    c = dx * dx + dy * dy - delta * delta
    if c >= 0.0:
        return 0.0
    b = dx * vx + dy * vy
    s = math.sqrt(b * b - a * c)
    moving_in = (s - b) / a
    moving_out = -c / (b + s)
    return moving_in if b <= 0.0 else moving_out


@njit(cache=True, inline="always")
def wall_contact_time(x, v, radius, length):
    """Time until a disk at coordinate ``x`` (velocity component ``v``) touches the wall at
    0 (``v < 0``) or at ``length`` (``v > 0``); never negative. Returns (τ, side), side 0 for
    the low wall and 1 for the high wall, -1 when the disk does not move along the axis."""
    if v < 0.0:
        tau = (x - radius) / -v
        return (tau if tau > 0.0 else 0.0), 0
    if v > 0.0:
        tau = (length - radius - x) / v
        return (tau if tau > 0.0 else 0.0), 1
    return INF, -1


@njit(cache=True, inline="always", error_model="numpy")
def first_contact_accelerated(h, v, a):
    """First time τ ≥ 0 at which a gap h ≥ 0, opening at rate v and accelerating at a, closes:
    the smaller non-negative root of h + v τ + a τ²/2 = 0, or inf when it never closes.

    Cancellation-free (Numerical Recipes §5.6) with D = v² − 2 a h:
      closing (v < 0):  τ = 2h/(√D − v), the root before any turning point; none when D < 0
                        (the gap turns and opens again first);
      opening (v ≥ 0):  τ = (v + √D)/(−a) when pulled back (a < 0), else never.
    A gap found negative by round-off counts as closed: τ = 0 when closing, never in the past.
    Used for wall contacts under gravity, where a disk flies on a parabola.
    """
    if h < 0.0:
        h = 0.0
    if a == 0.0:
        return h / -v if v < 0.0 else INF
    discriminant = v * v - 2.0 * a * h
    if v < 0.0:
        if discriminant < 0.0:
            return INF
        return 2.0 * h / (math.sqrt(discriminant) - v)
    if a < 0.0:
        return (v + math.sqrt(discriminant)) / -a
    return INF


@njit(cache=True, inline="always", error_model="numpy")
def shell_exit_time_accelerated(dx, dy, vx, vy, g, delta):
    """A time at or before the first exit of a disk on the parabola d + v τ + g_vec τ²/2
    (|g_vec| = g) from the circle of radius δ about its shell centre (d: displacement from the
    centre); never later than the true exit, which is the root of a quartic.

    Two lower bounds, the larger is returned. With τ_l the exit of the straight path,
    |d + v τ| ≤ δ − g τ_l²/2 up to the exit τ_s of the straight path from the shrunk circle of
    that radius, and the bend adds at most g τ²/2 ≤ g τ_l²/2; and by the triangle inequality
    |d| + |v| τ + g τ²/2 ≤ δ up to τ_t = 2(δ − |d|)/(|v| + √(|v|² + 2 g (δ − |d|))).
    An early exit only rebuilds the list early: safe, and rare when g τ_l² ≪ δ.
    """
    tau_straight = shell_exit_time(dx, dy, vx, vy, delta)
    tau_shrunk = 0.0
    if tau_straight < INF:
        shrunk = delta - 0.5 * g * tau_straight * tau_straight
        if shrunk > 0.0:
            tau_shrunk = shell_exit_time(dx, dy, vx, vy, shrunk)
    room = delta - math.sqrt(dx * dx + dy * dy)
    tau_triangle = 0.0
    if room > 0.0:
        speed = math.sqrt(vx * vx + vy * vy)
        tau_triangle = 2.0 * room / (speed + math.sqrt(speed * speed + 2.0 * g * room))
    return max(tau_shrunk, tau_triangle)


#: Safe steps of :func:`first_contact_oscillating` before it hands back a point short of
#: contact (the caller re-predicts from there): bounds the work of one prediction.
OSCILLATING_STEPS = 64


@njit(cache=True, inline="always", error_model="numpy")
def first_contact_oscillating(h, v, a, amplitude, omega, phase, tolerance, horizon):
    """First time τ ≥ 0 at which the gap f(τ) = h + v τ + a τ²/2 − A sin(ω τ + φ) closes:
    a disk on a parabola meeting a wall that oscillates as A sin(ω t) (a vibrated floor).

    The root is transcendental; it is approached from below by steps that can never pass it.
    With |f''| ≤ K = |a| + A ω², the gap obeys f(τ + s) ≥ f + f' s − K s²/2, whose first root
    s = 2f/(−f' + √(f'² + 2 K f)) is a safe step (Newton's step, to second order, near a simple
    root). While the parabola stays above the band |f − q| ≤ A the exact quadratic root of
    q − A (:func:`first_contact_accelerated`) is a safe step too, and the larger is taken.

    Returns (τ, touching): touching when the gap is below ``tolerance`` (or negative, by
    round-off) and closing (f' < 0); a gap that small but opening is stepped over as if it
    were ``tolerance``. Otherwise τ is a point short of contact, reached after
    ``OSCILLATING_STEPS`` steps (e.g. a grazing approach), from which the caller predicts
    again. τ = inf when the disk never reaches the band, or not before ``horizon`` (the time
    of an event already known to come first, which ends the search early).
    """
    curvature = abs(a) + amplitude * omega * omega
    tau = 0.0
    for _ in range(OSCILLATING_STEPS):
        if tau > horizon:
            return INF, False
        q = h + (v + 0.5 * a * tau) * tau
        q_rate = v + a * tau
        if q - amplitude > 0.0:
            band = first_contact_accelerated(q - amplitude, q_rate, a)
            if band == INF:
                return INF, False
        else:
            band = 0.0
        angle = omega * tau + phase
        gap = q - amplitude * math.sin(angle)
        rate = q_rate - amplitude * omega * math.cos(angle)
        if gap <= tolerance and rate < 0.0:
            return tau, True
        gap = max(gap, tolerance)
        step = 2.0 * gap / (-rate + math.sqrt(rate * rate + 2.0 * curvature * gap))
        tau += max(step, band)
        if tau == INF:
            return INF, False
    return tau, False


@njit(cache=True, inline="always", error_model="numpy")
def growing_contact_time(rx, ry, vx, vy, sigma, sigma_rate, tau):
    """Time until two growing disks touch: the first root of |r + v τ| = σ + ṡ τ, with
    separation r = r_i − r_j, relative velocity v = v_i − v_j, contact distance σ now and its
    rate of growth ṡ > 0 (Lubachevsky & Stillinger, J. Stat. Phys. 60, 561 (1990); Donev,
    Torquato & Stillinger, J. Comput. Phys. 202, 737 (2005)); ∞ when there is none, or when
    the filter shows that it comes no sooner than τ.

    Squared, f(τ) = A τ² + 2 B τ + C = 0 with A = |v|² − ṡ², B = r·v − σ ṡ, C = |r|² − σ².
    Unlike the hard core's, A may be ≤ 0 (disks slower than their growth always meet) and a
    pair receding (r·v > 0) still meets when B < 0. The filter: on [0, τ] f is at least
    C + 2 B τ' − ṡ² τ'², concave, so f > 0 there when C > 0 and C + (2 B − ṡ² τ) τ > 0.
    The root, cancellation-free (Numerical Recipes §5.6) with D = B² − A C formed as
    |v|² σ² − (r × v)² + ṡ (ṡ |r|² − 2 σ r·v) (no large |r|²|v|² taken from itself):
      B < 0:          τ = C / (−B + √D), none when A > 0 and D ≤ 0 (a miss);
      B ≥ 0, A < 0:   τ = (B + √D) / (−A), the later root (the pair first separates);
      B ≥ 0, A ≥ 0:   none (f grows for ever).
    A pair overlapping by round-off and closing (C < 0, B < 0) touches at once: τ = 0, never
    in the past.
    """
    b0 = rx * vx + ry * vy
    r_squared = rx * rx + ry * ry
    c = r_squared - sigma * sigma
    b = b0 - sigma * sigma_rate
    if c > 0.0 and c + (2.0 * b - sigma_rate * sigma_rate * tau) * tau > 0.0:
        return INF
    v_squared = vx * vx + vy * vy
    a = v_squared - sigma_rate * sigma_rate
    cross = rx * vy - ry * vx
    discriminant = (v_squared * sigma * sigma - cross * cross
                    + sigma_rate * (sigma_rate * r_squared - 2.0 * sigma * b0))
    root = math.sqrt(max(discriminant, 0.0))
    if b < 0.0:
        if a > 0.0 and discriminant <= 0.0:
            return INF
        return max(c / (root - b), 0.0)
    if a < 0.0:
        return (b + root) / -a
    return INF


@njit(cache=True, inline="always", error_model="numpy")
def shrinking_shell_exit_time(dx, dy, vx, vy, delta, rate):
    """Time until a disk at displacement ``d`` from its shell centre, moving with ``v``,
    leaves a circle about that centre whose radius δ shrinks at ``rate`` ≥ 0 (a growing disk's
    shell, :mod:`sim.effects.growth`): the first root of |d + v τ| = δ − rate τ.

    Squared: A τ² + 2 B τ + C = 0 with A = |v|² − rate², B = d·v + δ rate, C = |d|² − δ² < 0
    inside. The shrinking radius reaches zero at δ/rate, where |d + v τ| ≥ 0, so the first
    root of the squared equation is the exit. D = B² − A C is formed without cancellation (as
    in :func:`growing_contact_time`). B > 0: τ = −C/(B + √D); B ≤ 0 (then A > 0):
    τ = (√D − B)/A (as :func:`shell_exit_time`, which this is at rate 0). A disk found outside
    by round-off leaves at once (τ = 0); one whose speed and shrinking are both below
    ``TINY_SPEED_SQUARED`` counts as at rest, never leaving.
    """
    v_squared = vx * vx + vy * vy
    if v_squared + rate * rate < TINY_SPEED_SQUARED:
        return INF
    c = dx * dx + dy * dy - delta * delta
    if c >= 0.0:
        return 0.0
    a = v_squared - rate * rate
    d_dot_v = dx * vx + dy * vy
    b = d_dot_v + delta * rate
    cross = dx * vy - dy * vx
    # D = B² − A C formed as |v|² δ² − (d × v)² + rate (rate |d|² + 2 δ d·v): a disk far slower
    # than its shell shrinks keeps |v|² (lost in A = |v|² − rate²), so its exit is not late
    s = math.sqrt(max(v_squared * delta * delta - cross * cross
                      + rate * (rate * (dx * dx + dy * dy) + 2.0 * delta * d_dot_v), 0.0))
    if b > 0.0:
        return -c / (b + s)
    if a > 0.0:
        return (s - b) / a
    return INF


@njit(cache=True, inline="always", error_model="numpy")
def shrinking_shell_exit_time_accelerated(dx, dy, vx, vy, g, delta, rate):
    """:func:`shell_exit_time_accelerated` for a shell shrinking at ``rate``
    (:func:`shrinking_shell_exit_time`): a time at or before the first exit of a disk on a
    parabola (|g_vec| = g) from a circle of radius δ − rate τ. The same two lower bounds: the
    exit τ_s of the straight path from the circle shrunk by g τ_l²/2 (τ_l the straight path's
    exit), and the triangle bound |d| + (|v| + rate) τ + g τ²/2 ≤ δ."""
    tau_straight = shrinking_shell_exit_time(dx, dy, vx, vy, delta, rate)
    tau_shrunk = 0.0
    if tau_straight < INF:
        shrunk = delta - 0.5 * g * tau_straight * tau_straight
        if shrunk > 0.0:
            tau_shrunk = shrinking_shell_exit_time(dx, dy, vx, vy, shrunk, rate)
    room = delta - math.sqrt(dx * dx + dy * dy)
    tau_triangle = 0.0
    if room > 0.0:
        speed = math.sqrt(vx * vx + vy * vy) + rate
        tau_triangle = 2.0 * room / (speed + math.sqrt(speed * speed + 2.0 * g * room))
    return max(tau_shrunk, tau_triangle)
