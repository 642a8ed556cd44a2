"""The structure of a packing: its contact network and rattlers, the bond-orientational
order ψ₆ of its disks, and the pressure along a compression.

Contacts: disks i and j touch when their gap |r_ij| − (R_i + R_j) is below ``tolerance``
times the mean diameter 2⟨R⟩. A jammed packing from an LS compression stopped at a reduced
pressure βP/ρ ≈ 10⁶ has its contacts at gaps of about 10⁻⁶ σ and the next neighbours at
gaps of order 10⁻² σ, so the count is flat (a plateau) for tolerances between the two
(:func:`contact_numbers` sweeps them). Rattlers are disks held by fewer than three contacts
(d + 1 in d = 2 dimensions: no frictionless disk is stable with fewer); removing one takes
its contacts away from its neighbours, so they are removed recursively (O'Hern, Silbert, Liu
& Nagel, PRE 68, 011306 (2003)). The backbone's mean contact number z is 4 = 2d at the
isostatic point of frictionless disks, less a correction of order 1/N for a finite packing.

Bond order: ψ₆(i) = (1/n_i) Σ_j exp(6 i θ_ij) over the n_i Voronoi neighbours j of disk i
(θ_ij the angle of r_j − r_i, through the nearest periodic image; the neighbours are the
edges of the Delaunay triangulation of the centres, periodic images of the disks near the
edges included), and the global order |Ψ₆| = |(1/N) Σ_i ψ₆(i)|: 1 for a hexagonal crystal,
of order 1/√N for a fluid (Nelson & Halperin, PRB 19, 2457 (1979); Bernard & Krauth, PRL 107,
155704 (2011)). freud's ``Hexatic`` with its ``Voronoi`` neighbours is the test's oracle.

Positions float64[n, 2] in the box [0, L_x] × [0, L_y], radii float64[n].
"""

import numpy as np

from sim.checks.audit import kd_tree
from sim.engine.box import folded, nearest_images
from sim.engine.observables import virial_pressure

#: tolerances of :func:`contact_numbers`, in units of the mean diameter: from below the
#: contacts' gaps of an LS packing at βP/ρ ≈ 10⁶ to above them
CONTACT_TOLERANCES = np.logspace(-9, -1, 17)

#: the contacts a frictionless disk needs to be held, d + 1 in two dimensions
HELD = 3


def contacts(position, radius, box, periodic, tolerance):
    """The pairs (i, j), i < j, int64[k, 2], whose gap is below ``tolerance`` × 2⟨R⟩."""
    position = folded(np.asarray(position, np.float64), box, periodic)
    radius = np.asarray(radius, np.float64)
    slack = tolerance * 2.0 * float(np.mean(radius))
    tree = kd_tree(position, box, periodic)
    pairs = tree.query_pairs(2.0 * float(radius.max()) + slack, output_type="ndarray")
    if pairs.size == 0:
        return np.zeros((0, 2), np.int64)
    r = nearest_images(position[pairs[:, 0]] - position[pairs[:, 1]], box, periodic)
    gap = np.hypot(r[:, 0], r[:, 1]) - radius[pairs[:, 0]] - radius[pairs[:, 1]]
    return pairs[gap < slack].astype(np.int64)


def backbone(pairs, n):
    """Whether each of the ``n`` disks is in the backbone bool[n]: rattlers, disks with fewer
    than :data:`HELD` contacts among ``pairs``, removed until none is left."""
    kept = np.ones(n, bool)
    while True:
        live = pairs[kept[pairs[:, 0]] & kept[pairs[:, 1]]]
        count = np.bincount(live.ravel(), minlength=n)
        loose = kept & (count < HELD)
        if not loose.any():
            return kept
        kept &= ~loose


def contact_number(position, radius, box, periodic, tolerance):
    """(z, rattler fraction, backbone contacts) of a packing at one tolerance: z = 2 C / N_b,
    with C the contacts among the N_b backbone disks (:func:`backbone`); z = 0 with no
    backbone."""
    n = len(radius)
    pairs = contacts(position, radius, box, periodic, tolerance)
    kept = backbone(pairs, n)
    live = pairs[kept[pairs[:, 0]] & kept[pairs[:, 1]]]
    held = int(kept.sum())
    return (2.0 * len(live) / held if held else 0.0), 1.0 - held / n, len(live)


def contact_numbers(position, radius, box, periodic, tolerances=CONTACT_TOLERANCES):
    """:func:`contact_number` at every tolerance: float64 arrays (z, rattler fraction) over
    ``tolerances``, whose plateau is the packing's."""
    rows = [contact_number(position, radius, box, periodic, t)[:2] for t in tolerances]
    z, rattlers = np.array(rows).T
    return z, rattlers


def voronoi_neighbours(position, box, periodic):
    """The Voronoi neighbour pairs (i, j), i < j, int64[k, 2]: the edges of the Delaunay
    triangulation of the centres, with the periodic images of the disks within a margin
    of the edges (four mean spacings) on periodic axes."""
    position = folded(np.asarray(position, np.float64), box, periodic)
    n = position.shape[0]
    box = np.asarray(box, np.float64)
    margin = 4.0 * np.sqrt(np.prod(box) / n)
    points, owner = [position], [np.arange(n)]
    shifts = [(sx, sy) for sx in (-1, 0, 1) for sy in (-1, 0, 1) if (sx, sy) != (0, 0)
              and (periodic[0] or sx == 0) and (periodic[1] or sy == 0)]
    for sx, sy in shifts:
        moved = position + np.array([sx, sy]) * box
        near = np.all((moved > -margin) & (moved < box + margin), axis=1)
        points.append(moved[near])
        owner.append(np.flatnonzero(near))
    points, owner = np.vstack(points), np.concatenate(owner)
    from scipy.spatial import Delaunay  # here: every run's start would import it

    triangles = Delaunay(points).simplices
    edges = np.vstack([triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]])
    edges = edges[(edges < n).any(axis=1)]  # an edge of an original disk
    edges = np.sort(owner[edges], axis=1)
    edges = edges[edges[:, 0] != edges[:, 1]]
    return np.unique(edges, axis=0)


def bond_order(position, box, periodic):
    """ψ₆ of every disk, complex128[n], over its Voronoi neighbours
    (:func:`voronoi_neighbours`); see the module docstring."""
    position = folded(np.asarray(position, np.float64), box, periodic)
    n = position.shape[0]
    pairs = voronoi_neighbours(position, box, periodic)
    r = nearest_images(position[pairs[:, 1]] - position[pairs[:, 0]], box, periodic)
    bond = np.exp(6j * np.arctan2(r[:, 1], r[:, 0]))  # the bond j → i is the same (6 × π)
    total = np.zeros(n, complex)
    np.add.at(total, pairs[:, 0], bond)
    np.add.at(total, pairs[:, 1], bond)
    count = np.bincount(pairs.ravel(), minlength=n)
    return np.divide(total, count, out=np.zeros(n, complex), where=count > 0)


def orientational_correlation(position, psi, box, periodic, bins, r_max):
    """g₆(r) = ⟨ψ₆(i) ψ₆*(j)⟩ over the pairs (i ≠ j) at distances in each of ``bins`` equal
    bins up to ``r_max`` (nearest periodic images), the bond-orientational correlation whose
    decay tells a liquid (exponential) from a hexatic (algebraic) (Nelson & Halperin, PRB
    19, 2457 (1979)); ``psi`` complex[n] (:func:`bond_order`). Returns (bin centres
    float64[bins], g₆ complex128[bins], NaN in a bin without pairs)."""
    position = folded(np.asarray(position, np.float64), box, periodic)
    tree = kd_tree(position, box, periodic)
    pairs = tree.sparse_distance_matrix(tree, r_max, output_type="ndarray")
    pairs = pairs[(pairs["i"] != pairs["j"]) & (pairs["v"] < r_max)]
    edges = np.linspace(0.0, r_max, bins + 1)
    which = np.digitize(pairs["v"], edges) - 1
    products = psi[pairs["i"]] * np.conj(psi[pairs["j"]])
    total = np.zeros(bins, complex)
    np.add.at(total, which, products)
    count = np.bincount(which, minlength=bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        correlation = np.where(count > 0, total / np.maximum(count, 1), np.nan)
    return 0.5 * (edges[1:] + edges[:-1]), correlation


def global_bond_order(position, box, periodic):
    """|Ψ₆| = |⟨ψ₆⟩| over all disks (:func:`bond_order`)."""
    return float(abs(bond_order(position, box, periodic).mean()))


def compression_pressure(time, virial, kinetic, packing_fraction):
    """βP/ρ between consecutive instants of a compression: 1 + ΔX/(2 K̄ Δt)
    (:func:`sim.engine.observables.virial_pressure`), X the cumulative collision virial
    Σ r_ij·Δp_i, K̄ the kinetic energy averaged over the two ends (growth
    pumps it in, the rescaling takes it out: it stays near N T), Δt the interval; at the
    packing fraction of the interval's middle (φ grows as (1 + γ t)², nearly linearly over a
    short interval). Arrays over the instants; returns (φ, βP/ρ) over the intervals."""
    time, virial, kinetic, phi = (np.asarray(a, np.float64) for a in (
        time, virial, kinetic, packing_fraction))
    pressure = virial_pressure(np.diff(virial), 0.5 * (kinetic[1:] + kinetic[:-1]),
                               np.diff(time))
    return 0.5 * (phi[1:] + phi[:-1]), pressure
