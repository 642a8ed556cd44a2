"""The release: a run file records the version sim is installed as (from git tags) and the
commit only of sim's own checkout, and the scenes' YAML lies inside the package, where the
checkout's ``conf`` leads."""

import subprocess
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import h5py

import sim
from sim.pipeline import runner, writing
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


def _repository(folder, tracked):
    """A git repository at ``folder`` with one commit of the files ``tracked``; its HEAD."""
    git = ["git", "-C", str(folder), "-c", "user.name=u", "-c", "user.email=u@localhost"]
    subprocess.run(["git", "init", "-q", str(folder)], check=True)
    for name in tracked:
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(name)
    subprocess.run([*git, "add", *tracked], check=True)
    subprocess.run([*git, "commit", "-q", "-m", "one"], check=True)
    return subprocess.run([*git, "rev-parse", "HEAD"], capture_output=True, text=True,
                          check=True).stdout.strip()


def test_the_commit_is_that_of_a_checkout_tracking_sim(tmp_path, monkeypatch):
    head = _repository(tmp_path, ["src/sim/pipeline/writing.py"])
    monkeypatch.setattr(writing, "__file__", str(tmp_path / "src/sim/pipeline/writing.py"))
    assert writing._git_commit() == head


def test_an_install_inside_another_repository_records_no_commit(tmp_path, monkeypatch):
    _repository(tmp_path, ["README"])
    site = tmp_path / ".venv" / "sim" / "pipeline"
    site.mkdir(parents=True)
    (site / "writing.py").write_text("")
    monkeypatch.setattr(writing, "__file__", str(site / "writing.py"))
    assert writing._git_commit() == "unknown"
