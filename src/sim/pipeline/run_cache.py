"""Runs and sweeps made once per resolved config, for the figure stages and the experiments.

A run lives in ``<root>/<label>-<hash>/run.h5``, the hash taken over its resolved config and
how its scene is prepared (:func:`sim.pipeline.scenes.preparation`: a placement that changes under
an unchanged config, such as ``auto`` becoming a melt, is a new run), so a changed config makes
a new run and an unchanged one is reused if it finished. Sweeps run as one
Hydra multirun (``python -m sim … -m``) into ``<root>/<label>-<hash>/``.
"""

import hashlib
import subprocess
import sys
from pathlib import Path

from hydra import compose, initialize_config_dir
from hydra.core.override_parser.overrides_parser import OverridesParser
from omegaconf import OmegaConf

from sim.pipeline.cli import CONF_DIR
from sim.pipeline.config import register
from sim.pipeline.runner import run
from sim.pipeline.scenes import preparation

register()


def compose_config(overrides):
    """The config of ``overrides`` as ``python -m sim`` composes it from ``conf/``."""
    with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
        return compose("config", overrides=list(overrides))


def _identity(cfg):
    """What makes a run this run: its resolved config and how its scene is prepared."""
    return OmegaConf.to_yaml(cfg, resolve=True) + preparation(cfg)


def _digest(text):
    return hashlib.sha1(text.encode()).hexdigest()[:10]


def _run_config(label, overrides, root):
    """The config of a run of ``overrides`` and its folder under ``root``."""
    cfg = compose_config([*overrides, "output.progress=false"])
    return cfg, Path(root) / f"{label}-{_digest(_identity(cfg))}"


def cached_run_folder(label, overrides, root):
    """The folder under ``root`` of the run of ``overrides`` (:func:`ensure_run`)."""
    return _run_config(label, overrides, root)[1]


def ensure_run(label, overrides, root):
    """The run file of ``overrides`` under ``root``, simulated only if not there yet (a run
    cut short there is resumed, :func:`sim.pipeline.runner.run`)."""
    cfg, folder = _run_config(label, overrides, root)
    folder.mkdir(parents=True, exist_ok=True)
    return run(cfg, folder)


def _first_value(override):
    """The first job's value of a sweep override (``key=a,b,c`` → ``key=a``, ``range(0,4)`` →
    0), parsed by Hydra's own override grammar; other overrides stay whole."""
    parsed = OverridesParser.create().parse_override(override)
    if not parsed.is_sweep_override():
        return override
    return f"{parsed.get_key_element()}={next(iter(parsed.sweep_string_iterator()))}"


def cached_sweep_folder(label, overrides, root):
    """The directory under ``root`` of the sweep over ``overrides`` (:func:`ensure_sweep`):
    named by the overrides and the resolved config of its first job, so that a changed scene
    file makes the sweep again."""
    first_job = [_first_value(o) for o in overrides]
    key = " ".join(sorted(overrides)) + _identity(
        compose_config([*first_job, "output.progress=false"]))
    return Path(root) / f"{label}-{_digest(key)}"


def ensure_sweep(label, overrides, root):
    """The directory of a Hydra multirun over ``overrides`` (with comma lists), run only if
    it has not completed before (:func:`cached_sweep_folder`)."""
    folder = cached_sweep_folder(label, overrides, root)
    if not (folder / "sweep_summary.yaml").exists():
        command = [sys.executable, "-m", "sim", *overrides, "output.progress=false",
                   f"hydra.sweep.dir={folder}", "-m"]
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    return folder
