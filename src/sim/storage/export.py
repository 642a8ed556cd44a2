"""``python -m sim.storage.export RUN.h5 --format gsd|xyz [--out FILE] [--frames SPEC]`` (also
``sim-export``): a run's snapshots as a file that OVITO, freud, HOOMD-blue, ASE and VMD open.

``gsd``: HOOMD-blue's GSD, one frame per snapshot. The box is ``configuration.box = [Lx, Ly,
0, 0, 0, 0]`` with ``dimensions = 2``; HOOMD centres it on the origin, so positions are the
run's (box [0, Lx] × [0, Ly]) shifted by −L/2, as [x, y, 0]; on a periodic axis a disk that
float32 rounding puts on the edge +L/2 is written at its image −L/2, strictly inside as HOOMD
requires. Velocities [vx, vy, 0], ``diameter`` 2R, ``mass``, ``types`` "A", "B", … with
``typeid`` the disk's species; ``configuration.step`` the snapshot's step (contacts so far),
``log/sim/time`` the simulated time and ``log/sim/kinetic_energy`` Σ m v²/2 (float64).
Rough disks (a run that stores spins ω, :mod:`sim.effects.rotation`): ``moment_inertia`` (0, 0,
I) with I = q m a² (q: the run's ``disks.inertia_factor``) and ``angmom`` (0, 0, 0, 2 I ω),
HOOMD's angular momentum quaternion P = 2 o ⊗ (0, S) for the body-frame angular momentum S =
(0, 0, I ω) and the orientation o = (1, 0, 0, 0), so that S = ½ im(o* ⊗ P) reads it back
(HOOMD-blue's documentation, "Anisotropic particles: quaternions for angular momentum", after
Kamberaj, Low & Neal, J. Chem. Phys. 122, 224114 (2005)); ``orientation`` stays that identity,
as the run stores no angle of the disks, only their spins. Smooth disks keep GSD's defaults
(zero moment of inertia: HOOMD turns no particle without one).
Positions, velocities, diameters, masses, moments of inertia, angular momenta and the box are
float32, the HOOMD schema's type and the one every reader takes: seven significant digits,
errors up to 3e-8 in a unit box.
GSD has no periodicity flags: OVITO's GSD reader makes the cell periodic along every axis,
2D, and draws it as a rectangle. A walled box looks right all the same (the disks sit inside
and never cross it); only analyses that look across the edges (OVITO's coordination or RDF,
freud's neighbour queries) treat it as periodic: switch the flags off in OVITO's Simulation
cell panel, or export xyz.

``xyz``: extended XYZ, every number as the shortest text that reads back to the same float64.
Per snapshot: the number of disks; ``Lattice="Lx 0 0 0 Ly 0 0 0 D" Origin="0 0 −D/2"
Properties=type:I:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1 Time=t Step=s pbc="T T F"``
(``:spin:R:1`` appended for rough disks: ω, 1/time, counter-clockwise positive); one
line per disk. Positions are the run's, z = 0; ``pbc`` is T along a periodic axis, F along
walls (and z). The third cell vector is a slab one largest diameter D thick about the disks'
plane, because OVITO takes no cell from a Lattice with a zero vector. ``type`` is the species
number (the GSD ``typeid``): ASE reads a ``species`` column as chemical elements only.

What the formats cannot hold (:data:`CANNOT_HOLD`, said by ``--help``; one line of note on
stderr when the run exported has some of it, :func:`not_held`): GSD has no walls (its box is
periodic along every axis) and keeps seven digits; neither format holds the walls' motion
(pistons, vibrating walls: the cell is the box at rest), the observables but the time (and
GSD's kinetic energy), the event log, the config, or the disks' orientation (the run stores
none).

``--frames``: ``start:stop:step`` (a Python slice: bounds past the end are cut) or a comma
list of snapshot indices, negative ones counted from the end; every snapshot by default.
``--out``: by default the run file's name with ``.gsd`` or ``.xyz``, beside it; the file is
written under a hidden name beside it, made before any snapshot is read, and renamed when
whole (:mod:`sim.storage.whole_file`). Units are the run's. Exit status 0; 2 with one line on
stderr for bad input (not a run file, a bad ``--frames``, a damaged snapshot among those
asked, an output whose folder does not exist or cannot be written); 1 when writing fails
later (a full disk); 130 after Ctrl-C, 143 after SIGTERM. Nothing is left behind but a whole
file.
"""

import string
import sys
import warnings
from pathlib import Path

import gsd.hoomd
import numpy as np
import yaml

from sim.analysis.datasets import open_run
from sim.effects.rotation import moment_of_inertia
from sim.effects.walls import wall_motion
from sim.engine.box import WALL_NAMES
from sim.pipeline.command import BadInput, CannotWrite, Parser, run_command
from sim.storage.errors import RunFileError
from sim.storage.whole_file import whole_file

#: the columns of every disk's line in an xyz file; rough disks add :data:`XYZ_SPIN`
XYZ_PROPERTIES = "type:I:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1"
XYZ_SPIN = "spin:R:1"
#: what the formats cannot hold of a run, as ``--help`` says it
CANNOT_HOLD = ("GSD holds no walls (its box is periodic along every axis) and seven digits "
               "(float32); neither format holds the walls' motion (the cell is the box at rest), "
               "the observables but the time (and GSD's kinetic energy), the event log, the "
               "config, or the disks' orientation, which the run does not store. Spins of rough "
               "disks are written: GSD's angmom and moment_inertia, an xyz column spin.")


def frame_indices(spec, count):
    """The snapshot indices, out of ``count``, that ``spec`` selects (see the module
    docstring); every one for None. :class:`BadInput` for a spec that is neither form, an
    index out of range or a selection of no snapshot."""
    if spec is None:
        indices = range(count)
    else:
        try:
            if ":" in spec:
                parts = spec.split(":")
                if len(parts) > 3:
                    raise ValueError(spec)
                bounds = [int(p) if p.strip() else None for p in parts]
                indices = range(count)[slice(*bounds)]
            else:
                indices = [int(p) for p in spec.split(",")]
        except ValueError:
            raise BadInput(f"--frames {spec!r}: neither start:stop:step (step not 0) nor a "
                              f"comma list of snapshot indices") from None
        outside = [i for i in indices if not -count <= i < count]
        if outside:
            raise BadInput(f"--frames {spec!r}: snapshot {outside[0]} is out of range; the "
                              f"run has {count} snapshots, 0 to {count - 1}")
    if not indices:
        raise BadInput(f"--frames {spec!r} selects none of the run's {count} snapshots"
                          if spec is not None else "the run has no snapshots")
    return [i % count for i in indices]


def snapshots(run, indices):
    """(step, time, position, velocity, spin, radius) of the snapshots ``indices`` of the
    open run ``run`` (:func:`sim.analysis.datasets.open_run`), read one at a time; positions
    and velocities float64[n, 2], spins ω float64[n] (None when the disks do not turn), radii
    float64[n] (grown to the snapshot's time for growing disks, ``radius_scale``).
    :class:`BadInput` at a damaged snapshot."""
    steps, times = run["step"].values, run["time"].values
    scales = run["radius_scale"].values if "radius_scale" in run else np.ones(times.size)
    for i in indices:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)  # a damaged frame reads as NaN
            position = run["position"][i].values
            velocity = run["velocity"][i].values
            spin = run["angular_velocity"][i].values if "angular_velocity" in run else None
        step, time = steps[i], times[i]
        if not (np.isfinite(position).all() and np.isfinite(velocity).all()
                and (spin is None or np.isfinite(spin).all())
                and np.isfinite(step) and np.isfinite(time)):
            raise BadInput(f"{run.attrs['path']}: snapshot {i} is damaged (sim-inspect names "
                              f"what); leave it out with --frames")
        yield int(step), float(time), position, velocity, spin, run["radius"].values * scales[i]


def moments_of_inertia(run):
    """I = q m a² float64[n] of the open run ``run`` (q: its config's ``disks.inertia_factor``),
    or None when its disks do not turn; :class:`BadInput` for spins without q (a run file
    written by a script that gave :class:`sim.storage.h5md.RunWriter` a config without it)."""
    if "angular_velocity" not in run:
        return None
    q = (yaml.safe_load(run.attrs["config"]).get("disks") or {}).get("inertia_factor")
    if q is None:
        raise BadInput(f"{run.attrs['path']}: holds spins but its config has no "
                       f"disks.inertia_factor q, so no moments of inertia I = q m a² for GSD; "
                       f"--format xyz needs none")
    return moment_of_inertia(float(q), run["mass"].values, run["radius"].values)


def not_held(run, fmt):
    """What of the open run ``run`` the format ``fmt`` cannot hold (:data:`CANNOT_HOLD`), in
    words, one item each: walls in GSD, moving walls in either."""
    walled = [axis for axis, b in zip("xy", run.attrs["boundary"], strict=True)
              if b != "periodic"]
    items = []
    if fmt == "gsd" and walled:
        items.append(f"GSD's box is periodic along every axis: the walls along "
                     f"{' and '.join(walled)} read as periodic sides (xyz keeps them, as pbc)")
    walls = yaml.safe_load(run.attrs["config"]).get("walls") or {}
    motion = wall_motion({k: walls.get(name) or {} for k, name in enumerate(WALL_NAMES)
                          if "xy"[k >> 1] in walled})
    if motion is not None:
        items.append("the walls' motion is not written: the cell is the box at rest")
    return items


def hoomd_positions(position, box, periodic):
    """float32[n, 3] positions [x, y, 0] in HOOMD's box centred on the origin, from the run's
    float64[n, 2] in [0, Lx] × [0, Ly]: shifted by −L/2, and on a ``periodic`` axis a value
    that rounds onto +L/2 is put at its image −L/2 (exactly, in float32)."""
    out = np.zeros((position.shape[0], 3), np.float32)
    out[:, :2] = position - 0.5 * np.asarray(box)
    length = np.asarray(box, np.float32)
    out[:, :2] -= np.where(np.asarray(periodic) & (out[:, :2] >= length / 2), length, 0)
    return out


def _type_name(species):
    """The GSD type name of species number ``species``: A, B, …, Z, A1, …"""
    return string.ascii_uppercase[species % 26] + str(species // 26 or "")


def write_gsd(path, run, frames):
    """Write ``frames`` (of :func:`snapshots`) of the open run ``run`` to the GSD file
    ``path``; spins as ``angmom`` and ``moment_inertia`` (the module docstring)."""
    box = np.asarray(run.attrs["box"])
    periodic = [b == "periodic" for b in run.attrs["boundary"]]
    mass = run["mass"].values
    types = [_type_name(s) for s in range(run.sizes["species"])]
    typeid = run["species_id"].values.astype(np.uint32)
    inertia = moments_of_inertia(run)
    with gsd.hoomd.open(path, "w") as trajectory:
        for step, time, position, velocity, spin, radius in frames:
            frame = gsd.hoomd.Frame()
            frame.configuration.step = step
            frame.configuration.dimensions = 2
            frame.configuration.box = np.array([*box, 0, 0, 0, 0], np.float32)
            frame.particles.N = position.shape[0]
            frame.particles.types = types
            frame.particles.typeid = typeid
            frame.particles.diameter = (2.0 * radius).astype(np.float32)
            frame.particles.mass = mass.astype(np.float32)
            frame.particles.position = hoomd_positions(position, box, periodic)
            frame.particles.velocity = np.zeros((mass.size, 3), np.float32)
            frame.particles.velocity[:, :2] = velocity
            if inertia is not None:
                frame.particles.moment_inertia = np.zeros((mass.size, 3), np.float32)
                frame.particles.moment_inertia[:, 2] = inertia
                frame.particles.angmom = np.zeros((mass.size, 4), np.float32)
                frame.particles.angmom[:, 3] = 2.0 * inertia * spin
            frame.log["sim/time"] = np.array([time])
            frame.log["sim/kinetic_energy"] = np.array(
                [0.5 * np.sum(mass[:, None] * velocity**2)])
            trajectory.append(frame)


def write_xyz(path, run, frames):
    """Write ``frames`` (of :func:`snapshots`) of the open run ``run`` to the extended XYZ
    file ``path``; spins ω as a last column ``spin``."""
    lx, ly = run.attrs["box"]
    pbc = " ".join("T" if b == "periodic" else "F" for b in run.attrs["boundary"])
    species = run["species_id"].values.tolist()
    mass = run["mass"].values.tolist()
    properties = XYZ_PROPERTIES + (f":{XYZ_SPIN}" if "angular_velocity" in run else "")
    with open(path, "w") as out:
        for step, time, position, velocity, spin, radius in frames:
            slab = 2.0 * float(radius.max())
            cell = f'Lattice="{lx!r} 0 0 0 {ly!r} 0 0 0 {slab!r}" Origin="0 0 {-0.5 * slab!r}"'
            size_and_mass = [f"{r!r} {m!r}" for r, m in zip(radius.tolist(), mass, strict=True)]
            out.write(f"{len(species)}\n{cell} Properties={properties} Time={time!r} "
                      f"Step={step} pbc=\"{pbc} F\"\n")
            ends = ["\n"] * len(species) if spin is None else [f" {w!r}\n" for w in spin.tolist()]
            out.write("".join(f"{s} {x!r} {y!r} 0 {u!r} {v!r} 0 {rm}{end}"
                              for s, (x, y), (u, v), rm, end in
                              zip(species, position.tolist(), velocity.tolist(), size_and_mass,
                                  ends, strict=True)))


WRITERS = {"gsd": write_gsd, "xyz": write_xyz}


def export(run_path, fmt, out=None, frames=None, note=print):
    """Export the run file ``run_path`` as ``fmt`` (``gsd`` or ``xyz``) to ``out`` (default:
    beside the run file, its suffix replaced), the snapshots ``frames`` selects
    (:func:`frame_indices`); one line to ``note`` on what of the run the format cannot hold
    (:func:`not_held`). Returns the path written; :class:`BadInput` or
    :class:`sim.storage.errors.RunFileError` when it cannot be (an output that cannot be
    written among them), :class:`CannotWrite` when writing fails, and then nothing is left
    behind."""
    if fmt not in WRITERS:
        raise BadInput(f"unknown format {fmt!r}: {' or '.join(WRITERS)}")
    target = Path(out) if out is not None else Path(run_path).with_suffix(f".{fmt}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # damaged observables: not exported
        run = open_run(run_path)
    with run:
        indices = frame_indices(frames, run.sizes["time"])
        if target.exists() and target.resolve() == Path(run_path).resolve():
            raise BadInput(f"--out {target} is the run file itself")
        lost = not_held(run, fmt)
        try:
            with whole_file(target) as partial:
                WRITERS[fmt](partial, run, snapshots(run, indices))
        except OSError as error:
            raise CannotWrite(f"cannot write {target} ({error.strerror or error})") from error
    if lost:
        note(f"sim-export: note: {'; '.join(lost)}")
    return target


def main(argv=None):
    parser = Parser(prog="sim-export", description="A run's snapshots as GSD or extended XYZ.",
                    epilog=CANNOT_HOLD)
    parser.add_argument("path", help="run file (run.h5)")
    parser.add_argument("--format", required=True, choices=sorted(WRITERS), dest="fmt")
    parser.add_argument("--out", help="output file in a folder that exists and may be written "
                        "(default: beside the run file)")
    parser.add_argument("--frames", help="start:stop:step or a comma list of snapshot "
                        "indices (default: all), e.g. --frames=-5: (the last five; with '=', "
                        "as it starts with '-') or --frames 0,-1")

    def body():
        args = parser.parse_args(argv)
        export(args.path, args.fmt, args.out, args.frames,
               note=lambda line: print(line, file=sys.stderr, flush=True))

    return run_command("sim-export", body, bad_input=(RunFileError,))


if __name__ == "__main__":
    sys.exit(main())
