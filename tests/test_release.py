"""The release: a run file records the version sim is installed as (from git tags), and the
scenes' YAML lies inside the package, where the checkout's ``conf`` leads."""

from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import h5py

import sim
from sim.pipeline import runner
from sim.pipeline.config import register
from sim.pipeline.overrides import CONF_DIR, compose_overrides
from sim.storage.inspect import summary

register()


def installed_version():
    """The version of the installed distribution ``sim``, or None when it is not installed."""
    try:
        return version("sim")
    except PackageNotFoundError:
        return None


def test_a_run_file_records_the_installed_version(tmp_path):
    cfg = compose_overrides(["scenario=single_disk", "stop.contacts=20",
                             "output.progress=false"])
    path = runner.run(cfg, tmp_path)
    with h5py.File(path, "r") as f:
        creator = f["h5md/creator"].attrs["version"]
        versions = str(f["parameters"].attrs["versions"])
    installed = installed_version()
    assert creator == sim.__version__ == (installed or "0+unknown")
    assert installed != "0+unknown"  # installed: the version of its tag or commit
    assert versions.startswith(f"sim {creator}, ")
    assert summary(path)["creator"] == f"sim {creator}"


def test_the_scenes_ship_inside_the_package():
    package = Path(sim.__file__).resolve().parent
    assert Path(CONF_DIR) == package / "conf"
    assert (package / "conf" / "config.yaml").is_file()
    assert sorted((package / "conf" / "scenario").glob("*.yaml"))


def test_the_checkouts_conf_is_the_packages():
    checkout = Path(__file__).resolve().parents[1]
    assert (checkout / "conf").resolve() == (checkout / "src" / "sim" / "conf").resolve()

