"""``python -m sim.inspect PATH [--json]`` (also ``sim-inspect``): what a run file holds.

Scene, number of disks, snapshots, time span, energy drift (or dissipation), collisions and
the stop reason; ``--json`` prints the same as one JSON object for scripts. A file that is
not a readable sim run file ends with one line on stderr and exit status 2.
"""

import argparse
import json
import sys

import h5py
import numpy as np
import yaml


class RunFileError(ValueError):
    """Not a readable sim run file."""


#: what a read of a damaged run file raises: h5py's errors, and HDF5's for broken metadata
DAMAGE = (KeyError, OSError, RuntimeError, ValueError)


def open_run_file(path):
    """The run file at ``path`` opened for reading (an :class:`h5py.File`), or
    :class:`RunFileError` saying why it is not one: not HDF5 (or truncated), another HDF5
    file, or damaged."""
    try:
        f = h5py.File(path, "r")
    except (OSError, ValueError) as error:
        raise RunFileError(f"{path}: not a readable HDF5 file ({error})") from error
    try:
        is_run_file = "h5md" in f and "particles/disks/position" in f
    except RuntimeError as error:  # HDF5 finds its own metadata damaged
        f.close()
        raise RunFileError(f"{path}: damaged run file ({error})") from error
    if not is_run_file:
        f.close()
        raise RunFileError(f"{path}: an HDF5 file, but not an H5MD run file of sim "
                           f"(no /h5md or /particles/disks/position)")
    return f


def summary(path):
    """A dict describing the run file at ``path``."""
    with open_run_file(path) as f:
        try:
            parameters = f["parameters"].attrs
            config = yaml.safe_load(parameters["config"])
            time = f["particles/disks/position/time"][()]
            energy = f["observables/kinetic_energy/value"][()]
            dissipated = f["observables/dissipated_energy/value"][()]
            extra = {name: f[f"observables/{name}/value"][()] if name in f["observables"]
                     else np.zeros_like(energy) for name in ("potential_energy", "wall_work")}
            collisions = f["observables/collisions/value"][()]
            n = f["particles/disks/radius"].shape[0]
            creator = f["h5md/creator"].attrs
            result = {
                "path": str(path),
                "scene": config.get("scene"),
                "n": int(n),
                "species": int(np.max(f["particles/disks/species"][()]) + 1),
                "boundary": [b.decode() for b in f["particles/disks/box"].attrs["boundary"]],
                "snapshots": int(time.size),
                "time_span": [float(time[0]), float(time[-1])] if time.size else None,
                "collisions": int(collisions[-1]) if collisions.size else 0,
                "initial_energy": float(energy[0]) if energy.size else None,
                "final_energy": float(energy[-1]) if energy.size else None,
                "dissipated_energy": float(dissipated[-1]) if dissipated.size else 0.0,
                "stop_reason": str(parameters["stop_reason"]),
                "seed": int(parameters["seed"]),
                "creator": f"{creator['name']} {creator['version']}",
            }
        except (*DAMAGE, yaml.YAMLError) as error:
            raise RunFileError(f"{path}: damaged or incomplete run file ({error})") from error
    if energy.size:
        # energy balance: kinetic + potential + dissipated − work of the walls stays constant;
        # the drift is measured against the largest energy the run has seen
        mechanical = energy + extra["potential_energy"]
        balance = mechanical + dissipated - extra["wall_work"] - mechanical[0]
        scale = max(np.max(energy), np.max(np.abs(extra["wall_work"])), np.max(dissipated),
                    np.finfo(float).tiny)
        result["energy_drift"] = float(np.max(np.abs(balance)) / scale)
    return result


def main(argv=None):
    parser = argparse.ArgumentParser(prog="sim-inspect", description=__doc__.splitlines()[0])
    parser.add_argument("path", help="run file (run.h5)")
    parser.add_argument("--json", action="store_true", help="one JSON object")
    args = parser.parse_args(argv)
    try:
        info = summary(args.path)
    except RunFileError as error:
        print(f"sim-inspect: {error}", file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(info))
        return 0
    width = max(len(k) for k in info)
    for key, value in info.items():
        print(f"{key:<{width}}  {value}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
