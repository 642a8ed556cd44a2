"""``python -m sim``: run a scene, or a sweep with ``-m``, from the YAML in ``conf/``.

Every override of the command line (each combination of a sweep) is composed and validated
before any work starts: a bad key, type or value prints one line and exits with status 2.
"""

import itertools
import logging
import os
import sys
from pathlib import Path

import hydra
from hydra import compose, initialize_config_dir
from hydra.core.hydra_config import HydraConfig
from hydra.core.override_parser.overrides_parser import OverridesParser
from hydra.types import RunMode
from omegaconf import OmegaConf
from omegaconf.errors import OmegaConfBaseException

from sim import callbacks
from sim.config import ConfigError, register, validate

CONF_DIR = str((Path(__file__).resolve().parents[2] / "conf"))
EXIT_BAD_CONFIG = 2
EXIT_RUN_FILE = 1  # the run file could not be written
EXIT_INTERRUPTED = 130  # stopped by SIGINT, as shells report it
INTERRUPTED = []  # single runs that SIGINT stopped

register()


def _fail(message):
    print(f"sim: {message}", file=sys.stderr)
    sys.exit(EXIT_BAD_CONFIG)


def _first_line(error):
    """The innermost cause's first line: what the user needs, without Hydra's framing."""
    while error.__cause__ is not None:
        error = error.__cause__
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    return lines[0] if lines else type(error).__name__


def _explain_key(combination):
    """Why a key of the command line does not exist: the keys allowed beside a misspelt one
    (disks.nn -> n, radius, …), or the scenario a section belongs to."""
    scenario = [c.partition("=")[2] for c in combination if c.startswith("scenario=")]
    with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
        cfg = compose("config", overrides=[f"scenario={s}" for s in scenario])
    for item in combination:
        key = item.partition("=")[0].lstrip("+~")
        parent = key.rpartition(".")[0]
        if not parent or key.startswith("scenario"):
            continue
        head = parent.split(".")[0]
        if head in cfg and cfg[head] is None:
            return f"{key}: the scene '{cfg.scene}' has no '{head}' section (choose a " \
                   f"scenario that has one, e.g. scenario=crater for projectile and bed)"
        node = OmegaConf.select(cfg, parent)
        if OmegaConf.is_dict(node) and key.rpartition(".")[2] not in node:
            return f"{key}: no such key; allowed keys there: " + ", ".join(map(str, node))
    return None


def check_command_line(args):
    """Compose and validate every job the command line asks for; exit 2 on the first bad one."""
    overrides = [a for a in args if not a.startswith("-")]
    try:
        parsed = OverridesParser.create().parse_overrides(overrides)
    except OmegaConfBaseException as error:  # pragma: no cover - hydra raises its own types
        _fail(_first_line(error))
    except Exception as error:
        _fail(_first_line(error))
    choices = []
    for o in parsed:
        if o.get_key_element().lstrip("+~").startswith("hydra"):
            continue
        if o.is_sweep_override():
            values = [str(v) for v in o.sweep_string_iterator()]
        else:
            values = [o.get_value_element_as_str()]
        choices.append([f"{o.get_key_element()}={v}" for v in values])
    for combination in itertools.product(*choices):
        try:
            with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
                cfg = compose("config", overrides=list(combination))
            if cfg.resume is None:
                validate(cfg)
        except ConfigError as error:
            _fail(str(error))
        except Exception as error:
            try:
                explanation = _explain_key(combination)
            except Exception:
                explanation = None
            if explanation is None and "scenario/" in str(error):
                names = sorted(p.stem for p in Path(CONF_DIR, "scenario").glob("*.yaml"))
                explanation = (f"{' '.join(c for c in combination if 'scenario' in c)}: no "
                               f"such scenario; allowed: {', '.join(names)}")
            _fail(explanation or
                  f"{' '.join(combination) or 'default config'}: {_first_line(error)}")


def _existing_run(output_dir, cfg):
    """The run file a job has already made in ``output_dir`` (a sweep run again into its own
    folder): (path, stop reason, whether it has a checkpoint), or (None, None, False)."""
    import h5py

    path = Path(output_dir) / cfg.output.file
    try:
        with h5py.File(path, "r") as f:
            return path, str(f["parameters"].attrs["stop_reason"]), "checkpoint" in f
    except (OSError, KeyError):
        return None, None, False


@hydra.main(config_path=CONF_DIR, config_name="config", version_base="1.3")
def hydra_main(cfg):
    from sim.inspect import summary
    from sim.runner import FINISHED, RunFileError, resume, run

    sweeping = HydraConfig.get().mode == RunMode.MULTIRUN
    output_dir = HydraConfig.get().runtime.output_dir
    try:
        existing, reason, resumable = _existing_run(output_dir, cfg)
        if cfg.resume is not None:
            path = resume(cfg.resume)
        elif existing is not None and reason in FINISHED:
            path = existing  # a sweep run again: this job is complete
            print(f"sim: {path} is complete (stopped by {reason}); not run again")
        elif existing is not None and resumable:
            path = resume(existing)  # a sweep run again: continue the job where it stopped
        else:
            path = run(cfg, output_dir)
    except ConfigError as error:
        if not sweeping:
            _fail(str(error))
        return {"failed": f"ConfigError: {error}"}
    except RunFileError as error:
        if not sweeping:
            print(f"sim: {error}", file=sys.stderr, flush=True)
            # a file whose write failed can crash HDF5 when Python tears down: leave now
            os._exit(EXIT_RUN_FILE)
        return {"failed": f"RunFileError: {error}"}
    except Exception as error:
        if not sweeping:
            raise
        logging.getLogger(__name__).exception("job failed")
        return {"failed": f"{type(error).__name__}: {error}"}
    info = summary(path)
    print(f"{info['scene']}: {info['n']} disks, {info['collisions']} collisions to t = "
          f"{info['time_span'][1]:.6g}, {info['snapshots']} snapshots, energy "
          f"{info['final_energy']:.6g} (dissipated {info['dissipated_energy']:.3g}, balance "
          f"error {info['energy_drift']:.1e}), stopped by {info['stop_reason']}\n"
          f"run file: {path}")
    if info["stop_reason"] == "interrupted" and not sweeping:
        INTERRUPTED.append(path)
    return str(path)


def main():
    check_command_line(sys.argv[1:])
    hydra_main()
    if callbacks.FAILED_JOBS:
        sys.exit(1)
    if INTERRUPTED:
        print(f"sim: interrupted; continue with: python -m sim resume={INTERRUPTED[0]}",
              file=sys.stderr)
        sys.exit(EXIT_INTERRUPTED)


if __name__ == "__main__":
    main()
