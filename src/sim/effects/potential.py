"""Stepped pair potentials: a hard core with square wells and square shoulders around it.

The pair potential of disks i and j (σ = σ_ij = R_i + R_j, steps λ_1 < … < λ_K in units of
σ, energies ε_1 … ε_K in the run's energy units, m v²):

    u(r) = ∞ for r < σ,   u(r) = ε_k for λ_{k−1} σ ≤ r < λ_k σ (λ_0 = 1),   u(r) = 0 beyond λ_K σ;

a square well is one step with ε_1 < 0, a square shoulder one with ε_1 > 0 (Alder &
Wainwright, J. Chem. Phys. 31, 459 (1959); Rapaport, The Art of Molecular Dynamics
Simulation, 2nd ed. (2004), ch. 14; Bannerman, Sargant & Lue, J. Comput. Chem. 32, 3329
(2011), DynamO). Every pair has a state: the shell it is in, k = 1 … K, or 0 beyond the last
step, kept by the events alone (:func:`sim.engine.pairs.set_pair_state`), never read off a
distance that round-off may put on the wrong side of a step.

Events of a pair in shell k: its core contact (k = 1, the hard-disk collision with
restitution, :func:`sim.engine.pairs.collide`), the step at λ_{k−1} σ reached moving in
(k ≥ 2, or the last step from beyond, k = 0) and the step at λ_k σ reached moving out. At a
step, with r̂ the unit separation, v_n = r̂·(v_i − v_j) the normal relative velocity and
μ = m_i m_j / (m_i + m_j), crossing costs ΔU = u(beyond the step) − u(here): the pair
crosses when μ v_n²/2 > ΔU, its normal velocity becoming sign(v_n) √(v_n² − 2ΔU/μ), and
bounces back (v_n → −v_n, its shell kept) otherwise. The impulse is along r̂,
Δp_i = −Δp_j = μ (v_n' − v_n) r̂, so momentum is conserved and kinetic plus potential
energy as well; r·Δp_i enters the collision virial and hence the pressure.
"""

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from sim.effects.pressure_tensor import add_virial_tensor
from sim.effects.values import ConfigError
from sim.engine.box import separation
from sim.engine.inputs import refused
from sim.engine.kinematics import (
    INF,
    RADIUS,
    VX,
    VY,
    X,
    Y,
    may_touch_before,
    pair_contact_time,
    pair_exit_time,
)
from sim.engine.pairs import collide, hard_core_time, pair_state, rules, set_pair_state
from sim.engine.parameters import per_disk
from sim.engine.sizing import periodic_room
from sim.engine.stamps import invalidate

KEYWORDS = {
    "potential_steps": (None, "λ_1 < … < λ_K of a stepped pair potential in units of σ_ij "
                              "(:mod:`sim.effects.potential`), finite and > 1: a list for "
                              "every pair, or a symmetric [s][s] table of lists, one per "
                              "species pair; None or [] = hard disks"),
    "potential_energies": (None, "ε_1 … ε_K of the shells inside λ_1 … λ_K (energy units of "
                                 "½ m v²), finite, as potential_steps is given"),
}

#: the events of a pair: its core contact, a step reached moving in, a step reached moving out
CORE, INWARD, OUTWARD = 0, 1, 2


class SteppedPotential(NamedTuple):
    """A stepped pair potential per species pair (s species, at most K steps): ``steps``
    float64[s, s, K] λ_1 < … < λ_K in units of σ_ij, ``energies`` float64[s, s, K] ε_k of the
    shell inside λ_k, ``count`` int32[s, s] the steps of each species pair (the places
    beyond hold nothing), ``reach`` float64[s] the largest λ of each species' pairs."""

    steps: np.ndarray
    energies: np.ndarray
    count: np.ndarray
    reach: np.ndarray


def check_config(cfg):
    """potential.steps finite, > 1 and increasing; potential.energies finite, one per step;
    no steps with growing disks."""
    steps, energies = list(cfg.potential.steps), list(cfg.potential.energies)
    allowed = _check_steps(steps, energies)
    if allowed is not None:
        raise ConfigError(*allowed)
    if steps and cfg.growth.rate > 0.0:
        raise ConfigError("potential.steps", steps, "[] with growing disks (growth.rate > 0), "
                          "which grow hard cores")


def check_scene(cfg, scene):
    """The steps within the box's periodic-image rule (the engine's,
    :func:`sim.engine.sizing.periodic_room`, for reaches λ_K R_i): two disks of the largest
    radii R_1, R_2 have no pair event beyond λ_K (R_1 + R_2), which must stay below half a
    periodic side, where a separation is taken to its nearest image."""
    steps = list(cfg.potential.steps)
    if not steps:
        return
    box = scene.boundary.size
    room, axis, a_1, a_2 = periodic_room(box, scene.boundary.periodic,
                                         steps[-1] * np.asarray(scene.radius))
    if room <= 0.0:
        largest = steps[-1] * 0.5 * box[axis] / (a_1 + a_2)
        raise ConfigError("potential.steps", steps, f"steps below {largest:.4g} σ in this "
                          f"periodic box: a pair's last step must stay within half a side "
                          f"(λ_K (R_1 + R_2) < L/2, R_1, R_2 the largest radii)")


def _check_steps(steps, energies):
    """None for a good potential (lists of numbers), else (key, value, allowed)."""
    if not all(_number(x) and x > 1.0 for x in steps) or any(
            b <= a for a, b in zip(steps, steps[1:], strict=False)):
        return ("potential.steps", steps, "finite numbers > 1 (units of σ_ij), increasing: "
                                          "λ_1 < λ_2 < …; [] = hard disks")
    if len(energies) != len(steps) or not all(_number(x) for x in energies):
        return ("potential.energies", energies, f"{len(steps)} finite numbers, one per step "
                                                f"of potential.steps")
    return None


def _number(x):
    return isinstance(x, int | float) and not isinstance(x, bool) and math.isfinite(x)


def engine_arguments(cfg):
    """The steps and energies of the config (None for hard disks)."""
    steps = [float(x) for x in cfg.potential.steps]
    return {"potential_steps": steps or None,
            "potential_energies": [float(x) for x in cfg.potential.energies] if steps else None}


def loop_values(keywords, context):
    """The pair interaction: the :class:`SteppedPotential` of the keywords, None for hard
    disks; refused for steps that are not finite, > 1 and increasing, for energies not one
    finite number per step, and for a table that is not [s][s] over the scene's species."""
    steps, energies = keywords["potential_steps"], keywords["potential_energies"]
    if not steps:
        if energies:
            raise refused("Engine", "potential_energies", energies, "None without "
                          "potential_steps")
        return {"pair_interaction": None}
    n_species = context["n_species"]
    if not isinstance(steps[0], list | tuple | np.ndarray):  # one potential for every pair
        steps = [[list(steps)] * n_species] * n_species
        energies = [[list(energies or [])] * n_species] * n_species
    if any(len(table or []) != n_species or any(len(row) != n_species for row in table)
           for table in (steps, energies)):
        raise refused("Engine", "potential_steps", steps, f"a list for every pair, or a "
                      f"[{n_species}][{n_species}] table of lists, one per species pair")
    for a in range(n_species):
        for b in range(n_species):
            allowed = _check_steps(list(steps[a][b]), list(energies[a][b]))
            if allowed is not None:
                key = allowed[0].replace("potential.", "potential_")
                raise refused("Engine", key, allowed[1], allowed[2] + f" (species {a}, {b})")
            if (list(steps[a][b]), list(energies[a][b])) != (list(steps[b][a]),
                                                             list(energies[b][a])):
                raise refused("Engine", "potential_steps", steps, "a symmetric table: the "
                              f"potential of species {a}, {b} that of {b}, {a}")
    return {"pair_interaction": stepped_potential(steps, energies)}


def stepped_potential(steps, energies):
    """The :class:`SteppedPotential` of the [s][s] tables of lists ``steps`` and
    ``energies`` (checked by :func:`loop_values`)."""
    n_species = len(steps)
    most = max(1, max(len(steps[a][b]) for a in range(n_species) for b in range(n_species)))
    table = np.full((n_species, n_species, most), np.inf)
    values = np.zeros((n_species, n_species, most))
    count = np.zeros((n_species, n_species), np.int32)
    for a in range(n_species):
        for b in range(n_species):
            k = len(steps[a][b])
            table[a, b, :k], values[a, b, :k], count[a, b] = steps[a][b], energies[a][b], k
    reach = np.array([max([1.0, *table[a][np.isfinite(table[a])]]) for a in range(n_species)])
    return SteppedPotential(table, values, count, reach)


@njit(cache=True, inline="always")
def step_event_time(value, i, j, rx, ry, vx, vy, sigma, tau, state, disks):
    """The next event of the pair (i, j) in shell ``state`` (see the module docstring): the
    inner edge reached moving in, if the pair reaches it (and may before τ, the filter), else
    the outer one reached moving out (none beyond the last step)."""
    a, b = per_disk(disks.species, i), per_disk(disks.species, j)
    if value.count[a, b] == 0:  # a pair of hard disks
        return hard_core_time(rx, ry, vx, vy, sigma, tau), CORE
    if state == 0:  # the last step, from beyond it
        return hard_core_time(rx, ry, vx, vy, value.steps[a, b, value.count[a, b] - 1] * sigma,
                              tau), INWARD
    inner = sigma if state == 1 else value.steps[a, b, state - 2] * sigma
    if may_touch_before(rx, ry, vx, vy, inner, tau):
        t_in = pair_contact_time(rx, ry, vx, vy, inner)
        if t_in < INF:  # the filter passes pairs that miss the inner edge, too
            return t_in, CORE if state == 1 else INWARD
    return pair_exit_time(rx, ry, vx, vy, value.steps[a, b, state - 1] * sigma), OUTWARD


@njit(cache=True, inline="always")
def shell_energy(value, a, b, state):
    """u of species pair (a, b) in shell ``state`` (0: beyond the last step)."""
    return 0.0 if state == 0 else value.energies[a, b, state - 1]


@njit(cache=True, inline="always")
def cross_step(value, event, i, j, t, t_origin, disks, neighbours, box, effects, tallies,
               contact):
    """Apply the pair event ``event`` of disks i and j, both flown to time t: the core
    contact, or a step crossed or bounced off (see the module docstring). Returns (energy
    dissipated, r·Δp_i, event log full, the disk found collapsing or −1, whether it was a
    contact)."""
    if event == CORE:
        lost, virial, log_full, culprit = collide(i, j, t, t_origin, disks, box, effects,
                                                  tallies, contact)
        return lost, virial, log_full, culprit, True
    table = disks.table
    rx, ry = separation(box, table[i, X] - table[j, X], table[i, Y] - table[j, Y])
    r = math.sqrt(rx * rx + ry * ry)
    nx, ny = rx / r, ry / r
    v_n = nx * (table[i, VX] - table[j, VX]) + ny * (table[i, VY] - table[j, VY])
    outward = event == OUTWARD
    if (v_n > 0.0) != outward:  # round-off: not moving across the step; predicted again
        return 0.0, 0.0, False, -1, False
    a, b = per_disk(disks.species, i), per_disk(disks.species, j)
    here = pair_state(neighbours, i, j)
    last = value.count[a, b]
    beyond = (here + 1 if here < last else 0) if outward else (last if here == 0 else here - 1)
    rise = shell_energy(value, a, b, beyond) - shell_energy(value, a, b, here)
    m_i, m_j = per_disk(disks.mass, i), per_disk(disks.mass, j)
    mu = m_i * m_j / (m_i + m_j)
    if 0.5 * mu * v_n * v_n > rise:
        v_after = math.copysign(math.sqrt(v_n * v_n - 2.0 * rise / mu), v_n)
        set_pair_state(neighbours, i, j, beyond)
    else:
        v_after = -v_n
    dp = mu * (v_after - v_n)  # along r̂, on disk i
    table[i, VX] += dp * nx / m_i
    table[i, VY] += dp * ny / m_i
    table[j, VX] -= dp * nx / m_j
    table[j, VY] -= dp * ny / m_j
    invalidate(i, disks)
    invalidate(j, disks)
    add_virial_tensor(effects.virial_tensor, rx, ry, dp * r)
    return 0.0, dp * r, False, -1, False


@njit(cache=True, inline="always")
def step_reach(value, i, disks):
    """λ_max R_i: disks i and j have no event while farther apart than λ_max (R_i + R_j)."""
    return value.reach[per_disk(disks.species, i)] * disks.table[i, RADIUS]


@njit(cache=True)
def initial_shell(value, i, j, rx, ry, sigma, disks):
    """The shell of the pair (i, j) at the engine's construction, from its distance."""
    a, b = per_disk(disks.species, i), per_disk(disks.species, j)
    r2 = rx * rx + ry * ry
    for k in range(value.count[a, b]):
        edge = value.steps[a, b, k] * sigma
        if r2 < edge * edge:
            return np.int32(k + 1)
    return np.int32(0)


def pair_potential_energy(value, disks):
    """U = Σ over the listed pairs of u(their shell), each pair counted once from its two
    list entries (the lists of disk i: ``nb[nb_start[i]:nb_start[i] + nb_count[i]]``, with
    their states beside): float."""
    nb_start, nb_count, nb = disks.nb_start, disks.nb_count, disks.nb
    owner = np.repeat(np.arange(nb_start.shape[0]), nb_count)
    first = np.cumsum(nb_count) - nb_count
    entry = nb_start[owner] + np.arange(owner.shape[0]) - first[owner]
    state = disks.pair_state[entry]
    inside = state > 0
    species = np.broadcast_to(disks.species, nb_start.shape)
    a, b = species[owner[inside]], species[nb[entry[inside]]]
    return 0.5 * float(value.energies[a, b, state[inside] - 1].sum())


rules(SteppedPotential, step_event_time, cross_step, reach=step_reach,
      initial_state=initial_shell, energy=pair_potential_energy)
