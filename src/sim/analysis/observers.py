"""Observers: quantities computed from the state at every snapshot, chosen by the scene under
``observe:``, each written as its own H5MD observable ``/observables/<name>`` (step, time,
value) beside the built-in ones; the names of the value's dimensions are the group's attribute
``dims`` and their coordinates, where they have some, datasets beside ``value``.

An observer has a ``name``, ``unit``, ``description``, the ``shape`` and ``dtype`` of one value,
its ``dims`` and ``coords`` ({dim: values}), and ``__call__(engine, t, position, velocity)``
giving the value at a snapshot at absolute time t from the engine and the positions and
velocities float64[n, 2] at that time. Observers run in Python between compiled chunks, never
per event; a scene that names none pays nothing. Two need the compiled loop's help, which the
engine gives only when asked: unwrapped positions (``unwrap``, :mod:`sim.engine.flight`) and the
collision virial tensor (``pressure_tensor``, :mod:`sim.effects.pressure_tensor`).
"""

import numpy as np

from sim.analysis.cells import cell_index, granular_temperature, grid
from sim.analysis.packing import bond_order
from sim.checks.audit import kd_tree
from sim.pipeline.config import ConfigError


class RadialDistribution:
    """Pair distribution g(r) of all disks (Allen & Tildesley, *Computer Simulation of
    Liquids*, §2.6): the number of pairs at separation r in [r, r + Δr) over its ideal-gas
    value ½ N (N − 1) 2π r Δr / A, with r in units of σ = 2⟨R⟩, the mean contact distance.

    The ideal-gas normalisation is that of a periodic box; with walls, pairs near the walls
    are missing and g(r) falls below 1 by about (perimeter × r)/(π A) at large r.
    For equal disks in equilibrium the value just above contact, g(σ⁺), equals (Z − 1)/(2φ).
    """

    name = "radial_distribution"
    unit = "1"
    dtype = np.float64

    def __init__(self, bins, r_max, engine):
        self.sigma = 2.0 * float(np.mean(engine.radius))
        self.edges = np.linspace(0.0, r_max * self.sigma, bins + 1)
        centres = 0.5 * (self.edges[1:] + self.edges[:-1]) / self.sigma
        self.shape = (bins,)
        self.dims = ("r",)
        self.coords = {"r": centres}
        self.description = (f"g(r) over {bins} bins up to r = {r_max} σ, σ = 2⟨R⟩ = "
                            f"{self.sigma:.6g}; abscissa r (units of σ) in ./r")
        self.area = float(np.prod(engine.box))
        self.box = engine.box
        self.periodic = engine.periodic

    def __call__(self, engine, t, position, velocity):
        tree = kd_tree(position, self.box, self.periodic)
        distance = tree.sparse_distance_matrix(tree, self.edges[-1], output_type="ndarray")
        distance = distance["v"][distance["i"] < distance["j"]]
        counts = np.histogram(distance, bins=self.edges)[0]
        n = position.shape[0]
        ideal = 0.5 * n * (n - 1) * np.pi * np.diff(self.edges**2) / self.area
        return counts / ideal


class Clusters:
    """Clusters of disks closer than a gap: disks i and j are linked when
    |r_i − r_j| < R_i + R_j + gap × 2⟨R⟩, and a cluster is a connected set of links (scipy's
    connected components). The value is each disk's cluster label, numbered from 0 by
    decreasing cluster size, so label 0 is the largest cluster; the clustering instability
    of a cooling gas shows as the growth of that cluster.
    """

    name = "clusters"
    unit = "1"
    dtype = np.int32
    dims = ("disk",)
    coords = {}

    def __init__(self, gap, engine):
        self.gap = gap * 2.0 * float(engine.radius.mean())
        self.shape = (engine.n,)
        self.description = (f"cluster label of each disk (0 = largest), disks linked below a "
                            f"gap of {gap} × 2⟨R⟩")
        self.box = engine.box
        self.periodic = engine.periodic

    def __call__(self, engine, t, position, velocity):
        radius = engine.radii(t)  # growing disks grow (sim.effects.growth)
        tree = kd_tree(position, self.box, self.periodic)
        close = tree.sparse_distance_matrix(tree, 2.0 * float(radius.max()) + self.gap,
                                            output_type="ndarray")
        linked = close["v"] < radius[close["i"]] + radius[close["j"]] + self.gap
        from scipy.sparse import coo_matrix  # here: every run's start would import it
        from scipy.sparse.csgraph import connected_components

        n = position.shape[0]
        graph = coo_matrix((np.ones(linked.sum()), (close["i"][linked], close["j"][linked])),
                           shape=(n, n))
        _, labels = connected_components(graph, directed=False)
        sizes = np.bincount(labels)
        rank = np.empty_like(sizes)
        rank[np.argsort(-sizes, kind="stable")] = np.arange(sizes.size)
        return rank[labels].astype(np.int32)


class BondOrder:
    """The bond-orientational order ψ₆ of every disk over its Voronoi neighbours
    (:func:`sim.analysis.packing.bond_order`), as its real and imaginary parts; the global
    |Ψ₆| is the modulus of their mean (:func:`sim.analysis.datasets.global_bond_order`)."""

    name = "bond_order"
    unit = "1"
    dtype = np.float64
    dims = ("disk", "part")
    coords = {"part": np.array([b"re", b"im"])}
    description = "ψ₆ of each disk over its Voronoi neighbours, [disk, (re, im)]"

    def __init__(self, engine):
        self.shape = (engine.n, 2)
        self.box = engine.box
        self.periodic = engine.periodic

    def __call__(self, engine, t, position, velocity):
        psi = bond_order(position, self.box, self.periodic)
        return np.stack([psi.real, psi.imag], axis=1)


class LocalFields:
    """Packing fraction and granular temperature on the grid of :func:`sim.analysis.cells.grid`
    (``cells`` along x): a disk counts in the cell of its centre; the packing fraction is
    Σ πR² over the cell's area, the temperature that of the cell's disks in the frame of their
    mass-weighted mean velocity (:func:`sim.analysis.cells.granular_temperature`), NaN for a
    cell of fewer than two disks. Value [2, y, x]: packing fraction, then temperature."""

    name = "local_fields"
    unit = "1 (packing fraction), energy (temperature)"
    dtype = np.float64
    dims = ("field", "y", "x")

    def __init__(self, cells, engine):
        self.box = tuple(float(side) for side in engine.box)
        self.grid = grid(self.box, cells)
        ny, nx = self.grid
        width = (self.box[0] / nx, self.box[1] / ny)
        self.cell_area = width[0] * width[1]
        self.shape = (2, ny, nx)
        self.coords = {"field": np.array([b"packing_fraction", b"temperature"]),
                       "x": (np.arange(nx) + 0.5) * width[0],
                       "y": (np.arange(ny) + 0.5) * width[1]}
        self.description = ("packing fraction and granular temperature (./field) on "
                            f"{nx} × {ny} cells; cell centres in ./x, ./y")
        self.mass = np.asarray(engine.mass, dtype=np.float64)

    def __call__(self, engine, t, position, velocity):
        cell = cell_index(position, self.box, self.grid)
        n_cells = self.grid[0] * self.grid[1]
        disk_area = np.pi * engine.radii(t) ** 2  # growing disks grow (sim.effects.growth)
        packing = np.bincount(cell, weights=disk_area, minlength=n_cells) / self.cell_area
        temperature = granular_temperature(velocity, self.mass, cell, n_cells)
        return np.stack([packing, temperature]).reshape(self.shape)


class _BySpecies:
    """Base of observers that average a per-disk quantity over each species."""

    dtype = np.float64
    dims = ("species",)

    def __init__(self, engine):
        self.species = engine.species
        self.count = np.bincount(engine.species, minlength=engine.n_species)
        self.shape = (engine.n_species,)
        self.coords = {"species": np.arange(engine.n_species)}

    def _mean(self, per_disk):
        return np.bincount(self.species, weights=per_disk, minlength=self.shape[0]) / self.count


class MeanSquaredDisplacement(_BySpecies):
    """⟨|r(t) − r(0)|²⟩ per species from the start of the run, with positions continued across
    periodic boundaries (Allen & Tildesley §8.3; in 2D, 4 D t at long times, D the
    self-diffusion coefficient). The engine counts the windings in its loop
    (``unwrap=True``)."""

    name = "mean_squared_displacement"
    unit = "length²"
    description = "⟨|r(t) − r(0)|²⟩ per species, positions unwrapped across periodic sides"

    def __init__(self, engine):
        super().__init__(engine)
        self.start = engine.unwrapped_positions(0.0)

    def __call__(self, engine, t, position, velocity):
        moved = engine.unwrapped_positions(t) - self.start
        return self._mean(np.sum(moved**2, axis=1))


class VelocityAutocorrelation(_BySpecies):
    """⟨v(t)·v(0)⟩ per species, from the start of the run (Allen & Tildesley §2.7); its time
    integral is 2 D in 2D. For averages over many time origins use
    :func:`sim.analysis.datasets.velocity_autocorrelation` on the velocity snapshots."""

    name = "velocity_autocorrelation"
    unit = "length²/time²"
    description = "⟨v(t)·v(0)⟩ per species, time origin at the start of the run"

    def __init__(self, engine):
        super().__init__(engine)
        self.start = engine.velocities(0.0)

    def __call__(self, engine, t, position, velocity):
        return self._mean(np.sum(velocity * self.start, axis=1))


class KineticTensor:
    """Σ m v_a v_b over all disks: the kinetic part of the pressure tensor times the area."""

    name = "kinetic_tensor"
    unit = "energy"
    description = "Σ m v_a v_b, [a, b]"
    dtype = np.float64
    shape = (2, 2)
    dims = ("a", "b")
    coords = {"a": np.array([b"x", b"y"]), "b": np.array([b"x", b"y"])}

    def __init__(self, engine):
        self.mass = engine.mass

    def __call__(self, engine, t, position, velocity):
        return np.einsum("i,ia,ib->ab", self.mass, velocity, velocity)


class VirialTensor(KineticTensor):
    """Σ r_a Δp_b over all disk contacts so far (:mod:`sim.effects.pressure_tensor`): its growth
    over an interval, divided by the interval, is the collisional part of the pressure tensor times
    the area (:func:`sim.analysis.datasets.pressure_tensor`)."""

    name = "collision_virial_tensor"
    unit = "length × momentum"
    description = "cumulative Σ r_a Δp_b over disk contacts, [a, b]"

    def __call__(self, engine, t, position, velocity):
        xx, xy, yy = engine.virial_tensor
        return np.array([[xx, xy], [xy, yy]])


def from_config(cfg, engine):
    """The observers the scene's ``observe:`` section asks for, sized for ``engine``."""
    observers = []
    rdf = cfg.observe.radial_distribution
    if rdf.bins is not None:
        sigma = 2.0 * float(np.mean(engine.radius))
        limit = 0.5 * float(min(engine.box)) / sigma
        if rdf.r_max > limit:
            raise ConfigError("observe.radial_distribution.r_max", rdf.r_max,
                              f"at most half the shorter box side, {limit:.4g} σ here "
                              f"(σ = 2⟨R⟩ = {sigma:.4g})")
        observers.append(RadialDistribution(int(rdf.bins), float(rdf.r_max), engine))
    if cfg.observe.clusters.gap is not None:
        observers.append(Clusters(float(cfg.observe.clusters.gap), engine))
    if cfg.observe.local_fields.cells is not None:
        observers.append(LocalFields(int(cfg.observe.local_fields.cells), engine))
    if cfg.observe.mean_squared_displacement:
        observers.append(MeanSquaredDisplacement(engine))
    if cfg.observe.velocity_autocorrelation:
        observers.append(VelocityAutocorrelation(engine))
    if cfg.observe.pressure_tensor:
        observers += [KineticTensor(engine), VirialTensor(engine)]
    if cfg.observe.bond_order:
        observers.append(BondOrder(engine))
    return observers
