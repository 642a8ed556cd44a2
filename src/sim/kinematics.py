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
    never flies further than its shell (δ < L/4) before it is stored again.
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
    predictor, and the neighbour loop runs much faster without the mispredictions.
    """
    b = rx * vx + ry * vy
    c = rx * rx + ry * ry - sigma * sigma
    a = vx * vx + vy * vy
    cross = rx * vy - ry * vx
    discriminant = a * sigma * sigma - cross * cross
    tau = max(c / (-b + math.sqrt(max(discriminant, 0.0))), 0.0)
    return tau if (b < 0.0) & (discriminant > 0.0) else INF


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
